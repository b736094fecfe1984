// The force modules run every time step: after the first call at a given size they must not
// allocate. Counted with a replacement of the global operator new (for this test executable).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "curves.hpp"
#include "interactions/interactions.hpp"

namespace {
std::atomic<long> g_news{0};
}  // namespace

// The replacements pair malloc with free; GCC's -Wmismatched-new-delete cannot see that the
// operator new it matches them against is this one.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  ++g_news;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace ibrod::interactions {
namespace {

using namespace test;

TEST(Interactions, NoAllocationAfterTheFirstCall) {
  const auto ring = circle();
  const auto plec = plectoneme();
  std::vector<Vec3> F(kN, Vec3::Zero());
  for (double salt : {0.1, 0.001}) {  // cell-list and direct paths
    ElectroParams ep;
    ep.law = debye_huckel(kCharge, kDielectric, salt);
    ep.cutoff = kDefaultCutoffDebye / ep.law.kappa;
    Electrostatics e(ep, kN);
    StericParams sp;
    sp.stiffness = kDefaultStericStiffness;
    Steric s(sp, kN);
    // first calls size the scratch (the two shapes need different cell counts)
    e.accumulate(ring, F);
    e.accumulate(plec, F);
    s.accumulate(ring, F);
    s.accumulate(plec, F);
    const long before = g_news;
    for (int it = 0; it < 5; ++it)
      for (const auto* X : {&ring, &plec}) {
        e.accumulate(*X, F);
        s.accumulate(*X, F);
      }
    EXPECT_EQ(g_news - before, 0) << salt;
  }
}

}  // namespace
}  // namespace ibrod::interactions
