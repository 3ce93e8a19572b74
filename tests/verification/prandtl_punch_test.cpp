// Prandtl's punch (tests/support/prandtl_punch.hpp), smooth and rough, on the coarse mesh
// (elements of b / 10 near the punch): the load rises to the limit (2 + pi) k b of the half
// model within 5 % and stays there (the last steps within 0.5 % of each other); Newton's
// iterations per step bounded on the plateau. The refined mesh (b / 20, within 3 %):
// tests/hard/prandtl_punch_slow_test.cpp.
#include <gtest/gtest.h>

#include "tests/support/prandtl_punch.hpp"

namespace grip {
namespace {

using namespace grip::testing;

TEST(PrandtlPunch, CoarseMeshReachesTheLimitLoadAndStaysThere) {
  check_punch_curve(press_punch(0.1, 45, 35, 0.1, punch_path(), false), 0.05, "smooth, h = b/10");
  check_punch_curve(press_punch(0.1, 45, 35, 0.1, punch_path(), true), 0.05, "rough, h = b/10");
}

}  // namespace
}  // namespace grip
