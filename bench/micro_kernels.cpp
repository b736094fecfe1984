// Google Benchmark micro-benchmarks of the kernels of one time step (docs/performance.md).
// Reference system: MODEL §1 (64³ grid, 725 Å box, 600 points), built through config::to_params so
// that every parameter is the one a run uses. Threads: OMP_NUM_THREADS (FFTW and OpenMP loops).
//   ./build/bench/ibrod_microbench --benchmark_min_time=0.2
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "config/config.hpp"
#include "diagnostics/topology.hpp"
#include "fluid/advection.hpp"
#include "fluid/navier_stokes.hpp"
#include "ib/plane_coupler.hpp"
#include "interactions/interactions.hpp"
#include "rod/rod.hpp"
#include "sim/simulation.hpp"

using namespace ibrod;

namespace {

config::Config reference(int grid_n = 64, int points = 600, double salt = 0.1) {
  config::Config c;
  c.grid_n = grid_n;
  c.rod_base_pairs = points;
  c.solvent_salt_M = salt;
  return c;
}

// The reference ring after some buckling: a few thousand steps are too slow for a benchmark, so
// the circle gets a deterministic out-of-plane wave (what matters is the point distribution).
rod::RodState ring(const sim::SimParams& p) {
  rod::RodState s = rod::twisted_circle(p.stepper.rods[0], p.shapes[0].circle);
  for (int k = 0; k < s.size(); ++k)
    s.X[k][2] += 20.0 * std::sin(3.0 * 2.0 * std::numbers::pi * k / s.size());
  return s;
}

void fill_random(double* a, std::size_t n, double scale, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> nd(0.0, scale);
  for (std::size_t i = 0; i < n; ++i) a[i] = nd(rng);
}

// Peskin 4-point weights of one point: 3 × 6 φ evaluations (what each spread/interpolate point
// computes before touching the grid).
void BM_KernelWeights(benchmark::State& st) {
  double x = 0.123, acc = 0;
  for (auto _ : st) {
    for (int d = 0; d < 3; ++d)
      for (int q = 0; q < 6; ++q) acc += ib::phi4(q - 2.0 - x - 0.1 * d);
    x += 1e-7;
    benchmark::DoNotOptimize(acc);
  }
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_KernelWeights);

struct CouplingFixture {
  sim::SimParams p;
  rod::RodState s;
  ib::Coupler cp;
  std::vector<double> grid;
  std::vector<Vec3> F, T, U, W;
  explicit CouplingFixture(int n_grid, int points)
      : p(config::to_params(reference(n_grid, points))),
        s(ring(p)),
        cp(p.stepper.grid, p.stepper.kernel_width),
        grid(3 * p.stepper.grid.size()),
        F(s.size(), Vec3(1e-6, 2e-6, 3e-6)),
        T(s.size(), Vec3(1e-4, -1e-4, 2e-4)),
        U(s.size()),
        W(s.size()) {
    fill_random(grid.data(), grid.size(), 1e6, 3);
  }
  std::array<double*, 3> g() {
    const std::size_t n3 = p.stepper.grid.size();
    return {grid.data(), grid.data() + n3, grid.data() + 2 * n3};
  }
};

void BM_Spread(benchmark::State& st) {
  CouplingFixture fx(64, int(st.range(0)));
  for (auto _ : st) fx.cp.spread(fx.s.X, fx.F, fx.T, fx.g());
  st.SetItemsProcessed(st.iterations() * st.range(0));
}
BENCHMARK(BM_Spread)->Arg(600)->Arg(6000)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_Interpolate(benchmark::State& st) {
  CouplingFixture fx(64, int(st.range(0)));
  const auto g = fx.g();
  const std::array<const double*, 3> cg = {g[0], g[1], g[2]};
  for (auto _ : st) fx.cp.interpolate(fx.s.X, cg, fx.U, fx.W);
  st.SetItemsProcessed(st.iterations() * st.range(0));
}
BENCHMARK(BM_Interpolate)->Arg(600)->Arg(6000)->Unit(benchmark::kMicrosecond)->UseRealTime();

// the plane-by-plane coupling of the step (ib::PlaneCoupler): 0 = kernel weights and plane
// lists, 1 = spreading into every x-plane, 2 = sampling every x-plane + the per-point sums.
// Every plane is the same cache-resident buffer, as in the fluid's plane pass (where the plane
// was just written); the work per plane is the real one.
void BM_PlaneCoupling(benchmark::State& st) {
  CouplingFixture fx(64, int(st.range(0)));
  ib::PlaneCoupler pc(fx.cp, int(st.range(0)));
  pc.prepare(fx.s.X, fx.F, fx.T);
  const int n = fx.p.stepper.grid.n;
  const std::size_t np = std::size_t(n) * n;
  const auto g = fx.g();
  const int what = int(st.range(1));
  for (auto _ : st) {
    if (what == 0) pc.prepare(fx.s.X, fx.F, fx.T);
    for (int i = 0; what == 1 && i < n; ++i) pc.add_plane(i, {g[0], g[0] + np, g[0] + 2 * np});
    for (int i = 0; what == 2 && i < n; ++i) pc.sample_plane(i, {g[0], g[0] + np, g[0] + 2 * np});
    if (what == 2) pc.finish_interpolation(fx.U, fx.W);
  }
  st.SetItemsProcessed(st.iterations() * st.range(0));
}
BENCHMARK(BM_PlaneCoupling)
    ->ArgsProduct({{600, 6000}, {0, 1, 2}})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

void BM_ElasticForces(benchmark::State& st) {
  const auto p = config::to_params(reference(64, int(st.range(0))));
  const auto s = ring(p);
  rod::RodWork w;
  w.resize(s.size());
  std::vector<Vec3> F(s.size()), T(s.size());
  for (auto _ : st) benchmark::DoNotOptimize(rod::elastic_forces(p.stepper.rods[0], s, w, F, T));
  st.SetItemsProcessed(st.iterations() * st.range(0));
}
BENCHMARK(BM_ElasticForces)->Arg(600)->Arg(6000)->Unit(benchmark::kMicrosecond)->UseRealTime();

// range(0): salt in mM (100 = 0.1 M, 1 = 0.001 M: Debye length 96 Å, most pairs interact)
void BM_Electrostatics(benchmark::State& st) {
  const auto p = config::to_params(reference(64, 600, st.range(0) * 1e-3));
  const auto s = ring(p);
  interactions::Electrostatics el(p.stepper.electro, s.size());
  std::vector<Vec3> F(s.size());
  for (auto _ : st) benchmark::DoNotOptimize(el.accumulate(s.X, F));
  st.counters["cell_list"] = el.used_cell_list() ? 1 : 0;
}
BENCHMARK(BM_Electrostatics)->Arg(100)->Arg(1)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_Steric(benchmark::State& st) {
  const auto p = config::to_params(reference());
  const auto s = ring(p);
  interactions::Steric sr(p.stepper.steric, s.size());
  std::vector<Vec3> F(s.size());
  for (auto _ : st) benchmark::DoNotOptimize(sr.accumulate(s.X, F));
}
BENCHMARK(BM_Steric)->Unit(benchmark::kMicrosecond)->UseRealTime();

struct FluidFixture {
  fluid::FluidSolver fl;
  explicit FluidFixture(int n)
      : fl(config::to_params(reference(n)).stepper.grid,
           config::to_params(reference(n)).stepper.fluid, omp_get_max_threads(), true) {
    for (int c = 0; c < 3; ++c) fill_random(fl.velocity(c), fl.grid().size(), 1e6, 5 + c);
  }
};

// the three passes of FluidSolver::finish_step, alone: 0 = rhs + 2-D plane FFTs,
// 1 = x FFTs + solve + inverse x FFTs, 2 = inverse 2-D plane FFTs; 3 = the same transforms
// with nothing else (run_split_ffts_only)
void BM_FluidPass(benchmark::State& st) {
  FluidFixture fx(int(st.range(0)));
  const int pass = int(st.range(1));
  for (auto _ : st) {
    if (pass == 0) fx.fl.pass_rhs_planes();
    if (pass == 1) fx.fl.pass_pencils();
    if (pass == 2) fx.fl.pass_inverse_planes();
    if (pass == 3) fx.fl.run_split_ffts_only();
  }
  st.SetItemsProcessed(st.iterations() * std::int64_t(fx.fl.grid().size()));
}
BENCHMARK(BM_FluidPass)
    ->ArgsProduct({{32, 64, 128}, {0, 1, 2, 3}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// FFTW's threaded 3-D forward + backward plans, 3 components each (the six real FFTs of one step)
void BM_FftRoundTrip(benchmark::State& st) {
  FluidFixture fx(int(st.range(0)));
  for (auto _ : st) fx.fl.run_ffts_only();
  st.SetItemsProcessed(st.iterations() * std::int64_t(fx.fl.grid().size()));
}
BENCHMARK(BM_FftRoundTrip)
    ->Arg(32)
    ->Arg(64)
    ->Arg(128)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// the whole fluid step as the stepper does it (no forces)
void BM_FluidStep(benchmark::State& st) {
  FluidFixture fx(int(st.range(0)));
  for (auto _ : st) {
    fx.fl.begin_step();
    fx.fl.finish_step();
  }
}
BENCHMARK(BM_FluidStep)->Arg(64)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Writhe(benchmark::State& st) {
  const auto p = config::to_params(reference(64, int(st.range(0))));
  const auto s = ring(p);
  for (auto _ : st) benchmark::DoNotOptimize(diagnostics::writhe(s.X));
}
BENCHMARK(BM_Writhe)->Arg(600)->Arg(6000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
