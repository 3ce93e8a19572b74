// The O-ring (tests/verification/o_ring_test.cpp) on 16, 32 and 64 arc divisions: the sealing
// force and the contact width converge, and the shipped mesh (16) is within 1 % of the
// reference (64) in both. About 3 minutes: a *Slow suite (label hard_slow, configuration slow).
#include <gtest/gtest.h>

#include <cmath>

#include "tests/support/o_ring.hpp"

namespace grip {
namespace {

using namespace grip::testing;

TEST(ORingSlow, ForceAndWidthConvergeToTheRefinedReference) {
  const SealReading shipped = expect_seal(solve_o_ring(16));
  const SealReading middle = expect_seal(solve_o_ring(32));
  const SealReading reference = expect_seal(solve_o_ring(64));
  EXPECT_NEAR(shipped.force / reference.force, 1.0, 0.01);
  EXPECT_NEAR(shipped.width / reference.width, 1.0, 0.01);
  // Converging: each level closer to the reference than the one before.
  EXPECT_LT(std::abs(middle.force - reference.force), std::abs(shipped.force - reference.force));
  EXPECT_LT(std::abs(middle.width - reference.width), 0.01 * reference.width);
  EXPECT_NEAR(middle.walls / reference.walls, 1.0, 0.02);
}

}  // namespace
}  // namespace grip
