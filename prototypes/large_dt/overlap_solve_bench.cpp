// Issue 24: what the local solve with the kernel-overlap M_loc costs, by solver and ordering, on
// the reference ring (64³, 600 bp) at its twisted circle or a saved state.
//   overlap_solve_bench [dt_ns=2] [beta=0.25] [state=FILE (x y z per line, triads of the circle)]
#include <Eigen/OrderingMethods>
#include <Eigen/SparseLU>
#include <chrono>
#include <cstdio>
#include <map>
#include <string>

#include "config/config.hpp"
#include "integrate/implicit.hpp"
#include "integrate/local_mobility.hpp"

using namespace ibrod;

template <class F>
double time_ms(F&& f, int reps = 3) {
  double best = 1e300;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best,
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return 1e3 * best;
}

int main(int argc, char** argv) {
  std::map<std::string, std::string> kv{{"dt_ns", "2"}, {"beta", "0.25"}};
  config::Config cfg;
  for (const char* s : {"grid.n=64", "grid.box_A=725", "rod.base_pairs=600", "rod.excess_link=5",
                        "run.threads=1", "run.fftw_measure=false"})
    config::apply_override(cfg, s);
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto eq = a.find('=');
    if (a.substr(0, eq).find('.') != std::string::npos)
      config::apply_override(cfg, a);
    else
      kv[a.substr(0, eq)] = a.substr(eq + 1);
  }
  const double dt = std::stod(kv["dt_ns"]) * 1e-9, beta = std::stod(kv["beta"]);
  sim::SimParams p = config::to_params(cfg);
  rod::RodState s = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
  integrate::Stepper st(p.stepper);
  integrate::ImplicitParams ip;
  integrate::ImplicitStepper imp(st.system(), ip);
  const int n = s.size();
  Eigen::SparseMatrix<double> K;
  const double t_k = time_ms([&] { K = imp.stiffness(s); });
  Eigen::SparseMatrix<double> O;
  const double t_o = time_ms([&] { O = integrate::kernel_overlap(s.X, p.stepper.grid, 1); });
  // scale as ImplicitStepper does (self blocks → β m_t, β m_r)
  const std::vector<Vec3> X1{Vec3(0.31, 0.57, 0.73) * p.stepper.grid.h()};
  const auto O1 = integrate::kernel_overlap(X1, p.stepper.grid, 1);
  const double dtr = std::sqrt(imp.self_mobility_translation() / O1.coeff(0, 0));
  const double drr = std::sqrt(imp.self_mobility_rotation() / O1.coeff(3, 3));
  for (int c = 0; c < O.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(O, c); it; ++it)
      it.valueRef() *= beta * (it.row() % 6 < 3 ? dtr : drr) * (it.col() % 6 < 3 ? dtr : drr);
  Eigen::SparseMatrix<double> A;
  const double t_a = time_ms([&] {
    A = O * K;
    A *= dt;
    for (int i = 0; i < 6 * n; ++i) A.coeffRef(i, i) += 1.0;
    A.makeCompressed();
  });
  std::printf(
      "n = %d: K %.2f ms (nnz %ld), overlap %.2f ms (nnz %ld), A = I + dt M K %.2f ms "
      "(nnz %ld, %.0f per row)\n",
      n, t_k, long(K.nonZeros()), t_o, long(O.nonZeros()), t_a, long(A.nonZeros()),
      double(A.nonZeros()) / A.rows());
  Eigen::VectorXd v = Eigen::VectorXd::Random(6 * n), x;
  {
    Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu;
    const double ta = time_ms([&] { lu.analyzePattern(A); });
    const double tf = time_ms([&] { lu.factorize(A); });
    const double ts = time_ms([&] { x = lu.solve(v); });
    std::printf("SparseLU COLAMD : analyze %.2f factorize %.2f solve %.3f ms, residual %.2e\n", ta,
                tf, ts, (A * x - v).norm() / v.norm());
  }
  {
    Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::NaturalOrdering<int>> lu;
    const double ta = time_ms([&] { lu.analyzePattern(A); });
    const double tf = time_ms([&] { lu.factorize(A); });
    const double ts = time_ms([&] { x = lu.solve(v); });
    std::printf("SparseLU natural: analyze %.2f factorize %.2f solve %.3f ms, residual %.2e\n", ta,
                tf, ts, (A * x - v).norm() / v.norm());
  }
  {
    Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::AMDOrdering<int>> lu;
    const double ta = time_ms([&] { lu.analyzePattern(A); });
    const double tf = time_ms([&] { lu.factorize(A); });
    const double ts = time_ms([&] { x = lu.solve(v); });
    std::printf("SparseLU AMD    : analyze %.2f factorize %.2f solve %.3f ms, residual %.2e\n", ta,
                tf, ts, (A * x - v).norm() / v.norm());
  }
  {
    // the symmetric-pattern mode (diagonal preferred as pivot) with natural ordering
    Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::NaturalOrdering<int>> lu;
    lu.isSymmetric(true);
    lu.setPivotThreshold(0.1);
    const double ta = time_ms([&] { lu.analyzePattern(A); });
    const double tf = time_ms([&] { lu.factorize(A); });
    const double ts = time_ms([&] { x = lu.solve(v); });
    std::printf(
        "SparseLU natural, symmetric mode, diagonal pivots: analyze %.2f factorize %.2f "
        "solve %.3f ms, residual %.2e\n",
        ta, tf, ts, (A * x - v).norm() / v.norm());
  }
  // matrix-free application of A (for iterative refinement against a kept factorisation)
  const double tm = time_ms([&] { x = v + dt * (O * (K * v)); }, 10);
  std::printf("A v matrix-free: %.3f ms\n", tm);
  return 0;
}
