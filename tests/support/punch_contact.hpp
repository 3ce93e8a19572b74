#pragma once
// Prandtl's punch as a contact obstacle (issue 37): the square-edged punch of
// punch_obstacle_scene (tests/support/prandtl_punch.hpp) on the block of press_punch, b/5 near the
// punch's edge (24 x 18 elements), driven down 0.1 b in 10 steps, by one contact strategy. What
// tests/verification/prandtl_punch_contact_test.cpp and tests/hard/prandtl_punch_contact_slow_test.cpp check.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "tests/support/contact_checks.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/prandtl_punch.hpp"
#include "tests/support/scenes.hpp"

namespace grip::testing {

constexpr double kPunchContactH = 0.2;
constexpr int kPunchContactNx = 24, kPunchContactNy = 18, kPunchContactSteps = 10;
constexpr double kPunchContactDepth = 0.1;
// The pressing nodes' span: x = 0 ... 0.8 b (the edge node at x = b slides out past the corner).
constexpr double kPunchContactSpan = 0.8;

struct PunchByContact {
  bool completed = false;
  std::vector<double> load;  // per step: the sum of the normal contact forces (half model)
  int solves = 0, newton = 0;
};

// The run with `contact` (solver.contact) on the plastic block, or on the same block with the
// linear elastic law. On the plastic block every step is also checked: the invariants of
// contact_checks.hpp and the pressing nodes exactly those with reference x <= 0.8 b.
inline PunchByContact punch_by_contact(const nlohmann::json& contact, bool plastic) {
  const Solved s = solve_scene(punch_obstacle_scene(kPunchContactH, kPunchContactNx, kPunchContactNy,
                                                    kPunchContactDepth, kPunchContactSteps, plastic, contact));
  PunchByContact out;
  out.completed = s.run.completed;
  EXPECT_TRUE(s.run.completed) << s.run.reason;
  const Problem& problem = s.scene.problem;
  for (const StepRecord& rec : s.run.steps) {
    out.solves += rec.solves;
    out.newton += rec.newton_iterations;
    if (!rec.converged) continue;
    out.load.push_back(-contact_resultant(problem, rec).y());
    if (!plastic) continue;
    EXPECT_TRUE(step_invariants(problem, rec, tolerances_of(s.scene)));
    // Frictionless: no tangential resultant; and the pressing set.
    EXPECT_LT(std::abs(contact_resultant(problem, rec).x()), 1e-9 * out.load.back()) << "step " << rec.index;
    for (const ContactNode& n : contact_profile(problem, rec))
      EXPECT_EQ(n.p_n < 0, n.x <= kPunchContactSpan + 1e-9) << "step " << rec.index << ", node at x = " << n.x;
  }
  return out;
}

// The smooth punch of prescribed nodes over the same five nodes (press_punch with half-width
// 0.8 b) through the same 10 steps: the same discrete problem, whose load each step's must be.
inline PunchCurve punch_by_prescribed_nodes() {
  std::vector<double> fractions;
  for (int k = 1; k <= kPunchContactSteps; ++k) fractions.push_back(double(k) / kPunchContactSteps);
  return press_punch(kPunchContactH, kPunchContactNx, kPunchContactNy, kPunchContactDepth, fractions, false,
                     kPunchContactSpan);
}

// Every step's load against the prescribed nodes' within `relative` (of the plateau); the last
// three steps within 0.5 % of each other.
inline void expect_punch_load(const PunchByContact& run, const PunchCurve& reference, double relative,
                              const std::string& name) {
  ASSERT_EQ(run.load.size(), reference.load.size()) << name;
  const double limit = prandtl_limit_half(), plateau = reference.load.back();
  double worst = 0.0;
  for (size_t k = 0; k < run.load.size(); ++k) worst = std::max(worst, std::abs(run.load[k] - reference.load[k]));
  std::printf("%s: load / (2 + pi) k b per step:", name.c_str());
  for (double l : run.load) std::printf(" %.4f", l / limit);
  std::printf("; largest difference from the prescribed nodes' %.2e of the plateau\n", worst / plateau);
  EXPECT_LT(worst, relative * plateau) << name;
  const size_t n = run.load.size();
  for (size_t k = n - 3; k < n; ++k)
    EXPECT_NEAR(run.load[k] / run.load.back(), 1.0, 0.005) << name << ", step " << k + 1;
}

}  // namespace grip::testing
