#include "sim/stability.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "core/types.hpp"
#include "sim/simulation.hpp"

namespace ibrod::sim {

namespace {

double uniform01(std::mt19937_64& g) { return double(g() >> 11) * 0x1.0p-53; }

// The kick of step 3 (see the header) of the rod laid out as rod_range (s holds it alone), drawn
// from g: positions out of the mean plane, triads turned with their tangents, then the twist.
void kick(rod::RodState& s, const rod::RodRange& rod_range, const StabilityProbe& p,
          std::mt19937_64& g) {
  const int n = s.size();
  const double phi2 = 2 * std::numbers::pi * uniform01(g);
  const double u3 = 2 * uniform01(g) - 1;
  const double phi3 = 2 * std::numbers::pi * uniform01(g);
  std::vector<double> u(std::size_t(p.modes)), psi(std::size_t(p.modes));
  for (int m = 0; m < p.modes; ++m) {
    u[std::size_t(m)] = 2 * uniform01(g) - 1;
    psi[std::size_t(m)] = 2 * std::numbers::pi * uniform01(g);
  }
  if (p.kick > 0 && n >= 3) {
    Vec3 c = Vec3::Zero();
    for (const Vec3& x : s.X) c += x;
    c /= double(n);
    Mat3 G = Mat3::Zero();
    for (const Vec3& x : s.X) G += (x - c) * (x - c).transpose();
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(G);  // eigenvalues ascending
    const Vec3 normal = eig.eigenvectors().col(0);
    const Vec3 e1 = eig.eigenvectors().col(2), e2 = eig.eigenvectors().col(1);
    // central differences; one-sided at the free ends of an open rod
    auto tangent = [&](const std::vector<Vec3>& X, int k) {
      const int a = rod::point_before(rod_range, k), b = rod::point_after(rod_range, k);
      return Vec3(X[std::size_t(b)] - X[std::size_t(a)]).normalized();
    };
    std::vector<Vec3> X = s.X;
    for (int k = 0; k < n; ++k) {
      const Vec3 r = s.X[std::size_t(k)] - c;
      const double phi = std::atan2(r.dot(e2), r.dot(e1));
      X[std::size_t(k)] +=
          p.kick * (std::cos(2 * phi + phi2) + u3 * std::cos(3 * phi + phi3)) * normal;
    }
    for (int k = 0; k < n; ++k) {
      const Vec3 t0 = tangent(s.X, k), t1 = tangent(X, k);
      const Vec3 axis = t0.cross(t1);
      const double angle = std::atan2(axis.norm(), t0.dot(t1));
      if (axis.norm() > 0) s.D[k] = rotation(angle * axis.normalized()) * s.D[k];
    }
    s.X = std::move(X);
  }
  for (int k = 0; k < n; ++k) {
    const double th = 2 * std::numbers::pi * double(k) / double(n);
    double twist = 0;
    for (int m = 0; m < p.modes; ++m)
      twist += u[std::size_t(m)] * std::sin(double(m + 1) * th + psi[std::size_t(m)]);
    twist *= p.amplitude;
    s.D[k] = rotation(twist * s.D[k].col(2)) * s.D[k];
  }
}

// E_total along a copy's probe, sampled at the first step at or past each of kSamples equal
// divisions of the probe time.
constexpr int kSamples = 100;
struct Trace {
  std::vector<double> t, E;  ///< s, kT
  /// E at time t, linear between the samples (held at the ends)
  double at(double time) const {
    if (time <= t.front()) return E.front();
    if (time >= t.back()) return E.back();
    const auto i = std::size_t(std::upper_bound(t.begin(), t.end(), time) - t.begin());
    const double w = (time - t[i - 1]) / (t[i] - t[i - 1]);
    return (1 - w) * E[i - 1] + w * E[i];
  }
};

// Integrates sim from t0 until the probe time T has passed (whatever steps the scheme takes: with
// an adaptive Δt the count is not known in advance), sampling E_total; returns the steps taken.
std::int64_t integrate(Simulation& sim, double t0, double T, Trace& trace) {
  std::int64_t steps = 0;
  int next = 1;  // the next division to sample
  for (;;) {
    sim.step();
    ++steps;
    const double half = 0.5 * sim.dt();
    if (sim.time() >= t0 + next * T / kSamples - half) {
      trace.t.push_back(sim.time());
      trace.E.push_back(sim.total_energy_kT());
      while (next <= kSamples && sim.time() >= t0 + next * T / kSamples - half) ++next;
    }
    if (sim.time() >= t0 + T - half) break;
  }
  return steps;
}


// E of a rod does not change when every triad turns by the same angle about its own d3 (the
// body frame's strains turn about their third axis) iff bending, shear and the intrinsic
// curvature are isotropic in the cross-section plane at every link.
bool spin_invariant(const rod::RodParams& r) {
  auto iso = [](const Vec3& a, const Vec3& b) {
    return a.x() == a.y() && b.x() == b.y();
  };
  if (!iso(r.a, r.b) || r.omega0.x() != 0 || r.omega0.y() != 0) return false;
  for (std::size_t k = 0; k < r.a_k.size(); ++k)
    if (!iso(r.a_k[k], r.b_k[k])) return false;
  for (const Vec3& w : r.omega0_k)
    if (w.x() != 0 || w.y() != 0) return false;
  return true;
}

// The Hessian method (see the header): fills o's hessian fields and min_difference_kT, and
// leaves sim at the state kicked along the softest mode when unstable.
void hessian_probe(Simulation& sim, const StabilityProbe& p, ProbeOutcome& o) {
  o.hessian = true;
  const double kT = sim.params().kT;
  integrate::System& sys = sim.system();
  const rod::RodState s = sim.rod();
  const int n = s.size(), N = 6 * n;
  const double ell = sim.rods().front().ds;  // rotations × ℓ: Å
  const double dx = 1e-3;                    // Å, and dx/ℓ rad
  sys.compute_forces(s);
  double g2 = 0;
  for (int k = 0; k < n; ++k)
    g2 += sys.forces()[std::size_t(k)].squaredNorm() +
          (sys.torques()[std::size_t(k)] / ell).squaredNorm();
  o.gradient_kT_per_A = std::sqrt(g2) / kT;
  Eigen::MatrixXd H(N, N);
  rod::RodState q = s;
  std::vector<Vec3> Fa, Ta;
  for (int j = 0; j < N; ++j) {
    const int k = j / 6, d = j % 6;
    for (int side = 0; side < 2; ++side) {
      const double e = side == 0 ? dx : -dx;
      if (d < 3)
        q.X[std::size_t(k)][d] = s.X[std::size_t(k)][d] + e;
      else
        q.D[std::size_t(k)] = rotation((e / ell) * Vec3::Unit(d - 3)) * s.D[std::size_t(k)];
      sys.compute_forces(q);
      if (side == 0) {
        Fa = sys.forces();
        Ta = sys.torques();
        continue;
      }
      const std::vector<Vec3>& Fb = sys.forces();
      const std::vector<Vec3>& Tb = sys.torques();
      for (int i = 0; i < n; ++i)
        for (int r = 0; r < 3; ++r) {
          H(6 * i + r, j) = -(Fa[std::size_t(i)][r] - Fb[std::size_t(i)][r]) / (2 * dx * kT);
          H(6 * i + 3 + r, j) = -(Ta[std::size_t(i)][r] - Tb[std::size_t(i)][r]) / (2 * dx * ell * kT);
        }
    }
    q.X[std::size_t(k)] = s.X[std::size_t(k)];
    q.D[std::size_t(k)] = s.D[std::size_t(k)];
  }
  sys.compute_forces(s);  // leave the system's loads at the state, as a step would
  o.asymmetry = (H - H.transpose()).norm() / std::max(H.norm(), 1e-300);
  // the zero modes: translations, rotations about the centroid, each spin-invariant rod's spin
  std::vector<Eigen::VectorXd> zero;
  Vec3 c = Vec3::Zero();
  for (const Vec3& x : s.X) c += x;
  c /= double(n);
  for (int a = 0; a < 3; ++a) {
    Eigen::VectorXd t = Eigen::VectorXd::Zero(N), w = Eigen::VectorXd::Zero(N);
    for (int k = 0; k < n; ++k) {
      t(6 * k + a) = 1;
      w.segment<3>(6 * k) = Vec3::Unit(a).cross(s.X[std::size_t(k)] - c);
      w(6 * k + 3 + a) = ell;
    }
    zero.push_back(t);
    zero.push_back(w);
  }
  for (std::size_t r = 0; r < sim.rods().size(); ++r) {
    if (!spin_invariant(sim.rods()[r])) continue;
    const rod::RodRange& g = sim.rod_ranges()[r];
    Eigen::VectorXd v = Eigen::VectorXd::Zero(N);
    for (int k = g.offset; k < g.offset + g.n; ++k)
      v.segment<3>(6 * k + 3) = ell * s.D[std::size_t(k)].col(2);
    zero.push_back(v);
  }
  Eigen::MatrixXd Z(N, Eigen::Index(zero.size()));
  for (std::size_t i = 0; i < zero.size(); ++i) Z.col(Eigen::Index(i)) = zero[i];
  Eigen::MatrixXd Q = Eigen::HouseholderQR<Eigen::MatrixXd>(Z).householderQ() *
                      Eigen::MatrixXd::Identity(N, Z.cols());
  // each uniform closed rod's slithering, where it is not already (nearly) a rigid motion plus
  // the spin (a circle's is exactly one): the part of it that the modes above leave, if that
  // keeps more than kSlitherResidual of its length
  for (std::size_t r = 0; r < sim.rods().size(); ++r) {
    if (!slither_invariant(sim.rods()[r])) continue;
    const Eigen::VectorXd v = slithering_vector(s, sim.rod_ranges()[r], ell);
    Eigen::VectorXd w = v - Q * (Q.transpose() * v);
    w -= Q * (Q.transpose() * w);  // twice is enough
    if (w.norm() <= StabilityProbe::kSlitherResidual * v.norm()) continue;
    Q.conservativeResize(Eigen::NoChange, Q.cols() + 1);
    Q.col(Q.cols() - 1) = w.normalized();
    ++o.slithering_modes;
  }
  o.zero_modes = int(Q.cols());
  // P Hs P with P = I − Q Qᵀ: the zero modes get eigenvalue 0 exactly, which the count skips
  Eigen::MatrixXd Hs = 0.5 * (H + H.transpose());
  H.resize(0, 0);
  const Eigen::MatrixXd HQ = Hs * Q;
  Hs -= HQ * Q.transpose() + Q * HQ.transpose();
  Hs += Q * (Q.transpose() * HQ) * Q.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Hs);
  // the zero modes sit at 0 among the others: drop the o.zero_modes eigenvalues nearest 0 whose
  // vectors lie in span(Q)
  std::vector<int> keep;
  for (int i = 0; i < N; ++i)
    if ((Q.transpose() * eig.eigenvectors().col(i)).norm() < 0.5) keep.push_back(i);
  const double tol = p.tolerance / kT;
  const int first = keep.front();
  for (std::size_t i = 0; i < keep.size() && o.lowest_eigenvalues.size() < 8; ++i)
    o.lowest_eigenvalues.push_back(eig.eigenvalues()[keep[i]]);
  auto kick_energy = [&](int i, double& scale) {
    const Eigen::VectorXd v = eig.eigenvectors().col(i);
    double vmax = 0;
    for (int k = 0; k < n; ++k) vmax = std::max(vmax, v.segment<6>(6 * k).norm());
    scale = p.kick / vmax;
    return 0.5 * eig.eigenvalues()[i] * scale * scale;
  };
  for (int i : keep) {
    double sc;
    if (eig.eigenvalues()[i] >= 0) break;
    if (kick_energy(i, sc) < -tol) ++o.negative_modes;
  }
  double scale = 0;
  o.min_difference_kT = kick_energy(first, scale);
  o.stable = !(o.min_difference_kT < -tol);
  o.E_continuation_kT = o.E_after_kT = o.E_before_kT;
  o.writhe_continuation = o.writhe_after = o.writhe_before;
  if (o.stable) return;
  // unstable: the run goes on from the state kicked along the softest mode
  const Eigen::VectorXd v = scale * eig.eigenvectors().col(first);
  rod::RodState kicked = s;
  for (int k = 0; k < n; ++k) {
    kicked.X[std::size_t(k)] += v.segment<3>(6 * k);
    kicked.D[std::size_t(k)] = rotation(v.segment<3>(6 * k + 3) / ell) * s.D[std::size_t(k)];
  }
  sim.set_rod_state(std::move(kicked), "the stability test's kick");
  const Observables after = sim.observe();
  o.E_after_kT = after.E_total_kT;
  o.writhe_after = after.writhe;
}

}  // namespace

ProbeOutcome probe_stability(Simulation& sim, const StabilityProbe& p, std::uint64_t index) {
  ProbeOutcome o;
  const double kT = sim.params().kT;
  o.step = sim.step_count();
  o.time_us = sim.time() / 1e-6;
  const Observables before = sim.observe();
  o.E_before_kT = before.E_total_kT;
  o.writhe_before = before.writhe;
  if (p.method == StabilityProbe::Method::hessian) {
    hessian_probe(sim, p, o);
    return o;
  }

  // 1. save: the whole dynamical state (Simulation::snapshot, as a checkpoint keeps it)
  const Snapshot saved = sim.snapshot();
  const double saved_time = saved.time;
  auto restore = [&] { sim.restore(saved); };

  // 2. the continuation
  Trace cont, kicked;
  o.continuation_steps = integrate(sim, saved_time, p.time, cont);
  const Observables continuation = sim.observe();
  o.E_continuation_kT = continuation.E_total_kT;
  o.writhe_continuation = continuation.writhe;
  restore();

  // 3. the kicked copy: every rod of the collection on its own range, in order, each drawing its
  // kick from the same generator in turn (rod 0's kick is the one a run of that rod alone gets)
  std::mt19937_64 g(p.seed + index);
  rod::RodState one;
  for (const rod::RodRange& r : sim.rod_ranges()) {
    rod::extract(sim.rod(), r, one);
    kick(one, r, p, g);
    rod::insert(sim.rod(), r, one);
  }
  o.steps = integrate(sim, saved_time, p.time, kicked);
  o.duration_us = (sim.time() - saved_time) / 1e-6;
  const Observables after = sim.observe();
  o.E_after_kT = after.E_total_kT;
  o.writhe_after = after.writhe;

  // 4. decide: the lowest the kicked copy came relative to the continuation, at any sample
  o.min_difference_kT = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < kicked.t.size(); ++i) {
    const double d = kicked.E[i] - cont.at(kicked.t[i]);
    if (d < o.min_difference_kT) {
      o.min_difference_kT = d;
      o.min_difference_after_us = (kicked.t[i] - saved_time) / 1e-6;
    }
  }
  o.stable = !(o.min_difference_kT < -p.tolerance / kT);
  if (o.stable) restore();
  return o;
}

std::string describe(const ProbeOutcome& o) {
  char buf[400];
  if (o.hessian) {
    std::snprintf(buf, sizeof buf,
                  "%s (Hessian): lowest eigenvalue %.3g kT/A^2 less %d zero modes (%d slithering; "
                  "next %.3g); "
                  "a %s kick along its mode changes E_total by %+.3g kT; %d negative modes; "
                  "|grad E| %.3g kT/A, asymmetry %.2g; from t = %.4f us",
                  o.stable ? "stable" : "unstable",
                  o.lowest_eigenvalues.empty() ? 0.0 : o.lowest_eigenvalues[0], o.zero_modes,
                  o.slithering_modes,
                  o.lowest_eigenvalues.size() > 1 ? o.lowest_eigenvalues[1] : 0.0,
                  "time.stability_kick_A", o.min_difference_kT, o.negative_modes,
                  o.gradient_kT_per_A, o.asymmetry, o.time_us);
    return buf;
  }
  std::snprintf(buf, sizeof buf,
                "%s: the kicked copy's E_total minus the unperturbed continuation's: lowest %+.3g "
                "kT (%.4g us after the kick), %+.3g kT at the end (%.4g us; continuation %.9g kT, "
                "%.9g kT at the test); Wr %+.2e -> %+.2e (continuation %+.2e), from t = %.4f us",
                o.stable ? "stable" : "unstable", o.min_difference_kT, o.min_difference_after_us,
                o.E_after_kT - o.E_continuation_kT, o.duration_us, o.E_continuation_kT,
                o.E_before_kT, o.writhe_before, o.writhe_after, o.writhe_continuation, o.time_us);
  return buf;
}

bool slither_invariant(const rod::RodParams& r) {
  if (!r.closed) return false;
  auto uniform = [](const std::vector<Vec3>& v) {
    for (const Vec3& x : v)
      if (x != v.front()) return false;
    return true;
  };
  return uniform(r.a_k) && uniform(r.b_k) && uniform(r.omega0_k);
}

Eigen::VectorXd slithering_vector(const rod::RodState& s, const rod::RodRange& g, double ell) {
  auto rotvec = [](const Mat3& R) {
    const Eigen::AngleAxisd aa(R);
    return Vec3(aa.angle() * aa.axis());
  };
  Eigen::VectorXd v = Eigen::VectorXd::Zero(6 * Eigen::Index(s.size()));
  for (int i = 0; i < g.n; ++i) {
    const auto k = std::size_t(g.offset + i), kp = std::size_t(g.offset + (i + 1) % g.n),
               km = std::size_t(g.offset + (i + g.n - 1) % g.n);
    v.segment<3>(6 * Eigen::Index(k)) = 0.5 * (s.X[kp] - s.X[km]);
    v.segment<3>(6 * Eigen::Index(k) + 3) =
        0.5 * ell * (rotvec(s.D[kp] * s.D[k].transpose()) + rotvec(s.D[k] * s.D[km].transpose()));
  }
  return v;
}

}  // namespace ibrod::sim
