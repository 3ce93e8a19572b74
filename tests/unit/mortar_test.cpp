// The mortar pairing of two deformable surfaces (solver/obstacles/master_surface.*), on the
// flat, non-matching interface of schemas/examples/block-on-foundation.json (the block's
// bottom: 7 sides, the foundation's top: 20, both spanning x in [-5, 5] at y = 0), in the
// reference configuration, with either surface as slave:
// - each slave site's weights sum to 1 and its mortar point lies on the interface (gap 0);
// - slave forces that are a uniform traction's consistent loads (its tributary lengths) put
//   on the master exactly that traction's consistent loads (the master's tributary lengths):
//   what carries a uniform pressure across non-matching meshes (the patch test);
// - the pair's Jacobian puts f on the slave site and -f in all on the master.
#include <gtest/gtest.h>

#include "solver/core/body_set.hpp"
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

TEST(Mortar, TheFinerSlaveHandsTheMasterConsistentLoads) { expect_consistent_loads(example_scene("block-on-foundation")); }

TEST(Mortar, TheCoarserSlaveHandsTheMasterConsistentLoads) {
  json j = example_scene("block-on-foundation");
  j["contacts"][0] = {{"slave", "block.bottom"}, {"master", "foundation.top"}};
  expect_consistent_loads(j);
}

}  // namespace
}  // namespace grip
