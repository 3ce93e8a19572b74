// Prandtl's punch on the refined mesh (elements of b / 20 near the punch;
// tests/support/prandtl_punch.hpp), smooth and rough: the limit load within 3 % of (2 + pi) k b
// (half model), the curve flat at the limit, Newton's iterations bounded on the plateau. About
// 30 s of CPU: a *Slow suite (label hard_slow, configuration slow).
#include <gtest/gtest.h>

#include "tests/support/prandtl_punch.hpp"

namespace grip {
namespace {

using namespace grip::testing;

TEST(PrandtlPunchSlow, RefinedMeshWithinThreePerCent) {
  check_punch_curve(press_punch(0.05, 80, 60, 0.1, punch_path(), false), 0.03, "smooth, h = b/20");
  check_punch_curve(press_punch(0.05, 80, 60, 0.1, punch_path(), true), 0.03, "rough, h = b/20");
}

}  // namespace
}  // namespace grip
