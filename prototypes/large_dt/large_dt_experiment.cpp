// Issue 14 experiment: one ring, one scheme, one Δt; prints a time series and a summary line
// (docs/large_dt.md has the commands and the numbers).
//   large_dt_experiment scheme=explicit|stokes|imex|krylov dt_ns=… t_end_ns=… [key=value …]
// Any other key=value that contains a '.' is passed to the config (config::apply_override), e.g.
// grid.n=32 rod.base_pairs=150. Keys of this program: scheme, dt_ns, t_end_ns, out_ns, beta,
// kiter, tol, jac_every, mloc=self|overlap, save=FILE (final X), ref=FILE (max |X − X_ref| at the
// end).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <string>

#include "config/config.hpp"
#include "diagnostics/topology.hpp"
#include "integrate/adaptive_dt.hpp"
#include "integrate/implicit.hpp"

using namespace ibrod;

int main(int argc, char** argv) {
  std::map<std::string, std::string> kv{{"scheme", "imex"},
                                        {"dt_ns", "1"},
                                        {"t_end_ns", "200"},
                                        {"out_ns", "20"},
                                        {"beta", "2"},
                                        {"kiter", "10"},
                                        {"tol", "1e-2"},
                                        {"jac_every", "1"},
                                        {"K", "gn"},
                                        {"steric_implicit", "1"},
                                        {"adaptive", "0"},
                                        {"form", "velocity"},
                                        {"energy_every_step", "0"},
                                        {"dmax", "2"},
                                        {"etol", "1e-3"},
                                        {"order", "1"},
                                        {"mloc", "self"},
                                        {"ov_window", "0"},
                                        {"err_tol", "0"}};
  config::Config cfg;
  // the experiment's ring: 32³, h as at the reference (11.33 Å), 150 bp, ΔLk = 3, 0.1 M
  for (const char* s : {"grid.n=32", "grid.box_A=362.5", "rod.base_pairs=150", "rod.excess_link=3",
                        "run.threads=1", "run.fftw_measure=false"})
    config::apply_override(cfg, s);
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto eq = a.find('=');
    if (eq == std::string::npos) return std::fprintf(stderr, "bad argument %s\n", a.c_str()), 2;
    const std::string k = a.substr(0, eq);
    if (k.find('.') != std::string::npos)
      config::apply_override(cfg, a);
    else
      kv[k] = a.substr(eq + 1);
  }
  const std::string scheme = kv["scheme"];
  const double dt = std::stod(kv["dt_ns"]) * 1e-9;
  const double t_end = std::stod(kv["t_end_ns"]) * 1e-9;
  const double out = std::stod(kv["out_ns"]) * 1e-9;
  cfg.time_dt_ns = std::stod(kv["dt_ns"]);
  sim::SimParams p = config::to_params(cfg);
  rod::RodState rod = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
  integrate::Stepper st(p.stepper);
  integrate::ImplicitParams ip;
  ip.mobility_scale = scheme == "stokes" ? 0.0 : std::stod(kv["beta"]);
  ip.krylov_max_iter = scheme == "krylov" ? std::stoi(kv["kiter"]) : 0;
  ip.krylov_tol = std::stod(kv["tol"]);
  ip.jacobian_every = std::stoi(kv["jac_every"]);
  ip.gauss_newton = kv["K"] != "full";
  ip.stiffness_fd = kv["K"] == "fd";
  ip.steric_implicit = kv["steric_implicit"] == "1";
  ip.velocity_form = kv["form"] != "force";
  ip.order = std::stoi(kv["order"]);
  ip.overlap_window = std::stod(kv["ov_window"]);
  if (kv["mloc"] != "self" && kv["mloc"] != "overlap")
    return std::fprintf(stderr, "mloc must be self or overlap\n"), 2;
  ip.local_mobility = kv["mloc"] == "overlap" ? integrate::ImplicitParams::LocalMobility::overlap
                                              : integrate::ImplicitParams::LocalMobility::self;
  std::unique_ptr<integrate::ImplicitStepper> imp;
  if (scheme != "explicit") imp = std::make_unique<integrate::ImplicitStepper>(st.system(), ip);
  if (imp)
    std::printf("# self mobility m_t = %.4g A/s per g A/s^2, m_r = %.4g 1/s per g A^2/s^2\n",
                imp->self_mobility_translation(), imp->self_mobility_rotation());
  const double kT = p.kT;
  auto energy = [&](const integrate::StepEnergies& e) {
    return (e.elastic.total() + e.electro + e.steric) / kT;
  };
  auto potential = [&]() {
    double e = rod::elastic_energy(p.stepper.rods[0], rod).total();
    if (p.stepper.electro.enabled) e += st.system().electrostatics().energy(rod.X);
    if (p.stepper.steric.enabled) e += st.system().steric().energy(rod.X);
    return e / kT;
  };
  (void)energy;
  std::printf(
      "# t_ns Wr Lk E_kT closest_A spacing_min spacing_max iters solves max_disp_A dt_ns\n");
  const auto t0 = std::chrono::steady_clock::now();
  long steps = 0, solves = 0, iters = 0, notconv = 0;
  double res_sum = 0;
  double t = 0, next_out = 0, maxdisp = 0, E_prev = potential(), E_rise = 0, lk0 = 0;
  bool blown = false;
  const bool adaptive = kv["adaptive"] == "1";
  integrate::AdaptiveDtParams ap;
  ap.dt_max = dt;
  ap.dt_min = 1e-3 * dt;
  ap.max_displacement = std::stod(kv["dmax"]);
  ap.energy_tolerance = std::stod(kv["etol"]) * kT;
  ap.error_tolerance = std::stod(kv["err_tol"]);
  integrate::AdaptiveDt ctl(ap);
  double dt_min_used = dt;
  for (long s = 0;; ++s) {
    const bool done = t >= t_end - 1e-6 * dt;
    if (t >= next_out - 1e-6 * dt || done) {
      const int n = rod.size();
      std::vector<Vec3> d1(n);
      double smin = 1e300, smax = 0;
      for (int k = 0; k < n; ++k) {
        d1[k] = rod.D[k].col(0);
        const double sp = (rod.X[(k + 1) % n] - rod.X[k]).norm();
        smin = std::min(smin, sp);
        smax = std::max(smax, sp);
      }
      const double wr = diagnostics::writhe(rod.X), lk = wr + diagnostics::twist(rod.X, d1);
      if (s == 0) lk0 = lk;
      std::printf("%.3f %.5f %.6f %.4f %.3f %.4f %.4f %ld %ld %.4f %.4g\n", t * 1e9, wr, lk,
                  potential(), diagnostics::closest_approach(rod.X, 20), smin, smax, iters, solves,
                  maxdisp, (adaptive ? ctl.dt() : dt) * 1e9);
      while (next_out <= t + 1e-6 * dt) next_out += out;
      if (!std::isfinite(wr) || smax > 1.5 * p.stepper.rods[0].ds ||
          smin < 0.5 * p.stepper.rods[0].ds || std::abs(lk - lk0) > 0.1) {
        blown = true;
        std::printf("# BLOWUP at step %ld t = %.3f ns\n", s, t * 1e9);
        break;
      }
    }
    if (done) break;
    double h = adaptive ? std::min(ctl.dt(), t_end - t) : std::min(dt, t_end - t);
    if (imp) {
      const auto info = imp->step(rod, h);
      solves += info.fluid_solves;
      iters += info.krylov_iterations;
      if (adaptive) {
        integrate::StepOutcome o;
        o.max_displacement = info.max_displacement;
        o.max_rotation = info.max_rotation;
        o.energy_change = info.energy_after - info.energy_before;
        o.converged = info.converged;
        o.finite = info.finite;
        o.error = info.error;
        o.dt = h;
        if (!ctl.judge(o)) {
          imp->undo(rod);
          continue;
        }
        dt_min_used = std::min(dt_min_used, h);
      }
      notconv += !info.converged;
      res_sum += info.residual;
      maxdisp = std::max(maxdisp, info.max_displacement);
      E_rise = std::max(E_rise, (info.energy_after - info.energy_before) / kT);
    } else {
      st.step(rod);
      ++solves;
      for (const auto& u : st.velocities()) maxdisp = std::max(maxdisp, h * u.norm());
      if (kv["energy_every_step"] == "1" || t + h >= next_out - 1e-6 * dt) {
        const double E = potential();  // O(n²): every step only on request
        E_rise = std::max(E_rise, E - E_prev);
        E_prev = E;
      }
    }
    ++steps;
    t += h;
    if (!std::isfinite(E_prev)) {
      blown = true;
      std::printf("# BLOWUP (energy) at step %ld\n", s);
      break;
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  double err = -1;
  if (kv.count("save")) {
    std::ofstream f(kv["save"]);
    f.precision(17);
    for (const auto& x : rod.X) f << x.x() << ' ' << x.y() << ' ' << x.z() << '\n';
  }
  if (kv.count("ref") && !blown) {
    std::ifstream f(kv["ref"]);
    err = 0;
    for (const auto& x : rod.X) {
      Vec3 y;
      f >> y.x() >> y.y() >> y.z();
      err = std::max(err, (x - y).norm());
    }
  }
  std::printf(
      "SUMMARY scheme=%s dt_ns=%g beta=%g steps=%ld blown=%d solves=%ld iters_per_step=%.2f "
      "notconv=%ld max_energy_rise_kT=%.3g max_disp_A=%.3f wall_s=%.2f ms_per_step=%.3f "
      "err_A=%.4g mean_residual=%.3g rejections=%ld dt_min_used_ns=%.4g\n",
      scheme.c_str(), dt * 1e9, ip.mobility_scale, steps, blown, solves,
      steps ? double(iters) / steps : 0.0, notconv, E_rise, maxdisp, wall,
      steps ? 1e3 * wall / steps : 0.0, err, steps ? res_sum / steps : 0.0, ctl.rejections(),
      dt_min_used * 1e9);
  if (imp) {
    const auto& tm = imp->timings();
    std::printf(
        "TIMINGS_ms_per_step forces=%.3f stiffness=%.3f factorize=%.3f local_solve=%.3f "
        "stokes=%.3f overlap=%.3f analyze=%.3f\n",
        1e3 * tm.forces / steps, 1e3 * tm.stiffness / steps, 1e3 * tm.factorize / steps,
        1e3 * tm.local_solve / steps, 1e3 * tm.stokes / steps, 1e3 * tm.overlap / steps,
        1e3 * tm.analyze / steps);
  }
  return blown ? 1 : 0;
}
