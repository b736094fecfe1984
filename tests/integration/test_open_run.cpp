// Open rods in the coupled scheme and in a run directory (issue 17; docs/model.md "Open rods"):
// a straight open rod with no intrinsic strain stays straight and at rest; a run writes no link or
// writhe (empty CSV fields, null in summary.json), an open VTK polyline, and a checkpoint that
// cannot be resumed as a closed rod.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "helpers.hpp"
#include "io/csv.hpp"
#include "run_helpers.hpp"
#include "sim/simulation.hpp"

using namespace ibrod;
using namespace ibrod::test;
using ::testing::HasSubstr;

namespace {

config::Config open_config() {
  config::Config c = small_config(0);
  c.rod_closed = false;
  c.rod_base_pairs = 50;  // 167 Å + the 20 Å hard core in the 200 Å box
  c.rod_perturbation.clear();
  c.electrostatics_enabled = false;  // a charged straight rod would stretch itself
  return c;
}

}  // namespace

TEST(OpenRun, StraightRodWithoutIntrinsicStrainStaysStraightAndAtRest) {
  const config::Config c = open_config();
  config::validate(c);
  sim::Simulation s(config::to_params(c));
  const rod::RodState s0 = s.rod();
  for (int k = 0; k < 200; ++k) s.step();
  double dx = 0, dD = 0;
  for (int k = 0; k < s0.size(); ++k) {
    dx = std::max(dx, (s.rod().X[k] - s0.X[k]).norm());
    dD = std::max(dD, (s.rod().D[k] - s0.D[k]).norm());
  }
  const sim::Observables o = s.observe();
  std::printf("  after 200 steps: max |ΔX| = %.2e Å, max |ΔD| = %.2e, E_K = %.2e kT\n", dx, dD,
              o.E_kinetic_kT);
  // the loads are round-off of the positions (1e-13 Å on 80 Å), the motion far below an ångström
  EXPECT_LT(dx, 1e-9);
  EXPECT_LT(dD, 1e-12);
  EXPECT_LT(o.E_kinetic_kT, 1e-20);
  EXPECT_TRUE(std::isnan(o.writhe));  // not defined for an open rod
  EXPECT_TRUE(std::isnan(o.link));
  EXPECT_NEAR(o.twist, 0.0, 1e-12);
  EXPECT_NEAR(o.bp_spacing_A, c.rod_rise_A, 1e-12);
  // and a closed rod in the same place would not stay: the closing link pulls the ends together
  EXPECT_GT(rod::elastic_energy(
                [&] {
                  rod::RodParams p = s.params().stepper.rods[0];
                  p.closed = true;
                  return p;
                }(),
                s0)
                .total(),
            1e3 * s.params().kT);
}

TEST(OpenRun, RunDirectoryHasNoLinkAnOpenPolylineAndRefusesAClosedResume) {
  const fs::path root = fresh_dir("open_run");
  config::Config c = open_config();
  c.rod_intrinsic_curvature_per_A = {0.04, 0.0};
  c.rod_intrinsic_twist_per_A = 0.04;
  c.time_t_end_us = 0.01;
  c.output_every_steps = 50;
  c.output_frame_every_steps = 100;
  c.output_checkpoint_every_steps = 50;
  std::ofstream(root / "in.toml") << config::to_toml(c);
  const fs::path dir = root / "A";
  const Exit e =
      run_ibrod({"run", (root / "in.toml").string(), "-o", dir.string()}, root / "A.log");
  ASSERT_EQ(e.code, 0) << e.output;
  EXPECT_THAT(e.output, HasSubstr("open rod: Tw = "));
  // time series: writhe and link empty ("not defined"), never "nan"; read back as NaN
  const std::string ts = read_file(dir / "timeseries.csv");
  EXPECT_EQ(ts.find("nan"), std::string::npos) << ts;
  const io::CsvTable t = io::read_csv_table(dir / "timeseries.csv");
  ASSERT_EQ(t.rows(), 3u);
  for (double w : t.column("writhe")) EXPECT_TRUE(std::isnan(w));
  for (double l : t.column("link")) EXPECT_TRUE(std::isnan(l));
  EXPECT_NEAR(t.column("twist")[0], 0.0, 1e-12);
  EXPECT_GT(t.column("twist")[2], 0.01);  // the intrinsic twist turns the triads
  const std::string summary = read_file(dir / "summary.json");
  EXPECT_THAT(summary, HasSubstr("\"closed\": false"));
  EXPECT_THAT(summary, HasSubstr("\"link_drift\": null"));
  EXPECT_EQ(summary.find("NaN"), std::string::npos);
  EXPECT_EQ(summary.find("nan"), std::string::npos);
  // VTK: an open polyline of the 50 points (a closed one lists 51, the first again)
  const std::string vtp = read_file(dir / "vtk" / "rod_000100.vtp");
  EXPECT_THAT(vtp, HasSubstr("Name=\"offsets\""));
  const auto off = vtp.find("Name=\"offsets\"");
  EXPECT_THAT(vtp.substr(off, 200), HasSubstr(">\n          50\n"));
  // ibrod analyze: the ring's measures (shape class, stays_circular, writhe) are null
  const Exit an = run_ibrod({"analyze", dir.string()}, root / "analyze.log");
  ASSERT_EQ(an.code, 0) << an.output;
  const std::string analysed = read_file(dir / "summary.json");
  EXPECT_THAT(analysed, HasSubstr("\"stays_circular\": null"));
  EXPECT_THAT(analysed, HasSubstr("\"shape\": null"));
  EXPECT_THAT(analysed, HasSubstr("\"writhe_final\": null"));
  // resume as a closed rod: refused, even with --force
  const Exit r = run_ibrod({"run", "--resume", dir.string(), "--force", "--set", "rod.closed=true",
                            "--set", "rod.excess_link=0", "--set", "time.t_end_us=0.02"},
                           root / "B.log");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("rod.closed"));
  EXPECT_THAT(r.output, HasSubstr("even with --force"));
  // resumed as it was: continues
  const Exit ok =
      run_ibrod({"run", "--resume", dir.string(), "--set", "time.t_end_us=0.02"}, root / "C.log");
  EXPECT_EQ(ok.code, 0) << ok.output;
  fs::remove_all(root);
}
