// Issue 28: the linear model of the implicit thermal step on a real ring (docs/thermal.md, "The
// implicit step with noise"): at the initial shape of CONFIG (the twisted circle, turned by
// rod.rotation_deg), the dense Stokes mobility M (one
// Stokes solve per column), the overlap M_loc = β D O D scaled as ImplicitStepper does, and the
// Gauss–Newton stiffness split into its stretch/shear, bend and twist parts, written as raw
// doubles (6n × 6n each, column-major) for linear_ring.py.
// With onestep=S (and dt_ns=…): also S thermal implicit steps from that state, step i with the
// noise counter i, their velocities (δq/Δt, [6n] per step) in onestep.bin: the one-step
// covariance against the model's (linear_ring.py --onestep).
//   dump_linear CONFIG OUTDIR [key=value ...] [onestep=S dt_ns=DT]
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "config/config.hpp"
#include "integrate/implicit.hpp"
#include "integrate/local_mobility.hpp"
#include "rod/rod.hpp"
#include "sim/simulation.hpp"

using namespace ibrod;

namespace {
void write(const std::string& path, const Eigen::MatrixXd& A) {
  std::ofstream o(path, std::ios::binary);
  o.write(reinterpret_cast<const char*>(A.data()), std::streamsize(sizeof(double) * A.size()));
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: dump_linear CONFIG OUTDIR [key=value ...]\n");
    return 2;
  }
  config::Config cfg = config::load_config(argv[1]);
  int onestep = 0;
  std::string state_file;  // a final_state.csv (x, y, z, d1, d2, d3 per line) instead
  double dt_ns = 1;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("onestep=", 0) == 0)
      onestep = std::stoi(a.substr(8));
    else if (a.rfind("state=", 0) == 0)
      state_file = a.substr(6);
    else if (a.rfind("dt_ns=", 0) == 0)
      dt_ns = std::stod(a.substr(6));
    else
      config::apply_override(cfg, a);
  }
  const std::string out = argv[2];
  sim::SimParams p = config::to_params(cfg);
  const sim::SimParams pth = p;
  p.stepper.fluid.thermal_kT = 0;
  p.stepper.thermal_drift = false;
  rod::RodState s = sim::initial_state(p);  // with rod.rotation_deg: not in a grid plane
  if (!state_file.empty()) {
    std::ifstream in(state_file);
    std::string line;
    std::getline(in, line);
    for (int k = 0; k < s.size(); ++k) {
      std::getline(in, line);
      for (char& ch : line)
        if (ch == ',') ch = ' ';
      std::istringstream is(line);
      double v[12];
      for (double& x : v) is >> x;
      s.X[k] = Vec3(v[0], v[1], v[2]);
      for (int c = 0; c < 3; ++c) s.D[k].col(c) = Vec3(v[3 + 3 * c], v[4 + 3 * c], v[5 + 3 * c]);
    }
  }
  integrate::Stepper st(p.stepper);
  integrate::ImplicitParams ip = p.implicit;
  integrate::ImplicitStepper imp(st.system(), ip);
  const int n = s.size(), N = 6 * n;
  // M, column by column
  Eigen::MatrixXd M = imp.mobility_matrix(s.X);
  // M_loc = β D O D (ImplicitStepper's scaling: the self blocks at a generic point)
  const double h = p.stepper.grid.h();
  const std::vector<Vec3> X1{Vec3(0.31, 0.57, 0.73) * h};
  const int m = p.stepper.kernel_width;
  const auto O1 = integrate::kernel_overlap(X1, p.stepper.grid, m);
  const double dtr = std::sqrt(imp.self_mobility_translation() / O1.coeff(0, 0));
  const double drr = std::sqrt(imp.self_mobility_rotation() / O1.coeff(3, 3));
  Eigen::MatrixXd Ml = Eigen::MatrixXd(integrate::kernel_overlap(s.X, p.stepper.grid, m));
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j)
      Ml(i, j) *= ip.mobility_scale * (i % 6 < 3 ? dtr : drr) * (j % 6 < 3 ? dtr : drr);
  // K by parts: the moduli of one part at a time
  const rod::RodParams rp0 = p.stepper.rods[0];
  auto k_with = [&](Vec3 a, Vec3 b) {
    sim::SimParams q = p;
    q.stepper.rods[0].a = a;
    q.stepper.rods[0].b = b;
    integrate::Stepper st2(q.stepper);
    integrate::ImplicitStepper imp2(st2.system(), ip);
    return Eigen::MatrixXd(imp2.stiffness(s));
  };
  {  // the full Hessian −∂(F, T)/∂(X, θ) by central differences
    integrate::ImplicitParams full = ip;
    full.gauss_newton = false;
    integrate::ImplicitStepper imp4(st.system(), full);
    write(out + "/H.bin", Eigen::MatrixXd(imp4.stiffness(s)));
  }
  write(out + "/M.bin", M);
  write(out + "/Mloc.bin", Ml);
  write(out + "/K_stretch.bin", k_with(Vec3::Zero(), rp0.b));
  write(out + "/K_bend.bin", k_with(Vec3(rp0.a.x(), rp0.a.y(), 0), Vec3::Zero()));
  write(out + "/K_twist.bin", k_with(Vec3(0, 0, rp0.a.z()), Vec3::Zero()));
  std::ofstream(out + "/info.txt")
      << n << " " << p.stepper.rods[0].ds << " " << p.kT << " " << imp.self_mobility_translation()
      << " " << imp.self_mobility_rotation() << "\n";
  if (onestep < 0) {
    // the deterministic step's linear map on −onestep random δ (1e-5 Å, 1e-6 rad): columns
    // (δ, step(q0 + δ) − step(q0)) in linstep.bin, against linear_ring.py's B
    const int S = -onestep;
    Eigen::MatrixXd out2(N, 2 * S);
    integrate::ImplicitStepper imp5(st.system(), ip);
    const int m = std::getenv("LINSTEPS") ? std::atoi(std::getenv("LINSTEPS")) : 1;
    rod::RodState b0 = s;
    for (int j = 0; j < m; ++j) imp5.step(b0, dt_ns * 1e-9);
    std::srand(7);
    for (int i = 0; i < S; ++i) {
      Eigen::VectorXd d = Eigen::VectorXd::Random(N);
      for (int k = 0; k < N; ++k) d[k] *= (k % 6 < 3 ? 1e-5 : 1e-6);
      rod::RodState c = s;
      std::vector<Vec3> dX(n), dT(n);
      for (int k = 0; k < n; ++k) {
        dX[k] = d.segment<3>(6 * k);
        dT[k] = d.segment<3>(6 * k + 3);
      }
      rod::advance(c, dX, dT, 1.0);
      imp5.refresh_jacobian();
      for (int j = 0; j < m; ++j) imp5.step(c, dt_ns * 1e-9);
      out2.col(2 * i) = d;
      for (int k = 0; k < n; ++k) {
        out2.block<3, 1>(6 * k, 2 * i + 1) = c.X[k] - b0.X[k];
        const Mat3 R = c.D[k] * b0.D[k].transpose();  // small rotation: its vector
        out2.block<3, 1>(6 * k + 3, 2 * i + 1) =
            0.5 * Vec3(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
      }
    }
    write(out + "/linstep.bin", out2);
    std::printf("%d linear-map samples in %s/linstep.bin\n", S, out.c_str());
  }
  if (onestep > 0) {
    sim::SimParams q = pth;
    q.stepper.fluid.dt = dt_ns * 1e-9;
    integrate::Stepper st3(q.stepper);
    integrate::ImplicitStepper imp3(st3.system(), ip);
    Eigen::MatrixXd S(N, onestep);
    for (int i = 0; i < onestep; ++i) {
      rod::RodState c = s;
      st3.system().set_noise_step(std::uint64_t(i));
      imp3.step(c, dt_ns * 1e-9);
      for (int k = 0; k < n; ++k) {
        S.block<3, 1>(6 * k, i) = imp3.velocities()[k];
        S.block<3, 1>(6 * k + 3, i) = imp3.angular_velocities()[k];
      }
    }
    write(out + "/onestep.bin", S);
    std::printf("%d one-step samples at %g ns in %s/onestep.bin\n", onestep, dt_ns, out.c_str());
  }
  std::printf("n = %d, wrote %s/{M,Mloc,K_stretch,K_bend,K_twist}.bin, info.txt\n", n, out.c_str());
  return 0;
}
