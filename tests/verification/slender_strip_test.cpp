// Slender bodies and large rotations (issue 13): a strip modelled as a continuum bent far
// beyond small rotations, against the elastica; the same strip linear against beam theory;
// the strip wrapped onto a cylinder; the von Karman beam's warning where it stops being
// accurate.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "solver/elements/timoshenko_beam.hpp"
#include "tests/support/elastica.hpp"
#include "tests/support/strips.hpp"

namespace grip {
namespace {

using testing::elastica_tip;
using testing::ElasticaTip;
using testing::expect_every_step_sound;
using testing::solve_scene;
using testing::StripSpec;
using testing::strip_scene;
using testing::strip_tip;

// The shooting solution reproduces Mattiasson's (1981) table of the elastica.
TEST(Elastica, ReproducesMattiassonsTable) {
  struct Row {
    double alpha, v, u, theta;
  };
  for (const Row& row : {Row{1, 0.30172, 0.05643, 0.46135}, Row{2, 0.49346, 0.16064, 0.78175},
                         Row{5, 0.71379, 0.38763, 1.21537}, Row{10, 0.81061, 0.55500, 1.43029}}) {
    const ElasticaTip tip = elastica_tip(row.alpha);
    EXPECT_NEAR(tip.deflection, row.v, 1e-5) << row.alpha;
    EXPECT_NEAR(tip.shortening, row.u, 1e-5) << row.alpha;
    EXPECT_NEAR(tip.rotation, row.theta, 1e-5) << row.alpha;
  }
}

// A strip of L/t = 50 (q9, 50 x 2, finite strain) bent by a dead end load to F L^2/EI = 10
// (tip rotation 82 deg) in 20 steps: at every step its tip is the elastica's within 0.3 %
// of L (the continuum's own extension and shear, about (t/L)^2 and the load's spread over
// the end section), and Newton needs no cut of the increment. With the linearized stress in
// the tangent (docs/algorithm.md#newtons-tangent-the-linearized-stress) and every correction
// taken in full, Newton converges from the straight strip in 4 iterations and from each
// extrapolated start in 3-5: measured 80 for the run (85 where Deuflhard's test judged the
// corrections after the first, which the bound fails; 116, 18 at the first step and up to 9
// after it, with the stress at each iterate).
TEST(SlenderStrip, CantileverFollowsTheElastica) {
  const StripSpec spec;
  const auto s = solve_scene(strip_scene(spec));
  expect_every_step_sound(s);
  ASSERT_EQ(s.run.steps.size(), 20u);
  for (size_t k = 0; k < s.run.steps.size(); ++k) {
    const StepRecord& rec = s.run.steps[k];
    EXPECT_EQ(rec.cuts, 0) << "step " << k + 1;
    const ElasticaTip exact = elastica_tip(spec.alpha * rec.load_factor);
    const ElasticaTip tip = strip_tip(s, spec, k);
    std::printf(
        "F L^2/EI = %4.1f: %2d Newton; tip deflection %+.2e, shortening %+.2e (of L), rotation %+.2e (relative)\n",
        spec.alpha * rec.load_factor, rec.newton_iterations, tip.deflection - exact.deflection,
        tip.shortening - exact.shortening, tip.rotation / exact.rotation - 1);
    EXPECT_NEAR(tip.deflection, exact.deflection, 3e-3) << "step " << k + 1;
    EXPECT_NEAR(tip.shortening, exact.shortening, 3e-3) << "step " << k + 1;
    EXPECT_NEAR(tip.rotation, exact.rotation, 3e-3 * exact.rotation) << "step " << k + 1;
  }
  int newton = 0;
  for (const StepRecord& rec : s.run.steps) {
    EXPECT_LE(rec.newton_iterations, rec.index == 1 ? 5 : 6) << "step " << rec.index;
    newton += rec.newton_iterations;
  }
  EXPECT_LE(newton, 82);
}

// Doubling the mesh along the strip changes the tip by far less than the distance to the
// elastica: the 0.3 % above is the model's, not the mesh's.
TEST(SlenderStrip, CantileverIsMeshConverged) {
  StripSpec coarse, fine;
  coarse.steps = fine.steps = 10;
  fine.along = 100;
  const auto a = solve_scene(strip_scene(coarse)), b = solve_scene(strip_scene(fine));
  ASSERT_TRUE(a.run.completed && b.run.completed) << a.run.reason << b.run.reason;
  const ElasticaTip ta = strip_tip(a, coarse, 9), tb = strip_tip(b, fine, 9);
  EXPECT_NEAR(ta.deflection, tb.deflection, 5e-4);
  EXPECT_NEAR(ta.rotation, tb.rotation, 5e-4 * tb.rotation);
}

// The same strip at L/t = 1000 with linear kinematics: a constant tangent, so one
// factorization for the run and at most one correction per step; the tip deflection is
// beam theory's F L^3 / (3 EI) + F L / (kappa G A) to the mesh's accuracy.
TEST(SlenderStrip, LinearStripIsOneSolvePerStep) {
  StripSpec spec;
  spec.kinematics = "linear";
  spec.thickness = 1e-3;
  spec.young = 12.0 / 1e-9;  // EI = 1 again
  spec.along = 250;
  spec.alpha = 0.01;
  spec.steps = 5;
  const auto s = solve_scene(strip_scene(spec));
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  EXPECT_EQ(s.run.counters.factorizations, 1);
  // The supports carry the load to the round-off floor of a stiffness whose condition number
  // is about 1e12: the clamp's nodal forces are L/t = 1000 times the load, and each free dof's
  // residual sits at about 1e-6 of them, so the reactions' sum is good to about 1e-3 of the
  // load (measured: 1.1e-3 at step 1).
  for (const StepRecord& rec : s.run.steps) {
    EXPECT_LE(rec.newton_iterations, 2) << rec.index;
    double total = 0.0;
    for (Eigen::Index d = 1; d < rec.reactions.size(); d += 2) total += rec.reactions[d];
    const double F = spec.alpha * rec.load_factor;
    EXPECT_NEAR(total, F, 5e-3 * F) << rec.index;
    EXPECT_LT(rec.state.relative_residual, 1e-5) << rec.index;
  }
  const double F = spec.alpha, G = spec.young / 2, A = spec.thickness;
  const double beam = F / 3.0 + F / (5.0 / 6.0 * G * A);
  EXPECT_NEAR(strip_tip(s, spec, 4).deflection, beam, 5e-3 * beam);
}

// The strip wrapped onto a cylinder of radius 0.4 without friction (25 x 2 elements, 8
// steps): cev with its default exact inner solve and with the n = 2 accelerated iteration
// (a different path) find the same contact forces, and a mesh twice as fine moves the tip by
// less than 0.5 % of L. (Uzawa does not finish here: 500 iterations at the first step in
// contact, whose single contact point near the clamp is very stiff.)
TEST(SlenderStrip, WrapsOntoACylinder) {
  StripSpec spec;
  spec.radius = 0.4;
  spec.along = 25;
  spec.steps = 8;
  const auto cev = solve_scene(strip_scene(spec));
  expect_every_step_sound(cev);
  nlohmann::json other_scene = strip_scene(spec);
  other_scene["solver"]["contact"]["acceleration"] = {{"n", 2}};
  const auto other = solve_scene(other_scene);
  ASSERT_TRUE(other.run.completed) << other.run.reason;
  const StepRecord &a = cev.run.steps.back(), &b = other.run.steps.back();
  const double scale = a.p.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0.0);
  EXPECT_LT((a.p - b.p).cwiseAbs().maxCoeff(), 1e-4 * scale);
  int touching = 0;
  for (const Candidate& c : cev.scene.problem.candidates) touching += a.p[c.eta] < 0;
  EXPECT_GE(touching, 1);

  StripSpec fine = spec;
  fine.along = 50;
  const auto refined = solve_scene(strip_scene(fine));
  ASSERT_TRUE(refined.run.completed) << refined.run.reason;
  EXPECT_NEAR(strip_tip(cev, spec, 7).deflection, strip_tip(refined, fine, 7).deflection, 5e-3);
}

// With friction 0.3 (the shipped strip-on-cylinder scene): every step converges, Coulomb
// holds at every point, and the contact error falls monotonically. Its compliance holds the
// stiffness of the contact forces that turn with the cylinder (docs/algorithm.md, the contact
// compliance): 48 real solves and 134 Newton iterations measured (86 and 259 with the body's
// own compliance, 56 and 190 with the stress at each iterate in Newton's tangent, 53 and 144
// where the model's tau passes judged their force by the s of its unprojected value); the
// bounds leave room for a path that round-off moves by a solve or two. The model's semismooth
// Newton takes 276 iterations in all with its nonmonotone line search, 962 with a monotone one,
// which stalled at the stick/slip kinks and left the updates to the tau passes on the model.
// Chords with the last solve's factorization end most of the updates' solves without a
// factorization (docs/algorithm.md, Newton's stopping tests): 95 Newton iterations and 29
// chord-ended solves measured, where Newton alone took 133 and Newton with Deuflhard's test after
// the first correction 100 (the bound fails both).
TEST(SlenderStrip, WrapsOntoACylinderWithFriction) {
  const auto s = solve_scene(testing::example_scene("strip-on-cylinder"));
  expect_every_step_sound(s);
  ASSERT_EQ(s.run.steps.size(), 20u);
  int slipping = 0;
  for (const auto& p : s.scene.problem.candidates) slipping += std::abs(s.run.steps.back().p[p.xi]) > 0;
  EXPECT_GE(slipping, 1);
  std::printf("%ld real solves, %ld Newton iterations, %ld ended by chords\n", s.run.counters.solves,
              s.run.counters.newton_iterations, s.run.counters.chord_solves);
  EXPECT_LE(s.run.counters.solves, 50);
  EXPECT_LE(s.run.counters.newton_iterations, 97);
  EXPECT_GE(s.run.counters.chord_solves, 20);
  int inner = 0;
  for (const StepRecord& rec : s.run.steps) inner += rec.inner_iterations;
  std::printf("%d iterations on the linear model\n", inner);
  EXPECT_LE(inner, 400);
  // The counters are honest: a step's iteration events add up to its real solves and its
  // Newton iterations (rejected line-search trials included); a failed attempt (a cut, a
  // restart from the last force) ends without an event for its last trials.
  for (const StepRecord& rec : s.run.steps) {
    if (rec.cuts > 0 || rec.restarts > 0) continue;
    int trials = 0, newton = 0;
    for (const IterationEvent& ev : rec.history) {
      trials += ev.trials;
      newton += ev.newton_iterations;
    }
    EXPECT_EQ(trials, rec.solves) << "step " << rec.index;
    EXPECT_EQ(newton, rec.newton_iterations) << "step " << rec.index;
  }
}

// The linear model's rows (docs/algorithm.md, the contact compliance): after a step's first
// update a candidate joins only within 3 x its own last gap change (at least 1e-3 L), not
// within the 0.05 L window, which on this strip takes in most of the wrapped lower face (1 to 3
// of its points press). Each G formed covers 2 free dofs per candidate in the rows: with the
// window alone 3626 columns in 27 forms, 134 a form (1.9 x the 70 candidates within 0.05 L at
// the last step: the test fails there); with the reach 2248, 83 a form (measured, 48 real solves
// either way). The points that close from outside the rows are still caught: every step
// converges with the contact conditions met at every candidate (expect_every_step_sound).
TEST(SlenderStrip, ModelRowsFollowTheGapsReach) {
  const auto s = solve_scene(testing::example_scene("strip-on-cylinder"));
  expect_every_step_sound(s);
  ASSERT_EQ(s.run.steps.size(), 20u);
  const double L = s.scene.problem.body->characteristic_length();
  int within = 0;
  for (const Candidate& c : s.scene.problem.candidates) within += s.run.steps.back().state.s[c.eta] > -0.05 * L;
  ASSERT_GT(s.run.counters.compliance_forms, 0);
  const double per_form =
      static_cast<double>(s.run.counters.compliance_columns) / static_cast<double>(s.run.counters.compliance_forms);
  std::printf("%ld columns of G in %ld forms (%.1f a form), %d candidates within 0.05 L at the end, %ld real solves\n",
              s.run.counters.compliance_columns, s.run.counters.compliance_forms, per_form, within,
              s.run.counters.solves);
  EXPECT_LT(per_form, 1.6 * within);
}

// The von Karman beam as a cantilever (L/d = 60, so that shear adds only 2e-4 to the
// deflection): its tip deflection departs from the elastica like 0.45 theta^2 (1 % at
// 0.15 rad), and the step record warns exactly where the largest rotation passes 0.15 rad.
TEST(VonKarmanBeam, WarnsWhereItLeavesTheElastica) {
  nlohmann::json j = testing::example_scene("beam-on-cylinder");
  j["body"]["section"]["depth"] = 0.5;
  const double EI = 210000.0 * 2 * 0.125 / 12.0, L = 30.0,
               alpha = 0.9;  // tip rotations 0.045 k: none on the 0.15 limit
  j["body"]["loads"] = {{{"node", 40}, {"force", {0.0, -alpha * EI / (L * L)}}}};
  j["obstacles"][0]["shape"]["centre"] = {0, -500};
  j["steps"] = 10;
  const auto s = solve_scene(j);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  int warned = 0;
  for (const StepRecord& rec : s.run.steps) {
    const double theta = std::abs(rec.state.q[TimoshenkoBeam::node_dof(40, 2)]);
    const ElasticaTip exact = elastica_tip(alpha * rec.load_factor);
    const double error =
        std::abs(-rec.state.q[TimoshenkoBeam::node_dof(40, 1)] / L - exact.deflection) / exact.deflection;
    std::printf("step %d: tip rotation %.4f rad, deflection %.3f %% off the elastica\n", rec.index, theta, 100 * error);
    EXPECT_LE(error, 0.5 * theta * theta + 1e-3) << "step " << rec.index;
    EXPECT_EQ(!rec.warning.empty(), theta > 0.15) << "step " << rec.index << ": " << rec.warning;
    warned += !rec.warning.empty();
  }
  EXPECT_GE(warned, 1);
  EXPECT_LE(warned, 9);
}

}  // namespace
}  // namespace grip
