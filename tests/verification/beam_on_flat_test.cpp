// A beam clamped at one end and lying on a rigid flat under a uniform load: the contact
// forces and the support reaction carry the load, and no friction arises.
#include <gtest/gtest.h>

#include "solver/elements/timoshenko_beam.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

nlohmann::json beam_on_flat(const std::string& kinematics) {
  nlohmann::json loads = nlohmann::json::array();
  for (int i = 1; i <= 20; ++i) loads.push_back({{"node", i}, {"force", {0, i == 20 ? -0.5 : -1.0}}});
  return {{"body",
           {{"model", "timoshenko_beam"},
            {"kinematics", kinematics},
            {"material", {{"young", 2e5}, {"poisson", 0.3}}},
            {"section", {{"width", 1}, {"depth", 0.5}}},
            {"mesh", {{"length", 10}, {"elements", 20}}},
            {"supports", {{{"node", 0}, {"fix", {"u", "w", "theta"}}}}},
            {"loads", loads}}},
          {"obstacles",
           {{{"name", "flat"},
             {"shape", {{"type", "segment"}, {"from", {12, -0.25}}, {"to", {-2, -0.25}}}},
             {"friction", 0.3}}}},
          {"steps", 4}};
}

TEST(BeamOnFlat, ContactAndSupportCarryTheUniformLoad) {
  for (const std::string kin : {"linear", "von_karman"}) {
    const auto s = testing::solve_scene(beam_on_flat(kin));
    testing::expect_every_step_sound(s);
    ASSERT_TRUE(s.run.completed) << kin;
    for (const StepRecord& rec : s.run.steps) {
      double contact_y = 0.0, friction = 0.0;
      for (size_t i = 0; i < s.scene.problem.candidates.size(); ++i) {
        const auto& c = s.scene.problem.candidates[i];
        contact_y += (rec.p[c.eta] * rec.state.points[i].eta + rec.p[c.xi] * rec.state.points[i].xi).y();
        friction = std::max(friction, std::abs(rec.p[c.xi]));
      }
      const double applied = 19.5 * rec.load_factor;
      const double support = rec.reactions[TimoshenkoBeam::node_dof(0, 1)];
      EXPECT_NEAR(contact_y + support, applied, 1e-8 * applied) << kin;
      // Every free node rests on the flat and carries its own share.
      EXPECT_NEAR(contact_y, applied, 1e-6 * applied) << kin;
      // Zero up to what ||v|| <= tol pins a force to (tangential stiffness x tolerance).
      EXPECT_LT(friction, 1e-6 * applied) << kin;
    }
  }
}

}  // namespace
}  // namespace grip
