// Post-processing of a run directory (analysis/analyze.hpp, analysis/frames.hpp) on synthetic
// files: CSV reading (a row cut short by a killed run is dropped, a malformed one is an error), the
// analysis of a series with known answers, the atomic merge into summary.json (other keys kept, bad
// JSON refused and left untouched), config.toml, --size, and render_run on a known ring.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/analyze.hpp"
#include "analysis/frames.hpp"
#include "core/error.hpp"
#include "render/image.hpp"

namespace ibrod::analysis {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() /
             ("ibrod_analyze_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

std::string read_file(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

const char* kHeader =
    "step,time_us,E_bend_kT,E_twist_kT,E_stretch_kT,E_electro_kT,dE_electro_kT,E_steric_kT,"
    "E_kinetic_kT,E_total_kT,writhe,twist,link,closest_approach_A,bp_spacing_A\n";

/// A time series with known answers: E_K = e^{−2t/τ} (τ = 0.25 µs), Wr = 0.8 (1 − e^{−t/0.1}),
/// closest approach falling from 60 to 30 Å and back to 40 Å.
std::string synthetic_timeseries(int rows, double dt) {
  std::ostringstream os;
  os << kHeader;
  os.precision(15);
  for (int i = 0; i < rows; ++i) {
    const double t = i * dt;
    const double ek = std::exp(-2 * t / 0.25), wr = 0.8 * (1 - std::exp(-t / 0.1));
    const double ca = 30 + 30 * std::abs(t - 1.0) / 1.0 * (t < 1 ? 1.0 : 1.0 / 3.0);
    os << i * 10 << "," << t << ",10,20,1,5,-0.5,0," << ek << "," << 36 + ek << "," << wr << ","
       << 3 - wr << ",3," << ca << ",3.4\n";
  }
  return os.str();
}

TEST(Csv, ReadsColumnsAndDropsARowCutShort) {
  TempDir d("csv");
  write(d.path / "a.csv", "a,b,c\n1,2,3\n4,5e-3,inf\n7,8");  // last row cut short
  const CsvTable t = read_csv_table(d.path / "a.csv");
  ASSERT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.column("b")[1], 5e-3);
  EXPECT_TRUE(std::isinf(t.column("c")[1]));
  EXPECT_THROW(t.column("d"), ConfigError);
  write(d.path / "b.csv", "a,b\n1,2\n3,x\n4,5\n");  // malformed in the middle
  EXPECT_THROW(read_csv_table(d.path / "b.csv"), ConfigError);
  write(d.path / "c.csv", "a,b\n1,2\n3\n");  // complete line, wrong field count
  EXPECT_THROW(read_csv_table(d.path / "c.csv"), ConfigError);
  EXPECT_THROW(read_csv_table(d.path / "missing.csv"), ConfigError);
}

TEST(Analyze, KnownAnswersOfASyntheticSeries) {
  TempDir d("series");
  write(d.path / "timeseries.csv", synthetic_timeseries(401, 0.005));  // t ∈ [0, 2] µs
  const Analysis a = analyze_timeseries(read_csv_table(d.path / "timeseries.csv"));
  EXPECT_EQ(a.rows, 401u);
  // |Wr − Wr(2 µs)| = 0.8 (e^{−t/0.1} − e^{−20}) = 0.01 at t = 0.1 ln 80
  EXPECT_NEAR(*a.writhe_convergence_time_us, 0.1 * std::log(80.0), 1e-4);
  ASSERT_TRUE(a.relaxation_time_us);
  EXPECT_NEAR(*a.relaxation_time_us, 0.25, 1e-6);
  ASSERT_TRUE(a.relaxation_fit);
  EXPECT_EQ(a.relaxation_fit->points, 401u);  // a pure exponential: the whole series
  EXPECT_TRUE(a.relaxation_fit->within_tolerance);
  EXPECT_TRUE(a.transients.empty());
  EXPECT_NEAR(a.closest_approach_A, 40.0, 1e-9);
  EXPECT_NEAR(a.closest_approach_min_A, 30.0, 1e-9);
  EXPECT_NEAR(a.closest_approach_min_time_us, 1.0, 1e-9);
  EXPECT_FALSE(a.stays_circular);  // |Wr| reaches 0.8
  EXPECT_FALSE(a.kinetic_power_law_exponent);
  ASSERT_EQ(a.final_energies_kT.size(), 8u);
  EXPECT_EQ(a.final_energies_kT[0].first, "E_bend_kT");
  EXPECT_EQ(a.final_energies_kT[0].second, 10.0);
}

TEST(Analyze, MergesIntoSummaryAtomicallyAndKeepsOtherKeys) {
  TempDir d("summary");
  write(d.path / "timeseries.csv", synthetic_timeseries(201, 0.01));
  write(d.path / "summary.json",
        R"({"steps": 2000, "stop_reason": "equilibrium", "writhe_convergence_time_us": 99})");
  analyze_run(d.path);
  const auto j = nlohmann::json::parse(read_file(d.path / "summary.json"));
  EXPECT_EQ(j["steps"], 2000);
  EXPECT_EQ(j["stop_reason"], "equilibrium");
  EXPECT_NEAR(j["writhe_convergence_time_us"].get<double>(), 0.1 * std::log(80.0),
              1e-3);  // replaced
  EXPECT_NEAR(j["relaxation_time_us"].get<double>(), 0.25, 1e-6);
  EXPECT_TRUE(j["transients"].is_array());
  EXPECT_TRUE(j["kinetic_power_law_exponent"].is_null());
  EXPECT_EQ(j["closest_approach_A"].get<double>(), 40.0);
  EXPECT_EQ(j["analysis"]["writhe_delta"].get<double>(), 0.01);
  for (const auto& e : fs::directory_iterator(d.path))  // no temporary left behind
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();

  // a summary that is not JSON is refused and left as it was
  write(d.path / "summary.json", "{not json");
  EXPECT_THROW(analyze_run(d.path), ConfigError);
  EXPECT_EQ(read_file(d.path / "summary.json"), "{not json");
  // no time series: bad input
  fs::remove(d.path / "timeseries.csv");
  EXPECT_THROW(analyze_run(d.path), ConfigError);
  EXPECT_THROW(analyze_run(d.path / "nonexistent"), ConfigError);
}

TEST(Analyze, RowsRewrittenByAContinuedRunCountOnce) {
  // rows 0…150 written, then the run continued from the checkpoint at row 100 and wrote 100…200
  TempDir d("rewound");
  const std::string full = synthetic_timeseries(201, 0.01);
  std::istringstream in(full);
  std::string line, text;
  std::vector<std::string> rows;
  std::getline(in, line);
  text = line + "\n";
  while (std::getline(in, line)) rows.push_back(line);
  for (int i = 0; i <= 150; ++i) text += rows[i] + "\n";
  for (int i = 100; i <= 200; ++i) text += rows[i] + "\n";
  write(d.path / "timeseries.csv", text);
  write(d.path / "clean.csv", full);
  const Analysis a = analyze_timeseries(read_csv_table(d.path / "timeseries.csv"));
  const Analysis b = analyze_timeseries(read_csv_table(d.path / "clean.csv"));
  EXPECT_EQ(a.rows, 201u);
  EXPECT_EQ(a.writhe_convergence_time_us, b.writhe_convergence_time_us);
  EXPECT_EQ(a.relaxation_time_us, b.relaxation_time_us);
}

TEST(Analyze, CircularRunGetsAPowerLaw) {
  TempDir d("circular");
  std::ostringstream os;
  os << kHeader;
  os.precision(15);
  for (int i = 0; i <= 300; ++i) {
    const double t = 0.01 * i, ek = i ? 1e-6 * std::pow(t, -1.5) : 0.0;
    os << i << "," << t << ",1,1,1,1,0,0," << ek << "," << 4 + ek << ",0.001,1,1,50,3.4\n";
  }
  write(d.path / "timeseries.csv", os.str());
  const Analysis a = analyze_run(d.path);
  EXPECT_TRUE(a.stays_circular);
  ASSERT_TRUE(a.kinetic_power_law_exponent);
  EXPECT_NEAR(*a.kinetic_power_law_exponent, -1.5, 1e-6);
  // no summary.json: whether it reached equilibrium is unknown, so no convergence time
  EXPECT_FALSE(a.writhe_convergence_time_us);
  EXPECT_NE(a.not_finished_reason.find("no stop_reason"), std::string::npos);
  const auto j = nlohmann::json::parse(read_file(d.path / "summary.json"));  // created
  EXPECT_NEAR(j["kinetic_power_law_exponent"].get<double>(), -1.5, 1e-6);
  // Wr constant: inside the band from the start
  EXPECT_EQ(
      analyze_timeseries(read_csv_table(d.path / "timeseries.csv")).writhe_convergence_time_us,
      0.0);
}

TEST(Analyze, UnfinishedRunGivesNullWithAReasonNeverANumber) {
  TempDir d("unfinished");
  write(d.path / "timeseries.csv", synthetic_timeseries(201, 0.01));
  for (const char* reason : {"end_time", "interrupted"}) {
    write(d.path / "summary.json", std::string(R"({"stop_reason": ")") + reason + "\"}");
    const Analysis a = analyze_run(d.path);
    EXPECT_FALSE(a.equilibrium);
    EXPECT_FALSE(a.writhe_convergence_time_us);
    EXPECT_FALSE(a.relaxation_time_us);
    EXPECT_FALSE(a.relaxation_time_table_us);
    ASSERT_EQ(a.warnings.size(), 1u);
    EXPECT_NE(a.warnings[0].find("not finished"), std::string::npos);
    const auto j = nlohmann::json::parse(read_file(d.path / "summary.json"));
    EXPECT_EQ(j["equilibrium_reached"], false);
    EXPECT_NE(j["not_finished_reason"].get<std::string>().find(reason), std::string::npos);
    for (const char* key :
         {"writhe_convergence_time_us", "relaxation_time_us", "relaxation_fit",
          "relaxation_time_contacts_us", "relaxation_time_table_us", "limiting_energies_kT"})
      EXPECT_TRUE(j[key].is_null()) << reason << ": " << key << " = " << j[key];
    EXPECT_FALSE(j["final_energies_kT"].is_null());  // the last row's values, as they are
  }
  // the same series from a run that reached equilibrium: numbers
  write(d.path / "summary.json", R"({"stop_reason": "equilibrium"})");
  const Analysis a = analyze_run(d.path);
  EXPECT_TRUE(a.equilibrium);
  EXPECT_TRUE(a.warnings.empty());
  const auto j = nlohmann::json::parse(read_file(d.path / "summary.json"));
  EXPECT_EQ(j["equilibrium_reached"], true);
  EXPECT_TRUE(j["not_finished_reason"].is_null());
  EXPECT_NEAR(j["relaxation_time_us"].get<double>(), 0.25, 1e-6);
  EXPECT_TRUE(j["limiting_energies_kT"].is_object());
  // no trajectory: the table's τ is the final-window fit, and the summary says so
  EXPECT_EQ(j["relaxation_time_method"], "final_window");
  EXPECT_NEAR(j["relaxation_time_table_us"].get<double>(), 0.25, 1e-6);
  EXPECT_NE(j["relaxation_contacts_note"].get<std::string>().find("no trajectory.h5md"),
            std::string::npos);
  EXPECT_TRUE(j["contacts"]["source"].is_null());
}

TEST(Analyze, RelaxationTimeAfterTheLastContactChange) {
  // E_K decays with τ = 0.1 µs until t = 1 µs (contacts still forming), then with τ = 0.5 µs; the
  // last change of the contact count is at t = 1 µs
  TempDir d("contacts");
  std::ostringstream os;
  os << kHeader;
  os.precision(15);
  for (int i = 0; i <= 300; ++i) {
    const double t = 0.01 * i;
    const double ek =
        t < 1 ? std::exp(-2 * t / 0.1) : std::exp(-2 / 0.1) * std::exp(-2 * (t - 1) / 0.5);
    os << i << "," << t << ",1,1,1,1,0,0," << ek << "," << 4 + ek << ",0.5,1,1,50,3.4\n";
  }
  write(d.path / "timeseries.csv", os.str());
  const CsvTable table = read_csv_table(d.path / "timeseries.csv");
  Analysis a = analyze_timeseries(table);
  ShapeAnalysis sh;
  sh.contact_distance_A = 50;
  sh.contacts.time_us = {0, 0.5, 0.9, 1.0, 2.0, 3.0};
  sh.contacts.clusters = {0, 1, 1, 2, 2, 2};
  add_contact_relaxation(a, table, sh);
  ASSERT_TRUE(a.contacts_settled_time_us);
  EXPECT_EQ(*a.contacts_settled_time_us, 1.0);
  ASSERT_TRUE(a.relaxation_time_contacts_us);
  EXPECT_NEAR(*a.relaxation_time_contacts_us, 0.5, 1e-9);
  EXPECT_EQ(a.relaxation_time_method, "after_last_contact");
  EXPECT_EQ(a.relaxation_time_table_us, a.relaxation_time_contacts_us);
  EXPECT_NEAR(a.relaxation_contacts_fit->t_start_us, 1.0, 1e-12);
  // τ(t) over 1 µs windows: 0.1 µs in the first, 0.5 µs in the others
  ASSERT_EQ(a.local_relaxation.size(), 3u);
  EXPECT_NEAR(a.local_relaxation[0].tau, 0.1, 1e-9);
  EXPECT_NEAR(a.local_relaxation[1].tau, 0.5, 1e-9);
  EXPECT_NEAR(a.local_relaxation[2].tau, 0.5, 1e-9);
}

TEST(RunInfo, ReadsTheKeysLeniently) {
  TempDir d("info");
  EXPECT_EQ(read_run_info(d.path).diameter_A, 20.0);  // no config.toml: default
  write(d.path / "config.toml",
        "[steric]\ndiameter_A = 24.5\n[rod]\nexcess_link = 4\n[solvent]\nsalt_M = 0.05\n"
        "[future]\nunknown_key = 1\n");
  const RunInfo info = read_run_info(d.path);
  EXPECT_EQ(info.diameter_A, 24.5);
  EXPECT_EQ(info.excess_link, 4);
  EXPECT_EQ(info.salt_M, 0.05);
  write(d.path / "config.toml", "[steric\n");
  EXPECT_THROW(read_run_info(d.path), ConfigError);
}

TEST(RenderRun, SizeParsing) {
  int w = 0, h = 0;
  parse_size("640x480", w, h);
  EXPECT_EQ(w, 640);
  EXPECT_EQ(h, 480);
  for (const char* bad : {"640", "x480", "640x", "0x10", "64x48x2", "axb", "9000x100"})
    EXPECT_THROW(parse_size(bad, w, h), ConfigError) << bad;
}

TEST(RenderRun, FinalStateFromCsvIntoNamedFiles) {
  TempDir d("render");
  std::ostringstream os;
  os << "x_A,y_A,z_A,d1x,d1y,d1z,d2x,d2y,d2z,d3x,d3y,d3z\n";
  for (int k = 0; k < 120; ++k) {
    const double s = 2 * std::numbers::pi * k / 120;
    os << 100 + 60 * std::cos(s) << "," << 100 + 60 * std::sin(s) << ",100,0,0,1,0,0,0,0,0,0\n";
  }
  write(d.path / "final_state.csv", os.str());
  write(d.path / "summary.json", R"({"time_us": 0.25, "steps": 2500})");
  write(d.path / "config.toml", "[steric]\ndiameter_A = 12\n");
  RenderOptions opt;
  opt.views = {"top", "side"};
  opt.width = 96;
  opt.height = 64;
  opt.times = {"0.1"};  // no trajectory.h5md: the final state instead
  const auto files = render_run(d.path, opt, nullptr);
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[0], d.path / "render" / "rod_top_t0.2500.png");
  EXPECT_EQ(files[1], d.path / "render" / "rod_side_t0.2500.png");
  const render::Image top = render::read_png(files[0].string());
  EXPECT_EQ(top.width, 96);
  EXPECT_EQ(top.height, 64);
  EXPECT_EQ(top.at(48, 32), (render::Rgb{255, 255, 255}));  // the ring's centre
  opt.views = {"diagonal"};
  EXPECT_THROW(render_run(d.path, opt, nullptr), ConfigError);
  opt.views = {"top"};
  opt.times = {"-1"};
  EXPECT_THROW(render_run(d.path, opt, nullptr), ConfigError);
  EXPECT_THROW(render_run(d.path / "nonexistent", RenderOptions{}, nullptr), ConfigError);
}

}  // namespace
}  // namespace ibrod::analysis
