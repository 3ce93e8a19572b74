// The `rotation` support of a continuum: with finite kinematics it turns the held nodes exactly,
// (R(t angle) - I)(X - c) at load factor t, so a block turned by its bottom edge through 90
// degrees is a rigid rotation, every node on its turned position and no stress; with linear
// kinematics it is the small rotation t angle (-(y - yc), x - xc), exact for that kinematics.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "solver/io/scene.hpp"

namespace grip {
namespace {

// One q9 element, 2 x 1, every node in the set "all" turned about (1, -1) by a quarter turn.
nlohmann::json turned_block(const char* kinematics) {
  auto j = nlohmann::json::parse(R"({
    "body": {
      "model": "continuum", "element": "q9",
      "material": {"young": 1000, "poisson": 0.3},
      "mesh": {"nodes": [[0, 0], [2, 0], [2, 1], [0, 1], [1, 0], [2, 0.5], [1, 1], [0, 0.5], [1, 0.5]],
               "elements": [[0, 1, 2, 3, 4, 5, 6, 7, 8]],
               "sets": {"all": [0, 1, 2, 3, 4, 5, 6, 7, 8], "bottom": [0, 4, 1]}},
      "contact_set": "bottom",
      "supports": [{"set": "all", "rotation": {"about": [1, -1], "angle": 1.5707963267948966}}]
    },
    "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [100, -50], "to": [-100, -50]}}]
  })");
  j["body"]["kinematics"] = kinematics;
  return j;
}

// The displacement the supports prescribe at load factor t.
Vector prescribed(const Scene& s, double t) {
  Vector q = Vector::Zero(s.problem.body->dof_count());
  for (const Constraint& k : s.problem.constraints) q[k.dof] = k.at(t);
  return q;
}

TEST(RotationSupport, FiniteKinematicsTurnsTheBodyRigidlyThroughAQuarterTurn) {
  const Scene s = read_scene(turned_block("finite"));
  const Body& body = *s.problem.body;
  ASSERT_EQ(s.problem.constraints.size(), 18u);
  const Vector zero = Vector::Zero(body.dof_count());
  const Vec2 c(1, -1);
  for (double t : {0.25, 0.5, 1.0}) {
    const double a = t * std::numbers::pi / 2;
    const Eigen::Matrix2d R{{std::cos(a), -std::sin(a)}, {std::sin(a), std::cos(a)}};
    const Vector q = prescribed(s, t);
    // Every node on its rigidly turned position (on its circle, not the chord), and no internal
    // force (no stress) anywhere: the linearized rotation would stretch the block by
    // sqrt(1 + a^2) - 1, 62 % at a quarter turn.
    for (int n = 0; n < body.node_count(); ++n) {
      const Vec2 X = body.node_position(zero, n);
      EXPECT_LT((body.node_position(q, n) - (c + R * (X - c))).norm(), 1e-14 * 4) << "t " << t << " node " << n;
    }
    Vector f = Vector::Zero(body.dof_count());
    body.internal_force(q, f, nullptr);
    EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-12 * 1000) << "t " << t;  // E times a length^2 (thickness 1)
  }
}

TEST(RotationSupport, LinearKinematicsPrescribesTheSmallRotation) {
  Scene s = read_scene(turned_block("linear"));
  const Body& body = *s.problem.body;
  const Vector zero = Vector::Zero(body.dof_count());
  ASSERT_FALSE(s.problem.constraints.empty());
  for (const Constraint& k : s.problem.constraints) {
    const Vec2 d = body.node_position(zero, body.dof_node(k.dof)) - Vec2(1, -1);
    const double small = k.dof % 2 == 0 ? -d.y() : d.x();
    EXPECT_DOUBLE_EQ(k.at(0.5), 0.5 * std::numbers::pi / 2 * small);
  }
}

}  // namespace
}  // namespace grip
