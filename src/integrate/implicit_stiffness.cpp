// The local half of the implicit step (implicit.hpp): the Gauss–Newton elastic stiffness K and
// the steric contacts' stiffness, and the factorisation and solve of M_loc⁻¹ + Δt K.
#include "integrate/implicit.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "core/philox.hpp"

namespace ibrod::integrate {

using Vec6 = Eigen::Matrix<double, 6, 1>;

namespace {

using Eigen::VectorXd;

// Colours of the points of rod g such that two points of one colour are at least 3 apart along
// the rod (rod::along: round a ring): perturbing all of them at once changes each F_k, T_k
// through one of them at most. Greedy: ≤ 5 colours, 3 when n is a multiple of 3 or the rod is
// open.
std::vector<int> colouring(const rod::RodRange& g) {
  const int n = g.n;
  std::vector<int> c(n, -1);
  for (int k = 0; k < n; ++k) {
    bool used[8] = {};
    for (int o = -2; o <= 2; ++o) {
      const int j = rod::along(g, k, o);
      if (j < 0) continue;
      if (o != 0 && c[j] >= 0) used[c[j]] = true;
    }
    int col = 0;
    while (used[col]) ++col;
    c[k] = col;
  }
  return c;
}

// C = diag(b1, b2, b3, a1, a2, a3) of half point h: the link's moduli (rod.moduli_file) or the
// scalars.
Vec6 moduli(const rod::RodParams& rp, int h) {
  const Vec3& a = rp.a_k.empty() ? rp.a : rp.a_k[h];
  const Vec3& b = rp.b_k.empty() ? rp.b : rp.b_k[h];
  Eigen::Matrix<double, 6, 1> c;
  c << b.x(), b.y(), b.z(), a.x(), a.y(), a.z();
  return c;
}

using Mat6 = Eigen::Matrix<double, 6, 6>;

// The small-strain strain Jacobian of the half point between points a and b (triad Dh,
// X′ = xp): JL = ∂(Γ, Ω)/∂q_a, JR = ∂(Γ, Ω)/∂q_b (ImplicitStepper::gn_blocks below).
void link_jacobians(const Mat3& Dh, const Vec3& xp, double ds, Mat6& JL, Mat6& JR) {
  Mat3 G;  // rows (D^i × X′)ᵀ
  for (int i = 0; i < 3; ++i) G.row(i) = Dh.col(i).cross(xp).transpose();
  JL.setZero();
  JR.setZero();
  JL.block<3, 3>(0, 0) = -Dh.transpose() / ds;
  JR.block<3, 3>(0, 0) = Dh.transpose() / ds;
  JL.block<3, 3>(0, 3) = 0.5 * G;
  JR.block<3, 3>(0, 3) = 0.5 * G;
  JL.block<3, 3>(3, 3) = -Dh.transpose() / ds;
  JR.block<3, 3>(3, 3) = Dh.transpose() / ds;
}

/// Calls fn(a, b, ds, c, JL, JR) for every link h of every rod (its points a and b, the rod's Δs,
/// the link's moduli c = (b1, b2, b3, a1, a2, a3) and the strain Jacobians ∂(Γ, Ω)/∂q_a,
/// ∂(Γ, Ω)/∂q_b at s): the one walk of the Gauss–Newton K and of its thermal force.
template <class Fn>
void for_each_link(const std::vector<rod::RodParams>& rods,
                   const std::vector<rod::RodRange>& ranges, const rod::RodState& s, Fn&& fn) {
  rod::for_each_rod(ranges, [&](std::size_t r, const rod::RodRange& g) {
    const rod::RodParams& rp = rods[r];
    for (int h = 0; h < rod::links(g); ++h) {
      const int a = g.offset + h, b = g.offset + (h + 1) % g.n;
      Mat6 JL, JR;
      link_jacobians(rod::half_point_triad(s.D[a], s.D[b]), (s.X[b] - s.X[a]) / rp.ds, rp.ds, JL,
                     JR);
      fn(a, b, rp.ds, moduli(rp, h), JL, JR);
    }
  });
}

}  // namespace

namespace detail {

// The steric contacts' stiffness −∂F_steric/∂X, added to K as triplets: for each pair of
// segments in contact (closest points P(s), Q(t) at d < D along u), the linearisation of
// g (D − d) u with s, t and u frozen, g w wᵀ ⊗ u uᵀ, w = (1 − s, s, −(1 − t), −t) over the
// end points (X_k, X_{k+1}, X_l, X_{l+1}): positive semi-definite. (The transverse term
// −g (D − d)/d (I − u uᵀ), small at small overlap and destabilising, is left out.) Candidate
// segment pairs from a cell grid over the midpoints; trip = nullptr: count the contacts only.
int add_steric_stiffness(const interactions::StericParams& p, std::span<const Vec3> X,
                         std::vector<Eigen::Triplet<double>>* trip) {
  const int n = int(X.size());
  if (!p.enabled || n < 4 || !(p.diameter > 0) || !(p.stiffness > 0)) return 0;
  // the segments [X_a, X_b] as interactions::Steric lists them: each rod's own, in order
  const std::vector<rod::RodRange> chains = interactions::steric_rods(p, n);
  std::vector<int> seg_a, seg_b, seg_chain, seg_pos;
  for (std::size_t r = 0; r < chains.size(); ++r) {
    const rod::RodRange& c = chains[r];
    if (c.n < 2) continue;
    for (int k = 0; k < rod::links(c); ++k) {
      seg_a.push_back(c.offset + k);
      seg_b.push_back(c.offset + (k + 1) % c.n);
      seg_chain.push_back(int(r));
      seg_pos.push_back(k);
    }
  }
  const int ns = int(seg_a.size());
  // more than 2D apart along the rod (MODEL (2.17)), as Steric; segments of two rods always
  auto far_along_rod = [&](int k, int l) {
    if (seg_chain[k] != seg_chain[l]) return true;
    const rod::RodRange& c = chains[std::size_t(seg_chain[k])];
    return rod::arc_separation(c, seg_pos[k], seg_pos[l]) * c.ds > 2 * p.diameter;
  };
  std::vector<Vec3> mid(ns);
  double lmax2 = 0;
  for (int k = 0; k < ns; ++k) {
    mid[k] = 0.5 * (X[seg_a[k]] + X[seg_b[k]]);
    lmax2 = std::max(lmax2, (X[seg_b[k]] - X[seg_a[k]]).squaredNorm());
  }
  const double reach = p.diameter + std::sqrt(lmax2);
  // candidates from a grid of cells of edge `reach` over the midpoints (sorted by cell key):
  // for each k, the partners l > k in the 27 cells around it, in ascending order
  auto cell = [&](const Vec3& x, int d) { return std::int64_t(std::floor(x[d] / reach)); };
  auto key = [](std::int64_t i, std::int64_t j, std::int64_t k) {
    return ((i & 0x1FFFFF) << 42) | ((j & 0x1FFFFF) << 21) | (k & 0x1FFFFF);
  };
  std::vector<std::pair<std::int64_t, int>> sorted(ns);
  for (int k = 0; k < ns; ++k)
    sorted[k] = {key(cell(mid[k], 0), cell(mid[k], 1), cell(mid[k], 2)), k};
  std::sort(sorted.begin(), sorted.end());
  int contacts = 0;
  std::vector<int> partners;
  for (int k = 0; k < ns; ++k) {
    partners.clear();
    const std::int64_t ci = cell(mid[k], 0), cj = cell(mid[k], 1), ck = cell(mid[k], 2);
    for (std::int64_t di = -1; di <= 1; ++di)
      for (std::int64_t dj = -1; dj <= 1; ++dj)
        for (std::int64_t dk = -1; dk <= 1; ++dk) {
          const std::int64_t q = key(ci + di, cj + dj, ck + dk);
          auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(q, -1));
          for (; it != sorted.end() && it->first == q; ++it) {
            const int l = it->second;
            if (l > k && far_along_rod(k, l)) partners.push_back(l);
          }
        }
    std::sort(partners.begin(), partners.end());
    for (const int l : partners) {
      if ((mid[k] - mid[l]).squaredNorm() >= reach * reach) continue;
      const int k0 = seg_a[k], k1 = seg_b[k], l0 = seg_a[l], l1 = seg_b[l];
      const auto c = interactions::closest_points(X[k0], X[k1], X[l0], X[l1]);
      if (!(c.d < p.diameter) || !(c.d > 0)) continue;
      ++contacts;
      if (!trip) continue;
      const Vec3 u = c.sep / c.d;
      const Mat3 uu = p.stiffness * u * u.transpose();
      const int idx[4] = {k0, k1, l0, l1};
      const double w[4] = {1 - c.s, c.s, -(1 - c.t), -c.t};
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
          for (int r = 0; r < 3; ++r)
            for (int q = 0; q < 3; ++q)
              trip->emplace_back(6 * idx[a] + r, 6 * idx[b] + q, w[a] * w[b] * uu(r, q));
    }
  }
  return contacts;
}

}  // namespace detail

void ImplicitStepper::gn_blocks(const rod::RodState& s) {
  // Gauss–Newton with the small-strain strain Jacobian of half point h (between k and k+1,
  // triad D_h = [D¹ D² D³], X′ = (X_{k+1} − X_k)/Δs), MODEL §4 step 2 linearised:
  //   δΓ_i = D^i·(δX_{k+1} − δX_k)/Δs + ½ (D^i × X′)·(δθ_k + δθ_{k+1})
  //   δΩ_i = D^i·(δθ_{k+1} − δθ_k)/Δs
  // (a common rotation leaves Γ unchanged; the half-point triad turns by the mean of its two
  // ends'). K = Δs Σ_h J_hᵀ C_h J_h, C_h = diag(b1, b2, b3, a1, a2, a3) of link h (per link with
  // rod.moduli_file): symmetric positive semi-definite, O(n). Each rod on its own range with its
  // own Δs and moduli, over its links (an open rod has no link from its last point to its
  // first): block-cyclic-tridiagonal per closed rod, block-tridiagonal per open one:
  // Kd_[k] = K[k][k], Ko_[k] = K[k+1][k].
  // tests/unit/integrate/test_implicit_parts.cpp compares it with the finite-difference K.
  Kd_.assign(n_, Mat6::Zero());
  Ko_.assign(n_, Mat6::Zero());
  for_each_link(rods_, ranges_, s,
                [&](int a, int b, double ds, const Vec6& c, const Mat6& JL, const Mat6& JR) {
                  const Mat6 CL = ds * c.asDiagonal() * JL, CR = ds * c.asDiagonal() * JR;
                  Kd_[a].noalias() += JL.transpose() * CL;
                  Kd_[b].noalias() += JR.transpose() * CR;
                  Ko_[a].noalias() = JR.transpose() * CL;  // K[h+1][h]
                });
}

Eigen::VectorXd ImplicitStepper::thermal_force(const rod::RodState& s, std::uint64_t step) const {
  // f_K = Σ_h J_hᵀ √(kT Δs C_h) η_h: covariance Σ_h J_hᵀ kT Δs C_h J_h = kT K_GN (gn_blocks)
  VectorXd f = VectorXd::Zero(6 * Eigen::Index(n_));
  const std::uint64_t seed = st_.params().fluid.seed;
  const std::uint32_t key0 = std::uint32_t(seed), key1 = std::uint32_t(seed >> 32);
  const std::uint32_t st0 = std::uint32_t(step), st1 = std::uint32_t(step >> 32);
  for_each_link(rods_, ranges_, s,
                [&](int a, int b, double ds, const Vec6& c, const Mat6& JL, const Mat6& JR) {
                  double z[6];  // counter word 1 = 2: apart from the stress (0), the drift (1)
                  unit_variance6(philox4x32_10({std::uint32_t(a), 2u, st0, st1}, key0, key1), z);
                  Vec6 y;
                  for (int i = 0; i < 6; ++i) y[i] = std::sqrt(kT_ * ds * c[i]) * z[i];
                  f.segment<6>(6 * a) += JL.transpose() * y;
                  f.segment<6>(6 * b) += JR.transpose() * y;
                });
  return f;
}

Eigen::SparseMatrix<double> ImplicitStepper::stiffness(const rod::RodState& s) {
  if (s.size() != n_)
    throw std::invalid_argument("ImplicitStepper: the state has " + std::to_string(s.size()) +
                                " points, the rods " + std::to_string(n_));
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(std::size_t(n_) * 3 * 36 + 4096);
  if (p_.gauss_newton && !p_.stiffness_fd) {
    gn_blocks(s);
    for (const rod::RodRange& g : ranges_) {
      const int links = rod::links(g);
      for (int h = 0; h < g.n; ++h) {
        const int a = g.offset + h, b = g.offset + (h + 1) % g.n;
        for (int r = 0; r < 6; ++r)
          for (int q = 0; q < 6; ++q) {
            trip.emplace_back(6 * a + r, 6 * a + q, Kd_[a](r, q));
            if (h >= links) continue;
            trip.emplace_back(6 * b + r, 6 * a + q, Ko_[a](r, q));
            trip.emplace_back(6 * a + r, 6 * b + q, Ko_[a](q, r));
          }
      }
    }
  } else {
    for (std::size_t r = 0; r < rods_.size(); ++r) fd_stiffness(s, r, trip);
  }
  contacts_ =
      p_.steric_implicit ? detail::add_steric_stiffness(st_.steric().params(), s.X, &trip) : 0;
  Eigen::SparseMatrix<double> K(6 * n_, 6 * n_);
  K.setFromTriplets(trip.begin(), trip.end());
  K.makeCompressed();
  return K;
}

void ImplicitStepper::fd_stiffness(const rod::RodState& all, std::size_t rod_index,
                                   std::vector<Eigen::Triplet<double>>& trip) {
  // rod r alone, on a copy of its range: its elastic loads depend on its own points only
  const rod::RodParams& rp = rods_[rod_index];
  const rod::RodRange& g = ranges_[rod_index];
  const int n = g.n, off = g.offset;
  const int links = rod::links(g);
  rod::RodState s;
  rod::extract(all, g, s);
  pert_ = s;
  work_.resize(n);
  for (auto* v : {&Fa_, &Ta_, &Fb_, &Tb_}) v->assign(n, Vec3::Zero());
  const std::vector<int> col = colouring(g);
  const int ncol = *std::max_element(col.begin(), col.end()) + 1;
  // the neighbour of point j at offset o along the rod (−1: past an open rod's end)
  auto along = [&](int j, int o) { return rod::along(g, j, o); };
  // Gauss–Newton: the stress resultants of half point h, σ_h = (D_hᵀF_h, D_hᵀN_h) = C (ε_h − ε₀),
  // and their derivatives S_L = ∂σ_h/∂q_h, S_R = ∂σ_h/∂q_{h+1} by the same differences
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  std::vector<Mat6> SL, SR;
  std::vector<Vec6> sp, sm;
  if (p_.gauss_newton) {
    SL.assign(n, Mat6::Zero());
    SR.assign(n, Mat6::Zero());
    sp.assign(n, Vec6::Zero());
    sm.assign(n, Vec6::Zero());
  }
  auto sigma = [&](int h) {
    Vec6 v;
    v.head<3>() = work_.Dh[h].transpose() * work_.Fh[h];
    v.tail<3>() = work_.Dh[h].transpose() * work_.Nh[h];
    return v;
  };
  auto forces = [&](std::vector<Vec3>& F, std::vector<Vec3>& T, std::vector<Vec6>& sig, int c) {
    std::fill(F.begin(), F.end(), Vec3::Zero());
    std::fill(T.begin(), T.end(), Vec3::Zero());
    rod::elastic_forces(rp, pert_, work_, F, T);
    if (p_.gauss_newton)
      for (int j = 0; j < n; ++j)
        if (col[j] == c) {
          const int jm = along(j, -1);
          if (j < links) sig[j] = sigma(j);
          if (jm >= 0) sig[jm] = sigma(jm);
        }
  };
  for (int c = 0; c < ncol; ++c) {
    for (int d = 0; d < 6; ++d) {
      const double eps = d < 3 ? p_.fd_dx : p_.fd_dtheta;
      for (int side = 0; side < 2; ++side) {
        const double e = side == 0 ? eps : -eps;
        for (int j = 0; j < n; ++j) {
          if (col[j] != c) continue;
          if (d < 3)
            pert_.X[j][d] = s.X[j][d] + e;
          else
            pert_.D[j] = rotation(e * Vec3::Unit(d - 3)) * s.D[j];
        }
        if (side == 0)
          forces(Fa_, Ta_, sp, c);
        else
          forces(Fb_, Tb_, sm, c);
      }
      for (int j = 0; j < n; ++j) {
        if (col[j] != c) continue;
        pert_.X[j] = s.X[j];
        pert_.D[j] = s.D[j];
        if (p_.gauss_newton) {
          const int jm = along(j, -1);
          if (j < links) SL[j].col(d) = (sp[j] - sm[j]) / (2 * eps);
          if (jm >= 0) SR[jm].col(d) = (sp[jm] - sm[jm]) / (2 * eps);
          continue;
        }
        for (int o = -1; o <= 1; ++o) {
          const int i = along(j, o);
          if (i < 0) continue;
          for (int r = 0; r < 3; ++r) {
            trip.emplace_back(6 * (off + i) + r, 6 * (off + j) + d,
                              -(Fa_[i][r] - Fb_[i][r]) / (2 * eps));
            trip.emplace_back(6 * (off + i) + 3 + r, 6 * (off + j) + d,
                              -(Ta_[i][r] - Tb_[i][r]) / (2 * eps));
          }
        }
      }
    }
  }
  if (p_.gauss_newton) {
    // K = Δs Σ_h J_hᵀ C_h J_h = Δs Σ_h S_hᵀ C_h⁻¹ S_h over the points h, h+1 of each half point
    for (int h = 0; h < links; ++h) {
      const int h1 = (h + 1) % n;
      const Vec6 cinv = moduli(rp, h).cwiseInverse();
      const int idx[2] = {off + h, off + h1};
      const Mat6* S[2] = {&SL[h], &SR[h]};
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
          const Mat6 blk = rp.ds * S[a]->transpose() * cinv.asDiagonal() * (*S[b]);
          for (int r = 0; r < 6; ++r)
            for (int q = 0; q < 6; ++q)
              trip.emplace_back(6 * idx[a] + r, 6 * idx[b] + q, blk(r, q));
        }
    }
  }
}

void ImplicitStepper::factorize(double dt) {
  if (p_.local_mobility == ImplicitParams::LocalMobility::overlap) {
    // A = I + Δt M_loc K (velocity form) or I + Δt K M_loc, M_loc banded along the rod and over
    // close strands: sparse LU, the pattern analysed again whenever it changes. The LU's
    // symmetric mode: diagonal pivots unless below 0.1 of the column's largest (A is I plus a
    // matrix whose eigenvalues have non-negative real parts; ~25 % faster than partial pivoting
    // at the reference, prototypes/large_dt/overlap_solve_bench)
    Eigen::SparseMatrix<double> A = p_.velocity_form ? Eigen::SparseMatrix<double>(Mov_ * K_)
                                                     : Eigen::SparseMatrix<double>(K_ * Mov_);
    A *= dt;
    for (int i = 0; i < 6 * n_; ++i) A.coeffRef(i, i) += 1.0;
    A.makeCompressed();
    const bool same = pattern_ready_ &&
                      std::equal(lu_outer_.begin(), lu_outer_.end(), A.outerIndexPtr(),
                                 A.outerIndexPtr() + A.outerSize() + 1) &&
                      std::size_t(A.nonZeros()) == lu_inner_.size() &&
                      std::equal(lu_inner_.begin(), lu_inner_.end(), A.innerIndexPtr());
    if (!same) {
      const auto t0 = std::chrono::steady_clock::now();
      lu_.isSymmetric(true);
      lu_.setPivotThreshold(0.1);
      lu_.analyzePattern(A);
      timings_.analyze +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      pattern_ready_ = true;
      lu_outer_.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
      lu_inner_.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
    }
    lu_.factorize(A);
    if (lu_.info() != Eigen::Success)
      throw std::runtime_error("ImplicitStepper: the local implicit system is singular");
    lu_dt_ = dt;
    return;
  }
  // M_loc = β diag(m_t I, m_r I)
  mloc_.resize(6 * n_);
  for (int k = 0; k < n_; ++k) {
    mloc_.segment<3>(6 * k).setConstant(p_.mobility_scale * m_t_);
    mloc_.segment<3>(6 * k + 3).setConstant(p_.mobility_scale * m_r_);
  }
  if (use_blocks_) {
    // block-diagonal over the rods: each rod's band factorised on its own
    std::vector<Eigen::Matrix<double, 6, 6>>& diag = sdiag_;
    std::vector<Eigen::Matrix<double, 6, 6>>& lower = slower_;
    rod::for_each_rod(ranges_, [&](std::size_t r, const rod::RodRange& g) {
      diag.resize(g.n);
      lower.resize(g.n);
      for (int j = 0; j < g.n; ++j) {
        const int k = g.offset + j;
        diag[j] = dt * Kd_[k];
        for (int i = 0; i < 6; ++i) diag[j](i, i) += 1.0 / mloc_[6 * k + i];
        lower[j] = dt * Ko_[k];
      }
      if (!bcc_[r].factorize(diag, lower, rod::wraps(g)))
        throw std::runtime_error("ImplicitStepper: the local implicit system is not positive");
    });
    lu_dt_ = dt;
    return;
  }
  const bool contacts_changed = contacts_ > 0 || pattern_contacts_ > 0;
  if (p_.gauss_newton) {
    // K symmetric positive semi-definite: I + Δt M_loc K = M_loc (M_loc⁻¹ + Δt K), and
    // S = M_loc⁻¹ + Δt K is symmetric positive definite: sparse Cholesky (AMD ordering)
    Eigen::SparseMatrix<double> S = dt * K_;
    for (int i = 0; i < 6 * n_; ++i) S.coeffRef(i, i) += 1.0 / mloc_[i];
    S.makeCompressed();
    if (!pattern_ready_ || S.nonZeros() != pattern_nnz_ || contacts_changed) {
      llt_.analyzePattern(S);
      pattern_ready_ = true;
      pattern_nnz_ = S.nonZeros();
      pattern_contacts_ = contacts_;
    }
    llt_.factorize(S);
    if (llt_.info() != Eigen::Success)
      throw std::runtime_error("ImplicitStepper: the local implicit system is not positive");
    lu_dt_ = dt;
    return;
  }
  // velocity form: A = I + Δt M_loc K (row scaling); force form: I + Δt K M_loc (columns)
  Eigen::SparseMatrix<double> A = p_.velocity_form
                                      ? Eigen::SparseMatrix<double>(mloc_.asDiagonal() * K_)
                                      : Eigen::SparseMatrix<double>(K_ * mloc_.asDiagonal());
  A *= dt;
  for (int i = 0; i < 6 * n_; ++i) A.coeffRef(i, i) += 1.0;
  A.makeCompressed();
  // the band along the rod is fixed; steric contacts add and remove entries
  if (!pattern_ready_ || A.nonZeros() != pattern_nnz_ || contacts_changed) {
    lu_.analyzePattern(A);
    pattern_ready_ = true;
    pattern_nnz_ = A.nonZeros();
    pattern_contacts_ = contacts_;
  }
  lu_.factorize(A);
  if (lu_.info() != Eigen::Success)
    throw std::runtime_error("ImplicitStepper: the local implicit system is singular");
  lu_dt_ = dt;
}

Eigen::VectorXd ImplicitStepper::local_solve(const Eigen::VectorXd& v) const {
  if (use_blocks_) {
    VectorXd x = p_.velocity_form ? VectorXd(v.cwiseQuotient(mloc_)) : v;
    rod::for_each_rod(ranges_, [&](std::size_t r, const rod::RodRange& g) {
      bcc_[r].solve(x.segment(6 * g.offset, 6 * g.n));
    });
    return p_.velocity_form ? x : VectorXd(x.cwiseQuotient(mloc_));
  }
  if (!p_.gauss_newton || p_.local_mobility == ImplicitParams::LocalMobility::overlap)
    return lu_.solve(v);
  // velocity form: (I + Δt M_loc K) x = v ⇔ S x = M_loc⁻¹ v;
  // force form: (I + Δt K M_loc) x = v ⇔ S (M_loc x) = v
  if (p_.velocity_form) return llt_.solve(VectorXd(v.cwiseQuotient(mloc_)));
  return VectorXd(llt_.solve(v)).cwiseQuotient(mloc_);
}

}  // namespace ibrod::integrate
