// Progress lines of a run (driver/progress.hpp): throttled in a log, rewritten in place on a
// terminal.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "driver/progress.hpp"

using namespace ibrod;
using ::testing::HasSubstr;

namespace {
struct Captured {
  char* buf = nullptr;
  std::size_t size = 0;
  std::FILE* f = open_memstream(&buf, &size);
  ~Captured() {
    if (f) std::fclose(f);  // a test that read the text by fclose has set f to nullptr
    std::free(buf);
  }
  std::string text() {
    std::fflush(f);
    return std::string(buf, size);
  }
};
}  // namespace

TEST(Progress, PlainLinesAreThrottledToOnePerIntervalPlusFirstAndLast) {
  Captured out;
  {
    driver::Progress p(out.f, /*tty=*/0, /*interval_s=*/10.0);
    // one offer per 0.01 s over 60 s: 6000 offers
    for (int i = 0; i < 6000; ++i) p.update("line " + std::to_string(i), 0.01 * i);
    p.update("last", 60.0, /*last=*/true);
  }
  std::fclose(out.f);
  out.f = nullptr;
  std::string s(out.buf, out.size);
  const auto lines = std::count(s.begin(), s.end(), '\n');
  EXPECT_GE(lines, 7);  // first, at ~10, 20, 30, 40, 50 s, last
  EXPECT_LE(lines, 8);
  EXPECT_EQ(s.rfind("line 0\n", 0), 0u);
  EXPECT_THAT(s, HasSubstr("last\n"));
  EXPECT_EQ(s.find('\r'), std::string::npos);
}

TEST(Progress, FirstLineIsDueAfterOneIntervalEvenWithoutAnOutputStep) {
  // a 256³ run reaches its first output step after minutes: the log must not stay silent
  Captured out;
  driver::Progress p(out.f, /*tty=*/0, /*interval_s=*/10.0);
  EXPECT_FALSE(p.due(0.0));
  EXPECT_FALSE(p.due(9.9));
  EXPECT_TRUE(p.due(10.0));
  p.update("first", 12.0);
  EXPECT_FALSE(p.due(21.9));
  EXPECT_TRUE(p.due(22.0));
}

TEST(Progress, TerminalLineIsRewrittenInPlace) {
  Captured out;
  {
    driver::Progress p(out.f, /*tty=*/1, 10.0, /*tty_interval_s=*/0.0);
    p.update("a long first line", 0.0);
    p.update("short", 1.0);
    p.message("warning: something");
    p.update("done", 2.0, true);
  }
  std::fclose(out.f);
  out.f = nullptr;
  const std::string s(out.buf, out.size);
  // the short line overwrites the long one completely; a message starts on its own line
  EXPECT_EQ(s, "\ra long first line\rshort            \nwarning: something\n\rdone\n");
}
