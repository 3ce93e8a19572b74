// A rigid hub loaded by a moment (docs/algorithm.md#rigid-hubs): an annulus (inner radius a = 5, outer
// b = 10, q9, steel) held at its outer rim, its inner rim a hub turned by a moment M with its
// angle free. Linear elasticity has the closed form of the ring's torsion: the shear
// tau_r_theta = M / (2 pi r^2) (per unit thickness) and u_theta = r omega(r), omega' =
// tau / (mu r), so the hub turns by M / (4 pi mu) (1 / a^2 - 1 / b^2), whatever nu. With finite
// kinematics: the hub turned by a prescribed angle (its reaction moment M0) and the hub loaded
// by M0 agree on the angle, and the rim's reaction balances the moment about the centre.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "solver/elements/rigid_hubs.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using nlohmann::json;
using testing::Solved;

constexpr double kA = 5, kB = 10, kYoung = 210000, kPoisson = 0.3;

// The annulus as q9: nr elements across, nt around (a closed ring), sets "hub" (r = a) and
// "rim" (r = b); the hub loaded by `moment` or turned by `angle` (hub_key), over `steps` steps.
json annulus(const char* kinematics, const char* hub_key, double value, int nr = 6, int nt = 48) {
  const int NI = 2 * nr + 1, NJ = 2 * nt;
  json nodes = json::array(), elements = json::array(), hub = json::array(), rim = json::array();
  auto id = [&](int I, int J) { return (J % NJ) * NI + I; };
  for (int J = 0; J < NJ; ++J)
    for (int I = 0; I < NI; ++I) {
      const double r = kA + (kB - kA) * I / (NI - 1.0), t = 2 * std::numbers::pi * J / NJ;
      nodes.push_back({r * std::cos(t), r * std::sin(t)});
      if (I == 0) hub.push_back(id(I, J));
      if (I == NI - 1) rim.push_back(id(I, J));
    }
  for (int j = 0; j < nt; ++j)
    for (int i = 0; i < nr; ++i) {
      const int I = 2 * i, J = 2 * j;
      elements.push_back({id(I, J), id(I + 2, J), id(I + 2, J + 2), id(I, J + 2), id(I + 1, J), id(I + 2, J + 1),
                          id(I + 1, J + 2), id(I, J + 1), id(I + 1, J + 1)});
    }
  return {
      {"body",
       {{"model", "continuum"},
        {"kinematics", kinematics},
        {"analysis", "plane_strain"},
        {"element", "q9"},
        {"material", {{"young", kYoung}, {"poisson", kPoisson}}},
        {"mesh", {{"nodes", nodes}, {"elements", elements}, {"sets", {{"hub", hub}, {"rim", rim}}}}},
        {"contact_set", "rim"},
        {"supports", json::array({{{"set", "rim"}, {"fix", {"x", "y"}}}})},
        {"hubs", json::array({{{"set", "hub"}, {"centre", {0, 0}}, {hub_key, value}}})}}},
      // No contact: a flat far below (a scene has an obstacle).
      {"obstacles",
       json::array({{{"name", "far"}, {"shape", {{"type", "segment"}, {"from", {100, -50}}, {"to", {-100, -50}}}}}})},
      {"steps", 2}};
}

const RigidHubs& hubs_of(const Solved& s) { return dynamic_cast<const RigidHubs&>(*s.scene.problem.body); }

double hub_angle(const Solved& s) { return s.run.steps.back().state.q[hubs_of(s).hub_dof(0, 2)]; }

// The moment on the hub about the centre: the internal forces' on its angle.
double hub_moment(const Solved& s) {
  const RigidHubs& body = hubs_of(s);
  const Vector& q = s.run.steps.back().state.q;
  Vector f = Vector::Zero(q.size());
  body.internal_force(q, f, nullptr);
  return f[body.hub_dof(0, 2)];
}

// The rim's reaction moment about the centre (its nodes stay at their reference positions).
double rim_moment(const Solved& s) {
  const Problem& p = s.scene.problem;
  const RigidHubs& body = hubs_of(s);
  const StepRecord& rec = s.run.steps.back();
  double m = 0;
  for (const Constraint& c : p.constraints) {
    if (c.dof >= body.hub_dof(0, 0)) continue;
    const Vec2 x = body.node_position(rec.state.q, body.dof_node(c.dof));
    const bool along_x = body.rigid_translation(Vec2::UnitX())[c.dof] != 0;
    m += along_x ? -x.y() * rec.reactions[c.dof] : x.x() * rec.reactions[c.dof];
  }
  return m;
}

TEST(RigidHub, AnnulusTurnsByTheRingsTorsionAngle) {
  const double M = 1000, mu = kYoung / (2 * (1 + kPoisson));
  const double exact = M / (4 * std::numbers::pi * mu) * (1 / (kA * kA) - 1 / (kB * kB));
  const Solved s = testing::solve_scene(annulus("linear", "moment", M));
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const double angle = hub_angle(s);
  std::printf("annulus, linear: hub angle %.9e, closed form %.9e (%.2e), hub moment %.6f, rim %.6f\n", angle, exact,
              angle / exact - 1, hub_moment(s), rim_moment(s));
  EXPECT_NEAR(angle / exact, 1.0, 1e-5);
  EXPECT_NEAR(hub_moment(s), M, 1e-9 * M);
  EXPECT_NEAR(rim_moment(s), -M, 1e-6 * M);
}

TEST(RigidHub, FiniteTurnAndItsMomentAgree) {
  // A turn of 0.2 rad (finite: the hub's nodes on their circles), by angle and by moment.
  const double angle = 0.2;
  const Solved turned = testing::solve_scene(annulus("finite", "angle", angle));
  ASSERT_TRUE(turned.run.completed) << turned.run.reason;
  const double M0 = hub_moment(turned);
  const Solved loaded = testing::solve_scene(annulus("finite", "moment", M0));
  ASSERT_TRUE(loaded.run.completed) << loaded.run.reason;
  // The hub's nodes exactly on the turned circle.
  const RigidHubs& body = hubs_of(loaded);
  const Vector& q = loaded.run.steps.back().state.q;
  const double theta = hub_angle(loaded);
  double off = 0;
  for (int n : body.hubs()[0].nodes) {
    const Vec2 X = body.node_position(Vector::Zero(q.size()), n), x = body.node_position(q, n);
    off = std::max(off, (x - Vec2(std::cos(theta) * X.x() - std::sin(theta) * X.y(),
                                  std::sin(theta) * X.x() + std::cos(theta) * X.y()))
                            .norm());
  }
  // The linear closed form's angle for M0 (finite strain moves it at second order).
  const double mu = kYoung / (2 * (1 + kPoisson));
  const double small = M0 / (4 * std::numbers::pi * mu) * (1 / (kA * kA) - 1 / (kB * kB));
  std::printf(
      "annulus, finite: turned %.6f rad takes %.3f N mm/mm (linear closed form %.6f rad); loaded by it: "
      "%.12f rad (%.2e), rim moment %.6f, hub nodes off their circle %.1e\n",
      angle, M0, small, theta, theta / angle - 1, rim_moment(loaded), off);
  EXPECT_NEAR(theta, angle, 1e-6 * angle);
  EXPECT_NEAR(rim_moment(loaded), -M0, 1e-6 * M0);
  EXPECT_NEAR(rim_moment(turned), -M0, 1e-6 * M0);
  EXPECT_LT(off, 1e-12 * kA);
  EXPECT_GT(std::abs(small / angle - 1), 1e-3);  // finite kinematics shows: not the linear angle
}

TEST(RigidHub, SameAsTheRotationSupportOfItsNodes) {
  // The hub turned by angle and its nodes held by the exact rotation support: one state.
  json j = annulus("finite", "angle", 0.2);
  const Solved hub = testing::solve_scene(j);
  j["body"].erase("hubs");
  j["body"]["supports"].push_back({{"set", "hub"}, {"rotation", {{"about", {0, 0}}, {"angle", 0.2}}}});
  const Solved support = testing::solve_scene(j);
  ASSERT_TRUE(hub.run.completed && support.run.completed);
  const Vector full = hubs_of(hub).expand(hub.run.steps.back().state.q);
  const Vector& other = support.run.steps.back().state.q;
  EXPECT_LT((full - other).lpNorm<Eigen::Infinity>(), 1e-9 * kA);
}

TEST(RigidHub, BadInputNamesTheField) {
  json j = annulus("finite", "angle", 0.1);
  j["body"]["hubs"][0]["moment"] = 5.0;
  EXPECT_THROW(read_scene(j), SceneErrors);
  j = annulus("finite", "angle", 0.1);
  j["body"]["supports"].push_back({{"node", 0}, {"fix", {"x"}}});
  try {
    read_scene(j);
    FAIL() << "a support on a hub node was read";
  } catch (const SceneErrors& e) {
    EXPECT_NE(std::string(e.what()).find("/body/supports"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace grip
