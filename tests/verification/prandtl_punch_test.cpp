// Prandtl's punch (tests/support/prandtl_punch.hpp), smooth and rough, on the coarse mesh
// (elements of b / 10 near the punch): the load rises to the limit (2 + pi) k b of the half
// model within 5 % and stays there (the last steps within 0.5 % of each other); Newton's
// iterations per step bounded on the plateau; at the last step the plastic strain localised at the
// punch's edge (its largest in an element within 2 h of the edge and the surface, many times the
// one under the punch's centre at the same depth and the one 2 b further along). The refined mesh (b / 20, within 3 %):
// tests/hard/prandtl_punch_slow_test.cpp.
#include <gtest/gtest.h>

#include "tests/support/prandtl_punch.hpp"

namespace grip {
namespace {

using namespace grip::testing;

TEST(PrandtlPunch, CoarseMeshReachesTheLimitLoadAndStaysThere) {
  const PunchCurve smooth = press_punch(0.1, 45, 35, 0.1, punch_path(), false);
  const PunchCurve rough = press_punch(0.1, 45, 35, 0.1, punch_path(), true);
  check_punch_curve(smooth, 0.05, "smooth, h = b/10");
  check_punch_curve(rough, 0.05, "rough, h = b/10");
  // Measured at depth 0.1 b: smooth, the largest alpha 0.77 at the edge's outer surface element,
  // 17 times the one under the centre at the same depth, 30 times the one 2 b along; rough, 0.44
  // one row down inside the edge, 460 and 8 times. Asserted about half of each.
  check_edge_localisation(smooth, 8.0, 0.07, "smooth, h = b/10");
  check_edge_localisation(rough, 200.0, 0.25, "rough, h = b/10");
}

}  // namespace
}  // namespace grip
