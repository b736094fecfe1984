#include "integrate/implicit.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "core/philox.hpp"
#include "integrate/local_mobility.hpp"

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

}  // namespace

ImplicitStepper::ImplicitStepper(System& system, const ImplicitParams& p)
    : st_(system), p_(p), rods_(system.rods()), ranges_(system.ranges()), n_(system.point_count()) {
  if (st_.params().distributed)
    throw std::invalid_argument("ImplicitStepper: the fluid must not be distributed");
  if (!(p_.mobility_scale >= 0)) throw std::invalid_argument("ImplicitStepper: mobility_scale < 0");
  if (p_.krylov_max_iter < 0) throw std::invalid_argument("ImplicitStepper: krylov_max_iter < 0");
  if (p_.jacobian_every < 1) throw std::invalid_argument("ImplicitStepper: jacobian_every < 1");
  if (p_.order != 1 && p_.order != 2)
    throw std::invalid_argument("ImplicitStepper: order not 1 or 2");
  if (p_.order == 2 && (!p_.velocity_form || !(p_.mobility_scale > 0)))
    throw std::invalid_argument(
        "ImplicitStepper: order 2 needs the velocity form and mobility_scale > 0");
  kT_ = st_.params().fluid.thermal_kT;
  drift_ = kT_ > 0 && st_.params().thermal_drift;
  if (kT_ > 0 &&
      (p_.order != 1 || !p_.velocity_form || p_.krylov_max_iter > 0 ||
       p_.local_mobility != ImplicitParams::LocalMobility::overlap || !(p_.mobility_scale > 0)))
    throw std::invalid_argument(
        "ImplicitStepper: thermal noise needs order 1, the velocity form, no GMRES and the "
        "overlap local mobility with mobility_scale > 0 (docs/thermal.md)");
  if (kT_ > 0 && !(p_.thermal_force_local >= 0 && p_.thermal_force_local <= 1))
    throw std::invalid_argument("ImplicitStepper: thermal_force_local not in [0, 1]");
  // with noise the filter takes the full Hessian (the thermal stresses' geometric stiffness;
  // docs/thermal.md "The geometric stiffness in the filter")
  if (kT_ > 0 && p_.thermal_hessian) p_.gauss_newton = false;
  for (auto* v : {&U_, &W_}) v->assign(n_, Vec3::Zero());
  bcc_.resize(rods_.size());

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
  // the overlap's self blocks at the same point, to scale it to the self mobilities
  if (p_.local_mobility == ImplicitParams::LocalMobility::overlap) {
    const Eigen::SparseMatrix<double> O1 =
        kernel_overlap(X, st_.params().grid, st_.params().kernel_width);
    ov_t_ = std::sqrt(m_t_ / O1.coeff(0, 0));
    ov_r_ = std::sqrt(m_r_ / O1.coeff(3, 3));
  }
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

Eigen::MatrixXd ImplicitStepper::mobility_matrix(std::span<const Vec3> X) {
  const int n = int(X.size()), N = 6 * n;
  Eigen::MatrixXd M(N, N);
  std::vector<Vec3> F(n), T(n), U(n), W(n);
  for (int c = 0; c < N; ++c) {
    std::fill(F.begin(), F.end(), Vec3::Zero());
    std::fill(T.begin(), T.end(), Vec3::Zero());
    (c % 6 < 3 ? F : T)[c / 6][c % 3] = 1.0;
    mobility(X, F, T, U, W);
    for (int k = 0; k < n; ++k) {
      M.block<3, 1>(6 * k, c) = U[k];
      M.block<3, 1>(6 * k + 3, c) = W[k];
    }
  }
  return M;
}

namespace {
double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

void ImplicitStepper::overlap_at(std::span<const Vec3> X) {
  const double t1 = now();
  // the taper along each rod (off by default), in points: the narrowest of the rods' (each
  // rod's kernel reach along it, clamped to half the rod)
  double window = 0.0;
  if (p_.overlap_window > 0) {
    window = HUGE_VAL;
    for (const rod::RodRange& g : ranges_) {
      const double reach = 4 * st_.params().kernel_width * st_.params().grid.h() / g.ds;
      window = std::min(window, std::min(p_.overlap_window * reach, 0.5 * g.n));
    }
  }
  Mov_ = kernel_overlap(X, st_.params().grid, st_.params().kernel_width, window, ranges_);
  auto d = [&](Eigen::Index i) { return i % 6 < 3 ? ov_t_ : ov_r_; };
  for (Eigen::Index c = 0; c < Mov_.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(Mov_, c); it; ++it)
      it.valueRef() *= p_.mobility_scale * d(it.row()) * d(it.col());
  timings_.overlap += now() - t1;
}

namespace {
bool same_state(const rod::RodState& a, const rod::RodState& b) {
  return a.X.size() == b.X.size() && std::equal(a.X.begin(), a.X.end(), b.X.begin()) &&
         std::equal(a.D.begin(), a.D.end(), b.D.begin());
}
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
  info.energy_before = c0.E.potential();
  VectorXd b;
  pack(c0.F, c0.T, b);

  if (local || p_.krylov_max_iter > 0) {
    bool moved = false;
    // (with noise the held K, M_loc are those of the previous step's midpoint, only the
    // predictor's: no refresh by displacement)
    if (p_.refresh_displacement > 0 && kT_ <= 0 && have_K_ && X_K_.size() == s.X.size()) {
      const double d2 = p_.refresh_displacement * p_.refresh_displacement;
      for (std::size_t k = 0; k < s.X.size() && !moved; ++k)
        moved = (s.X[k] - X_K_[k]).squaredNorm() > d2;
    }
    if (moved && steps_since_jacobian_ != 0) {  // (a refresh due anyway is not early)
      steps_since_jacobian_ = 0;
      ++timings_.moved_refreshes;
    }
    if (steps_since_jacobian_ == 0 || !have_K_) {
      X_K_ = s.X;
      const double t0 = now();
      // the fast path: no contacts, the local system is block-diagonal over the rods, each
      // block block-cyclic-tridiagonal (closed) or block-tridiagonal (open)
      use_blocks_ = false;
      const bool bands = std::all_of(ranges_.begin(), ranges_.end(), [](const rod::RodRange& g) {
        return BlockCyclicCholesky::fits(g.n, rod::wraps(g));
      });
      const bool overlap = p_.local_mobility == ImplicitParams::LocalMobility::overlap;
      if (p_.block_solver && local && !overlap && p_.gauss_newton && !p_.stiffness_fd &&
          p_.krylov_max_iter == 0 && bands &&
          (!p_.steric_implicit ||
           detail::add_steric_stiffness(st_.steric().params(), s.X, nullptr) == 0)) {
        gn_blocks(s);
        contacts_ = 0;
        use_blocks_ = true;
      } else {
        K_ = stiffness(s);
      }
      if (overlap && local) overlap_at(s.X);  // M_loc = β D O D at qⁿ
      have_K_ = true;
      timings_.stiffness += now() - t0;
      info.jacobian_refreshed = true;
      lu_dt_ = -1;
    }
    steps_since_jacobian_ = (steps_since_jacobian_ + 1) % p_.jacobian_every;
  }
  // ROS2 factorises W = I + γΔt M_loc K
  constexpr double kGamma = 1.0 + 0.70710678118654752440;
  const double wdt = p_.order == 2 ? kGamma * dt : dt;
  // the overlap's LU costs more than a step: between refreshes of K it is kept for any Δt up to
  // 3/2 of the Δt it was made for (W = I + γΔt' M_loc K is a valid W for any Δt', and the stiff
  // modes' amplification 1 − (Δt/Δt') r x/(1 + x) stays within (−1, 1) for (Δt/Δt') r < 2: for a
  // shorter step, e.g. one cut to land on an output time or retried after a rejection, wherever
  // it does with the W of its own Δt). At (5, 0.1 M) to 4 µs with rows every 0.2 µs: 99 LUs
  // instead of 129 with a lower bound of ½ (docs/large_dt.md)
  const bool keep = p_.local_mobility == ImplicitParams::LocalMobility::overlap && lu_dt_ > 0 &&
                    wdt <= 1.5 * lu_dt_;
  if (local && lu_dt_ != wdt && !keep) {
    const double t0 = now();
    factorize(wdt);
    timings_.factorize += now() - t0;
    ++timings_.factorizations;
  }
  auto precondition = [&](const VectorXd& v) -> VectorXd {
    if (!local) return v;
    const double t0 = now();
    VectorXd x = local_solve(v);
    timings_.local_solve += now() - t0;
    return x;
  };
  std::vector<Vec3> aF(n), aT(n), aU(n), aW(n);
  const std::vector<Vec3>* at = &s.X;             // where M is taken (ROS2's stage: elsewhere)
  auto apply_mobility = [&](const VectorXd& g) {  // M g: one Stokes solve
    unpack(g, aF, aT);
    const double t0 = now();
    mobility(*at, aF, aT, aU, aW);
    timings_.stokes += now() - t0;
    ++info.fluid_solves;
    ++timings_.stokes_solves;
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
  // GMRES's products leave on the grid the velocity of a Krylov direction, not of the loads: the
  // field of the last solve of the loads (M F) is kept across them, so that E_K (and E_total,
  // the .vti, the stop rules) stay the fluid's
  auto keep_field = [&] {
    const fluid::FluidSolver& f = st_.fluid();
    const std::size_t n3 = st_.params().grid.size();
    kept_u_.resize(3 * n3);
    for (int c = 0; c < 3; ++c) std::copy_n(f.velocity(c), n3, kept_u_.data() + c * n3);
  };
  auto restore_field = [&] {
    const std::size_t n3 = st_.params().grid.size();
    st_.set_whole_velocity({kept_u_.data(), kept_u_.data() + n3, kept_u_.data() + 2 * n3});
  };
  VectorXd u;
  if (p_.order == 2) {
    // ROS2: W k₁ = M F(qⁿ); W k₂ = M F(qⁿ + Δt k₁) − 2 k₁; u = 3/2 k₁ + 1/2 k₂. W is
    // W_loc = I + γΔt M_loc K (one LU solve a stage), or with GMRES the true
    // W = I + γΔt M K, M at qⁿ in both stages (a W-method needs the same W in both), solved
    // from W_loc⁻¹ rhs by krylov_max_iter iterations right-preconditioned by W_loc (each one
    // Stokes solve, plus one for the first residual). The step is not rejected for a residual
    // above krylov_tol: any W keeps the order, the error estimate judges the step
    auto stage_solve = [&](const VectorXd& rhs) -> VectorXd {
      VectorXd k = precondition(rhs);
      if (krylov && k.allFinite()) {
        auto apply = [&](const VectorXd& x) -> VectorXd {
          return x + wdt * apply_mobility(K_ * x);
        };
        double res = 0;
        double tol = p_.krylov_tol;
        if (p_.krylov_error_budget > 0) {
          const double bnorm = std::sqrt(dot(rhs, rhs));
          // Δt ‖r‖/√n: the residual's move of the rod's points in RMS
          if (bnorm > 0)
            tol = std::max(tol, p_.krylov_error_budget * std::sqrt(double(n)) / (dt * bnorm));
        }
        info.krylov_iterations +=
            gmres(apply, precondition, rhs, k, p_.krylov_max_iter, tol, dot, res);
        info.residual = std::max(info.residual, res);
      }
      return k;
    };
    const VectorXd k1 = stage_solve(apply_mobility(b));
    unpack(k1, U_, W_);
    stage_ = s;
    rod::advance(stage_, U_, W_, dt);
    VectorXd b2;
    bool stage_finite = k1.allFinite();
    if (stage_finite) {
      try {
        const double t0 = now();
        st_.compute_forces(stage_);
        timings_.forces += now() - t0;
        pack(st_.forces(), st_.torques(), b2);
        stage_finite = b2.allFinite();
      } catch (const std::exception&) {  // a position out of any range: not finite
        stage_finite = false;
      }
    }
    if (!stage_finite) {
      u = VectorXd::Constant(6 * n, std::numeric_limits<double>::quiet_NaN());
    } else {
      at = &stage_.X;
      const VectorXd f2 = apply_mobility(b2);
      at = &s.X;
      if (krylov) keep_field();
      const VectorXd k2 = stage_solve(VectorXd(f2 - 2.0 * k1));
      if (krylov) restore_field();
      u = 1.5 * k1 + 0.5 * k2;
      // the embedded first-order solution qⁿ + Δt k₁ is Δt ½ (k₁ + k₂) away
      for (int k = 0; k < n; ++k) {
        const double ex = 0.5 * dt * (k1.segment<3>(6 * k) + k2.segment<3>(6 * k)).norm();
        const double er = 0.5 * dt * (k1.segment<3>(6 * k + 3) + k2.segment<3>(6 * k + 3)).norm();
        info.error = std::max({info.error, ex, p_.rotation_length * er});
      }
    }
  } else if (kT_ > 0) {
    // with thermal noise (docs/thermal.md, "The implicit step with noise"; a = 0: candidate D)
    //   u = A [J G 𝒮(F + (1 − a) f_K) + J G ξ + a M_loc f_K],  A = (I + Δt M_loc K)⁻¹,
    // G = (−μL_h)⁻¹P, ξ the random stress of the same solve, f_K ~ N(0, kT K_GN): the
    // displacement's covariance Δt² A (2kT M/Δt + kT M K M) Aᵀ for a = 0. The filter A (through
    // M_loc and K) and, with the drift, J are taken at the step's midpoint
    // q̃ = qⁿ ⊕ (Δt/2) u₀, u₀ a predictor with the filter held (docs/thermal.md "Why the
    // implicit step with noise was hot": A(qⁿ) makes the noise multiplicative in the stiff
    // strains and the stretch/shear energy runs away)
    const std::uint64_t step = st_.fluid().noise_step();
    const double a = p_.thermal_force_local;
    const std::size_t pts = drift_ ? 3 * std::size_t(n) : std::size_t(n);
    Xn_.resize(pts);
    Fn_.resize(pts);
    Tn_.assign(pts, Vec3::Zero());
    const VectorXd fK =
        p_.thermal_force ? thermal_force(s, step) : VectorXd(VectorXd::Zero(6 * Eigen::Index(n)));
    // the rod's points and forces of the solve: F + (1 − a) f_K at Xⁿ
    for (int k = 0; k < n; ++k) {
      Xn_[k] = s.X[k];
      Fn_[k] = c0.F[k] + (1 - a) * fK.segment<3>(6 * k);
      Tn_[k] = c0.T[k] + (1 - a) * fK.segment<3>(6 * k + 3);
    }
    if (drift_) {
      // the random finite difference of the spreading (as Stepper::drift_step: the force pairs
      // ±(kT/δ) W̃_k at X_k ± (δ/2) W̃_k, W̃ keyed by (seed; k, 1, step)): in the mean the force
      // density kT ∂_X·𝒮, whose Stokes response J G kT ∂_X·𝒮 the rod picks up with M F
      const double delta = 1e-4 * st_.params().grid.h();
      const std::uint64_t seed = st_.params().fluid.seed;
      const std::uint32_t key0 = std::uint32_t(seed), key1 = std::uint32_t(seed >> 32);
      const std::uint32_t st0 = std::uint32_t(step), st1 = std::uint32_t(step >> 32);
      for (int k = 0; k < n; ++k) {
        double z[6];
        unit_variance6(philox4x32_10({std::uint32_t(k), 1u, st0, st1}, key0, key1), z);
        const Vec3 w(z[0], z[1], z[2]);
        Xn_[n + k] = s.X[k] + (0.5 * delta) * w;
        Xn_[2 * n + k] = s.X[k] - (0.5 * delta) * w;
        Fn_[n + k] = (kT_ / delta) * w;
        Fn_[2 * n + k] = -(kT_ / delta) * w;
      }
    }
    ib::PlaneCoupler& pc = st_.plane_coupler();
    fluid::FluidSolver& fl = st_.fluid();
    fl.set_dt(dt);  // the random stress's variance is 2kT/Δt
    // the Stokes solve of the forces and the random stress, U, W interpolated at Xⁿ
    const double t0 = now();
    pc.prepare(Xn_, Fn_, Tn_);
    {
      const PlaneCouplerSampler sampler(pc, std::size_t(n));  // the force pairs: spread only
      fl.solve_stokes(PlaneCouplerForcing(pc), &sampler, true);
    }
    pc.finish_interpolation(U_, W_, std::size_t(n));
    timings_.stokes += now() - t0;
    ++info.fluid_solves;
    ++timings_.stokes_solves;
    VectorXd v;
    pack(U_, W_, v);
    auto local_share = [&]() {  // a M_loc f_K (M_loc held, then q̃'s)
      return a > 0 ? VectorXd(a * (Mov_ * fK)) : VectorXd(VectorXd::Zero(6 * Eigen::Index(n)));
    };
    // the predictor, with the filter held (the previous step's midpoint one, or qⁿ's after a
    // refresh): it only places the midpoint
    u = precondition(VectorXd(v + local_share()));
    // the midpoint q̃ and its filter: M_loc (the kernel overlap of neighbouring points, over
    // its sub-kernel modes) and K (through X′ and the triads) depend on the stiff strains
    // themselves; a covariance taken at the midpoint is the same for the step and its
    // reverse, as for an additive noise
    mid_ = s;
    unpack(u, U_, W_);
    rod::advance(mid_, U_, W_, 0.5 * dt);
    {
      const double t1 = now();
      K_ = stiffness(mid_);
      overlap_at(mid_.X);
      X_K_ = mid_.X;
      const double t2 = now();
      timings_.stiffness += t2 - t1;
      factorize(wdt);
      timings_.factorize += now() - t2;
      ++timings_.factorizations;
    }
    // (f_K stays at qⁿ: taken at q̃ too — a second Stokes solve — it measured no cooler,
    // docs/thermal.md)
    if (drift_) {
      // (∂_X J) : G 𝒮 by the midpoint interpolation U, W = J(X̃) u, X̃ = Xⁿ + (Δt/2) u_X (the
      // midpoint q̃'s positions): the velocity the solve left on the grid, sampled plane by
      // plane as Stepper::drift_step does (its mean over the noise is kT (∂_X J) : (A J G) —
      // the Stokes-limit velocity covariance 2kT G/Δt on every mode — filtered like M F)
      const double t1 = now();
      pc.prepare(mid_.X, {}, {});
      const int N = st_.params().grid.n;
      const std::size_t np = std::size_t(N) * std::size_t(N);
      const std::array<const double*, 3> ug{fl.velocity(0), fl.velocity(1), fl.velocity(2)};
#pragma omp parallel for schedule(static)
      for (int i = 0; i < N; ++i)
        pc.sample_plane(i, {ug[0] + i * np, ug[1] + i * np, ug[2] + i * np});
      pc.finish_interpolation(U_, W_);
      timings_.stokes += now() - t1;
      pack(U_, W_, v);
    }
    u = precondition(VectorXd(v + local_share()));
  } else if (p_.velocity_form) {
    // (I + Δt M K) u = M F, δ = Δt u; the IMEX guess u₀ = (I + Δt M_loc K)⁻¹ M F
    const VectorXd mf = apply_mobility(b);
    u = precondition(mf);
    if (krylov) {
      auto apply = [&](const VectorXd& x) -> VectorXd { return x + dt * apply_mobility(K_ * x); };
      keep_field();
      info.krylov_iterations =
          gmres(apply, precondition, mf, u, p_.krylov_max_iter, p_.krylov_tol, dot, info.residual);
      info.converged = info.residual <= p_.krylov_tol;
      restore_field();
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
      info.energy_after = forces_at(s).E.potential();
    } catch (const std::exception&) {  // a position out of any range: not finite
      info.finite = false;
    }
  }
  if (!info.finite) info.energy_after = HUGE_VAL;
  return info;
}

double ImplicitStepper::power() const {
  // after a step prev_ holds the loads at its start (an undone step swapped them back)
  return has_prev_ ? integrate::power(prev_.F, prev_.T, U_, W_)
                   : std::numeric_limits<double>::quiet_NaN();
}

StepOutcome outcome(const ImplicitStepInfo& info) {
  StepOutcome o;
  o.max_displacement = info.max_displacement;
  o.max_rotation = info.max_rotation;
  o.energy_change = info.energy_after - info.energy_before;
  o.converged = info.converged;
  o.finite = info.finite;
  o.error = info.error;
  return o;
}

ImplicitStepInfo step_adaptive(ImplicitStepper& stepper, rod::RodState& s, AdaptiveDt& ctl,
                               double cap, double* dt_taken, int* rejected) {
  int undone = 0;
  for (;;) {
    const double dt = std::min(ctl.dt(), cap);
    const ImplicitStepInfo info = stepper.step(s, dt);
    StepOutcome o = outcome(info);
    o.dt = dt;
    if (ctl.judge(o)) {
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

ImplicitIntegrator::ImplicitIntegrator(System& system, const ImplicitParams& p,
                                       const AdaptiveDtParams& a)
    : stepper_(system, p), ctl_(a) {}

double ImplicitIntegrator::advance(rod::RodState& s, double max_dt) {
  if (stepper_.thermal()) {
    // with noise a step is never judged: a controller that rejects steps by their outcome
    // would select the noise and bias the statistics. A fixed Δt = the controller's largest
    // step (time.dt_ns), as the explicit scheme's (adaptive() is false: the cap is not taken,
    // so a run cut at any step and resumed takes the same steps; docs/thermal.md)
    const double dt = ctl_.params().dt_max;
    info_ = stepper_.step(s, dt);
    rejected_ = 0;
    return dt;
  }
  double dt = 0;
  info_ = step_adaptive(stepper_, s, ctl_, max_dt, &dt, &rejected_);
  return dt;
}

void ImplicitIntegrator::restore(const State& st) {
  ctl_ = AdaptiveDt(ctl_.params(), st.next_dt, st.accepted_in_a_row);
  if (st.held && stepper_.thermal())
    stepper_.restore_held_filter(*st.held, ctl_.params().dt_max);  // (noise: a fixed Δt)
  else
    stepper_.refresh_jacobian();
}

std::optional<ImplicitStepper::HeldFilter> ImplicitStepper::held_filter() const {
  // with noise every step ends with K, M_loc and the LU made at its midpoint mid_
  if (kT_ <= 0 || !have_K_ || lu_dt_ <= 0 || steps_since_jacobian_ == 0) return std::nullopt;
  return HeldFilter{steps_since_jacobian_, mid_};
}

void ImplicitStepper::restore_held_filter(const HeldFilter& h, double dt) {
  if (kT_ <= 0) throw std::logic_error("ImplicitStepper::restore_held_filter: no thermal noise");
  if (h.at.size() != n_ || h.steps_since_refresh <= 0)
    throw std::invalid_argument("ImplicitStepper::restore_held_filter: a filter state of " +
                                std::to_string(h.at.size()) + " points (the rods have " +
                                std::to_string(n_) + ") or a count of " +
                                std::to_string(h.steps_since_refresh) + " steps (≥ 1)");
  // as the thermal step makes them at its midpoint
  mid_ = h.at;
  const double t0 = now();
  use_blocks_ = false;
  K_ = stiffness(mid_);
  overlap_at(mid_.X);
  X_K_ = mid_.X;
  have_K_ = true;
  timings_.stiffness += now() - t0;
  const double t1 = now();
  factorize(dt);
  timings_.factorize += now() - t1;
  ++timings_.factorizations;
  steps_since_jacobian_ = h.steps_since_refresh % p_.jacobian_every;
}

}  // namespace ibrod::integrate
