#include "integrate/implicit.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "core/error.hpp"

namespace ibrod::integrate {

namespace {

using Eigen::VectorXd;

// A vector of the 6n rod unknowns, per point (x, y, z, θx, θy, θz) or (F, T) or (U, W).
void pack(std::span<const Vec3> a, std::span<const Vec3> b, VectorXd& v) {
  const std::size_t n = a.size();
  v.resize(6 * Eigen::Index(n));
  for (std::size_t k = 0; k < n; ++k) {
    v.segment<3>(6 * k) = a[k];
    v.segment<3>(6 * k + 3) = b[k];
  }
}
void unpack(const VectorXd& v, std::span<Vec3> a, std::span<Vec3> b) {
  for (std::size_t k = 0; k < a.size(); ++k) {
    a[k] = v.segment<3>(6 * k);
    b[k] = v.segment<3>(6 * k + 3);
  }
}

// Colours of a closed rod of n points such that two points of one colour are at least 3 apart
// along the rod (cyclically): perturbing all of them at once changes each F_k, T_k through one
// of them at most. Greedy: ≤ 5 colours, 3 when n is a multiple of 3.
std::vector<int> colouring(int n) {
  std::vector<int> c(n, -1);
  for (int k = 0; k < n; ++k) {
    bool used[8] = {};
    for (int o = -2; o <= 2; ++o) {
      const int j = ((k + o) % n + n) % n;
      if (o != 0 && c[j] >= 0) used[c[j]] = true;
    }
    int col = 0;
    while (used[col]) ++col;
    c[k] = col;
  }
  return c;
}

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
  std::vector<Vec3> mid(n);
  double lmax2 = 0;
  for (int k = 0; k < n; ++k) {
    mid[k] = 0.5 * (X[k] + X[(k + 1) % n]);
    lmax2 = std::max(lmax2, (X[(k + 1) % n] - X[k]).squaredNorm());
  }
  const double reach = p.diameter + std::sqrt(lmax2);
  // candidates from a grid of cells of edge `reach` over the midpoints (sorted by cell key):
  // for each k, the partners l > k in the 27 cells around it, in ascending order
  auto cell = [&](const Vec3& x, int d) { return std::int64_t(std::floor(x[d] / reach)); };
  auto key = [](std::int64_t i, std::int64_t j, std::int64_t k) {
    return ((i & 0x1FFFFF) << 42) | ((j & 0x1FFFFF) << 21) | (k & 0x1FFFFF);
  };
  std::vector<std::pair<std::int64_t, int>> sorted(n);
  for (int k = 0; k < n; ++k)
    sorted[k] = {key(cell(mid[k], 0), cell(mid[k], 1), cell(mid[k], 2)), k};
  std::sort(sorted.begin(), sorted.end());
  int contacts = 0;
  std::vector<int> partners;
  for (int k = 0; k < n; ++k) {
    partners.clear();
    const std::int64_t ci = cell(mid[k], 0), cj = cell(mid[k], 1), ck = cell(mid[k], 2);
    for (std::int64_t di = -1; di <= 1; ++di)
      for (std::int64_t dj = -1; dj <= 1; ++dj)
        for (std::int64_t dk = -1; dk <= 1; ++dk) {
          const std::int64_t q = key(ci + di, cj + dj, ck + dk);
          auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(q, -1));
          for (; it != sorted.end() && it->first == q; ++it) {
            const int l = it->second, m = l - k;
            // more than 2D apart along the rod (MODEL (2.17)), as Steric
            if (l > k && std::min(m, n - m) * p.ds > 2 * p.diameter) partners.push_back(l);
          }
        }
    std::sort(partners.begin(), partners.end());
    for (const int l : partners) {
      if ((mid[k] - mid[l]).squaredNorm() >= reach * reach) continue;
      const int k1 = (k + 1) % n, l1 = (l + 1) % n;
      const auto c = interactions::closest_points(X[k], X[k1], X[l], X[l1]);
      if (!(c.d < p.diameter) || !(c.d > 0)) continue;
      ++contacts;
      if (!trip) continue;
      const Vec3 u = c.sep / c.d;
      const Mat3 uu = p.stiffness * u * u.transpose();
      const int idx[4] = {k, k1, l, l1};
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

}  // namespace

ImplicitStepper::ImplicitStepper(Stepper& stepper, const ImplicitParams& p)
    : st_(stepper), p_(p), n_(stepper.params().rod.n) {
  if (st_.params().distributed)
    throw std::invalid_argument("ImplicitStepper: the fluid must not be distributed");
  if (!(p_.mobility_scale >= 0)) throw std::invalid_argument("ImplicitStepper: mobility_scale < 0");
  if (p_.krylov_max_iter < 0) throw std::invalid_argument("ImplicitStepper: krylov_max_iter < 0");
  if (p_.jacobian_every < 1) throw std::invalid_argument("ImplicitStepper: jacobian_every < 1");
  work_.resize(n_);
  for (auto* v : {&U_, &W_, &Fa_, &Ta_, &Fb_, &Tb_}) v->assign(n_, Vec3::Zero());

  // Self mobilities of one kernel-spread point: a unit force (torque) at a generic position
  // of the grid, the velocity (angular velocity) interpolated at the same point.
  const double h = st_.params().grid.h();
  const Vec3 x0 = Vec3(0.31, 0.57, 0.73) * h;
  const std::vector<Vec3> X{x0}, Z{Vec3::Zero()};
  std::vector<Vec3> U(1), W(1);
  mobility(X, std::vector<Vec3>{Vec3(1, 0, 0)}, Z, U, W);
  m_t_ = U[0].x();
  mobility(X, Z, std::vector<Vec3>{Vec3(0, 0, 1)}, U, W);
  m_r_ = W[0].z();
  scale_t_ = std::sqrt(m_r_ / m_t_);
}

ImplicitStepper::~ImplicitStepper() = default;

void ImplicitStepper::mobility(std::span<const Vec3> X, std::span<const Vec3> F,
                               std::span<const Vec3> T, std::span<Vec3> U, std::span<Vec3> W) {
  ib::PlaneCoupler& pc = st_.plane_coupler();
  pc.prepare(X, F, T);
  const PlaneCouplerSampler sampler(pc);
  st_.fluid().solve_stokes(PlaneCouplerForcing(pc), &sampler);
  pc.finish_interpolation(U, W);
}

void ImplicitStepper::gn_blocks(const rod::RodState& s) {
  // Gauss–Newton with the small-strain strain Jacobian of half point h (between k and k+1,
  // triad D_h = [D¹ D² D³], X′ = (X_{k+1} − X_k)/Δs), MODEL §4 step 2 linearised:
  //   δΓ_i = D^i·(δX_{k+1} − δX_k)/Δs + ½ (D^i × X′)·(δθ_k + δθ_{k+1})
  //   δΩ_i = D^i·(δθ_{k+1} − δθ_k)/Δs
  // (a common rotation leaves Γ unchanged; the half-point triad turns by the mean of its two
  // ends'). K = Δs Σ_h J_hᵀ C J_h, C = diag(b1, b2, b3, a1, a2, a3): symmetric positive
  // semi-definite, O(n), block-cyclic-tridiagonal: Kd_[k] = K[k][k], Ko_[k] = K[k+1][k].
  // tests/unit/integrate/test_implicit_parts.cpp compares it with the finite-difference K.
  const int n = s.size();
  const rod::RodParams& rp = st_.params().rod;
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  Kd_.assign(n, Mat6::Zero());
  Ko_.assign(n, Mat6::Zero());
  Eigen::Matrix<double, 6, 1> c;
  c << rp.b.x(), rp.b.y(), rp.b.z(), rp.a.x(), rp.a.y(), rp.a.z();
  for (int h = 0; h < n; ++h) {
    const int h1 = (h + 1) % n;
    const Mat3 Dh = rod::half_point_triad(s.D[h], s.D[h1]);
    const Vec3 xp = (s.X[h1] - s.X[h]) / rp.ds;
    Mat3 G;  // rows (D^i × X′)ᵀ
    for (int i = 0; i < 3; ++i) G.row(i) = Dh.col(i).cross(xp).transpose();
    Mat6 JL = Mat6::Zero(), JR = Mat6::Zero();  // ∂(Γ, Ω)/∂q_h, ∂(Γ, Ω)/∂q_{h+1}
    JL.block<3, 3>(0, 0) = -Dh.transpose() / rp.ds;
    JR.block<3, 3>(0, 0) = Dh.transpose() / rp.ds;
    JL.block<3, 3>(0, 3) = 0.5 * G;
    JR.block<3, 3>(0, 3) = 0.5 * G;
    JL.block<3, 3>(3, 3) = -Dh.transpose() / rp.ds;
    JR.block<3, 3>(3, 3) = Dh.transpose() / rp.ds;
    const Mat6 CL = rp.ds * c.asDiagonal() * JL, CR = rp.ds * c.asDiagonal() * JR;
    Kd_[h].noalias() += JL.transpose() * CL;
    Kd_[h1].noalias() += JR.transpose() * CR;
    Ko_[h].noalias() = JR.transpose() * CL;  // K[h+1][h]
  }
}

Eigen::SparseMatrix<double> ImplicitStepper::stiffness(const rod::RodState& s) {
  const int n = s.size();
  const rod::RodParams& rp = st_.params().rod;
  if (p_.gauss_newton && !p_.stiffness_fd) {
    gn_blocks(s);
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(std::size_t(n) * 3 * 36 + 4096);
    for (int h = 0; h < n; ++h) {
      const int h1 = (h + 1) % n;
      for (int r = 0; r < 6; ++r)
        for (int q = 0; q < 6; ++q) {
          trip.emplace_back(6 * h + r, 6 * h + q, Kd_[h](r, q));
          trip.emplace_back(6 * h1 + r, 6 * h + q, Ko_[h](r, q));
          trip.emplace_back(6 * h + r, 6 * h1 + q, Ko_[h](q, r));
        }
    }
    contacts_ = p_.steric_implicit ? add_steric_stiffness(st_.params().steric, s.X, &trip) : 0;
    Eigen::SparseMatrix<double> K(6 * n, 6 * n);
    K.setFromTriplets(trip.begin(), trip.end());
    K.makeCompressed();
    return K;
  }
  const std::vector<int> col = colouring(n);
  const int ncol = *std::max_element(col.begin(), col.end()) + 1;
  pert_ = s;
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(std::size_t(n) * 3 * 36 + 4096);
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  // Gauss–Newton: the stress resultants of half point h, σ_h = (D_hᵀF_h, D_hᵀN_h) = C (ε_h − ε₀),
  // and their derivatives S_L = ∂σ_h/∂q_h, S_R = ∂σ_h/∂q_{h+1} by the same differences
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
          const int jm = (j + n - 1) % n;
          sig[j] = sigma(j);
          sig[jm] = sigma(jm);
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
          const int jm = (j + n - 1) % n;
          SL[j].col(d) = (sp[j] - sm[j]) / (2 * eps);
          SR[jm].col(d) = (sp[jm] - sm[jm]) / (2 * eps);
          continue;
        }
        for (int o = -1; o <= 1; ++o) {
          const int i = ((j + o) % n + n) % n;
          for (int r = 0; r < 3; ++r) {
            trip.emplace_back(6 * i + r, 6 * j + d, -(Fa_[i][r] - Fb_[i][r]) / (2 * eps));
            trip.emplace_back(6 * i + 3 + r, 6 * j + d, -(Ta_[i][r] - Tb_[i][r]) / (2 * eps));
          }
        }
      }
    }
  }
  if (p_.gauss_newton) {
    // K = Δs Σ_h J_hᵀ C J_h = Δs Σ_h S_hᵀ C⁻¹ S_h over the points h, h+1 of each half point
    Vec6 cinv;
    cinv << 1 / rp.b.x(), 1 / rp.b.y(), 1 / rp.b.z(), 1 / rp.a.x(), 1 / rp.a.y(), 1 / rp.a.z();
    for (int h = 0; h < n; ++h) {
      const int h1 = (h + 1) % n;
      const int idx[2] = {h, h1};
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
  contacts_ = p_.steric_implicit ? add_steric_stiffness(st_.params().steric, s.X, &trip) : 0;
  Eigen::SparseMatrix<double> K(6 * n, 6 * n);
  K.setFromTriplets(trip.begin(), trip.end());
  K.makeCompressed();
  return K;
}

void ImplicitStepper::factorize(double dt) {
  // M_loc = β diag(m_t I, m_r I)
  mloc_.resize(6 * n_);
  for (int k = 0; k < n_; ++k) {
    mloc_.segment<3>(6 * k).setConstant(p_.mobility_scale * m_t_);
    mloc_.segment<3>(6 * k + 3).setConstant(p_.mobility_scale * m_r_);
  }
  if (use_blocks_) {
    std::vector<Eigen::Matrix<double, 6, 6>>& diag = sdiag_;
    std::vector<Eigen::Matrix<double, 6, 6>>& lower = slower_;
    diag.resize(n_);
    lower.resize(n_);
    for (int k = 0; k < n_; ++k) {
      diag[k] = dt * Kd_[k];
      for (int i = 0; i < 6; ++i) diag[k](i, i) += 1.0 / mloc_[6 * k + i];
      lower[k] = dt * Ko_[k];
    }
    if (!bcc_.factorize(diag, lower))
      throw std::runtime_error("ImplicitStepper: the local implicit system is not positive");
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
    bcc_.solve(x);
    return p_.velocity_form ? x : VectorXd(x.cwiseQuotient(mloc_));
  }
  if (!p_.gauss_newton) return lu_.solve(v);
  // velocity form: (I + Δt M_loc K) x = v ⇔ S x = M_loc⁻¹ v;
  // force form: (I + Δt K M_loc) x = v ⇔ S (M_loc x) = v
  if (p_.velocity_form) return llt_.solve(VectorXd(v.cwiseQuotient(mloc_)));
  return VectorXd(llt_.solve(v)).cwiseQuotient(mloc_);
}

namespace {
double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
bool same_state(const rod::RodState& a, const rod::RodState& b) {
  return a.X.size() == b.X.size() && std::equal(a.X.begin(), a.X.end(), b.X.begin()) &&
         std::equal(a.D.begin(), a.D.end(), b.D.begin());
}
double potential(const StepEnergies& e) { return e.elastic.total() + e.electro + e.steric; }
}  // namespace

namespace {
// GMRES(m) without restart, right-preconditioned: solves A x = b from x (in/out) in the inner
// product `dot`, stopping at ‖b − A x‖ ≤ tol ‖b‖ or after m iterations. `apply` is A (here: one
// Stokes solve each), `prec` the right preconditioner. Returns the iterations; rel_res the
// relative residual (Arnoldi's estimate, exact in exact arithmetic).
template <class Apply, class Prec, class Dot>
int gmres(const Apply& apply, const Prec& prec, const VectorXd& b, VectorXd& x, int m, double tol,
          const Dot& dot, double& rel_res) {
  auto norm = [&](const VectorXd& a) { return std::sqrt(dot(a, a)); };
  const double bnorm = norm(b);
  VectorXd r = b - apply(x);
  double rnorm = norm(r);
  rel_res = bnorm > 0 ? rnorm / bnorm : 0.0;
  if (rel_res <= tol || m == 0) return 0;
  std::vector<VectorXd> V{r / rnorm}, Z;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m + 1, m);
  VectorXd cs = VectorXd::Zero(m), sn = VectorXd::Zero(m), e = VectorXd::Zero(m + 1);
  e[0] = rnorm;
  int j = 0;
  while (j < m) {
    Z.push_back(prec(V[j]));
    VectorXd w = apply(Z[j]);
    for (int i = 0; i <= j; ++i) {  // modified Gram–Schmidt
      H(i, j) = dot(w, V[i]);
      w -= H(i, j) * V[i];
    }
    const double hnext = norm(w);
    H(j + 1, j) = hnext;
    for (int i = 0; i < j; ++i) {  // the previous Givens rotations
      const double t = cs[i] * H(i, j) + sn[i] * H(i + 1, j);
      H(i + 1, j) = -sn[i] * H(i, j) + cs[i] * H(i + 1, j);
      H(i, j) = t;
    }
    const double rr = std::hypot(H(j, j), H(j + 1, j));
    cs[j] = H(j, j) / rr;
    sn[j] = H(j + 1, j) / rr;
    H(j, j) = rr;
    H(j + 1, j) = 0;
    e[j + 1] = -sn[j] * e[j];
    e[j] = cs[j] * e[j];
    ++j;
    rel_res = std::abs(e[j]) / bnorm;
    if (rel_res <= tol || hnext == 0 || j == m) break;
    V.push_back(w / hnext);
  }
  const VectorXd c = H.topLeftCorner(j, j).triangularView<Eigen::Upper>().solve(e.head(j));
  for (int i = 0; i < j; ++i) x += c[i] * Z[i];
  return j;
}
}  // namespace

const ImplicitStepper::Cached& ImplicitStepper::forces_at(const rod::RodState& s) {
  if (!has_cur_ || !same_state(cur_.q, s)) {
    const double t0 = now();
    cur_.E = st_.compute_forces(s);
    timings_.forces += now() - t0;
    cur_.q = s;
    cur_.F = st_.forces();
    cur_.T = st_.torques();
    has_cur_ = true;
  }
  return cur_;
}

void ImplicitStepper::undo(rod::RodState& s) {
  if (!has_prev_) throw std::logic_error("ImplicitStepper::undo: no step to undo");
  s = prev_.q;
  std::swap(cur_, prev_);
  has_cur_ = true;
  has_prev_ = false;
}

ImplicitStepInfo ImplicitStepper::step(rod::RodState& s, double dt) {
  ImplicitStepInfo info;
  const int n = n_;
  const bool local = p_.mobility_scale > 0;
  const Cached& c0 = forces_at(s);
  last_ = c0.E;
  info.energy_before = potential(c0.E);
  VectorXd b;
  pack(c0.F, c0.T, b);

  if (local || p_.krylov_max_iter > 0) {
    if (steps_since_jacobian_ == 0 || !have_K_) {
      const double t0 = now();
      // the fast path: no contacts, the local system is block-cyclic-tridiagonal
      use_blocks_ = false;
      if (p_.block_solver && local && p_.gauss_newton && !p_.stiffness_fd &&
          p_.krylov_max_iter == 0 && n >= 3 &&
          (!p_.steric_implicit || add_steric_stiffness(st_.params().steric, s.X, nullptr) == 0)) {
        gn_blocks(s);
        contacts_ = 0;
        use_blocks_ = true;
      } else {
        K_ = stiffness(s);
      }
      have_K_ = true;
      timings_.stiffness += now() - t0;
      info.jacobian_refreshed = true;
      lu_dt_ = -1;
    }
    steps_since_jacobian_ = (steps_since_jacobian_ + 1) % p_.jacobian_every;
  }
  if (local && lu_dt_ != dt) {
    const double t0 = now();
    factorize(dt);
    timings_.factorize += now() - t0;
  }
  auto precondition = [&](const VectorXd& v) -> VectorXd {
    if (!local) return v;
    const double t0 = now();
    VectorXd x = local_solve(v);
    timings_.local_solve += now() - t0;
    return x;
  };
  std::vector<Vec3> aF(n), aT(n), aU(n), aW(n);
  auto apply_mobility = [&](const VectorXd& g) {  // M g: one Stokes solve
    unpack(g, aF, aT);
    const double t0 = now();
    mobility(s.X, aF, aT, aU, aW);
    timings_.stokes += now() - t0;
    ++info.fluid_solves;
    VectorXd u;
    pack(aU, aW, u);
    return u;
  };
  // weights of the inner products: torques over ℓ = √(m_t/m_r) in the force form, angular
  // velocities times ℓ in the velocity form (mobility-balanced)
  VectorXd w2(6 * n);
  const double wr = p_.velocity_form ? 1.0 / (scale_t_ * scale_t_) : scale_t_ * scale_t_;
  for (int k = 0; k < n; ++k) {
    w2.segment<3>(6 * k).setOnes();
    w2.segment<3>(6 * k + 3).setConstant(wr);
  }
  auto dot = [&](const VectorXd& x, const VectorXd& y) {
    return (x.array() * y.array() * w2.array()).sum();
  };
  const bool krylov = p_.krylov_max_iter > 0;
  VectorXd u;
  if (p_.velocity_form) {
    // (I + Δt M K) u = M F, δ = Δt u; the IMEX guess u₀ = (I + Δt M_loc K)⁻¹ M F
    const VectorXd mf = apply_mobility(b);
    u = precondition(mf);
    if (krylov) {
      auto apply = [&](const VectorXd& x) -> VectorXd { return x + dt * apply_mobility(K_ * x); };
      info.krylov_iterations =
          gmres(apply, precondition, mf, u, p_.krylov_max_iter, p_.krylov_tol, dot, info.residual);
      info.converged = info.residual <= p_.krylov_tol;
    }
  } else {
    // (I + Δt K M) g = F, δ = Δt M g; the IMEX guess g₀ = (I + Δt K M_loc)⁻¹ F
    VectorXd g = precondition(b);
    if (krylov) {
      auto apply = [&](const VectorXd& x) -> VectorXd { return x + dt * (K_ * apply_mobility(x)); };
      info.krylov_iterations =
          gmres(apply, precondition, b, g, p_.krylov_max_iter, p_.krylov_tol, dot, info.residual);
      info.converged = info.residual <= p_.krylov_tol;
    }
    u = apply_mobility(g);  // (with Krylov: one more solve than iterations + 1)
  }
  unpack(u, U_, W_);
  for (int k = 0; k < n; ++k) {
    info.max_displacement = std::max(info.max_displacement, dt * U_[k].norm());
    info.max_rotation = std::max(info.max_rotation, dt * W_[k].norm());
  }
  // qⁿ⁺¹; its forces now (energy_after), kept for the next step
  std::swap(prev_, cur_);
  has_prev_ = true;
  has_cur_ = false;
  rod::advance(s, U_, W_, dt);
  info.finite = std::isfinite(info.max_displacement) && std::isfinite(info.max_rotation);
  if (info.finite) {
    try {
      info.energy_after = potential(forces_at(s).E);
    } catch (const std::exception&) {  // a position out of any range: not finite
      info.finite = false;
    }
  }
  if (!info.finite) info.energy_after = HUGE_VAL;
  return info;
}

StepOutcome outcome(const ImplicitStepInfo& info) {
  StepOutcome o;
  o.max_displacement = info.max_displacement;
  o.max_rotation = info.max_rotation;
  o.energy_change = info.energy_after - info.energy_before;
  o.converged = info.converged;
  o.finite = info.finite;
  return o;
}

ImplicitStepInfo step_adaptive(ImplicitStepper& stepper, rod::RodState& s, AdaptiveDt& ctl,
                               double cap, double* dt_taken, int* rejected) {
  int undone = 0;
  for (;;) {
    const double dt = std::min(ctl.dt(), cap);
    const ImplicitStepInfo info = stepper.step(s, dt);
    if (ctl.judge(outcome(info))) {
      if (dt_taken) *dt_taken = dt;
      if (rejected) *rejected = undone;
      return info;
    }
    stepper.undo(s);
    if (++undone >= 60)
      throw RunError("implicit step: 60 trial steps rejected in a row (last Δt = " +
                     std::to_string(dt) + " s)");
  }
}

ImplicitIntegrator::ImplicitIntegrator(Stepper& stepper, const ImplicitParams& p,
                                       const AdaptiveDtParams& a)
    : stepper_(stepper, p), ctl_(a) {}

double ImplicitIntegrator::advance(rod::RodState& s, double max_dt) {
  double dt = 0;
  info_ = step_adaptive(stepper_, s, ctl_, max_dt, &dt, &rejected_);
  return dt;
}

void ImplicitIntegrator::restore(const State& st) {
  ctl_ = AdaptiveDt(ctl_.params(), st.next_dt, st.accepted_in_a_row);
  stepper_.refresh_jacobian();
}

}  // namespace ibrod::integrate
