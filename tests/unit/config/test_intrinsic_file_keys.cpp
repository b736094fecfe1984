// rod.intrinsic_file (issue 17): a CSV of per-link intrinsic strains reaches RodParams::omega0_k
// row for row; a missing file, a wrong row count or a bad number is refused with an error naming
// the key, the file and what is wrong.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <string>

#include "config/config.hpp"
#include "core/error.hpp"

using namespace ibrod;
using ::testing::HasSubstr;

namespace {

std::string write_file(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("ibrod_intrinsic_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path.string();
}

config::Config with_file(const std::string& path, int n) {
  config::Config c;
  config::apply_override(c, "rod.base_pairs=" + std::to_string(n));
  config::apply_override(c, "rod.intrinsic_file=\"" + path + "\"");
  return c;
}

std::string params_error(const config::Config& c) {
  try {
    config::to_params(c);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(IntrinsicFileKey, RowsReachTheRodInOrder) {
  std::string text = "# kappa1, kappa2, tau (rad/A)\n";
  const int n = 50;
  for (int k = 0; k < n; ++k)
    text += std::to_string(0.001 * k) + ", " + std::to_string(-0.002 * k) + ",0.0436\r\n";
  const std::string path = write_file("ok.csv", text);
  const config::Config c = with_file(path, n);
  const rod::RodParams rod = config::to_params(c).stepper.rods[0];
  ASSERT_EQ(int(rod.omega0_k.size()), n);
  for (int k = 0; k < n; ++k) {
    EXPECT_DOUBLE_EQ(rod.omega0_k[k].x(), 0.001 * k);
    EXPECT_DOUBLE_EQ(rod.omega0_k[k].y(), -0.002 * k);
    EXPECT_DOUBLE_EQ(rod.omega0_k[k].z(), 0.0436);
  }
  EXPECT_THAT(config::to_toml(c), HasSubstr("intrinsic_file = "));
  // none by default: the scalar keys apply
  EXPECT_TRUE(config::to_params(config::Config{}).stepper.rods[0].omega0_k.empty());
  std::filesystem::remove(path);
}

TEST(IntrinsicFileKey, BadFilesAreRefusedNamingKeyAndProblem) {
  const std::string missing = with_file("/nonexistent/omega.csv", 50).rod_intrinsic_file;
  EXPECT_THAT(params_error(with_file(missing, 50)),
              AllOf(HasSubstr("rod.intrinsic_file"), HasSubstr("/nonexistent/omega.csv"),
                    HasSubstr("it does not exist")));
  std::string rows;
  for (int k = 0; k < 49; ++k) rows += "0,0,0.04\n";
  const std::string short_file = write_file("short.csv", rows);
  EXPECT_THAT(params_error(with_file(short_file, 50)),
              AllOf(HasSubstr("rod.intrinsic_file"), HasSubstr("50 rows"), HasSubstr("has 49")));
  const std::string nan_file = write_file("nan.csv", rows + "0,nan,0.04\n");
  EXPECT_THAT(params_error(with_file(nan_file, 50)),
              AllOf(HasSubstr("rod.intrinsic_file"), HasSubstr("line 50"), HasSubstr("finite")));
  const std::string two = write_file("two.csv", rows + "0,0.04\n");
  EXPECT_THAT(params_error(with_file(two, 50)), AllOf(HasSubstr("line 50"), HasSubstr("0,0.04")));
  const std::string word = write_file("word.csv", rows + "0,0.04,abc\n");
  EXPECT_THAT(params_error(with_file(word, 50)), HasSubstr("line 50"));
  const std::string big = write_file("big.csv", rows + "0,0.5,0.04\n");  // 0.5 × 3.4 > π/2
  EXPECT_THAT(params_error(with_file(big, 50)),
              AllOf(HasSubstr("rod.intrinsic_file"), HasSubstr("row 50 exceeds")));
  for (const auto& p : {short_file, nan_file, two, word, big}) std::filesystem::remove(p);
  // a non-string value for the key itself
  config::Config c;
  EXPECT_THROW(config::apply_override(c, "rod.intrinsic_file=3"), ConfigError);
}
