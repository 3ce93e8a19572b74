// The shipped gear pair (schemas/examples/gear-pair.json, its gmsh mesh beside it): two spur gear
// sectors with involute teeth, both hubs turned by exact finite rotations in the driver's ratio,
// the driven one preloaded into the mesh by a small extra angle, friction 0.1. Over the steps the
// contact on the driver's middle tooth runs up its leading flank, from near the root to near the
// tip (the path of contact of involute gears); each gear's hub carries the moment of the contact
// forces on it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "solver/elements/rigid_hubs.hpp"
#include "tests/support/two_bodies.hpp"

namespace grip {
namespace {

using testing::Solved;

constexpr double kDeg = std::numbers::pi / 180;
const Vec2 kCentre[2] = {Vec2(0, 0), Vec2(50, 0)};  // gear-pair.geo: the driver's, the driven's
constexpr double kMiddle = -12 * kDeg;              // the driver's middle tooth in the drawing
constexpr double kRb1 = 20 * 0.93969262078590838;   // the driver's base radius, m z1 cos(20) / 2
// The leading flank crosses the pitch circle half a tooth's thickness there (pi / (2 z1) = 4.5
// degrees) ahead of the tooth's axis: it touches at the pitch point when the axis is that far
// short of the line of centres (driver angle -4.5 degrees in the drawing's frame).
constexpr double kHalfTooth = std::numbers::pi / 40;

// The radius on the driver of the point of contact of the involutes at driver angle `angle`
// (the middle tooth's axis from the line of centres): on the line of action at rb1 times the
// flank's angle from the pitch point (radius 20).
double involute_radius(double angle) {
  return std::hypot(kRb1, 20 * std::sin(20 * kDeg) + kRb1 * (angle + kHalfTooth));
}

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// The moment about body b's centre of a generalized force on it, at the current positions.
double moment(const Problem& problem, int b, const Vector& q, const Vector& force) {
  const BodySet& all = testing::body_set(problem);
  const Body& body = all.part(b);
  const int o = all.dof_offset(b);
  const Vector qb = q.segment(o, body.dof_count());
  double m = 0;
  for (int n = 0; n < body.node_count(); ++n)
    m += cross(body.node_position(qb, n) - kCentre[b], force.segment<2>(o + 2 * n));
  return m;
}

TEST(GearPair, TheContactRunsUpTheFlankAndTheHubsCarryItsMoment) {
  const Solved s = testing::solve_example("gear-pair");
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  ASSERT_EQ(s.run.steps.size(), 10u);
  const Problem& problem = s.scene.problem;
  const BodySet& all = testing::body_set(problem);
  const Body& driver = all.part(0);
  const Vector zero = Vector::Zero(driver.dof_count());
  double last_radius = 0;
  for (size_t k = 0; k < s.run.steps.size(); ++k) {
    const StepRecord& rec = s.run.steps[k];
    ASSERT_TRUE(rec.converged) << "step " << k + 1;
    const Vector f = testing::contact_forces(problem, rec);
    // The middle tooth's contact: its flank nodes' forces, their centroid's radius (reference
    // positions, the place on the flank), the peak node's force per unit flank length.
    double total = 0, weighted = 0, peak = 0, peak_radius = 0, other = 0;
    for (int n = 0; n < driver.node_count(); ++n) {
      const double force = f.segment<2>(2 * n).norm();
      if (force == 0) continue;
      const Vec2 X = driver.node_position(zero, n);
      if (std::abs(std::atan2(X.y(), X.x()) - kMiddle) > 9 * kDeg) {
        other += force;
        continue;
      }
      total += force;
      weighted += force * X.norm();
      if (force > peak) peak = force, peak_radius = X.norm();
    }
    ASSERT_GT(total, 0) << "step " << k + 1;
    const double radius = weighted / total;
    // Where the involutes put it, the driver at -12 degrees at step 1 and 1.5 degrees a step on.
    const double angle = (-12 + 1.5 * std::max(0.0, static_cast<double>(k))) * kDeg;
    const double involute = involute_radius(angle);
    const double driver_hub = moment(problem, 0, rec.state.q, rec.reactions);
    const double driven_hub = moment(problem, 1, rec.state.q, rec.reactions);
    const double driver_contact = moment(problem, 0, rec.state.q, f);
    const double driven_contact = moment(problem, 1, rec.state.q, f);
    std::printf(
        "gear-pair step %2zu: driver %+5.1f deg, contact radius %.3f (involute %.3f, peak node %.3f, %.1f N), "
        "middle tooth %.1f N, next tooth %.1f N; hub moments %.1f (contact %.1f), %.1f (contact %.1f) N mm/mm\n",
        k + 1, angle / kDeg, radius, involute, peak_radius, peak, total, other, driver_hub, driver_contact, driven_hub,
        driven_contact);
    // Each hub carries the contact forces' moment about its centre (at the current positions).
    const double scale = std::abs(driver_contact);
    EXPECT_NEAR(driver_hub + driver_contact, 0.0, 1e-6 * scale) << "step " << k + 1;
    EXPECT_NEAR(driven_hub + driven_contact, 0.0, 1e-6 * scale) << "step " << k + 1;
    // The contact sits on the involutes' path to about a third of the flank's element size
    // (measured -0.09 to +0.08) and runs up the flank, never down.
    EXPECT_NEAR(radius, involute, 0.15) << "step " << k + 1;
    if (k > 0) EXPECT_GE(radius, last_radius) << "step " << k + 1;
    // The driven hub's moment over the driver's: z2 / z1 = 1.5 for forces along the line of
    // action, friction moving it by a few per cent.
    EXPECT_NEAR(driven_hub / driver_hub, 1.5, 0.05) << "step " << k + 1;
    last_radius = radius;
  }
}

// The moment about `centre` of a generalized force on body b of a scene of several bodies, at
// the state q: sum (x - centre) x f through the body's own rotation at q (any dof numbering, a
// rigid hub's too) less centre x the resultant.
double moment_about(const Problem& problem, int b, const Vector& q, const Vector& force, const Vec2& centre) {
  const BodySet& all = testing::body_set(problem);
  const Body& body = all.part(b);
  const int o = all.dof_offset(b), m = body.dof_count();
  const Vector fb = force.segment(o, m), qb = q.segment(o, m);
  const Vec2 resultant(body.rigid_translation(Vec2::UnitX()).dot(fb), body.rigid_translation(Vec2::UnitY()).dot(fb));
  return body.own_rotation_at(qb).dot(fb) - cross(centre, resultant);
}

// schemas/examples/gear-pair-torque.json: the driven gear on a free rigid hub loaded by a moment
// (docs/algorithm.md#rigid-hubs), the driver's hub turned. Each hub carries the contact's moment
// about its centre (the free one: the applied moment, its equilibrium), the driven gear follows
// the driver in the ratio z1 / z2, and the contact runs up the driver's flank through the pitch
// radius.
TEST(GearPair, DrivenByATorqueOnAFreeHub) {
  const Solved s = testing::solve_example("gear-pair-torque");
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const Problem& problem = s.scene.problem;
  const BodySet& all = testing::body_set(problem);
  const auto& driver = dynamic_cast<const RigidHubs&>(all.part(0));
  const auto& driven = dynamic_cast<const RigidHubs&>(all.part(1));
  const int driver_theta = all.dof_offset(0) + driver.hub_dof(0, 2),
            driven_theta = all.dof_offset(1) + driven.hub_dof(0, 2);
  constexpr double kMoment = 4400;  // the driven hub's load
  const int turn_steps = static_cast<int>(s.run.steps.size()) - 1;
  double last_radius = 0, first_radius = 0;
  for (size_t k = 0; k < s.run.steps.size(); ++k) {
    const StepRecord& rec = s.run.steps[k];
    ASSERT_TRUE(rec.converged) << "step " << k + 1;
    const Vector f = testing::contact_forces(problem, rec);
    // The driver's middle tooth: the force-weighted reference radius of its contact points.
    double total = 0, weighted = 0, other = 0;
    for (size_t i = 0; i < problem.candidates.size(); ++i) {
      const Candidate& c = problem.candidates[i];
      const double force = std::hypot(rec.p[c.eta], c.xi >= 0 ? rec.p[c.xi] : 0.0);
      if (force == 0) continue;
      const Vec2 X = all.site_reference(c.site);
      if (std::abs(std::atan2(X.y(), X.x()) - kMiddle) > 9 * kDeg) {
        other += force;
        continue;
      }
      total += force;
      weighted += force * X.norm();
    }
    ASSERT_GT(total, 0) << "step " << k + 1;
    const double radius = weighted / total;
    const double theta1 = rec.state.q[driver_theta], theta2 = rec.state.q[driven_theta];
    const double driver_contact = moment_about(problem, 0, rec.state.q, f, kCentre[0]);
    const double driven_contact = moment_about(problem, 1, rec.state.q, f, kCentre[1]);
    Vector internal = Vector::Zero(driver.dof_count());
    driver.internal_force(rec.state.q.segment(all.dof_offset(0), driver.dof_count()), internal, nullptr);
    const double driver_hub = internal[driver.hub_dof(0, 2)];
    std::printf(
        "gear-pair-torque step %2zu: driver %+7.3f deg, driven %+7.3f deg (%+.4f of z1/z2), contact radius %.3f, "
        "middle tooth %.1f N, next %.1f N; driver hub %.1f (contact %.1f), driven hub %.1f (contact %.1f) N mm/mm\n",
        k + 1, theta1 / kDeg, theta2 / kDeg, theta1 != 0 ? -theta2 / theta1 - 20.0 / 30 : 0.0, radius, total, other,
        driver_hub, driver_contact, kMoment, driven_contact);
    // The free hub's equilibrium: the contact's moment about its centre balances the load.
    EXPECT_NEAR(driven_contact, -kMoment, 1e-6 * kMoment) << "step " << k + 1;
    EXPECT_NEAR(driver_hub + driver_contact, 0.0, 1e-6 * kMoment) << "step " << k + 1;
    // The driven gear follows in the ratio z1 / z2 (to the teeth's deflection, a few mrad).
    EXPECT_NEAR(theta2, -theta1 * 20 / 30, 3e-3) << "step " << k + 1;
    // On the involutes' path, the driver's middle tooth at -12 degrees plus its hub's angle.
    EXPECT_NEAR(radius, involute_radius(-12 * kDeg + theta1), 0.15) << "step " << k + 1;
    if (k > 0) EXPECT_GE(radius, last_radius - 1e-9) << "step " << k + 1;
    if (k == 0) first_radius = radius;
    last_radius = radius;
  }
  // Up the flank from below the pitch radius (20) to above it.
  EXPECT_LT(first_radius, 20.0);
  EXPECT_GT(last_radius, 20.0);
  EXPECT_GT(turn_steps, 0);
}

}  // namespace
}  // namespace grip
