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
// And a cut step restores the plastic history (docs/algorithm.md#load-stepping-and-cuts): the
// same scene with one step of the in leg and one of the out leg refused at their whole
// increment (a test's observer, SteppingObserver::refuse_attempt: the attempt converged, its
// plastic flow was evaluated) and so cut in halves, against the run whose steps are those halves.
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

Solved run_cycle(const json& j, const SteppingObserver& observer = {}) {
  Solved s{read_scene(j), {}};
  s.run = run_load_steps(s.scene.problem, s.scene.steps, s.scene.params, observer);
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

// (a) in 4 steps and out in 4; (b) the same with step 2 (in, 0 -> 0.25) and step 6 (out,
// 1 -> 0.75) refused at their whole increment, so each is cut once; (c) the run whose steps are
// the halves that the cuts made (0.125 and 0.875 added). (b) and (c) pass through the same
// states, so they agree to the solves' tolerances: the plastic strain of every element, the
// displacements, the contact forces. Had the refused attempt (its whole increment converged,
// its plastic flow evaluated) left its history behind, (b) would start its halves from it.
TEST(J2PressFitCycle, ACutStepRestoresThePlasticHistory) {
  const Solved a = run_cycle(bar_through_plate({{4, 1.0}, {4, 0.0}}));
  SteppingObserver refusing;
  std::vector<std::string> refused;
  refusing.refuse_attempt = [&](int step, double from, double to) {
    const bool refuse = (step == 2 || step == 6) && from == 0.0 && to == 1.0;
    if (refuse) refused.push_back(std::to_string(step));
    return refuse;
  };
  const Solved b = run_cycle(bar_through_plate({{4, 1.0}, {4, 0.0}}), refusing);
  const Solved c = run_cycle(bar_through_plate({{2, 0.25}, {3, 1.0}, {2, 0.75}, {3, 0.0}}));
  for (const Solved* s : {&a, &b, &c}) {
    ASSERT_TRUE(s->run.completed) << s->run.reason;
    for (const StepRecord& rec : s->run.steps)
      EXPECT_TRUE(step_invariants(s->scene.problem, rec, tolerances_of(s->scene))) << "step " << rec.index;
  }
  ASSERT_EQ(a.run.steps.size(), 9u);
  ASSERT_EQ(b.run.steps.size(), 9u);
  ASSERT_EQ(c.run.steps.size(), 11u);
  // Each refused step was cut once (its whole increment refused, then its halves taken); (c)
  // needed no cut; (a)'s whole increments of those steps made plastic flow.
  for (size_t k = 0; k < 9; ++k) {
    const bool cut = k == 1 || k == 5;
    EXPECT_EQ(b.run.steps[k].cuts, cut ? 1 : 0) << "step " << k + 1;
    EXPECT_EQ(a.run.steps[k].cuts, 0) << "step " << k + 1;
  }
  EXPECT_EQ(refused.size(), 2u);
  for (const StepRecord& rec : c.run.steps) EXPECT_EQ(rec.cuts, 0) << "step " << rec.index;
  for (size_t k : {1, 5}) {
    const std::vector<double> from = plastic_strain(a.run.steps[k - 1]), to = plastic_strain(a.run.steps[k]);
    double grown = 0;
    for (size_t e = 0; e < to.size(); ++e) grown = std::max(grown, to[e] - from[e]);
    std::printf("(a) step %zu: plastic strain grown by up to %.3e over the whole increment\n", k + 1, grown);
    EXPECT_GT(grown, 1e-5);
  }
  // (b)'s steps against (c)'s: (c) has a step more in each leg.
  const std::vector<size_t> in_c = {0, 2, 3, 4, 5, 7, 8, 9, 10};
  double alpha_bc = 0, q_bc = 0, p_bc = 0, alpha_ab = 0, q_ab = 0, alpha_max = 0, q_max = 0, p_max = 0;
  for (size_t k = 0; k < 9; ++k) {
    const StepRecord &ra = a.run.steps[k], &rb = b.run.steps[k], &rc = c.run.steps[in_c[k]];
    EXPECT_EQ(rb.factors, rc.factors) << "step " << k + 1;
    const std::vector<double> aa = plastic_strain(ra), ab = plastic_strain(rb), ac = plastic_strain(rc);
    for (size_t e = 0; e < ab.size(); ++e) {
      alpha_bc = std::max(alpha_bc, std::abs(ab[e] - ac[e]));
      alpha_ab = std::max(alpha_ab, std::abs(ab[e] - aa[e]));
      alpha_max = std::max(alpha_max, ab[e]);
    }
    q_bc = std::max(q_bc, (rb.state.q - rc.state.q).cwiseAbs().maxCoeff());
    q_ab = std::max(q_ab, (rb.state.q - ra.state.q).cwiseAbs().maxCoeff());
    q_max = std::max(q_max, rb.state.q.cwiseAbs().maxCoeff());
    p_bc = std::max(p_bc, (rb.p - rc.p).cwiseAbs().maxCoeff());
    p_max = std::max(p_max, rb.p.cwiseAbs().maxCoeff());
  }
  std::printf(
      "cut (b) against its halves (c): plastic strain %.1e (of %.2e), displacement %.1e mm (of %.2f), contact forces "
      "%.1e N/mm (of %.1f); (b) against the uncut (a): plastic strain %.1e, displacement %.1e mm\n",
      alpha_bc, alpha_max, q_bc, q_max, p_bc, p_max, alpha_ab, q_ab);
  EXPECT_LT(alpha_bc, 1e-8);
  EXPECT_LT(q_bc, 1e-8);
  EXPECT_LT(p_bc, 1e-6 * p_max);
}

}  // namespace
}  // namespace grip
