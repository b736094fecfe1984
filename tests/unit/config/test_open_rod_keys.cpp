// rod.closed (issue 17): an open rod reaches RodParams and StericParams, and the combinations an
// open rod cannot have (an excess link, a box shorter than the rod) are refused with an error
// naming both keys; the implicit scheme takes it (issue 25).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config/config.hpp"
#include "core/error.hpp"

using namespace ibrod;
using ::testing::HasSubstr;

namespace {

std::string validation_error(const config::Config& c) {
  try {
    config::validate(c);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

config::Config open_rod() {
  config::Config c;
  config::apply_override(c, "rod.closed=false");
  config::apply_override(c, "rod.excess_link=0");
  config::apply_override(c, "rod.base_pairs=200");  // a straight rod 677 Å long fits the box
  return c;
}

}  // namespace

TEST(OpenRodKeys, ClosedByDefaultOpenOnRequest) {
  config::Config c;
  EXPECT_TRUE(config::to_params(c).stepper.rods[0].closed);
  // the hard core takes each rod's layout (integrate::System: StericParams::rods = the rods'
  // rod::RodRange), closed or open as the rod
  EXPECT_TRUE(rod::ranges_of(config::to_params(c).stepper.rods)[0].closed);
  const config::Config o = open_rod();
  EXPECT_EQ(validation_error(o), "");
  const sim::SimParams p = config::to_params(o);
  EXPECT_FALSE(p.stepper.rods[0].closed);
  EXPECT_FALSE(rod::ranges_of(p.stepper.rods)[0].closed);
  EXPECT_THAT(config::describe(o), HasSubstr("rod.closed"));
  EXPECT_THAT(config::to_toml(o), HasSubstr("closed = false"));
  // written back and read again: the same configuration
  config::Config back;
  config::apply_toml(back, config::to_toml(o), "round trip");
  EXPECT_FALSE(back.rod_closed);
  EXPECT_THROW(config::apply_override(back, "rod.closed=1"), ConfigError);
}

TEST(OpenRodKeys, AnExcessLinkNeedsAClosedRod) {
  config::Config c;
  config::apply_override(c, "rod.closed=false");  // rod.excess_link is 6 by default
  const std::string e = validation_error(c);
  EXPECT_THAT(e, HasSubstr("rod.excess_link"));
  EXPECT_THAT(e, HasSubstr("rod.closed = false"));
  EXPECT_THAT(e, HasSubstr("6"));
}

TEST(OpenRodKeys, TheImplicitSchemeTakesAnOpenRod) {
  // refused before issue 25 (the local solve was a ring's); tests/integration/test_implicit_
  // rods.cpp runs it
  config::Config c = open_rod();
  config::apply_override(c, "time.scheme=\"implicit\"");
  config::apply_override(c, "time.dt_ns=2");
  EXPECT_EQ(validation_error(c), "");
}

TEST(OpenRodKeys, TheStraightRodMustFitInTheBox) {
  // 600 × 3.4 Å = 2037 Å of rod in the default 725 Å box: refused (a ring of that length fits)
  config::Config c = open_rod();
  config::apply_override(c, "rod.base_pairs=600");
  const std::string e = validation_error(c);
  EXPECT_THAT(e, HasSubstr("grid.box_A"));
  EXPECT_THAT(e, HasSubstr("open rod"));
  config::apply_override(c, "rod.base_pairs=200");  // 677 Å + 20 Å hard core < 725 Å
  EXPECT_EQ(validation_error(c), "");
  config::apply_override(c, "rod.base_pairs=210");  // 709.6 + 20 ≥ 725
  EXPECT_THAT(validation_error(c), HasSubstr("grid.box_A"));
}

// config::rod_layout: the rods' layout as rod_configs resolves them, without reading any file.
TEST(RodLayout, OneRodOrTheRodsTablesEndToEnd) {
  config::Config c;
  config::apply_override(c, "rod.closed=false");
  config::apply_override(c, "rod.base_pairs=120");
  const std::vector<rod::RodRange> one = config::rod_layout(c);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].offset, 0);
  EXPECT_EQ(one[0].n, 120);
  EXPECT_FALSE(one[0].closed);
  EXPECT_EQ(one[0].ds, c.rod_rise_A);
  config::Config f;
  config::apply_toml(
      f,
      "[rod]\nbase_pairs = 50\n[[rods]]\nexcess_link = 0\n[[rods]]\nbase_pairs = 30\n"
      "closed = false\nexcess_link = 0\nrise_A = 3.3\n",
      "f.toml");
  const std::vector<rod::RodRange> two = config::rod_layout(f);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].offset, 0);
  EXPECT_EQ(two[0].n, 50);
  EXPECT_TRUE(two[0].closed);
  EXPECT_EQ(two[1].offset, 50);
  EXPECT_EQ(two[1].n, 30);
  EXPECT_FALSE(two[1].closed);
  EXPECT_EQ(two[1].ds, 3.3);
  // the layout of the parameters a run gets (config::to_params), field by field
  const std::vector<rod::RodRange> run = rod::ranges_of(config::to_params(f).stepper.rods);
  ASSERT_EQ(run.size(), two.size());
  for (std::size_t r = 0; r < run.size(); ++r) {
    EXPECT_EQ(run[r].offset, two[r].offset);
    EXPECT_EQ(run[r].n, two[r].n);
    EXPECT_EQ(run[r].closed, two[r].closed);
    EXPECT_EQ(run[r].ds, two[r].ds);
  }
}
