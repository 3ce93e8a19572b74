// A beam on a deformable foundation (issue 19) at its harder end: slender (10 mm long, 0.1 mm
// deep: L / d = 100, 200 elements), on a foundation 2000 x softer than the beam (E 100 MPa,
// 67 x 8 q4, not matching the beam), the foundation's top the slave. The beam has no support
// but its axial dof at the middle node: contact holds its translation and rotation
// (docs/algorithm.md#bodies-held-only-by-contact). Closed form: a uniform load on a straight beam
// over a uniformly compressed foundation is a uniform pressure, away from the foundation's free
// right end, which stretches nu (1 + nu) sigma / E L = 0.044 mm beyond the beam's end and unloads
// over about the beam's length on its bed, (4 EI / k)^(1/4) = 1.3 mm with k = E / 4 mm.
//
// With the beam as slave (its 201 nodes on the foundation's 67 segments) node-to-segment does
// not pass this patch test: the straight, 2000 x stiffer beam meets the faceted surface at every
// third node only where the facets kink, and the nodal pressure oscillates with the segments'
// period (every third node open toward the right end, up to 2.4 x the mean), while the
// resultant is right. So the softer body is the slave here (README, two deformable bodies).
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/support/held.hpp"
#include "tests/support/two_bodies.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

constexpr int kElements = 200;
constexpr double kLength = 10.0, kDepth = 0.1, kLoad = 1.0;  // mm, mm, N/mm

json slender_beam_on_soft_foundation() {
  json loads = json::array();
  for (int n = 0; n <= kElements; ++n) {
    const double f = kLoad * kLength / kElements * (n == 0 || n == kElements ? 0.5 : 1.0);
    loads.push_back({{"node", n}, {"force", {0.0, -f}}});
  }
  const json beam = {{"name", "beam"},
                     {"model", "timoshenko_beam"},
                     {"kinematics", "linear"},
                     {"material", {{"young", 200000}, {"poisson", 0.3}}},
                     {"section", {{"width", 1}, {"depth", kDepth}}},
                     {"mesh", {{"origin", {-kLength / 2, kDepth / 2}}, {"length", kLength}, {"elements", kElements}}},
                     {"supports", {{{"node", kElements / 2}, {"fix", {"u"}}}}},
                     {"loads", loads}};
  const json foundation = {
      {"name", "foundation"},
      {"model", "continuum"},
      {"kinematics", "linear"},
      {"analysis", "plane_strain"},
      {"element", "q4"},
      {"material", {{"young", 100}, {"poisson", 0.33}}},
      {"mesh", {{"rectangle", {{"origin", {-kLength / 2, -4}}, {"size", {kLength, 4}}, {"divisions", {67, 8}}}}}},
      {"contact_set", "top"},
      {"supports", {{{"set", "left"}, {"fix", {"x"}}}, {{"set", "bottom"}, {"fix", {"y"}}}}}};
  return {{"bodies", {beam, foundation}},
          {"contacts", {{{"slave", "foundation.top"}, {"master", "beam.lower"}}}},
          {"steps", 1},
          {"solver", {{"contact", {{"method", "cev"}, {"tolerance", 1e-8}}}}}};
}

TEST(BeamOnFoundationHard, SlenderBeamOnASoftFoundationPressesUniformly) {
  const Solved s = solve_scene(slender_beam_on_soft_foundation());
  // Held by contact alone, the pair's forces cancel, the contact carries the whole load.
  expect_carried_by_contact(s, {"beam: translate along y", "beam: rotate about (0, 0.05)"}, 0, kLoad * kLength);
  const StepRecord& rec = s.run.steps.back();
  const double edge_zone = 1.5;  // mm from the right end: the beam's length on its bed, 1.3 mm
  double spread = 0.0;
  int pressing = 0, nodes = 0;
  for (const ContactNode& n : contact_profile(s.scene.problem, rec)) {
    ++nodes;
    if (n.p_n < 0) ++pressing;
    if (n.x < kLength / 2 - edge_zone) spread = std::max(spread, std::abs(-n.sigma_n / kLoad - 1));
  }
  std::printf(
      "%d of %d slave nodes press, largest departure from %.0f MPa away from the end %.3f %%; %d real solves, "
      "%d Newton\n",
      pressing, nodes, kLoad, 100 * spread, rec.solves, rec.newton_iterations);
  EXPECT_EQ(nodes, 68);
  EXPECT_EQ(pressing, nodes);
  EXPECT_LT(spread, 0.01);  // the 1 % of the foundation's patch test, as in the friendly case
}

}  // namespace
}  // namespace grip
