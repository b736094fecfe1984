// Issue 16: the Monte-Carlo half of the equilibrium check (docs/thermal.md, "Writhe and shape
// against Monte Carlo"; the sampler in mc_sampler.hpp). Two modes:
//
//   mc_ring CONFIG.toml [section.key=value …] [sweeps=N] [burn=B] [every=K] [seed=S] [out=FILE]
//       samples exp(−E/kT) of the ring that CONFIG describes (the energy, its parameters and the
//       initial twisted circle from config::to_params, as `ibrod run` builds them); burn-in B
//       sweeps (step sizes adapting), then N sweeps, one row of statistics every K sweeps to FILE
//       (CSV: sweep, writhe, twist, link, rg2_A2, P1 … P4 (Å²), E_bend, E_twist, E_stretch,
//       E_pairs (kT)); acceptance rates and the Lk checks on stderr.
//
//   mc_ring --selftest [n=24] [sweeps=4000] [salt=0.1]
//       the sampler's check against two exact identities of the Boltzmann distribution:
//       ⟨Σ_k X_k·∂E/∂X_k⟩ = (3n − 3) kT (the virial: generalized equipartition, with the code's
//       exact point forces), and ⟨Σ (L E)²⟩ = ⟨Σ L² E⟩ over the triads' rotation generators
//       (configurational temperature, kT = 1), and ⟨Σ |∂E/∂X|²⟩ = ⟨Σ ∂²E/∂X²⟩ (the same for the
//       positions). Prints the three ratios with their blocked standard errors; exit status 1 if
//       a configurational temperature is off 1 by more than 4 standard errors or 3 %, the virial by
//       more than 4 standard errors or 5 %, or
//       if a triad drifted off SO(3) by 1e-9 or the running pair energy off its full sum by 1e-8
//       kT.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "mc_sampler.hpp"

using namespace ibrod;

namespace {

struct MeanErr {
  double mean = 0, err = 0;
};

/// mean and the standard error from 20 contiguous blocks (time correlation inside a block)
MeanErr blocked(const std::vector<double>& x) {
  const int nb = 20, per = int(x.size()) / nb;
  double m = 0;
  std::vector<double> b(nb, 0.0);
  for (int i = 0; i < nb * per; ++i) b[i / per] += x[i] / per;
  for (double v : b) m += v / nb;
  double var = 0;
  for (double v : b) var += (v - m) * (v - m) / (nb - 1);
  return {m, std::sqrt(var / nb)};
}

void print_rates(const mc::RingMC& mc, const char* when) {
  const auto& c = mc.counts();
  const char* names[6] = {"crankshaft", "twist", "tilt", "shift", "spin", "dilate"};
  std::fprintf(stderr, "%s: acceptance", when);
  for (int w = 0; w < 6; ++w)
    std::fprintf(stderr, " %s %.3f", names[w],
                 c.tried[w] ? double(c.accepted[w]) / double(c.tried[w]) : 0.0);
  std::fprintf(stderr,
               "; steps: crank %.3f rad, twist %.3f rad, tilt %.4f rad, shift %.3f Å, spin %.3f "
               "rad, dilate %.4f; "
               "Lk checks %lld, moves rejected for Lk %lld; incremental pair energy off the "
               "full sum by at most %.2g kT; triads off orthonormal by at most %.2g\n",
               mc.steps().crank, mc.steps().twist, mc.steps().tilt, mc.steps().shift,
               mc.steps().spin, mc.steps().dilate, (long long)c.lk_checks, (long long)c.lk_rejects,
               mc.max_pair_drift(), mc.max_triad_drift());
}

int selftest(std::map<std::string, std::string>& kv) {
  config::Config cfg;
  const int n = std::stoi(kv.count("n") ? kv["n"] : "24");
  config::apply_override(cfg, "rod.base_pairs=" + std::to_string(n));
  config::apply_override(cfg, "rod.excess_link=0");
  config::apply_override(cfg, "rod.perturbation=[0.0]");
  config::apply_override(cfg, "solvent.salt_M=" + (kv.count("salt") ? kv["salt"] : "0.1"));
  const sim::SimParams p = config::to_params(cfg);
  mc::RingEnergy E(p.stepper.rods[0], p.stepper.electro, p.stepper.steric, p.kT);
  mc::RingMC mc(E, rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle), 7);
  const int sweeps = std::stoi(kv.count("sweeps") ? kv["sweeps"] : "4000");
  for (int i = 0; i < 200; ++i) mc.sweep(true);
  mc.reset_counts();
  std::vector<double> vir, sq, lap, psq, plap;
  for (int i = 0; i < sweeps; ++i) {
    mc.sweep();
    rod::RodState s = mc.state();
    vir.push_back(E.virial(s));
    const auto t = E.rotation_temperature_terms(s);
    sq.push_back(t[0]);
    lap.push_back(t[1]);
    const auto q = E.position_temperature_terms(s);
    psq.push_back(q[0]);
    plap.push_back(q[1]);
  }
  print_rates(mc, "selftest");
  const MeanErr v = blocked(vir), a = blocked(sq), b = blocked(lap);
  const double want = 3.0 * n - 3.0;
  const double rv = v.mean / want, rv_err = v.err / want;
  const double rr = a.mean / b.mean,
               rr_err = rr * std::hypot(a.err / a.mean, b.err / b.mean);  // conservative
  std::printf("virial / (3n-3) kT = %.4f +- %.4f   (n = %d, %d sweeps)\n", rv, rv_err, n, sweeps);
  std::printf("rotational configurational temperature / T = %.4f +- %.4f\n", rr, rr_err);
  const MeanErr c = blocked(psq), d = blocked(plap);
  const double rp = c.mean / d.mean, rp_err = rp * std::hypot(c.err / c.mean, d.err / d.mean);
  std::printf("positional configurational temperature / T = %.4f +- %.4f\n", rp, rp_err);
  std::printf(
      "triads off orthonormal by at most %.2g; running pair energy off by at most %.2g kT\n",
      mc.max_triad_drift(), mc.max_pair_drift());
  const bool ok = mc.max_triad_drift() < 1e-9 && mc.max_pair_drift() < 1e-8 &&
                  std::abs(rv - 1) < 4 * rv_err && std::abs(rv - 1) < 0.05 &&
                  std::abs(rr - 1) < 4 * rr_err && std::abs(rr - 1) < 0.03 &&
                  std::abs(rp - 1) < 4 * rp_err && std::abs(rp - 1) < 0.03;
  std::printf("%s\n", ok ? "selftest passed" : "selftest FAILED");
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) try {
  std::map<std::string, std::string> kv{{"sweeps", "20000"},
                                        {"burn", "1000"},
                                        {"every", "10"},
                                        {"seed", "1"},
                                        {"out", "mc_samples.csv"}};
  std::string cfg_path;
  std::vector<std::string> overrides;
  bool self = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto eq = a.find('=');
    if (a == "--selftest")
      self = true;
    else if (eq == std::string::npos)
      cfg_path = a;
    else if (a.substr(0, eq).find('.') != std::string::npos)
      overrides.push_back(a);
    else
      kv[a.substr(0, eq)] = a.substr(eq + 1);
  }
  if (self) return selftest(kv);
  if (cfg_path.empty()) {
    std::fprintf(stderr,
                 "usage: mc_ring CONFIG.toml [section.key=value…] [sweeps=N] [burn=B] "
                 "[every=K] [seed=S] [out=FILE] | mc_ring --selftest\n");
    return 2;
  }
  config::Config cfg = config::load_config(cfg_path);
  for (const auto& o : overrides) config::apply_override(cfg, o);
  config::validate(cfg);
  const sim::SimParams p = config::to_params(cfg);
  mc::RingEnergy E(p.stepper.rods[0], p.stepper.electro, p.stepper.steric, p.kT);
  mc::RingMC mc(E, rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle),
                std::stoull(kv["seed"]));
  const long sweeps = std::stol(kv["sweeps"]), burn = std::stol(kv["burn"]),
             every = std::stol(kv["every"]);
  const auto t0 = std::chrono::steady_clock::now();
  for (long i = 0; i < burn; ++i) mc.sweep(i < burn * 4 / 5);
  print_rates(mc, "burn-in");
  mc.reset_counts();
  std::FILE* f = std::fopen(kv["out"].c_str(), "w");
  if (!f) return std::fprintf(stderr, "cannot write %s\n", kv["out"].c_str()), 1;
  std::fprintf(f,
               "sweep,writhe,twist,link,rg2_A2,P1_A2,P2_A2,P3_A2,P4_A2,E_bend_kT,E_twist_kT,"
               "E_stretch_kT,E_pairs_kT\n");
  const long debug_from = kv.count("debug_from") ? std::stol(kv["debug_from"]) : -1;
  for (long i = 1; i <= sweeps; ++i) {
    if (i == debug_from) mc.debug_ = true;
    mc.sweep();
    if (i % every) continue;
    const mc::RingSample r = mc::measure(E, mc.state());
    std::fprintf(f, "%ld,%.8g,%.8g,%.8g,%.8g,%.8g,%.8g,%.8g,%.8g,%.8g,%.8g,%.8g,%.8g\n", i,
                 r.writhe, r.twist, r.link, r.rg2, r.power[1], r.power[2], r.power[3], r.power[4],
                 r.E_bend, r.E_twist, r.E_stretch, r.E_pairs);
  }
  std::fclose(f);
  if (kv.count("final")) {  // the last state: x y z, D¹, D², D³ per point
    std::FILE* g = std::fopen(kv["final"].c_str(), "w");
    if (!g) return std::fprintf(stderr, "cannot write %s\n", kv["final"].c_str()), 1;
    for (int k = 0; k < mc.state().size(); ++k) {
      const Vec3& x = mc.state().X[k];
      const Mat3& D = mc.state().D[k];
      std::fprintf(g, "%.12g %.12g %.12g", x[0], x[1], x[2]);
      for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) std::fprintf(g, " %.12g", D(r, c));
      std::fprintf(g, "\n");
    }
    std::fclose(g);
  }
  print_rates(mc, "production");
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::fprintf(stderr, "Lk0 = %.6f; %ld + %ld sweeps of %d points, %.1f s (%.2f ms/sweep)\n",
               mc.link0(), burn, sweeps, p.stepper.rods[0].n, wall,
               1e3 * wall / double(burn + sweeps));
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "mc_ring: %s\n", e.what());
  return 1;
}
