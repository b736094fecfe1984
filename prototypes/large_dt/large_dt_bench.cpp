// Issue 14: simulated µs per wall hour of the explicit and the implicit scheme in the same run,
// at the reference (64³, 600 bp, ΔLk = 6, 0.1 M, 2 threads, FFTW_MEASURE), from the same initial
// twisted circle. The explicit scheme runs `explicit_steps` steps of time.dt_ns (0.1 ns, the
// reference step; its stability limit is ~0.22 ns); the implicit one runs `implicit_ns` of
// simulated time with the adaptive controller at Δt ≤ `dt_max_ns`. Last line:
//   us_per_hour_explicit=… us_per_hour_implicit=…
// Usage: large_dt_bench [dt_max_ns=2] [implicit_ns=200] [explicit_steps=300] [beta=8]
//        [jac_every=N (default: ImplicitParams's)] [section.key=value…]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "config/config.hpp"
#include "integrate/implicit.hpp"

using namespace ibrod;

int main(int argc, char** argv) {
  std::map<std::string, std::string> kv{{"dt_max_ns", "2"},
                                        {"implicit_ns", "200"},
                                        {"explicit_steps", "300"},
                                        {"beta", "8"},
                                        {"jac_every", "0"}};
  config::Config cfg;
  config::apply_override(cfg, "run.threads=2");
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto eq = a.find('=');
    if (eq == std::string::npos) return std::fprintf(stderr, "bad argument %s\n", a.c_str()), 2;
    if (a.substr(0, eq).find('.') != std::string::npos)
      config::apply_override(cfg, a);
    else
      kv[a.substr(0, eq)] = a.substr(eq + 1);
  }
  const sim::SimParams p = config::to_params(cfg);
  using clock = std::chrono::steady_clock;
  auto secs = [](clock::time_point a) {
    return std::chrono::duration<double>(clock::now() - a).count();
  };

  // explicit: the reference step
  double us_hour_explicit = 0;
  {
    rod::RodState rod = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
    integrate::Stepper st(p.stepper);
    for (int k = 0; k < 10; ++k) st.step(rod);  // warm-up
    const long n = std::stol(kv["explicit_steps"]);
    const auto t0 = clock::now();
    for (long k = 0; k < n; ++k) st.step(rod);
    const double wall = secs(t0);
    us_hour_explicit = n * p.stepper.fluid.dt / 1e-6 / wall * 3600;
    std::printf("explicit: dt = %.3g ns, %ld steps, %.3f ms/step\n", p.stepper.fluid.dt * 1e9, n,
                1e3 * wall / n);
  }
  // implicit: IMEX, adaptive (docs/large_dt.md)
  double us_hour_implicit = 0;
  {
    rod::RodState rod = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
    integrate::Stepper st(p.stepper);
    integrate::ImplicitParams ip;
    ip.mobility_scale = std::stod(kv["beta"]);
    if (std::stoi(kv["jac_every"]) > 0) ip.jacobian_every = std::stoi(kv["jac_every"]);
    integrate::ImplicitStepper imp(st.system(), ip);
    integrate::AdaptiveDtParams ap;
    ap.dt_max = std::stod(kv["dt_max_ns"]) * 1e-9;
    ap.dt_min = 1e-3 * ap.dt_max;
    ap.max_displacement =
        0.2 * std::min(1 / p.stepper.electro.law.kappa, p.stepper.steric.diameter);
    ap.energy_tolerance = 1e-6 * p.kT;
    integrate::AdaptiveDt ctl(ap);
    const double T = std::stod(kv["implicit_ns"]) * 1e-9;
    double t = 0;
    long steps = 0, trials = 0;
    const auto t0 = clock::now();
    while (t < T * (1 - 1e-12)) {
      double dt = 0;
      int rejected = 0;
      integrate::step_adaptive(imp, rod, ctl, T - t, &dt, &rejected);
      t += dt;
      ++steps;
      trials += 1 + rejected;
    }
    const double wall = secs(t0);
    us_hour_implicit = t / 1e-6 / wall * 3600;
    const auto& tm = imp.timings();
    std::printf(
        "implicit: dt_max = %s ns, %.0f ns in %ld steps (%ld trials, mean dt %.3g ns), "
        "%.3f ms/step\n",
        kv["dt_max_ns"].c_str(), t * 1e9, steps, trials, t / steps * 1e9, 1e3 * wall / steps);
    std::printf(
        "implicit ms/trial: forces %.3f, stiffness %.3f, factorisation %.3f, local solve "
        "%.3f, Stokes %.3f\n",
        1e3 * tm.forces / trials, 1e3 * tm.stiffness / trials, 1e3 * tm.factorize / trials,
        1e3 * tm.local_solve / trials, 1e3 * tm.stokes / trials);
  }
  std::printf("ratio=%.1f\n", us_hour_implicit / us_hour_explicit);
  std::printf("us_per_hour_explicit=%.4g us_per_hour_implicit=%.4g\n", us_hour_explicit,
              us_hour_implicit);
  return 0;
}
