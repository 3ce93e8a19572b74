// An O-ring squeezed 25 % in a rectangular groove (schemas/examples/seal-o-ring.json; docs/verification.md#o-ring):
// axisymmetric, nearly incompressible Mooney-Rivlin (bulk 2000 x shear), finite strain, q9.
// Here the shipped coarse mesh and one twice as coarse: every step sound, the reactions carry
// the sealing force, the two forces within 1 %; the refined reference (32 and 64 divisions)
// in tests/hard/o_ring_slow_test.cpp.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace grip
