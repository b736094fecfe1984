// Issue 16, the probe that separates the cause of the IB/MC disagreement (docs/thermal.md,
// "Which suspect: the torque is not the gradient of the energy"): free-draining Brownian dynamics
// of the ring, without fluid, with the rod's own elastic point forces and one of two torques:
//
//   torque=rod    T_k from rod::elastic_forces, the torque the IB run spreads into the fluid
//                 (MODEL §4 step 4; −∂E_h/∂θ_k only to O(Δs²) for a smooth rod);
//   torque=exact  T_k = −∂E_h/∂θ_k, central differences (ε = 1e-5 rad) of the energy of the two
//                 half points next to D_k under D_k ← exp(ε ê_a) D_k (lab axes ê_a).
//
// Euler–Maruyama with constant scalar mobilities m_t (points) and m_r (triads):
//   X_k ← X_k + Δt m_t F_k + √(2 kT m_t Δt) ξ_k,   D_k ← R(Δt m_r T_k + √(2 kT m_r Δt) η_k) D_k.
// With a conservative force/torque field and constant mobilities the stationary distribution is
// exp(−E_h/kT) (Lebesgue × Haar; the left-invariant flows of the noise preserve Haar measure) for
// ANY m_t, m_r, up to O(λΔt) from the step; a non-conservative torque makes the stationary
// distribution depend on m_r/m_t. Only the elastic energy (no electrostatics, no steric): the
// local energies E_stretch, E_bend, E_twist, which equilibrate within a few hundred steps here.
//
//   bd_ring CONFIG.toml [section.key=value …] [torque=rod|exact] [steps=N] [burn=B] [every=K]
//           [lam=0.02] [ratio=1] [seed=S] [out=FILE]
// The time step is set by lam = Δt m_t (4 b/Δs) (the stiffest stretch mode's λΔt) and the
// rotational mobility by ratio = m_r (4 a3/Δs) / (m_t (4 b/Δs)) (the stiffest twist mode's rate
// relative to the stiffest stretch mode's). Prints the mean energies in kT with blocked errors and
// the mean |T_rod − T_exact| / |T_exact| over the samples; the rows (step, E_bend, E_twist,
// E_stretch in kT) go to FILE if out= is given.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "rod/rod.hpp"

using namespace ibrod;

namespace {

struct MeanErr {
  double mean = 0, err = 0;
};

/// mean and the standard error from 20 contiguous blocks
MeanErr blocked(const std::vector<double>& x) {
  const int nb = 20, per = int(x.size()) / nb;
  std::vector<double> b(nb, 0.0);
  for (int i = 0; i < nb * per; ++i) b[i / per] += x[i] / per;
  double m = 0, var = 0;
  for (double v : b) m += v / nb;
  for (double v : b) var += (v - m) * (v - m) / (nb - 1);
  return {m, std::sqrt(var / nb)};
}

/// The exact rotation gradient of E_h at every triad: the two half points next to D_k as an open
/// rod of three points (the same moduli, Δs and intrinsic strains).
class ExactTorque {
 public:
  explicit ExactTorque(const rod::RodParams& p) : p3_(p) {
    p3_.n = 3;
    p3_.closed = false;
    if (!p.omega0_k.empty()) throw std::runtime_error("bd_ring: per-link intrinsic strains");
    s3_.X.resize(3);
    s3_.D.resize(3);
  }
  void operator()(const rod::RodState& s, std::vector<Vec3>& T) {
    const int n = s.size();
    const double eps = 1e-5;
    for (int k = 0; k < n; ++k) {
      for (int j = 0; j < 3; ++j) {
        const int i = (k - 1 + j + n) % n;
        s3_.X[j] = s.X[i];
        s3_.D[j] = s.D[i];
      }
      // unwrap nothing: the positions are the rod's own (never folded)
      for (int a = 0; a < 3; ++a) {
        const Vec3 e = Vec3::Unit(a) * eps;
        s3_.D[1] = rotation(e) * s.D[k];
        const double ep = rod::elastic_energy(p3_, s3_).total();
        s3_.D[1] = rotation(-e) * s.D[k];
        const double em = rod::elastic_energy(p3_, s3_).total();
        T[k][a] = -(ep - em) / (2 * eps);
      }
    }
  }

 private:
  rod::RodParams p3_;
  rod::RodState s3_;
};

}  // namespace

int main(int argc, char** argv) try {
  std::map<std::string, std::string> kv{{"torque", "rod"}, {"steps", "200000"}, {"burn", "20000"},
                                        {"every", "100"},  {"lam", "0.02"},     {"ratio", "1"},
                                        {"seed", "1"}};
  std::string cfg_path;
  std::vector<std::string> overrides;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto eq = a.find('=');
    if (eq == std::string::npos)
      cfg_path = a;
    else if (a.substr(0, eq).find('.') != std::string::npos)
      overrides.push_back(a);
    else
      kv[a.substr(0, eq)] = a.substr(eq + 1);
  }
  if (cfg_path.empty()) {
    std::fprintf(stderr,
                 "usage: bd_ring CONFIG.toml [section.key=value…] [torque=rod|exact] [steps=N] "
                 "[burn=B] [every=K] [lam=0.02] [ratio=1] [seed=S] [out=FILE]\n");
    return 2;
  }
  const bool exact = kv["torque"] == "exact";
  if (!exact && kv["torque"] != "rod")
    throw std::runtime_error("bd_ring: torque = " + kv["torque"] + ", expected rod or exact");
  config::Config cfg = config::load_config(cfg_path);
  for (const auto& o : overrides) config::apply_override(cfg, o);
  config::validate(cfg);
  const sim::SimParams sp = config::to_params(cfg);
  const rod::RodParams& p = sp.stepper.rods[0];
  const double kT = sp.kT;
  rod::RodState s = rod::twisted_circle(p, sp.shapes[0].circle);
  const int n = s.size();
  const double kt_max = 4 * p.b.maxCoeff() / p.ds, kr_max = 4 * p.a.maxCoeff() / p.ds;
  const double lam = std::stod(kv["lam"]), ratio = std::stod(kv["ratio"]);
  const double mt_dt = lam / kt_max, mr_dt = ratio * lam / kr_max;  // Δt m_t, Δt m_r
  const double st = std::sqrt(2 * kT * mt_dt), sr = std::sqrt(2 * kT * mr_dt);
  const long steps = std::stol(kv["steps"]), burn = std::stol(kv["burn"]),
             every = std::stol(kv["every"]);
  std::mt19937_64 rng(std::stoull(kv["seed"]));
  std::normal_distribution<double> N01;
  rod::RodWork w;
  ExactTorque exact_torque(p);
  std::vector<Vec3> F(n), T(n), Tx(n), U(n), W(n);
  std::vector<double> eb, et, es, terr;
  std::FILE* f = kv.count("out") ? std::fopen(kv["out"].c_str(), "w") : nullptr;
  if (f) std::fprintf(f, "step,E_bend_kT,E_twist_kT,E_stretch_kT\n");
  const auto t0 = std::chrono::steady_clock::now();
  for (long i = -burn; i < steps; ++i) {
    for (int k = 0; k < n; ++k) F[k] = T[k] = Vec3::Zero();
    const rod::ElasticEnergy E = rod::elastic_forces(p, s, w, F, T);
    const bool sample = i >= 0 && i % every == 0;
    if (exact || sample) exact_torque(s, Tx);
    if (sample) {
      eb.push_back(E.bend / kT);
      et.push_back(E.twist / kT);
      es.push_back(E.stretch / kT);
      double num = 0, den = 0;
      for (int k = 0; k < n; ++k) num += (T[k] - Tx[k]).norm(), den += Tx[k].norm();
      terr.push_back(num / den);
      if (f) std::fprintf(f, "%ld,%.8g,%.8g,%.8g\n", i, eb.back(), et.back(), es.back());
    }
    const std::vector<Vec3>& Tu = exact ? Tx : T;
    // U, W as velocities over a unit step: advance(s, U, W, 1) moves by U and turns by W
    for (int k = 0; k < n; ++k) {
      U[k] = mt_dt * F[k] + st * Vec3(N01(rng), N01(rng), N01(rng));
      W[k] = mr_dt * Tu[k] + sr * Vec3(N01(rng), N01(rng), N01(rng));
    }
    rod::advance(s, U, W, 1.0);
    if ((i & 1023) == 0)  // back onto SO(3)
      for (auto& D : s.D) {
        Eigen::JacobiSVD<Mat3> svd(D, Eigen::ComputeFullU | Eigen::ComputeFullV);
        D = svd.matrixU() * svd.matrixV().transpose();
      }
  }
  if (f) std::fclose(f);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const MeanErr b = blocked(eb), t = blocked(et), st_ = blocked(es), te = blocked(terr);
  std::printf(
      "torque=%s lam=%g ratio=%g n=%d steps=%ld: E_stretch %.2f +- %.2f  E_bend %.2f +- %.2f  "
      "E_twist %.2f +- %.2f kT;  <|T_rod - T_exact|>/<|T_exact|> = %.3f;  %.1f s\n",
      exact ? "exact" : "rod", lam, ratio, n, steps, st_.mean, st_.err, b.mean, b.err, t.mean,
      t.err, te.mean, wall);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bd_ring: %s\n", e.what());
  return 1;
}
