// The locking table's references a level finer (tests/verification/locking_test.cpp): q9 on
// 16, 32, 64 (Cook's membrane) and 8, 16, 32 (the cantilever) extrapolated again, against the
// extrapolation of the default test from the three coarser meshes. About 2 minutes of CPU: a
// *Slow suite (label hard_slow, configuration slow).
#include <gtest/gtest.h>

#include "tests/support/locking_table.hpp"

namespace grip {
namespace {

using namespace grip::testing;

TEST(LockingSlow, ReferencesHoldOneLevelFiner) {
  for (auto [panel, n] : {std::pair{Panel::cook, 8}, std::pair{Panel::cantilever, 4}}) {
    const Extrapolated coarse = q9_reference(panel, ContinuumKinematics::finite, n);
    const Extrapolated fine = q9_reference(panel, ContinuumKinematics::finite, 2 * n);
    EXPECT_NEAR(fine.value / coarse.value, 1.0, 0.003);
    EXPECT_NEAR(fine.order, coarse.order, 0.3);
  }
}

}  // namespace
}  // namespace grip
