// A plastic press-fit pushed in, pulled out and pushed in again (docs/algorithm.md#j2-plasticity;
// issue 37's hard case "cycling a press-fit in and out keeps the plastic strain monotone"). Plane
// strain, linear kinematics, q4_bbar, half of it by symmetry about x = 0: a steel bar of
// half-width 5.02 (12 long) through a hole of half-width 5 in a steel plate (4 thick, 10 wide,
// held at its far edge), a radial interference of 0.02; both von Mises, yield stress 150 MPa,
// linear hardening 2000 MPa (the elastic interference pressure, about 290 MPa, yields both
// sides of the interface); friction 0.2. Stage 1 closes the interference; then the bar's end is
// moved down 1 (in, 4 steps), back to 0 (out, 4 steps) and down 1 again (in, 4 steps), the
// bar always covering the hole's wall (the plate's wall is the slave side).
// - every step converges; each body balances its contact forces with its reactions, the
//   contact forces on the two bodies cancel, every point lies in Coulomb's cone and, once the
//   bar moves, slides: the friction on the plate is mu times the pressure and drags it the
//   way the bar moves;
// - the equivalent plastic strain of no element decreases from one step to the next, and it
//   grows somewhere on each leg (in, out, in again).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "tests/support/two_bodies.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

constexpr double kMu = 0.2;

// `stages`: [steps, the push factor] after the press (one step at factor 0).
json bar_through_plate(const std::vector<std::pair<int, double>>& stages) {
  const json steel = {{"young", 200000},
                      {"poisson", 0.3},
                      {"law", "j2_plasticity"},
                      {"yield_stress", 150.0},
                      {"hardening", {{"linear", 2000.0}}}};
  const auto body = [&](const char* name, json rectangle, const char* contact_set, json supports) {
    return json{{"name", name},
                {"model", "continuum"},
                {"kinematics", "linear"},
                {"analysis", "plane_strain"},
                {"element", "q4_bbar"},
                {"material", steel},
                {"mesh", {{"rectangle", rectangle}}},
                {"contact_set", contact_set},
                {"supports", supports}};
  };
  json j = {{"bodies",
             {body("bar", {{"origin", {0, -6}}, {"size", {5.02, 12}}, {"divisions", {4, 24}}}, "right",
                   {{{"set", "left"}, {"fix", {"x"}}},
                    {{"set", "top"}, {"fix", {"y"}}, {"values", {{"y", -1.0}}}, {"case", "push"}}}),
              body("plate", {{"origin", {5, -2}}, {"size", {10, 4}}, {"divisions", {10, 8}}}, "left",
                   {{{"set", "right"}, {"fix", {"x", "y"}}}})}},
            {"contacts", {{{"slave", "plate.left"}, {"master", "bar.right"}, {"friction", kMu}}}},
            {"stages", {{{"steps", 1}, {"factors", {{"push", 0.0}}}}}},
            {"solver", {{"contact", {{"method", "cev"}, {"tolerance", 1e-8}}}}}};
  for (const auto& [steps, push] : stages) j["stages"].push_back({{"steps", steps}, {"factors", {{"push", push}}}});
  return j;
}

// The equivalent plastic strain of every element (both bodies) at a step.
std::vector<double> plastic_strain(const StepRecord& rec) {
  const std::vector<std::string>& names = rec.element_fields.names;
  const auto at = std::find(names.begin(), names.end(), "equivalent_plastic_strain");
  EXPECT_NE(at, names.end());
  std::vector<double> alpha;
  if (at == names.end()) return alpha;
  for (const auto& row : rec.element_fields.rows) alpha.push_back(row[at - names.begin()]);
  return alpha;
}

Solved run_cycle(const json& j) {
  Solved s{read_scene(j), {}};
  s.run = run_load_steps(s.scene.problem, s.scene.steps, s.scene.params);
  return s;
}

TEST(J2PressFitCycle, PlasticStrainNeverDecreasesOverInOutIn) {
  const Solved s = run_cycle(bar_through_plate({{4, 1.0}, {4, 0.0}, {4, 1.0}}));
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  ASSERT_EQ(s.run.steps.size(), 13u);
  const Problem& problem = s.scene.problem;
  // The legs: the steps that end them (from 0: the press, in, out, in again).
  const std::vector<size_t> leg_end = {0, 4, 8, 12};
  std::vector<double> before = plastic_strain(s.run.steps[0]), leg_start = before;
  int yielded = 0;
  for (double a : before) yielded += a > 0;
  std::printf("bar through plate: after the press %d of %zu elements yielded, largest plastic strain %.3e\n", yielded,
              before.size(), *std::max_element(before.begin(), before.end()));
  EXPECT_GT(yielded, 20);
  size_t leg = 1;
  for (size_t k = 0; k < s.run.steps.size(); ++k) {
    const StepRecord& rec = s.run.steps[k];
    EXPECT_TRUE(rec.converged) << "step " << k + 1;
    EXPECT_TRUE(step_invariants(problem, rec, tolerances_of(s.scene))) << "step " << k + 1;
    expect_pairs_balanced(s, rec);
    // The contact: the pressure, the friction; from step 2 every pressing point slides.
    double pressure = 0, friction = 0;
    int pressing = 0, sliding = 0;
    for (size_t i = 0; i < problem.candidates.size(); ++i) {
      const Candidate& c = problem.candidates[i];
      if (rec.p[c.eta] >= 0) continue;
      ++pressing;
      pressure -= rec.p[c.eta];
      friction += rec.p[c.xi];
      sliding += contact_state(problem, i, rec.p, rec.tau) == ContactState::slip;
    }
    const Vec2 on_plate = body_resultant(problem, 1, contact_forces(problem, rec));
    EXPECT_GT(pressing, 3) << "step " << k + 1;
    if (k > 0) {
      EXPECT_EQ(sliding, pressing) << "step " << k + 1;
      EXPECT_NEAR(std::abs(friction), kMu * pressure, 1e-6 * kMu * pressure) << "step " << k + 1;
      // The bar moves down on the in legs, up on the out leg: it drags the plate's wall along.
      const double moving = leg == 2 ? 1.0 : -1.0;
      EXPECT_GT(moving * on_plate.y(), 0.9 * kMu * pressure) << "step " << k + 1;
    }
    // The plastic strain of no element decreases.
    const std::vector<double> alpha = plastic_strain(rec);
    ASSERT_EQ(alpha.size(), before.size());
    int lower = 0;
    double fall = 0;
    for (size_t e = 0; e < alpha.size(); ++e)
      if (alpha[e] < before[e]) {
        ++lower;
        fall = std::max(fall, before[e] - alpha[e]);
      }
    EXPECT_EQ(lower, 0) << "step " << k + 1 << ": the plastic strain fell by up to " << fall;
    before = alpha;
    // It grows somewhere on each leg.
    if (k > 0 && k == leg_end[leg]) {
      double grown = 0;
      int grew = 0;
      for (size_t e = 0; e < alpha.size(); ++e) {
        grown = std::max(grown, alpha[e] - leg_start[e]);
        grew += alpha[e] > leg_start[e];
      }
      std::printf(
          "leg %zu (%s, steps %zu-%zu): %d elements' plastic strain grew, by up to %.3e; pressure %.1f N/mm, "
          "friction on the plate %+.1f N/mm\n",
          leg, leg == 2 ? "out" : "in", leg_end[leg - 1] + 2, k + 1, grew, grown, pressure, on_plate.y());
      EXPECT_GT(grown, 1e-5) << "leg " << leg;
      leg_start = alpha;
      ++leg;
    }
  }
}

}  // namespace
}  // namespace grip
