// Distributed loads on the beams (body.loads[].traction): a dead uniform load on a cantilever,
// over the whole beam and over part of it, against the Timoshenko closed form (both beam
// models); and a follower pressure that stays normal to the deformed axis of a reissner_beam
// against an independent integration of the inextensible elastica under that pressure.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tests/support/beam_cantilever.hpp"

namespace grip {
namespace {

using nlohmann::json;
using testing::cantilever;
using testing::solve_scene;
using testing::tip;

// Tip deflection of a cantilever (length 1, EI = 1) under q per unit length over [a, 1]:
// bending q (3 - 4 a^3 + a^4) / 24, shear q ((1 - a) a + (1 - a)^2 / 2) / kGA.
double tip_deflection(double q, double a, double kGA) {
  return q * (3 - 4 * a * a * a + a * a * a * a) / 24 + q * ((1 - a) * a + (1 - a) * (1 - a) / 2) / kGA;
}

json as_model(json scene, const std::string& model) {
  if (model == "timoshenko_beam") {
    scene["body"]["model"] = model;
    scene["body"].erase("element");
    scene["body"]["kinematics"] = "linear";
  } else {
    scene["body"]["element"] = model == "reissner_beam b2" ? "b2" : "b3";
  }
  return scene;
}

// Depth 0.1 (L/t 10): the shear deflection is 3 % of the bending one, so the test sees it. The
// load is small enough (tip rotation 2e-5 rad) that the geometrically exact beam is linear to
// 1e-9. The span [0.37, 1] starts inside an element (20 elements: between nodes 7 and 8).
TEST(BeamLineLoad, DeadUniformLoadGivesTheTimoshenkoCantilever) {
  const double t = 0.1, q = -1e-4, kGA = 5.0 / 6.0 * 12.0 / (t * t * t) / 2.6 * t;
  for (const std::string model : {"timoshenko_beam", "reissner_beam b3", "reissner_beam b2"})
    for (const double a : {0.0, 0.37}) {
      json load = {{"traction", {0.0, q}}};
      if (a > 0) load["from"] = a;
      const auto s = solve_scene(as_model(cantilever(20, "b3", load, 1, t), model));
      ASSERT_TRUE(s.run.completed) << model << ": " << s.run.reason;
      const double w = tip(s, 0, 20).y(), exact = tip_deflection(q, a, kGA);
      std::printf("%s, load over [%.2f, 1]: tip %.8e, closed form %.8e (%+.1e)\n", model.c_str(), a, w, exact,
                  w / exact - 1);
      EXPECT_NEAR(w / exact, 1.0, model == "reissner_beam b2" ? 2e-3 : 1e-4) << model << " a " << a;
    }
}

// The inextensible cantilever (L = 1, EI = 1) under a pressure alpha per unit current length,
// normal to the axis: the load beyond s has the moment alpha |x(L) - x(s)|^2 / 2 about x(s)
// (the integral of (x - x(s)) . t), so phi' = alpha |r|^2 / 2 with r = x(L) - x(s). The equations
// do not change under a turn of the whole beam: integrated (RK4) from the free end with
// phi(L) = 0, the clamp's angle is -phi_L, and the answer is that state turned by phi_L.
struct PressureTip {
  double rotation;  // clockwise, as theta
  Vec2 position;    // relative to the clamp
};

PressureTip pressure_elastica(double alpha) {
  const int n = 4000;
  const double h = -1.0 / n;
  Eigen::Vector3d y(0.0, 0.0, 0.0);  // phi, r_x, r_y from s = 1 down to s = 0
  auto rate = [alpha](const Eigen::Vector3d& v) {
    return Eigen::Vector3d(alpha / 2 * (v[1] * v[1] + v[2] * v[2]), -std::cos(v[0]), -std::sin(v[0]));
  };
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d k1 = rate(y), k2 = rate(y + h / 2 * k1), k3 = rate(y + h / 2 * k2), k4 = rate(y + h * k3);
    y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  const double phi_L = -y[0], c = std::cos(phi_L), s = std::sin(phi_L);
  return {-phi_L, Vec2(c * y[1] - s * y[2], s * y[1] + c * y[2])};
}

// alpha to 12 in 24 steps turns the tip through 1.82 rad, past 90 degrees; at every step the
// tip's rotation and position are the integration's within 1e-4 of L (t = 3e-3: extension and
// shear near 1e-5; measured within 1e-5).
// A dead load of the same size turns it less: the follower's pressure keeps pushing across.
TEST(BeamLineLoad, FollowerPressureFollowsThePressureElastica) {
  const auto s = solve_scene(cantilever(20, "b3", {{"traction", {0.0, 12.0}}, {"follower", true}}, 24, 3e-3));
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  for (size_t k = 0; k < s.run.steps.size(); ++k) {
    const double alpha = 12.0 * s.run.steps[k].load_factor;
    const PressureTip exact = pressure_elastica(alpha);
    const Vec2 at = Vec2(1.0, 0.0) + tip(s, k, 20);
    const double theta = s.run.steps[k].state.q[StraightBeam::node_dof(20, 2)];
    std::printf("pressure alpha %.1f: rotation %.5f (%+.1e), tip (%.5f, %.5f) (%+.1e, %+.1e), %d Newton\n", alpha,
                theta, theta - exact.rotation, at.x(), at.y(), at.x() - exact.position.x(), at.y() - exact.position.y(),
                s.run.steps[k].newton_iterations);
    EXPECT_NEAR(theta, exact.rotation, 1e-4) << alpha;
    EXPECT_NEAR(at.x(), exact.position.x(), 1e-4) << alpha;
    EXPECT_NEAR(at.y(), exact.position.y(), 1e-4) << alpha;
  }
  // Small alpha: the linear cantilever's tip rotation alpha / 6 and deflection alpha / 8.
  EXPECT_NEAR(pressure_elastica(1e-4).rotation, -1e-4 / 6, 1e-10);
  EXPECT_NEAR(pressure_elastica(1e-4).position.y(), 1e-4 / 8, 1e-10);
  const auto dead = solve_scene(cantilever(20, "b3", {{"traction", {0.0, 12.0}}}, 24, 3e-3));
  ASSERT_TRUE(dead.run.completed) << dead.run.reason;
  EXPECT_LT(-dead.run.steps.back().state.q[StraightBeam::node_dof(20, 2)], -pressure_elastica(12.0).rotation - 0.05);
}

}  // namespace
}  // namespace grip
