// Issue 36, hard cases of axisymmetry: a point load on the axis of a body held only by contact,
// the axis node of quadratic contact sides (no share of the swept area), and the Hertz sphere
// refined to a / h 40 (82 contact points), frictionless and with friction 0.3 in 10 steps.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "solver/io/result.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using namespace grip::testing;
using nlohmann::json;

// A solid cylinder (r <= 2, 0 <= z <= 4) standing on a rigid frictionless flat and held by
// nothing else.
json cylinder_on_flat(const std::string& element) {
  json j = json::parse(R"({
    "body": {"model": "continuum", "kinematics": "linear", "analysis": "axisymmetric",
             "material": {"young": 1000, "poisson": 0.3},
             "mesh": {"rectangle": {"size": [2, 4], "divisions": [6, 12]}},
             "contact_set": "bottom"},
    "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [5, 0], "to": [-5, 0]}}],
    "steps": 2,
    "solver": {"contact": {"method": "cev", "tolerance": 1e-8}}
  })");
  j["body"]["element"] = element;
  return j;
}

// The load a point force on the axis at the top (a ring of zero radius: the total force). The
// reader holds u_r there like at every axis node; contact holds the translation along the axis
// and carries the whole force; every contact stress is finite, the axis corner of a quadratic
// bottom side reading its neighbour's.
TEST(AxisymmetricHard, PointLoadOnTheAxisOfABodyHeldByContact) {
  constexpr double F = 50.0;
  for (const std::string element : {"q4", "q8", "t6"}) {
    json j = cylinder_on_flat(element);
    const Scene probe = read_scene(j);
    const Vector zero = Vector::Zero(probe.problem.body->dof_count());
    int top = -1;
    for (int n = 0; n < probe.problem.body->node_count(); ++n)
      if ((probe.problem.body->node_position(zero, n) - Vec2(0, 4)).norm() < 1e-12) top = n;
    ASSERT_GE(top, 0);
    j["body"]["loads"] = {{{"node", top}, {"force", {0.0, -F}}}};
    const Solved s = solve_scene(j);
    expect_every_step_sound(s);
    ASSERT_TRUE(s.run.completed) << element << ": " << s.run.reason;
    ASSERT_EQ(s.scene.problem.rigid.names.size(), 1u);
    const StepRecord& rec = s.run.steps.back();
    EXPECT_NEAR(contact_resultant(s.scene.problem, rec).y(), F, 1e-6 * F) << element;
    EXPECT_EQ(rec.state.q[2 * top], 0.0) << element;  // u_r on the axis
    EXPECT_LT(rec.state.q[2 * top + 1], 0.0) << element;
    const std::vector<ContactPointRow> rows = contact_point_rows(s.scene.problem, rec);
    double total = 0;
    for (const ContactPointRow& r : rows) {
      EXPECT_TRUE(std::isfinite(r.sigma_n)) << element << " node " << r.node;
      total -= r.p_n;
    }
    EXPECT_NEAR(total, F, 1e-6 * F);
    // Far from the load the pressure is F / (pi R^2): within a few per cent at the middle.
    const auto nodes = contact_profile(s.scene.problem, rec);
    const double mean = F / (std::numbers::pi * 4.0);
    std::printf("%s: axis node sigma %.4f, mean pressure %.4f, u_z under the load %.4g\n", element.c_str(),
                -nodes.front().sigma_n, mean, rec.state.q[2 * top + 1]);
    EXPECT_NEAR(-nodes.front().sigma_n, mean, 0.1 * mean) << element;
  }
}

// The shipped sphere with elements of 0.0177 mm near the pole (a / h 40), at the fewest
// divisions the generator accepts.
json refined_sphere(double mu, int steps) {
  json j = example_scene("hertz-sphere");
  j["body"]["mesh"]["half_disc"]["refine"]["size"] = 0.0177;
  j["body"]["mesh"]["half_disc"]["divisions"] = {170, 85};
  j["obstacles"][0]["friction"] = mu;
  j["steps"] = steps;
  return j;
}

struct SphereContact {
  double a = 0, p0 = 0;  // Hertz at the computed load
  double peak = 0;       // largest nodal pressure
  double last_in = 0;    // the outermost node that presses
  int pressing = 0, sticking = 0;
};

SphereContact sphere_contact(const Solved& s) {
  const StepRecord& rec = s.run.steps.back();
  const double P = contact_resultant(s.scene.problem, rec).y(), E = 200000, nu = 0.3, R = 10;
  SphereContact c;
  c.a = std::cbrt(3 * P * R * (1 - nu * nu) / (4 * E));
  c.p0 = 3 * P / (2 * std::numbers::pi * c.a * c.a);
  for (const auto& n : contact_profile(s.scene.problem, rec)) {
    if (n.p_n >= 0) continue;
    c.peak = std::max(c.peak, -n.sigma_n);
    c.last_in = std::max(c.last_in, n.x);
    ++c.pressing;
    c.sticking += n.state == ContactState::stick;
  }
  return c;
}

// Frictionless at a / h 40: the peak nodal pressure within 0.5 % of Hertz's p0, the contact's
// end between the last pressing node and a node spacing (h / 2) beyond it. With friction 0.3
// (Spence: the tangential traction that the coupling of normal and tangential displacements
// (nu < 1/2) sets up narrows the zone and raises the peak): every step sound (Coulomb's cone,
// balance, monotone error), the peak above p0 by less than 15 %, the zone inside Hertz's, a
// central stick zone with slip at its edge.
TEST(AxisymmetricHard, RefinedSphereFrictionlessAndWithFriction) {
  const Solved frictionless = solve_scene(refined_sphere(0.0, 2));
  expect_every_step_sound(frictionless);
  ASSERT_TRUE(frictionless.run.completed) << frictionless.run.reason;
  const SphereContact h = sphere_contact(frictionless);
  std::printf("mu 0: %d pressing, peak / p0 %.4f, last pressing node / a %.4f\n", h.pressing, h.peak / h.p0,
              h.last_in / h.a);
  EXPECT_GT(h.pressing, 60);
  EXPECT_NEAR(h.peak, h.p0, 0.005 * h.p0);
  EXPECT_LE(h.last_in, h.a);
  EXPECT_GT(h.last_in, h.a - 0.0177);

  const Solved rough = solve_scene(refined_sphere(0.3, 10));
  expect_every_step_sound(rough);
  ASSERT_TRUE(rough.run.completed) << rough.run.reason;
  const SphereContact f = sphere_contact(rough);
  std::printf("mu 0.3: %d pressing, %d sticking, peak / p0 %.4f, last pressing node / a %.4f\n", f.pressing, f.sticking,
              f.peak / f.p0, f.last_in / f.a);
  EXPECT_GT(f.peak, h.peak / h.p0 * f.p0);
  EXPECT_LT(f.peak, 1.15 * f.p0);
  EXPECT_LT(f.last_in, f.a);
  EXPECT_GT(f.sticking, f.pressing / 2);
  EXPECT_LT(f.sticking, f.pressing);
}

}  // namespace
}  // namespace grip
