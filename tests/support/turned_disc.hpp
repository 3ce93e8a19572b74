#pragma once
// A disc held only by contact with finite kinematics and its rotation left free
// (docs/algorithm.md#bodies-held-only-by-contact): a neo-Hookean disc (radius 10, q4, nu 0.3, no
// supports) squeezed between two flats (mu 0.3) and turned by a couple from two opposite vertical
// forces at the ends of its horizontal diameter. Contact alone holds its three motions. Shared by
// tests/verification/held_by_contact_finite_test.cpp and tests/hard/held_by_contact_hard_test.cpp:
// the scene, the balance of force and moment about any point with the deformed positions, each
// flat's resultant, and the agreement of two runs to what the contact tolerance pins them to.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "solver/elements/continuum.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/force_precision.hpp"
#include "tests/support/held.hpp"
#include "tests/support/result_checks.hpp"

namespace grip::testing {

inline constexpr double kDiscRadius = 10.0;

// Node (i, k) of the disc's grid of (grid + 1)^2 nodes (disc_between_flats).
inline int disc_node(int grid, int i, int k) { return k * (grid + 1) + i; }

// The disc between two flats (scenes.hpp) on a grid x grid mesh (even) with `kinematics`, nu =
// 0.3 and q4 (q4_bbar is linear only), the upper flat moved down by `delta`, and a couple M =
// 2 R F (counter-clockwise) from two opposite vertical forces F at the ends of its horizontal
// diameter, both raised over `steps` equal steps.
inline nlohmann::json turned_disc(const char* kinematics, double delta, double F, int steps, int grid = 32) {
  nlohmann::json j = disc_between_flats(grid, delta);
  j["body"]["kinematics"] = kinematics;
  j["body"]["element"] = "q4";
  j["body"]["material"]["poisson"] = 0.3;
  j["body"]["loads"] = nlohmann::json::array({{{"node", disc_node(grid, grid, grid / 2)}, {"force", {0.0, F}}},
                                              {{"node", disc_node(grid, 0, grid / 2)}, {"force", {0.0, -F}}}});
  j["steps"] = steps;
  return j;
}

// The same disc on a grid x grid mesh squeezed by 0.1 mm in a first step, then turned by the
// couple 2 R F x each of `turns` in one step each (load cases squeeze and turn).
inline nlohmann::json turned_in_stages(int grid, double F, const std::vector<double>& turns) {
  using nlohmann::json;
  json j = turned_disc("finite", 0.1, F, 1, grid);
  for (json& load : j["body"]["loads"]) load["case"] = "turn";
  j["obstacles"][1]["motion"]["case"] = "squeeze";
  j.erase("steps");
  j["stages"] = json::array({{{"steps", 1}, {"factors", {{"squeeze", 1}}}}});
  for (const double f : turns) j["stages"].push_back({{"steps", 1}, {"factors", {{"squeeze", 1}, {"turn", f}}}});
  return j;
}

// The resultant force and the moment about `o` of the load and the contact forces on the disc,
// at the deformed positions X + u of the nodes they act on; and the size they are measured
// against: the sum of the forces' magnitudes (times R for the moment).
struct DiscBalance {
  Vec2 force = Vec2::Zero();
  double moment = 0.0;
  double force_size = 0.0;
};

inline DiscBalance balance_about(const Problem& problem, const StepRecord& rec, const Vec2& o) {
  const auto& mesh = dynamic_cast<const ContinuumBody&>(*problem.body).mesh();
  Vector f = problem.load(rec.factors);
  DiscBalance b;
  b.force_size = f.cwiseAbs().sum();
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    const PairedPoint& pp = rec.state.points[i];
    const Vec2 force = rec.p[c.eta] * pp.eta + (c.xi >= 0 ? rec.p[c.xi] : 0.0) * pp.xi;
    for (const auto& j : pp.point.jacobian) f[j.dof] += j.dx.dot(force);
    b.force_size += force.norm();
  }
  for (size_t n = 0; n < mesh.nodes.size(); ++n) {
    const Vec2 x = mesh.nodes[n] + rec.state.q.segment<2>(2 * n) - o, fn = f.segment<2>(2 * n);
    b.force += fn;
    b.moment += x.x() * fn.y() - x.y() * fn.x();
  }
  return b;
}

// Every converged step: held and sound (expect_held: the balance on the motions about the
// current shape to 1e-9), and the force and the moment about two points balance to 1e-9 of the
// forces' size (times R), measured here from the positions themselves.
inline void expect_disc_balanced(const Solved& s) {
  expect_held(s);
  for (const StepRecord& rec : s.run.steps) {
    if (!rec.converged) continue;
    for (const Vec2& o : {Vec2(0, 0), Vec2(3, -7)}) {
      const DiscBalance b = balance_about(s.scene.problem, rec, o);
      EXPECT_LT(b.force.norm(), 1e-9 * b.force_size) << "step " << rec.index;
      EXPECT_LT(std::abs(b.moment), 1e-9 * b.force_size * kDiscRadius)
          << "step " << rec.index << " about (" << o.x() << ", " << o.y() << ")";
      std::printf("step %d: force unbalance %.2e, moment unbalance about (%g, %g) %.2e (of the forces' size)\n",
                  rec.index, b.force.norm() / b.force_size, o.x(), o.y(),
                  std::abs(b.moment) / (b.force_size * kDiscRadius));
    }
  }
}

// Two runs of the same scene agree at every step to what their contact errors pin them to: the
// contact forces to both runs' first-order errors (force_errors: the error each run reached, the
// one carried from its earlier steps and the rounding of s, with a slipping point's friction
// force moving with its normal force where the bound moves: near the friction limit nearly every
// point slips, and C_EE^-1 v alone said 2e-6 N where the runs differed by 1e-3 N), plus the
// friction bound's settling (with tau passes, p* settles to tau_tolerance of the largest normal
// force, which moves a slipping point's bound mu times that); the displacements to each run's
// tolerance (every gap and slip of an answer within tol of the exact one's) plus both runs'
// Newton correction tolerance, to which each real solve fixes them. Returns the largest differences
// over the steps (forces relative to the largest normal force, displacements) for the report.
inline std::pair<double, double> expect_same_answer(const Solved& a, const Solved& b) {
  std::pair<double, double> worst{0.0, 0.0};
  if (!a.run.completed || !b.run.completed || a.run.steps.size() != b.run.steps.size()) {
    ADD_FAILURE() << "the runs did not both complete the same steps";
    return worst;
  }
  const Problem& problem = a.scene.problem;
  double mu = 0.0;
  for (const ObstacleInstance& o : problem.obstacles) mu = std::max(mu, o.friction);
  const std::vector<ForceError> ea = force_errors(a, a.run.steps.size()), eb = force_errors(b, b.run.steps.size());
  for (size_t k = 0; k < a.run.steps.size(); ++k) {
    const StepRecord &ra = a.run.steps[k], &rb = b.run.steps[k];
    double p_max = 0.0, dp = 0.0;
    for (const Candidate& c : problem.candidates) {
      p_max = std::max(p_max, std::abs(ra.p[c.eta]));
      dp = std::max(dp, std::abs(ra.p[c.eta] - rb.p[c.eta]));
      if (c.xi >= 0) dp = std::max(dp, std::abs(ra.p[c.xi] - rb.p[c.xi]));
    }
    double settle = 0.0, newton = 0.0, errors = 0.0;
    for (const ForceError& e : {ea[k], eb[k]})
      errors += largest_force(problem, e.own) + largest_force(problem, e.carried) + e.rounding;
    for (const Solved* s : {&a, &b}) {
      const ContactParams& c = s->scene.params.contact;
      const bool passes =
          c.method == ContactMethod::uzawa ||
          (c.method == ContactMethod::cev && (c.loop == ContactLoop::paper || c.friction_loop == FrictionLoop::passes));
      if (passes) settle += mu * c.tau_tolerance * p_max;
      newton += (1 + c.newton_fraction) * c.tolerance * problem.body->characteristic_length();
    }
    const double dq = (ra.state.q - rb.state.q).lpNorm<Eigen::Infinity>();
    const double force_bound = errors + settle;
    const double length_bound = newton;
    EXPECT_LT(dp, force_bound) << "step " << k + 1;
    EXPECT_LT(dq, length_bound) << "step " << k + 1;
    std::printf(
        "step %zu: forces differ by %.2e (bound %.2e, ratio %.2f, of max |p_n| %.1f), displacements by %.2e "
        "(bound %.2e)\n",
        k + 1, dp, force_bound, dp / force_bound, p_max, dq, length_bound);
    worst.first = std::max(worst.first, dp / p_max);
    worst.second = std::max(worst.second, dq);
  }
  return worst;
}

// The disc (33 x 33 nodes) squeezed, turned by 0.9 x the couple of F = 1369 N, then by 1.05 x it:
// beyond what friction holds (the first turn carries Q / (mu P) = 0.914 on each flat, so 1.05
// asks about 1.066). No static equilibrium exists at the last step: a disc turned about its
// squeezed shape re-flattens wherever it touches, so only friction resists the couple, and P is
// fixed by the squeeze.
inline nlohmann::json turned_beyond_the_limit() { return turned_in_stages(32, 1369.0, {0.9, 1.05}); }

// The ratio M / (mu sum N r) of the run's failed step's reason, or 0 where it gives none.
inline constexpr const char* kCoupleLimit = "the couple exceeds what friction can hold: M / (mu sum N r) = ";
inline double limit_ratio(const Solved& s) {
  if (s.run.steps.empty()) return 0.0;
  const std::string& why = s.run.steps.back().reason;
  return why.find(kCoupleLimit) == 0 ? std::stod(why.substr(std::string(kCoupleLimit).size())) : 0.0;
}

// What the ratio of the failed step reads at the state `now` beyond what it reads at `ref`, relative:
// the squeeze force P = P_lower - P_upper (|P_now / P_ref - 1|), the unbalance of the two flats
// (with it the moment of the normal forces depends on the centre of the turn), the levers of
// friction by the pressed points' positions (their |s_eta| against `ref`'s, or against the flats'
// lines without `geometry`, over the two levers 2R), and the couple's arm by its loaded nodes'
// displacements (against `ref`'s, or against none, over the arm 2R).
inline double limit_drift(const Problem& problem, const StepRecord& now, const StepRecord& ref, bool geometry) {
  const Vec2 lower = contact_resultant(problem, now, 0), upper = contact_resultant(problem, now, 1);
  const Vec2 lower_ref = contact_resultant(problem, ref, 0), upper_ref = contact_resultant(problem, ref, 1);
  const double P_now = lower.y() - upper.y(), P_ref = lower_ref.y() - upper_ref.y();
  double drift = std::abs(P_now / P_ref - 1) + std::abs(lower.y() + upper.y()) / P_now +
                 std::abs(lower_ref.y() + upper_ref.y()) / P_ref;
  for (const Candidate& c : problem.candidates)
    if (now.p[c.eta] < 0 || (geometry && ref.p[c.eta] < 0))
      drift += std::abs(now.state.s[c.eta] - (geometry ? ref.state.s[c.eta] : 0.0)) / kDiscRadius / 2;
  for (const int node : {disc_node(32, 32, 16), disc_node(32, 0, 16)})
    drift +=
        (now.state.q.segment<2>(2 * node) - (geometry ? Vec2(ref.state.q.segment<2>(2 * node)) : Vec2::Zero())).norm() /
        kDiscRadius / 2;
  return drift;
}

// The run of turned_beyond_the_limit: the first two steps converged and balanced, the third
// failed at once (no cut of its increment) with the reason in words, no NaN; its ratio
// M / (mu sum N r) against the closed form of the scene, 2 R F / (mu (P_top + P_bottom) h) with
// h = R - delta / 2 (the flats' distance from the centre, the levers of the two flats' friction
// about a turn between them) and P from the converged previous step. Returns the ratio reported.
inline double expect_turned_beyond_the_limit(const Solved& s) {
  EXPECT_TRUE(result_is_finite(s));
  EXPECT_FALSE(s.run.completed);
  if (s.run.steps.size() != 3u) {
    ADD_FAILURE() << "steps " << s.run.steps.size() << ": " << s.run.reason;
    return 0.0;
  }
  EXPECT_TRUE(s.run.steps[0].converged && s.run.steps[1].converged) << s.run.reason;
  expect_disc_balanced(s);
  const StepRecord& failed = s.run.steps[2];
  EXPECT_FALSE(failed.converged);
  EXPECT_EQ(failed.cuts, 0) << failed.reason;
  const std::string& why = failed.reason;
  const std::string head = kCoupleLimit;
  EXPECT_EQ(why.find(head), 0u) << why;
  EXPECT_NE(why.find("at load factors turn 1.05, squeeze 1 (the body turns about"), std::string::npos) << why;
  EXPECT_NE(why.find("no static equilibrium exists"), std::string::npos) << why;
  EXPECT_NE(s.run.reason.find("step 3 failed: " + head), std::string::npos) << s.run.reason;
  const double ratio = limit_ratio(s);
  if (ratio == 0.0) return 0.0;
  // The closed form from the previous step's normal forces.
  const StepRecord& before = s.run.steps[1];
  const double P =
      contact_resultant(s.scene.problem, before, 0).y() - contact_resultant(s.scene.problem, before, 1).y();
  const double F = 1369.0 * 1.05, mu = 0.3, h = kDiscRadius - 0.1 / 2;
  const double closed = 2 * kDiscRadius * F / (mu * P * h);
  // The diagnosis reads the normal forces where the attempt stopped, not the previous step's:
  // they differ by the change of P over the step (the couple lowers the squeeze force), the
  // unbalance of the two flats, and the levers by the displacements (|u| / R at the loaded
  // nodes, the contact points' distance from the flats' lines); all read from that state.
  const double P_now =
      contact_resultant(s.scene.problem, failed, 0).y() - contact_resultant(s.scene.problem, failed, 1).y();
  const double drift = limit_drift(s.scene.problem, failed, before, false);
  EXPECT_GT(ratio, 1.0);
  EXPECT_NEAR(ratio, closed, drift * closed + 1e-6);
  std::printf(
      "beyond the limit: M / (mu sum N r) = %.6f, closed form %.6f (P %.3f of the previous step, %.3f at the "
      "state reached; bound %.2e); failed step: %d real solves, %d Newton, %d cuts\n",
      ratio, closed, P, P_now, drift * closed, failed.solves, failed.newton_iterations, failed.cuts);
  return ratio;
}

// Every strategy reports the ratio of one decision (load_stepping.cpp: cev's default loop from
// the failed attempt's start): the same as cev default's run `reference`, but for what the two
// decided states differ by (limit_drift between them) and the rounding of the two printed ratios
// (6 digits: 5e-6 of the ratio each).
inline void expect_same_limit(const Solved& reference, const Solved& s) {
  const double r = limit_ratio(reference), ratio = limit_ratio(s);
  if (r == 0.0 || ratio == 0.0 || reference.run.steps.size() != 3u || s.run.steps.size() != 3u) {
    ADD_FAILURE() << "no ratio to compare: " << reference.run.reason << " / " << s.run.reason;
    return;
  }
  const double gap = (limit_drift(s.scene.problem, s.run.steps[2], reference.run.steps[2], true) + 1e-5) * r;
  EXPECT_NEAR(ratio, r, gap);
  std::printf("ratio %.6f against cev default's %.6f: differ by %.2e (bound %.2e)\n", ratio, r, std::abs(ratio - r),
              gap);
}

}  // namespace grip::testing
