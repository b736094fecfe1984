// Issue 24 probe: why the implicit scheme's E_K stalls in contact states (docs/large_dt.md
// "Stiff modes at rest"). Starts from a saved configuration (rod.initial_shape=FILE, e.g. a run's
// final_state.csv) and takes implicit steps of a fixed Δt (or under the controller), printing per
// step the fluid kinetic energy of M F(qⁿ), the potential energy change, the largest point
// velocity, the cosine between successive step velocities (−1: a period-2 oscillation, +1: a
// monotone creep), the steric contacts and whether the set of contacts changed.
//   contact_probe rod.initial_shape=DIR/final_state.csv dt_ns=4.4 steps=200 [key=value …]
// Other keys: beta (8), adaptive (0), margin_A (implicit contact margin, 0), and any config
// key (section.key=value) as in large_dt_experiment.
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "config/config.hpp"
#include "integrate/implicit.hpp"
#include "io/rod_shape.hpp"

using namespace ibrod;

int main(int argc, char** argv) {
  std::map<std::string, std::string> kv{
      {"dt_ns", "4.4"}, {"steps", "200"}, {"beta", "8"}, {"adaptive", "0"}, {"every", "1"}};
  config::Config cfg;
  for (const char* s : {"grid.n=64", "grid.box_A=725", "rod.base_pairs=600", "rod.excess_link=5",
                        "run.threads=1", "run.fftw_measure=false"})
    config::apply_override(cfg, s);
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto eq = a.find('=');
    if (eq == std::string::npos) return std::fprintf(stderr, "bad argument %s\n", a.c_str()), 2;
    if (a.substr(0, eq).find('.') != std::string::npos)
      config::apply_override(cfg, a);
    else
      kv[a.substr(0, eq)] = a.substr(eq + 1);
  }
  const double dt = std::stod(kv["dt_ns"]) * 1e-9;
  cfg.time_dt_ns = std::stod(kv["dt_ns"]);
  sim::SimParams p = config::to_params(cfg);
  rod::RodState rod = io::read_rod_shape(cfg.rod_initial_shape, "rod.initial_shape");
  integrate::Stepper st(p.stepper);
  integrate::ImplicitParams ip = p.implicit;
  ip.mobility_scale = std::stod(kv["beta"]);
  if (kv.count("order")) ip.order = std::stoi(kv["order"]);
  integrate::ImplicitStepper imp(st.system(), ip);
  integrate::AdaptiveDtParams ap = p.adaptive;
  ap.dt_max = dt;
  ap.dt_min = 1e-3 * dt;
  if (!(ap.max_displacement > 0))
    ap.max_displacement = std::stod(kv.count("dmax") ? kv["dmax"] : "1.92");
  integrate::AdaptiveDt ctl(ap);
  const bool adaptive = kv["adaptive"] == "1";
  const int steps = std::stoi(kv["steps"]), every = std::stoi(kv["every"]);
  const int n = rod.size();
  std::vector<Vec3> Uprev(n, Vec3::Zero()), Wprev(n, Vec3::Zero());
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::printf("# step t_ns dt_ns E_K_kT dE_kT max_u_A_per_ns cos_prev contacts ek_fluid_kT\n");
  double t = 0;
  int prev_contacts = -1;
  for (int s = 0; s < steps; ++s) {
    integrate::ImplicitStepInfo info;
    double h = dt;
    if (adaptive) {
      info = integrate::step_adaptive(imp, rod, ctl, HUGE_VAL, &h);
    } else {
      info = imp.step(rod, dt);
    }
    t += h;
    if (!info.finite) {
      std::printf("# not finite at step %d\n", s);
      return 1;
    }
    const auto& U = imp.velocities();
    const auto& W = imp.angular_velocities();
    double dot = 0, n1 = 0, n2 = 0, umax = 0;
    const double l2 = imp.self_mobility_translation() / imp.self_mobility_rotation();
    for (int k = 0; k < n; ++k) {
      dot += U[k].dot(Uprev[k]) + l2 * W[k].dot(Wprev[k]);
      n1 += U[k].squaredNorm() + l2 * W[k].squaredNorm();
      n2 += Uprev[k].squaredNorm() + l2 * Wprev[k].squaredNorm();
      umax = std::max(umax, U[k].norm());
    }
    const double cosv = (n1 > 0 && n2 > 0) ? dot / std::sqrt(n1 * n2) : 0;
    Uprev.assign(U.begin(), U.end());
    Wprev.assign(W.begin(), W.end());
    // the fluid's velocity is the Stokes velocity of M F(qⁿ): E_K as the run reports it
    const double ek = st.system().fluid_kinetic_energy() / p.kT;
    if (s % every == 0 || s == steps - 1)
      std::printf("%d %.4f %.4g %.4e %.3e %.4e %+.4f %d%s\n", s, t * 1e9, h * 1e9, ek,
                  (info.energy_after - info.energy_before) / p.kT, umax * 1e-9, cosv,
                  imp.contacts(),
                  prev_contacts >= 0 && prev_contacts != imp.contacts() ? " *" : "");
    prev_contacts = imp.contacts();
  }
  return 0;
}
