// Issue 28: why implicit thermal runs are hot (docs/thermal.md, "The implicit step with noise").
// From the initial shape of CONFIG (or state=FILE, a final_state.csv), S samples of: `noisy`
// thermal implicit steps (sample j, step i: noise counter 1000 j + i) followed by `det`
// deterministic implicit steps of the same Δt (the same ImplicitParams, kT = 0), each step's
// displacement from the start (positions, rotation vectors log(D Dₛᵀ)) in traj.bin
// ([6n] × S (noisy + det + 1), column-major) and its elastic energies relative to the start in
// energies.csv, for probe_linear.py to set against the linear model (dump_linear's B) applied to
// the same displacements.
//   probe_steps CONFIG OUTDIR [key=value ...] [state=FILE] [dt_ns=DT] [noisy=N1] [det=N2]
//   [samples=S]
//               [relax=R] [fk=0] [gn=0] [second=1] [apply=FILE]
// relax=R: R deterministic steps first, the relaxed start written to relaxed.csv; fk=0: no
// thermal force (candidate A); gn=0: the full Hessian in the filter (the stepper's default with
// noise since the geometric-stiffness fix; gn=1, this probe's default, is K_GN as before);
// second=1: the second step's noise against the first's (second.bin); apply=FILE: energies of given
// displacements.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "config/config.hpp"
#include "integrate/implicit.hpp"
#include "rod/rod.hpp"
#include "sim/simulation.hpp"

using namespace ibrod;

namespace {
Vec3 log_rotation(const Mat3& R) {
  const double c = std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0);
  const double th = std::acos(c);
  const Vec3 v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  if (th < 1e-8) return 0.5 * v;
  return v * (th / (2.0 * std::sin(th)));
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: probe_steps CONFIG OUTDIR [key=value ...]\n");
    return 2;
  }
  config::Config cfg = config::load_config(argv[1]);
  std::string state_file;
  double dt_ns = 1;
  int noisy = 1, det = 10, samples = 1;
  int relax = 0;  // relax=R: R deterministic steps first (the circle is an equilibrium only to
                  // O(Δs²)); the relaxed state in relaxed.csv, for dump_linear state=…
  std::string apply_file;  // apply=FILE: displacement columns ([6n] × m doubles) applied to the
                           // start by rod::advance: their elastic energies in applied.csv
  int fk = 1, gn = 1;      // fk=0: no thermal force f_K (candidate A); gn=0: the full Hessian in W
  bool second = false;     // second=1: per sample q1 = noisy(q0; a), q2d = det(q1), q2n = noisy(q1;
                        // b), q1b = noisy(q0; b): traj columns (q1, q2d, q2n, q1b) − q0
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("state=", 0) == 0)
      state_file = a.substr(6);
    else if (a.rfind("dt_ns=", 0) == 0)
      dt_ns = std::stod(a.substr(6));
    else if (a.rfind("noisy=", 0) == 0)
      noisy = std::stoi(a.substr(6));
    else if (a.rfind("det=", 0) == 0)
      det = std::stoi(a.substr(4));
    else if (a.rfind("fk=", 0) == 0)
      fk = std::stoi(a.substr(3));
    else if (a.rfind("gn=", 0) == 0)
      gn = std::stoi(a.substr(3));
    else if (a.rfind("apply=", 0) == 0)
      apply_file = a.substr(6);
    else if (a.rfind("relax=", 0) == 0)
      relax = std::stoi(a.substr(6));
    else if (a.rfind("second=", 0) == 0)
      second = std::stoi(a.substr(7)) != 0;
    else if (a.rfind("samples=", 0) == 0)
      samples = std::stoi(a.substr(8));
    else
      config::apply_override(cfg, a);
  }
  const std::string out = argv[2];
  const sim::SimParams pth = config::to_params(cfg);
  sim::SimParams p = pth;
  p.stepper.fluid.thermal_kT = 0;
  p.stepper.thermal_drift = false;
  rod::RodState s0 = sim::initial_state(p);
  if (!state_file.empty()) {
    std::ifstream in(state_file);
    std::string line;
    std::getline(in, line);
    for (int k = 0; k < s0.size(); ++k) {
      std::getline(in, line);
      for (char& ch : line)
        if (ch == ',') ch = ' ';
      std::istringstream is(line);
      double v[12];
      for (double& x : v) is >> x;
      s0.X[k] = Vec3(v[0], v[1], v[2]);
      for (int c = 0; c < 3; ++c) s0.D[k].col(c) = Vec3(v[3 + 3 * c], v[4 + 3 * c], v[5 + 3 * c]);
    }
  }
  const double dt = dt_ns * 1e-9;
  integrate::ImplicitParams ip = p.implicit;
  ip.thermal_force = fk != 0;
  ip.gauss_newton = gn != 0;
  ip.thermal_hessian = gn == 0;  // (the stepper's default is the full Hessian with noise)
  integrate::Stepper st(p.stepper);
  integrate::ImplicitStepper det_step(st.system(), ip);
  sim::SimParams q = pth;
  q.stepper.fluid.dt = dt;
  integrate::Stepper stt(q.stepper);
  integrate::ImplicitStepper th_step(stt.system(), ip);
  const int n = s0.size(), N = 6 * n, L = noisy + det + 1;
  const double kT = pth.kT;
  const rod::RodParams& rp = p.stepper.rods[0];
  if (relax > 0) {
    for (int i = 0; i < relax; ++i) det_step.step(s0, dt);
    std::ofstream r(out + "/relaxed.csv");
    r << "x,y,z,d1x,d1y,d1z,d2x,d2y,d2z,d3x,d3y,d3z\n";
    r.precision(17);
    for (int k = 0; k < n; ++k) {
      r << s0.X[k].x() << "," << s0.X[k].y() << "," << s0.X[k].z();
      for (int c = 0; c < 3; ++c)
        for (int d = 0; d < 3; ++d) r << "," << s0.D[k](d, c);
      r << "\n";
    }
  }
  const rod::ElasticEnergy e0 = rod::elastic_energy(rp, s0);
  auto put = [&](Eigen::MatrixXd& T, int col, const rod::RodState& s) {
    for (int k = 0; k < n; ++k) {
      T.block<3, 1>(6 * k, col) = s.X[k] - s0.X[k];
      T.block<3, 1>(6 * k + 3, col) = log_rotation(s.D[k] * s0.D[k].transpose());
    }
  };
  if (!apply_file.empty()) {
    std::ifstream in(apply_file, std::ios::binary | std::ios::ate);
    const std::size_t m = std::size_t(in.tellg()) / (sizeof(double) * std::size_t(N));
    in.seekg(0);
    Eigen::MatrixXd Dm(N, Eigen::Index(m));
    in.read(reinterpret_cast<char*>(Dm.data()), std::streamsize(sizeof(double) * Dm.size()));
    std::ofstream a(out + "/applied.csv");
    a << "col,stretch,bend,twist\n";
    for (Eigen::Index c = 0; c < Dm.cols(); ++c) {
      rod::RodState s = s0;
      std::vector<Vec3> dX(n), dT(n);
      for (int k = 0; k < n; ++k) {
        dX[k] = Dm.block<3, 1>(6 * k, c);
        dT[k] = Dm.block<3, 1>(6 * k + 3, c);
      }
      rod::advance(s, dX, dT, 1.0);
      const rod::ElasticEnergy e = rod::elastic_energy(rp, s);
      a << c << "," << (e.stretch - e0.stretch) / (1.5 * n * kT) << ","
        << (e.bend - e0.bend) / (n * kT) << "," << (e.twist - e0.twist) / (0.5 * n * kT)
        << std::endl;
    }
    std::printf("%zu displacements applied: %s/applied.csv\n", m, out.c_str());
    return 0;
  }
  if (second) {
    Eigen::MatrixXd T(N, 4 * samples);
    for (int j = 0; j < samples; ++j) {
      rod::RodState q1 = s0, q2d, q2n, q1b = s0;
      stt.system().set_noise_step(std::uint64_t(2 * j));
      th_step.step(q1, dt);
      q2d = q1;
      q2n = q1;
      det_step.step(q2d, dt);
      stt.system().set_noise_step(std::uint64_t(2 * j + 1));
      th_step.step(q2n, dt);
      th_step.step(q1b, dt);
      put(T, 4 * j, q1);
      put(T, 4 * j + 1, q2d);
      put(T, 4 * j + 2, q2n);
      put(T, 4 * j + 3, q1b);
    }
    std::ofstream o(out + "/second.bin", std::ios::binary);
    o.write(reinterpret_cast<const char*>(T.data()), std::streamsize(sizeof(double) * T.size()));
    std::printf("%d samples of (q1, q2d, q2n, q1b) in %s/second.bin\n", samples, out.c_str());
    return 0;
  }
  Eigen::MatrixXd traj(N, samples * L);
  std::ofstream ecsv(out + "/energies.csv");
  ecsv << "sample,step,noisy,stretch,bend,twist\n";  // E − E(start) over equipartition
  for (int j = 0; j < samples; ++j) {
    rod::RodState s = s0;
    for (int i = 0; i < L; ++i) {
      if (i > 0) {
        try {
          if (i <= noisy) {
            stt.system().set_noise_step(std::uint64_t(1000 * j + i - 1));
            th_step.step(s, dt);
          } else {
            det_step.step(s, dt);
          }
        } catch (const std::exception& e) {
          std::printf("sample %d step %d: %s\n", j, i, e.what());
          return 1;
        }
      }
      const rod::ElasticEnergy e = rod::elastic_energy(rp, s);
      ecsv << j << "," << i << "," << (i > 0 && i <= noisy) << ","
           << (e.stretch - e0.stretch) / (1.5 * n * kT) << "," << (e.bend - e0.bend) / (n * kT)
           << "," << (e.twist - e0.twist) / (0.5 * n * kT) << std::endl;
      for (int k = 0; k < n; ++k) {
        traj.block<3, 1>(6 * k, j * L + i) = s.X[k] - s0.X[k];
        traj.block<3, 1>(6 * k + 3, j * L + i) = log_rotation(s.D[k] * s0.D[k].transpose());
      }
    }
  }
  std::ofstream o(out + "/traj.bin", std::ios::binary);
  o.write(reinterpret_cast<const char*>(traj.data()),
          std::streamsize(sizeof(double) * traj.size()));
  std::printf("%d samples of %d noisy + %d deterministic steps at %g ns in %s\n", samples, noisy,
              det, dt_ns, out.c_str());
  return 0;
}
