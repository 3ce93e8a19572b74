// An O-ring squeezed 25 % in a rectangular groove (schemas/examples/seal-o-ring.json; docs/verification.md#o-ring):
// axisymmetric, nearly incompressible Mooney-Rivlin (bulk 2000 x shear), finite strain, q9.
// Here the shipped coarse mesh and one twice as coarse: every step sound, the reactions carry
// the sealing force, the two forces within 1 %; the refined reference (32 and 64 divisions)
// in tests/hard/o_ring_slow_test.cpp.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/support/o_ring.hpp"

namespace grip {
namespace {

using namespace grip::testing;

TEST(ORing, ShippedSceneIsSoundAndBalanced) {
  const SealReading coarse = expect_seal(solve_o_ring(8));
  const SealReading shipped = expect_seal(solve_o_ring(16));
  // Halving the elements moves the force by under 1 % (the width by 13 %: 8 divisions leave
  // about two elements under the flat; the shipped mesh is within 0.5 % of the refined
  // reference in both, tests/hard/o_ring_slow_test.cpp).
  EXPECT_NEAR(shipped.force / coarse.force, 1.0, 0.01);
  // 25 % squeeze of an incompressible ring: it widens against the groove's walls.
  EXPECT_GT(shipped.walls, 0.0);
}

// The same ring in the formulations against locking: q9 with the mixed u-p form (a linear
// pressure per element) on the shipped mesh, and q4 with F-bar in axisymmetry on twice the
// divisions (the same nodes), against the plain q9.
TEST(ORing, MixedQ9AndAxisymmetricFBarAgreeWithQ9) {
  const SealReading q9 = expect_seal(solve_o_ring(16));
  const SealReading mixed = expect_seal(solve_o_ring(16, "q9", "mixed"));
  const SealReading f_bar = expect_seal(solve_o_ring(32, "q4", "f_bar"));
  std::printf(
      "O-ring against plain q9 (16): q9 mixed (16) force %+.3f %%, width %+.3f %%; q4 f_bar (32) force %+.3f %%, "
      "width %+.3f %%\n",
      100 * (mixed.force / q9.force - 1), 100 * (mixed.width / q9.width - 1), 100 * (f_bar.force / q9.force - 1),
      100 * (f_bar.width / q9.width - 1));
  EXPECT_NEAR(mixed.force / q9.force, 1.0, 0.01);
  EXPECT_NEAR(mixed.width / q9.width, 1.0, 0.01);
  EXPECT_NEAR(f_bar.force / q9.force, 1.0, 0.02);
  EXPECT_NEAR(f_bar.width / q9.width, 1.0, 0.02);
}

}  // namespace
}  // namespace grip
