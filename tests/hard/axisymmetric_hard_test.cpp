// Issue 36, hard cases of axisymmetry: a point load on the axis of a body held only by contact,
// and the axis node of quadratic contact sides (no share of the swept area).
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

}  // namespace
}  // namespace grip
