// The rigid motion reported for a body held by contact (rigid_amplitudes, the result's
// rigid_motion): a body moved rigidly reports exactly that motion. With finite kinematics at any
// angle (a finite rotation is no linear combination of the displacement modes, so a least-squares
// fit over them is only approximate: at 0.7 rad it reports 0.644 rad); with linear kinematics
// the infinitesimal motion, as before.
#include <gtest/gtest.h>

#include <cmath>

#include "solver/io/scene.hpp"
#include "solver/problem/rigid_modes.hpp"

namespace grip {
namespace {

using nlohmann::json;

// A 4 x 1 block (4 x 2 elements, lower-left corner at (1, 2), away from the origin), no supports.
Scene block(const char* kinematics) {
  return read_scene(json::parse(std::string(R"({
    "body": {
      "model": "continuum", "kinematics": ")") +
                                kinematics + R"(", "element": "q4",
      "material": {"young": 1000},
      "mesh": {"rectangle": {"origin": [1, 2], "size": [4, 1], "divisions": [4, 2]}},
      "loads": [{"node": 0, "force": [0, -1]}]
    },
    "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [10, 2], "to": [-10, 2]}, "friction": 0.3}]
  })"));
}

// Every node's reference position X (rigid_rotation = (-Y, X) at each node).
std::vector<Vec2> positions(const Body& body) {
  const Vector rot = body.rigid_rotation();
  std::vector<Vec2> X;
  for (int i = 0; i < rot.size() / 2; ++i) X.emplace_back(rot[2 * i + 1], -rot[2 * i]);
  return X;
}

TEST(RigidMotion, FiniteRotationAndTranslationReportedExactly) {
  const Scene scene = block("finite");
  const Body& body = *scene.problem.body;
  const std::vector<Vec2> X = positions(body);
  for (const double angle : {1e-3, 0.7, 2.5, -3.0}) {
    // Turned by `angle` about (2, 3), then moved by (0.4, -1.3): x = R (X - c) + c + d. The point
    // at the origin goes to t = c + d - R c.
    const Vec2 c(2, 3), d(0.4, -1.3);
    const double co = std::cos(angle), si = std::sin(angle);
    auto turn = [&](const Vec2& v) { return Vec2(co * v.x() - si * v.y(), si * v.x() + co * v.y()); };
    Vector q(body.dof_count());
    for (size_t i = 0; i < X.size(); ++i) q.segment<2>(2 * i) = turn(X[i] - c) + c + d - X[i];
    const Vec2 t = c + d - turn(c);
    const Vector a = rigid_amplitudes(body, q);
    ASSERT_EQ(a.size(), 3);
    EXPECT_NEAR(a[2], angle, 1e-14) << angle;
    EXPECT_NEAR(a[0], t.x(), 1e-13) << angle;
    EXPECT_NEAR(a[1], t.y(), 1e-13) << angle;
  }
}

// Linear kinematics: u = t + theta (-y, x) is the body's rigid motion, reported as it is.
TEST(RigidMotion, InfinitesimalMotionOfALinearBodyUnchanged) {
  const Scene scene = block("linear");
  const Body& body = *scene.problem.body;
  const Vector q = 0.02 * body.rigid_translation(Vec2::UnitX()) - 0.05 * body.rigid_translation(Vec2::UnitY()) +
                   0.3 * body.rigid_rotation();
  const Vector a = rigid_amplitudes(body, q);
  ASSERT_EQ(a.size(), 3);
  EXPECT_NEAR(a[0], 0.02, 1e-14);
  EXPECT_NEAR(a[1], -0.05, 1e-14);
  EXPECT_NEAR(a[2], 0.3, 1e-14);
}

}  // namespace
}  // namespace grip
