// Volumetric locking (docs/verification.md#locking): Cook's membrane and a cantilever in plane
// strain with nu = 0.4999 (K / G = 5000), shear-loaded at the free end
// (tests/support/locking_panels.hpp). The reference: q9 on three meshes each twice as fine,
// extrapolated at the order they show (tests/support/locking_table.hpp; confirmed a level finer
// by tests/hard/locking_slow_test.cpp). Against it, the tip deflection of each element and
// formulation on coarse meshes: q4 with F-bar (finite kinematics) and q4_bbar (linear) reach it
// within 2 % where the plain q4 is short by 70 to 95 %.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "tests/support/locking_table.hpp"

namespace grip {
namespace {

using namespace grip::testing;

struct Row {
  const char* name;
  PanelRun run;
};

// The table's rows: q4_bbar is the linear twin of F-bar, compared with the linear reference.
std::vector<Row> rows(Panel panel) {
  using E = ContinuumElement;
  using I = Incompressibility;
  using K = ContinuumKinematics;
  return {{"q4", {panel, E::q4, I::none, K::finite}},           {"q4 f_bar", {panel, E::q4, I::f_bar, K::finite}},
          {"q4_bbar", {panel, E::q4_bbar, I::none, K::linear}}, {"t6", {panel, E::t6, I::none, K::finite}},
          {"q8", {panel, E::q8, I::none, K::finite}},           {"q9", {panel, E::q9, I::none, K::finite}}};
}

// error[row][mesh] in %, printed as the table of docs/verification.md#locking.
std::vector<std::vector<double>> table(Panel panel, const std::vector<int>& meshes, double finite, double linear) {
  std::printf("%-9s", "n");
  for (int n : meshes) std::printf(" %8d", n);
  std::printf("   (tip deflection / reference - 1, %%)\n");
  std::vector<std::vector<double>> error;
  for (const Row& row : rows(panel)) {
    const double reference = row.run.kinematics == ContinuumKinematics::finite ? finite : linear;
    error.emplace_back();
    std::printf("%-9s", row.name);
    for (int n : meshes) {
      // The quadratic elements on the finest mesh: as costly as the reference, not computed.
      if (n == meshes.back() && row.run.element != ContinuumElement::q4 &&
          row.run.element != ContinuumElement::q4_bbar) {
        error.back().push_back(NAN);
        std::printf(" %8s", "-");
        continue;
      }
      error.back().push_back(100 * (panel_tip(row.run, n) / reference - 1));
      std::printf(" %+8.2f", error.back().back());
    }
    std::printf("\n");
  }
  return error;
}

enum RowIndex { kQ4, kFBar, kBBar, kT6, kQ8, kQ9 };

TEST(Locking, CooksMembrane) {
  const Extrapolated finite = q9_reference(Panel::cook, ContinuumKinematics::finite, 8);
  const Extrapolated linear = q9_reference(Panel::cook, ContinuumKinematics::linear, 8);
  // The clamped corners are singular: q9 converges at order about 1 (1.1 measured), not 3.
  for (const Extrapolated& e : {finite, linear}) {
    EXPECT_GT(e.order, 0.8);
    EXPECT_LT(e.order, 2.0);
  }
  EXPECT_NEAR(finite.value / linear.value, 1.0, 0.003);  // a load of 1 on E = 250: nearly linear
  const auto error = table(Panel::cook, {4, 8, 16, 32}, finite.value, linear.value);
  for (RowIndex r : {kFBar, kBBar}) {
    EXPECT_LT(std::abs(error[r][2]), 2.2);  // 16 x 16: -2.0 % measured
    EXPECT_LT(std::abs(error[r][3]), 1.0);  // 32 x 32
    for (size_t m = 1; m < 4; ++m) EXPECT_LT(std::abs(error[r][m]), std::abs(error[r][m - 1]));
  }
  for (size_t m = 0; m < 4; ++m) EXPECT_LT(error[kQ4][m], -60.0);  // the plain q4 locks on every mesh
  // Per mesh, F-bar is closer than the quadratic elements on 16 x 16 and finer (4 times fewer dofs).
  for (RowIndex r : {kT6, kQ8, kQ9}) EXPECT_LT(std::abs(error[kFBar][2]), std::abs(error[r][2]));
}

TEST(Locking, Cantilever) {
  const Extrapolated finite = q9_reference(Panel::cantilever, ContinuumKinematics::finite, 4);
  const Extrapolated linear = q9_reference(Panel::cantilever, ContinuumKinematics::linear, 4);
  for (const Extrapolated& e : {finite, linear}) {
    EXPECT_GT(e.order, 0.8);
    EXPECT_LT(e.order, 2.5);
  }
  // n elements through the depth, 5 n along the length.
  const auto error = table(Panel::cantilever, {2, 4, 8, 16}, finite.value, linear.value);
  for (RowIndex r : {kFBar, kBBar}) {
    EXPECT_LT(std::abs(error[r][1]), 2.0);  // 20 x 4
    EXPECT_LT(std::abs(error[r][2]), 0.5);  // 40 x 8
  }
  for (size_t m = 0; m < 4; ++m) EXPECT_LT(error[kQ4][m], -75.0);  // locked: 82 to 96 % short
}

}  // namespace
}  // namespace grip
