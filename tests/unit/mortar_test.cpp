// The mortar pairing of two deformable surfaces (solver/obstacles/master_surface.*), on the
// flat, non-matching interface of schemas/examples/block-on-foundation.json (the block's
// bottom: 7 sides, the foundation's top: 20, both spanning x in [-5, 5] at y = 0), in the
// reference configuration, with either surface as slave:
// - each slave site's weights sum to 1 and its mortar point lies on the interface (gap 0);
// - slave forces that are a uniform traction's consistent loads (its tributary lengths) put
//   on the master exactly that traction's consistent loads (the master's tributary lengths):
//   what carries a uniform pressure across non-matching meshes (the patch test);
// - the pair's Jacobian puts f on the slave site and -f in all on the master;
// - the pair's stiffness (the normal's turn and the mortar weights' redistribution with both
//   bodies' positions, DeformedMaster::force_derivative) is the derivative of its forces T p:
//   against central differences on a curved, sliding interface, with friction.
#include <gtest/gtest.h>

#include <cmath>

#include "solver/equilibrium/equilibrium.hpp"
#include "solver/model/body_set.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

void expect_consistent_loads(const json& scene) {
  const Scene s = read_scene(scene);
  const Problem& problem = s.problem;
  const auto& all = dynamic_cast<const BodySet&>(*problem.body);
  const ObstacleInstance& pair = problem.obstacles.at(0);
  ASSERT_TRUE(pair.master);
  const Vector q0 = Vector::Zero(all.dof_count());
  const DeformedMaster master(all, q0, *pair.master);
  Vector loads = Vector::Zero(all.dof_count());  // T p for p_eta = -D_j at every slave site
  Vec2 normal = Vec2::Zero();                    // the master's outward normal (flat)
  for (int site : pair.slaves) {
    const SurfacePoint sp = all.surface_point(q0, site, 0);
    const MasterPoint mp = master.project(sp.x, site);
    EXPECT_NEAR(mp.projection.gap, 0.0, 1e-12) << "site " << site;
    Vec2 on_master = Vec2::Zero();
    for (const auto& j : mp.jacobian) on_master += j.dx;  // -sum_k w_k (times I)
    EXPECT_NEAR(on_master.x(), -1.0, 1e-12) << "site " << site;
    normal = mp.projection.normal;
    const Vec2 f = all.tributary_area(site) * normal;  // pressing on the slave
    for (const auto& j : sp.jacobian) loads[j.dof] += j.dx.dot(f);
    for (const auto& j : mp.jacobian) loads[j.dof] += j.dx.dot(f);
  }
  const int b = pair.master->body;
  double total = 0.0;
  for (int site = all.site_offset(b); site < all.site_offset(b + 1); ++site) {
    const SurfacePoint sp = all.surface_point(q0, site, 0);
    Vec2 force = Vec2::Zero();
    for (const auto& j : sp.jacobian) force += loads[j.dof] * j.dx;
    EXPECT_NEAR(force.dot(normal), -all.tributary_area(site), 1e-12) << "master site " << site;
    EXPECT_NEAR(force.dot(rot90(normal)), 0.0, 1e-12) << "master site " << site;
    total += force.dot(normal);
  }
  EXPECT_NEAR(std::abs(normal.y()), 1.0, 1e-15);
  EXPECT_NEAR(total, -10.0, 1e-12);
}

TEST(Mortar, TheFinerSlaveHandsTheMasterConsistentLoads) {
  expect_consistent_loads(example_scene("block-on-foundation"));
}

TEST(Mortar, TheCoarserSlaveHandsTheMasterConsistentLoads) {
  json j = example_scene("block-on-foundation");
  j["contacts"][0] = {{"slave", "block.bottom"}, {"master", "foundation.top"}};
  expect_consistent_loads(j);
}

// The contact forces T(q) p on every dof (no loads are set: F = 0).
Vector pair_forces(const Equilibrium& eq, const Vector& q, const Vector& p) {
  return eq.applied_forces(eq.evaluate(q), p);
}

void expect_stiffness_is_the_derivative(json scene) {
  scene["contacts"][0]["friction"] = 0.3;
  const Scene s = read_scene(scene);
  const Problem& problem = s.problem;
  const auto& all = dynamic_cast<const BodySet&>(*problem.body);
  const int n = all.dof_count();
  // Both surfaces curved and the block slid 0.13 mm along the foundation (element sides
  // 0.5 and 1.43 mm): the weights, the normals and the node-to-segment ends all move.
  Vector q = Vector::Zero(n);
  const Vector q0 = Vector::Zero(n);
  for (int site = 0; site < all.site_count(); ++site) {
    const SurfacePoint sp = all.surface_point(q0, site, 0);
    const double x = sp.x.x();
    const Vec2 u = all.body_of_site(site) == 0
                       ? Vec2(0.13 + 0.02 * std::sin(x), -0.01 + 0.03 * std::cos(0.4 * x))
                       : Vec2(0.01 * std::cos(x), 0.02 * std::cos(0.4 * x) + 0.005 * std::sin(2 * x));
    for (const auto& j : sp.jacobian) q[j.dof] = j.dx.dot(u);
  }
  Equilibrium eq(problem, NewtonParams{});
  Vector p = Vector::Zero(problem.component_count);
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    p[c.eta] = -(1.0 + 0.1 * i);
    ASSERT_GE(c.xi, 0);
    p[c.xi] = i % 2 ? 0.3 : -0.2;
  }
  Triplets triplets, internal;  // the residual's tangent holds -d(T p)/dq beside the body's
  eq.residual(q, p, &triplets);
  Vector ignored = Vector::Zero(n);
  TripletSink sink(internal);
  all.internal_force(q, ignored, &sink);
  Eigen::SparseMatrix<double> tangent(n, n), body(n, n);
  tangent.setFromTriplets(triplets.begin(), triplets.end());
  body.setFromTriplets(internal.begin(), internal.end());
  const Matrix analytic = -Matrix(tangent - body);  // d(T p)/dq
  // Central differences: the forces are smooth in q away from the pairing's switches (a
  // master site's projection crossing a slave segment's end), which a step of 1e-7 mm misses;
  // truncation (h / element)^2 ~ 1e-13 and round-off eps |T p| / h ~ 1e-9 of the entries.
  const double h = 1e-7;
  Matrix numeric = Matrix::Zero(n, n);
  for (int k = 0; k < n; ++k) {
    Vector plus = q, minus = q;
    plus[k] += h;
    minus[k] -= h;
    numeric.col(k) = (pair_forces(eq, plus, p) - pair_forces(eq, minus, p)) / (2 * h);
  }
  const double scale = numeric.cwiseAbs().maxCoeff();
  // The pair's stiffness is that of forces ~1 N turning and moving over element sides ~1 mm.
  EXPECT_GT(scale, 0.1);
  EXPECT_LT((analytic - numeric).cwiseAbs().maxCoeff(), 1e-6 * scale);
}

TEST(Mortar, TheStiffnessOfAFinerSlaveIsTheDerivativeOfItsForces) {
  expect_stiffness_is_the_derivative(example_scene("block-on-foundation"));
}

TEST(Mortar, TheStiffnessOfACoarserSlaveIsTheDerivativeOfItsForces) {
  json j = example_scene("block-on-foundation");
  j["contacts"][0] = {{"slave", "block.bottom"}, {"master", "foundation.top"}};
  expect_stiffness_is_the_derivative(j);
}

// A beam's lower surface as the master (its sites: the axis offset by half the depth, moved by
// the rotation dof too) over a q4 foundation's top as the slave. The beam's surface point is
// linear in q (x + u + z theta, y + z + w: Body::surface_point), so its Jacobian is constant and
// the pair's stiffness needs no curvature term of its own: the derivative test holds as for two
// continua.
TEST(Mortar, TheStiffnessOfABeamMasterIsTheDerivativeOfItsForces) {
  const json beam = {{"name", "beam"},
                     {"model", "timoshenko_beam"},
                     {"kinematics", "linear"},
                     {"material", {{"young", 200000}, {"poisson", 0.3}}},
                     {"section", {{"width", 1}, {"depth", 1}}},
                     {"mesh", {{"origin", {-5, 0.5}}, {"length", 10}, {"elements", 20}}},
                     {"supports", {{{"node", 10}, {"fix", {"u", "w"}}}}}};
  const json foundation = {{"name", "foundation"},
                           {"model", "continuum"},
                           {"kinematics", "linear"},
                           {"analysis", "plane_strain"},
                           {"element", "q4"},
                           {"material", {{"young", 70000}, {"poisson", 0.33}}},
                           {"mesh", {{"rectangle", {{"origin", {-5, -4}}, {"size", {10, 4}}, {"divisions", {13, 4}}}}}},
                           {"contact_set", "top"},
                           {"supports", {{{"set", "left"}, {"fix", {"x"}}}, {{"set", "bottom"}, {"fix", {"y"}}}}}};
  expect_stiffness_is_the_derivative({{"bodies", {beam, foundation}},
                                      {"contacts", {{{"slave", "foundation.top"}, {"master", "beam.lower"}}}},
                                      {"steps", 1}});
}

}  // namespace
}  // namespace grip
