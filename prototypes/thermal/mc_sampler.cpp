#include "mc_sampler.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>

#include "diagnostics/topology.hpp"

namespace ibrod::mc {

namespace {

Mat3 rotation(const Vec3& unit_axis, double angle) {
  return Eigen::AngleAxisd(angle, unit_axis).toRotationMatrix();
}

double link_of(const rod::RodState& s) {
  std::vector<Vec3> d1(s.size());
  for (int k = 0; k < s.size(); ++k) d1[k] = s.D[k].col(0);
  return diagnostics::twist(s.X, d1) + diagnostics::writhe(s.X);
}

}  // namespace

void RingEnergy::forces(const rod::RodState& s, std::vector<Vec3>& F) {
  const int n = s.size();
  F.assign(n, Vec3::Zero());
  T_.assign(n, Vec3::Zero());
  rod::elastic_forces(rod, s, work_, F, T_);
  electro.accumulate_direct(s.X, F);
  steric.accumulate_direct(s.X, F);
}

std::array<double, 2> RingEnergy::position_temperature_terms(rod::RodState& s) {
  const double eps = 1e-4;
  forces(s, F_);
  double sq = 0, lap = 0;
  for (const Vec3& f : F_) sq += f.squaredNorm();
  for (int k = 0; k < s.size(); ++k)
    for (int a = 0; a < 3; ++a) {
      const double x = s.X[k][a];
      s.X[k][a] = x + eps;
      forces(s, Fp_);
      s.X[k][a] = x - eps;
      forces(s, Fm_);
      s.X[k][a] = x;
      lap -= (Fp_[k][a] - Fm_[k][a]) / (2 * eps);
    }
  return {sq / (kT * kT), lap / kT};
}

double RingEnergy::virial(const rod::RodState& s) {
  const int n = s.size();
  forces(s, F_);
  Vec3 c = Vec3::Zero();
  for (const Vec3& x : s.X) c += x / n;
  double v = 0;
  for (int k = 0; k < n; ++k) v -= (s.X[k] - c).dot(F_[k]);  // F = −∂E/∂X, Σ F = 0
  return v / kT;
}

std::array<double, 2> RingEnergy::rotation_temperature_terms(rod::RodState& s) const {
  const double eps = 1e-4;
  const double e0 = elastic(s);
  double sq = 0, lap = 0;
  for (int k = 0; k < s.size(); ++k) {
    const Mat3 D = s.D[k];
    for (int a = 0; a < 3; ++a) {
      s.D[k] = rotation(Vec3::Unit(a), eps) * D;
      const double ep = elastic(s);
      s.D[k] = rotation(Vec3::Unit(a), -eps) * D;
      const double em = elastic(s);
      const double d1 = (ep - em) / (2 * eps), d2 = (ep - 2 * e0 + em) / (eps * eps);
      sq += d1 * d1;
      lap += d2;
    }
    s.D[k] = D;
  }
  return {sq, lap};
}

std::array<double, 2> RingEnergy::pairs_delta(const std::vector<Vec3>& Xold,
                                              const std::vector<Vec3>& Xnew,
                                              const std::vector<int>& moved, bool rigid) const {
  const int n = int(Xold.size());
  std::vector<char> mv(n, 0);
  for (int i : moved) mv[i] = 1;
  double dE = 0, dS = 0;
  if (electro.params().enabled) {
    const auto& ep = electro.params();
    const double rc2 = ep.cutoff > 0 ? ep.cutoff * ep.cutoff : HUGE_VAL;
    const double shift = ep.cutoff > 0 ? ep.law.energy(ep.cutoff) : 0.0;
    auto u = [&](const Vec3& a, const Vec3& b) {
      const double d2 = (a - b).squaredNorm();
      return d2 <= rc2 ? ep.law.energy(std::sqrt(d2)) - shift : 0.0;
    };
    for (int i : moved)
      for (int j = 0; j < n; ++j) {
        if (j == i || (mv[j] && (rigid || j < i))) continue;
        dE += u(Xnew[i], Xnew[j]) - u(Xold[i], Xold[j]);
      }
  }
  const auto& sp = steric.params();
  if (sp.enabled && sp.diameter > 0) {
    // segments k (X_k → X_{k+1}) with a moved end; a segment pair counts if either is affected
    std::vector<char> aff(n, 0);
    for (int i : moved) aff[i] = aff[(i - 1 + n) % n] = 1;
    double lmax2 = 0;
    for (int k = 0; k < n; ++k)
      lmax2 = std::max({lmax2, (Xold[(k + 1) % n] - Xold[k]).squaredNorm(),
                        (Xnew[(k + 1) % n] - Xnew[k]).squaredNorm()});
    const double reach = sp.diameter + std::sqrt(lmax2), reach2 = reach * reach;
    std::array<Vec3, 4> f;
    auto e = [&](const std::vector<Vec3>& X, int k, int l) {
      const Vec3 &a = X[k], &b = X[(k + 1) % n], &c = X[l], &d = X[(l + 1) % n];
      if ((0.5 * (a + b) - 0.5 * (c + d)).squaredNorm() >= reach2) return 0.0;  // exact filter
      return interactions::steric_pair(sp.diameter, sp.stiffness, a, b, c, d, f);
    };
    for (int k = 0; k < n; ++k) {
      if (!aff[k]) continue;
      for (int l = 0; l < n; ++l) {
        if (l == k || (aff[l] && l < k)) continue;
        const int m = std::abs(k - l);
        if (!(std::min(m, n - m) * sp.ds > 2 * sp.diameter)) continue;  // Steric's along-rod rule
        dS += e(Xnew, k, l) - e(Xold, k, l);
      }
    }
  }
  return {dE / kT, dS / kT};
}

RingSample measure(const RingEnergy& E, const rod::RodState& s) {
  RingSample r;
  const int n = s.size();
  std::vector<Vec3> d1(n);
  for (int k = 0; k < n; ++k) d1[k] = s.D[k].col(0);
  r.writhe = diagnostics::writhe(s.X);
  r.twist = diagnostics::twist(s.X, d1);
  r.link = r.writhe + r.twist;
  Vec3 c = Vec3::Zero();
  for (const Vec3& x : s.X) c += x;
  c /= n;
  for (const Vec3& x : s.X) r.rg2 += (x - c).squaredNorm();
  r.rg2 /= n;
  for (int m = 1; m < int(r.power.size()); ++m) {
    std::array<std::complex<double>, 3> h{};
    for (int k = 0; k < n; ++k) {
      const std::complex<double> w = std::polar(1.0, -2 * std::numbers::pi * m * k / n);
      for (int a = 0; a < 3; ++a) h[a] += s.X[k][a] * w;
    }
    for (int a = 0; a < 3; ++a) r.power[m] += std::norm(h[a] / double(n));
  }
  const rod::ElasticEnergy el = rod::elastic_energy(E.rod, s);
  r.E_bend = el.bend / E.kT;
  r.E_twist = el.twist / E.kT;
  r.E_stretch = el.stretch / E.kT;
  r.E_pairs = E.pairs(s.X);
  return r;
}

RingMC::RingMC(RingEnergy& energy, rod::RodState start, std::uint64_t seed, McSteps steps)
    : E_(energy), s_(std::move(start)), trial_(s_), rng_(seed), steps_(steps) {
  e_el_ = E_.elastic(s_);
  e_pair_ = E_.pairs(s_.X);
  e_steric_ = E_.steric_only(s_.X);
  lk0_ = link_of(s_);
}

bool RingMC::accept(double dE) {
  if (dE <= 0) return true;
  return std::uniform_real_distribution<double>(0, 1)(rng_) < std::exp(-dE);
}

bool RingMC::link_changed(double max_path, double e_steric) {
  const double D = E_.steric.params().diameter;
  if (max_path < D && !(e_steric > 1e-12)) return false;
  ++counts_.lk_checks;
  if (std::abs(link_of(trial_) - lk0_) > 0.5) {
    ++counts_.lk_rejects;
    return true;
  }
  return false;
}

bool RingMC::crank() {
  const int n = s_.size();
  std::uniform_int_distribution<int> pick_i(0, n - 1), pick_m(1, n / 2);
  const int i = pick_i(rng_), m = pick_m(rng_), j = (i + m + 1) % n;
  const double th = std::uniform_real_distribution<double>(-steps_.crank, steps_.crank)(rng_);
  const Vec3 axis = (s_.X[j] - s_.X[i]).normalized();
  const Mat3 R = rotation(axis, th);
  double max_r = 0;
  for (int q = 1; q <= m; ++q) {
    const int k = (i + q) % n;
    const Vec3 r = s_.X[k] - s_.X[i];
    max_r = std::max(max_r, (r - r.dot(axis) * axis).norm());
    trial_.X[k] = s_.X[i] + R * r;
    trial_.D[k] = R * s_.D[k];
  }
  moved_.clear();
  for (int q = 1; q <= m; ++q) moved_.push_back((i + q) % n);
  std::sort(moved_.begin(), moved_.end());
  const double e_el = E_.elastic(trial_);
  const auto d = E_.pairs_delta(s_.X, trial_.X, moved_, true);
  const double e_pair = e_pair_ + d[0] + d[1], e_steric = e_steric_ + d[1];
  bool ok = accept(e_el + e_pair - e_el_ - e_pair_);
  if (ok && link_changed(max_r * std::abs(th), e_steric)) ok = false;
  for (int q = 1; q <= m; ++q) {
    const int k = (i + q) % n;
    if (ok) {
      s_.X[k] = trial_.X[k];
      s_.D[k] = trial_.D[k];
    } else {
      trial_.X[k] = s_.X[k];
      trial_.D[k] = s_.D[k];
    }
  }
  if (ok) e_el_ = e_el, e_pair_ = e_pair, e_steric_ = e_steric;
  return ok;
}

bool RingMC::twist_move() {
  const int k = std::uniform_int_distribution<int>(0, s_.size() - 1)(rng_);
  const double ph = std::uniform_real_distribution<double>(-steps_.twist, steps_.twist)(rng_);
  trial_.D[k] = rotation(s_.D[k].col(2).normalized(), ph) * s_.D[k];
  const double e_el = E_.elastic(trial_);  // the pair energies do not see the triads
  const bool ok = accept(e_el - e_el_);
  if (ok)
    s_.D[k] = trial_.D[k], e_el_ = e_el;
  else
    trial_.D[k] = s_.D[k];
  return ok;
}

bool RingMC::tilt_move() {
  const int k = std::uniform_int_distribution<int>(0, s_.size() - 1)(rng_);
  std::normal_distribution<double> g;
  Vec3 axis;
  do axis = Vec3(g(rng_), g(rng_), g(rng_));
  while (axis.norm() < 1e-12);
  const double ph = std::uniform_real_distribution<double>(-steps_.tilt, steps_.tilt)(rng_);
  trial_.D[k] = rotation(axis.normalized(), ph) * s_.D[k];
  const double e_el = E_.elastic(trial_);
  const bool ok = accept(e_el - e_el_);
  if (ok)
    s_.D[k] = trial_.D[k], e_el_ = e_el;
  else
    trial_.D[k] = s_.D[k];
  return ok;
}

bool RingMC::shift_move() {
  const int k = std::uniform_int_distribution<int>(0, s_.size() - 1)(rng_);
  std::uniform_real_distribution<double> u(-steps_.shift, steps_.shift);
  const Vec3 d(u(rng_), u(rng_), u(rng_));
  trial_.X[k] = s_.X[k] + d;
  moved_.assign(1, k);
  const double e_el = E_.elastic(trial_);
  const auto dp = E_.pairs_delta(s_.X, trial_.X, moved_, true);
  const double e_pair = e_pair_ + dp[0] + dp[1], e_steric = e_steric_ + dp[1];
  bool ok = accept(e_el + e_pair - e_el_ - e_pair_);
  if (ok && link_changed(d.norm(), e_steric)) ok = false;
  if (ok)
    s_.X[k] = trial_.X[k], e_el_ = e_el, e_pair_ = e_pair, e_steric_ = e_steric;
  else
    trial_.X[k] = s_.X[k];
  return ok;
}

bool RingMC::spin_move() {
  const int n = s_.size();
  std::uniform_int_distribution<int> pick_i(0, n - 1), pick_m(1, n / 2);
  const int i = pick_i(rng_), m = pick_m(rng_);
  const double ph = std::uniform_real_distribution<double>(-steps_.spin, steps_.spin)(rng_);
  for (int q = 0; q < m; ++q) {
    const int k = (i + q) % n;
    trial_.D[k] = rotation(s_.D[k].col(2).normalized(), ph) * s_.D[k];
  }
  const double e_el = E_.elastic(trial_);
  const bool ok = accept(e_el - e_el_);
  for (int q = 0; q < m; ++q) {
    const int k = (i + q) % n;
    if (ok)
      s_.D[k] = trial_.D[k];
    else
      trial_.D[k] = s_.D[k];
  }
  if (ok) e_el_ = e_el;
  return ok;
}

bool RingMC::dilate_move() {
  const int n = s_.size();
  const double u = std::uniform_real_distribution<double>(-steps_.dilate, steps_.dilate)(rng_);
  Vec3 c = Vec3::Zero();
  for (const Vec3& x : s_.X) c += x / n;
  const double lam = std::exp(u);
  for (int k = 0; k < n; ++k) trial_.X[k] = c + lam * (s_.X[k] - c);
  const double e_el = E_.elastic(trial_), e_pair = E_.pairs(trial_.X);
  const double e_steric = E_.steric_only(trial_.X);
  double max_path = 0;
  for (int k = 0; k < n; ++k) max_path = std::max(max_path, (trial_.X[k] - s_.X[k]).norm());
  // Metropolis–Hastings: the map's Jacobian e^{(3n−3)u} on the relative coordinates
  bool ok = accept(e_el + e_pair - e_el_ - e_pair_ - (3.0 * n - 3.0) * u);
  if (ok && link_changed(max_path, e_steric)) ok = false;
  for (int k = 0; k < n; ++k) {
    if (ok)
      s_.X[k] = trial_.X[k];
    else
      trial_.X[k] = s_.X[k];
  }
  if (ok) e_el_ = e_el, e_pair_ = e_pair, e_steric_ = e_steric;
  return ok;
}

void RingMC::sweep(bool adapt) {
  const int n = s_.size();
  const McCounts before = counts_;
  std::uniform_int_distribution<int> kind(0, 3);
  const int big = std::max(1, n / 10);
  std::uniform_int_distribution<int> any(0, 4 * n + 2 * big - 1);
  for (int t = 0; t < 4 * n + 2 * big; ++t) {
    const int r = any(rng_);
    const int w = r < 4 * n ? kind(rng_) : (r < 4 * n + big ? 4 : 5);
    bool ok = false;
    switch (w) {
      case 4:
        ok = spin_move();
        break;
      case 5:
        ok = dilate_move();
        break;
      case 0:
        ok = crank();
        break;
      case 1:
        ok = twist_move();
        break;
      case 2:
        ok = tilt_move();
        break;
      default:
        ok = shift_move();
        break;
    }
    ++counts_.tried[w];
    if (ok) ++counts_.accepted[w];
    if (debug_) {
      const double a = E_.elastic(s_), b = E_.pairs(s_.X);
      bool sync = true;
      for (int k = 0; k < n; ++k) sync = sync && s_.X[k] == trial_.X[k] && s_.D[k] == trial_.D[k];
      if (std::abs(a - e_el_) > 1e-7 || std::abs(b - e_pair_) > 1e-7 || !sync)
        std::fprintf(stderr, "move %d ok %d: elastic %.9g vs %.9g, pairs %.9g vs %.9g, sync %d\n",
                     w, int(ok), a, e_el_, b, e_pair_, int(sync));
    }
  }
  if (adapt) {
    double* step[6] = {&steps_.crank, &steps_.twist, &steps_.tilt,
                       &steps_.shift, &steps_.spin,  &steps_.dilate};
    for (int w = 0; w < 6; ++w) {
      const double tried = double(counts_.tried[w] - before.tried[w]);
      if (tried == 0) continue;
      const double rate = double(counts_.accepted[w] - before.accepted[w]) / tried;
      *step[w] *= std::clamp(std::exp(rate - 0.4), 0.8, 1.25);
      if (w != 3 && w != 5) *step[w] = std::min(*step[w], std::numbers::pi);
    }
  }
  // Products of many rotations drift off SO(3) by round-off (and a rotation about a D³ that is
  // not exactly unit is not orthogonal: the error would feed on itself): put each triad back on
  // the nearest rotation, U Vᵀ of its SVD, recording how far off it was.
  for (int k = 0; k < n; ++k) {
    const double off = (s_.D[k].transpose() * s_.D[k] - Mat3::Identity()).cwiseAbs().maxCoeff();
    max_triad_drift_ = std::max(max_triad_drift_, off);
    Eigen::JacobiSVD<Mat3> svd(s_.D[k], Eigen::ComputeFullU | Eigen::ComputeFullV);
    s_.D[k] = trial_.D[k] = svd.matrixU() * svd.matrixV().transpose();
  }
  // the pair energy is kept incrementally: check it against the full sums and refresh it
  e_el_ = E_.elastic(s_);
  const double full = E_.pairs(s_.X), st = E_.steric_only(s_.X);
  max_pair_drift_ = std::max({max_pair_drift_, std::abs(full - e_pair_), std::abs(st - e_steric_)});
  e_pair_ = full;
  e_steric_ = st;
}

}  // namespace ibrod::mc
