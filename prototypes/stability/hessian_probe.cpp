// Issue 24 / the stability test: the lowest eigenvalues of the total energy's Hessian at a state
// (docs/study.md, "The dynamic test misses a slow instability"). For overdamped dynamics
// q̇ = −M ∇E with M symmetric positive definite, the linearisation −M H has as many growing modes
// as H has negative eigenvalues (Sylvester), whatever M is: so a state is linearly unstable iff H,
// less its six rigid-body zero modes, has a negative eigenvalue.
//
// H = −∂(F, T)/∂(X, ℓθ) by central differences of System::compute_forces (every term: elastic,
// electrostatic, steric, external), θ the space-frame rotation vector of each triad, ℓ a length
// that puts rotations in Å (the count of negative eigenvalues does not depend on it); symmetrised.
//   hessian_probe CONFIG STATE.csv [key=value ...] [ell=ΔS] [dx=1e-3] [k=12] [ibrod=1]
// (ibrod=1: ibrod's own test at the state instead, sim::probe_stability with the Hessian method:
// rigid modes, spin and slithering projected out). STATE: a final_state.csv or H5MD@FRAME.
#include <Eigen/Dense>
#include <chrono>
#include <cstdio>
#include <string>

#include "config/config.hpp"
#include "integrate/stepper.hpp"
#include "io/rod_shape.hpp"
#include "rod/rod.hpp"
#include "sim/simulation.hpp"
#include "sim/stability.hpp"

using namespace ibrod;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: hessian_probe CONFIG STATE.csv [key=value ...]\n");
    return 2;
  }
  config::Config cfg = config::load_config(argv[1]);
  double ell = -1, dx = 1e-3;
  int k_print = 12;
  bool vectors = true, ibrod_test = false;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("ell=", 0) == 0)
      ell = std::stod(a.substr(4));
    else if (a.rfind("dx=", 0) == 0)
      dx = std::stod(a.substr(3));
    else if (a.rfind("vectors=", 0) == 0)
      vectors = a.substr(8) != "0";
    else if (a.rfind("k=", 0) == 0)
      k_print = std::stoi(a.substr(2));
    else if (a.rfind("ibrod=", 0) == 0)
      ibrod_test = a.substr(6) != "0";
    else
      config::apply_override(cfg, a);
  }
  sim::SimParams p = config::to_params(cfg);
  const rod::RodState s = io::read_rod_shape(argv[2], "STATE.csv");
  if (ell <= 0) ell = p.stepper.rods[0].ds;
  if (ibrod_test) {  // ibrod's own test (sim::probe_stability, the Hessian method) at the state
    p.stability.method = sim::StabilityProbe::Method::hessian;
    sim::Simulation sim(p);
    sim.set_rod_state(s, "STATE.csv");
    const sim::ProbeOutcome o = sim::probe_stability(sim, p.stability, 0);
    std::printf("%s\nlowest:", sim::describe(o).c_str());
    for (double e : o.lowest_eigenvalues) std::printf(" %.4e", e);
    std::printf("\n");
    return 0;
  }
  integrate::Stepper st(p.stepper);
  integrate::System& sys = st.system();
  const int n = s.size(), N = 6 * n;
  const double kT = p.kT;
  auto t0 = std::chrono::steady_clock::now();
  sys.compute_forces(s);
  std::vector<Vec3> F0 = sys.forces(), T0 = sys.torques();
  double gnorm = 0;
  for (int k = 0; k < n; ++k) gnorm += F0[k].squaredNorm() + (T0[k] / ell).squaredNorm();
  Eigen::MatrixXd H(N, N);
  rod::RodState q = s;
  std::vector<Vec3> Fa, Ta;
  for (int j = 0; j < N; ++j) {
    const int k = j / 6, d = j % 6;
    for (int side = 0; side < 2; ++side) {
      const double e = side == 0 ? dx : -dx;
      if (d < 3)
        q.X[k][d] = s.X[k][d] + e;
      else
        q.D[k] = rotation((e / ell) * Vec3::Unit(d - 3)) * s.D[k];
      sys.compute_forces(q);
      if (side == 0) {
        Fa = sys.forces();
        Ta = sys.torques();
      } else {
        const auto& Fb = sys.forces();
        const auto& Tb = sys.torques();
        for (int i = 0; i < n; ++i)
          for (int r = 0; r < 3; ++r) {
            H(6 * i + r, j) = -(Fa[i][r] - Fb[i][r]) / (2 * dx) / kT;
            H(6 * i + 3 + r, j) = -(Ta[i][r] - Tb[i][r]) / ell / (2 * dx) / kT;
          }
      }
      q.X[k] = s.X[k];
      q.D[k] = s.D[k];
    }
  }
  auto t1 = std::chrono::steady_clock::now();
  const double asym = (H - H.transpose()).norm() / H.norm();
  {  // the Rayleigh quotient of the triads' uniform spin about d3 (an exact invariance of an
     // isotropic rod, so 0 for the Hessian of E along it)
    Eigen::VectorXd v = Eigen::VectorXd::Zero(N);
    for (int k = 0; k < n; ++k) v.segment<3>(6 * k + 3) = ell * s.D[k].col(2);
    v.normalize();
    std::printf("spin: v^T H v = %.4e kT/A^2 (symmetric part)\n", v.dot(H * v));
  }
  // the slithering of the closed rod along its own contour (sim::slithering_vector, the vector
  // the test projects out)
  Eigen::VectorXd slither =
      sim::slithering_vector(s, rod::RodRange{0, n, true, p.stepper.rods[0].ds}, ell);
  slither.normalize();
  std::printf("slithering: v^T H v = %.4e kT/A^2 (symmetric part)\n", slither.dot(H * slither));
  Eigen::MatrixXd Hs = 0.5 * (H + H.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(
      Hs, vectors ? Eigen::ComputeEigenvectors : Eigen::EigenvaluesOnly);
  auto t2 = std::chrono::steady_clock::now();
  std::printf("n %d, N %d, |grad| %.3e kT/A, asym %.2e, Hessian %.1f s, eigenvalues %.1f s\n", n,
              N, std::sqrt(gnorm) / kT, asym, std::chrono::duration<double>(t1 - t0).count(),
              std::chrono::duration<double>(t2 - t1).count());
  std::printf("lowest eigenvalues (kT/A^2, rotations per %g A):", ell);
  for (int i = 0; i < k_print && i < N; ++i) std::printf(" %.4e", eig.eigenvalues()[i]);
  std::printf("\nlargest %.4e\n", eig.eigenvalues()[N - 1]);
  // each of the lowest modes: the share of its position part, and its roughness
  // Σ|v_{k+1} − v_k|² / Σ|v_k|² over the positions (4 for a zig-zag, ~(2π m/n)² for a smooth m)
  for (int i = 0; i < k_print && i < N && vectors; ++i) {
    const Eigen::VectorXd v = eig.eigenvectors().col(i);
    double px = 0, rough = 0, prot = 0;
    for (int k = 0; k < n; ++k) {
      const int k1 = (k + 1) % n;
      px += v.segment<3>(6 * k).squaredNorm();
      prot += v.segment<3>(6 * k + 3).squaredNorm();
      rough += (v.segment<3>(6 * k1) - v.segment<3>(6 * k)).squaredNorm() +
               (v.segment<3>(6 * k1 + 3) - v.segment<3>(6 * k + 3)).squaredNorm();
    }
    std::printf("mode %d: %.4e  position share %.3f  roughness %.3e  overlap with slithering %.3f\n",
                i, eig.eigenvalues()[i], px, rough / (px + prot), std::abs(v.dot(slither)));
  }
  return 0;
}
