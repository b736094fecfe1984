// Output writers: the H5MD trajectory (append, truncate on resume, read back), the VTK PolyData
// of the rod (twist density and stretch strain against closed forms), the progress throttle and
// the blow-up guard.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "io/h5md.hpp"
#include "io/vtk.hpp"

using namespace ibrod;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("ibrod_out_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// A straight rod along z, spacing `stretch` Δs, triads turning about z by tau per unit length.
rod::RodState twisted_line(int n, double ds, double stretch, double tau) {
  rod::RodState s;
  for (int k = 0; k < n; ++k) {
    s.X.push_back(Vec3(0, 0, k * ds * stretch));
    s.D.push_back(rotation(Vec3(0, 0, tau * k * ds)));
  }
  return s;
}

// The numbers of the DataArray called `name` in a VTK XML text.
std::vector<double> data_array(const std::string& xml, const std::string& name) {
  const auto at = xml.find("Name=\"" + name + "\"");
  if (at == std::string::npos) return {};
  const auto open = xml.find('>', at) + 1;
  const auto close = xml.find("</DataArray>", open);
  std::istringstream in(xml.substr(open, close - open));
  std::vector<double> v;
  double x;
  while (in >> x) v.push_back(x);
  return v;
}

}  // namespace

TEST(Vtk, RodPolylineCarriesTriadsTwistAndStretch) {
  const int n = 12;
  const double ds = 3.4, tau = 0.05;
  const rod::RodState s = twisted_line(n, ds, 1.1, tau);
  const std::string xml = io::rod_vtp(s, ds);
  EXPECT_THAT(xml,
              HasSubstr("<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\""));
  EXPECT_THAT(xml, HasSubstr("NumberOfPoints=\"12\""));
  EXPECT_THAT(xml, HasSubstr("NumberOfLines=\"1\""));
  EXPECT_EQ(data_array(xml, "Points").size(), 3u * n);
  EXPECT_EQ(data_array(xml, "d1").size(), 3u * n);
  // closed: the polyline returns to point 0
  const auto conn = data_array(xml, "connectivity");
  ASSERT_EQ(conn.size(), std::size_t(n + 1));
  EXPECT_EQ(conn.front(), 0);
  EXPECT_EQ(conn.back(), 0);
  EXPECT_EQ(data_array(xml, "offsets"), std::vector<double>{double(n + 1)});
  // interior points (the closing segment from n−1 back to 0 is not part of a straight line):
  // a uniform turn by τΔs per segment gives Ω³ = 2 sin(τΔs/2)/Δs at every half point
  const auto twist = data_array(xml, "twist_density_rad_per_A");
  const auto strain = data_array(xml, "stretch_strain");
  ASSERT_EQ(twist.size(), std::size_t(n));
  const double omega = 2 * std::sin(0.5 * tau * ds) / ds;
  for (int k = 1; k < n - 2; ++k) {
    EXPECT_NEAR(twist[k], omega, 1e-9) << k;  // 10 printed digits
    EXPECT_NEAR(strain[k], 0.1, 1e-9) << k;
  }
}

TEST(Vtk, PvdListsEveryFrameAndResumeDropsLaterOnes) {
  const fs::path d = scratch("pvd");
  const rod::RodState s = twisted_line(5, 3.4, 1.0, 0.0);
  {
    io::PvdSeries pvd(d, "rod", "vtp");
    for (int step : {0, 10, 20, 30}) pvd.add(step, step * 1e-4, io::rod_vtp(s, 3.4));
  }
  EXPECT_TRUE(fs::exists(d / "vtk" / "rod_000030.vtp"));
  io::PvdSeries again(d, "rod", "vtp");
  again.resume(15);
  EXPECT_EQ(again.size(), 2u);
  EXPECT_FALSE(fs::exists(d / "vtk" / "rod_000020.vtp"));
  EXPECT_FALSE(fs::exists(d / "vtk" / "rod_000030.vtp"));
  again.add(20, 20e-4, io::rod_vtp(s, 3.4));
  std::ifstream in(d / "rod.pvd");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string pvd = ss.str();
  EXPECT_THAT(pvd, HasSubstr("file=\"vtk/rod_000000.vtp\""));
  EXPECT_THAT(pvd, HasSubstr("file=\"vtk/rod_000010.vtp\""));
  EXPECT_THAT(pvd, HasSubstr("file=\"vtk/rod_000020.vtp\""));
  EXPECT_THAT(pvd, ::testing::Not(HasSubstr("rod_000030")));
  fs::remove_all(d);
}

TEST(H5md, FramesAppendTruncateOnResumeAndReadBack) {
  const fs::path d = scratch("h5");
  const int n = 7;
  auto frame = [&](int step) { return twisted_line(n, 3.4, 1.0 + 0.01 * step, 0.1 * step); };
  {
    auto w = io::H5mdWriter::create(d / "t.h5", n, 200.0, "[grid]\nn = 16\n");
    for (int step : {0, 5, 10, 15}) {
      w->write_frame(step, step * 1e-4, frame(step));
      sim::Observables o;
      o.step = step;
      o.time_us = step * 1e-4;
      o.link = 2.0 + step;
      w->write_observables(o);
    }
    EXPECT_EQ(w->frames(), 4);
  }
  {
    // a resume from step 7 drops frames 10 and 15, then a new frame 10 follows
    auto w = io::H5mdWriter::reopen(d / "t.h5", n, 200.0, 7, "[grid]\nn = 16\n");
    EXPECT_EQ(w->frames(), 2);
    w->write_frame(10, 10e-4, frame(11));
  }
  const io::H5mdSeries pos = io::read_h5md_series(d / "t.h5", "position");
  EXPECT_EQ(pos.step, (std::vector<std::int64_t>{0, 5, 10}));
  EXPECT_EQ(pos.time_us, (std::vector<double>{0, 5e-4, 10e-4}));
  ASSERT_EQ(pos.n, n);
  const rod::RodState last = frame(11);
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < 3; ++i) EXPECT_EQ(pos.value[(2 * n + k) * 3 + i], last.X[k][i]);
  const io::H5mdSeries d2 = io::read_h5md_series(d / "t.h5", "d2");
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < 3; ++i) EXPECT_EQ(d2.value[(2 * n + k) * 3 + i], last.D[k](i, 1));
  // a rod of another size cannot continue this file
  EXPECT_THROW(io::H5mdWriter::reopen(d / "t.h5", n + 1, 200.0, 7, ""), RunError);
  fs::remove_all(d);
}

TEST(H5md, UnreadableFileIsARunError) {
  const fs::path d = scratch("h5bad");
  std::ofstream(d / "bad.h5") << "this is not HDF5";
  try {
    io::H5mdWriter::reopen(d / "bad.h5", 5, 200.0, 0, "");
    FAIL() << "no error";
  } catch (const RunError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bad.h5"));
  }
  fs::remove_all(d);
}
