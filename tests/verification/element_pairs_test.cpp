// Element-formulation pairs near incompressibility (docs/algorithm.md#element-formulation-pairs):
// the volumetric locking of each element kind, measured on a problem with no other error
// source, and the scene's refusal of the pairs that lock.
// The problem: a unit block on rollers (bottom held in y, both sides in x) whose top is
// pressed into the wave u_y = -delta cos(pi x) (linear kinematics, plane strain, Hooke's law):
// the wave keeps the volume, so a locking element answers a force that grows with K / G
// where the converged force stays of the shear modulus's size. Measured: the generalized
// force (sum of f_y cos(pi x) over the top) of each kind on 8 x 8 against q9 on 32 x 32; the
// pairs refused are those that lock, and the scenes that ask for them are refused with the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "solver/elements/continuum.hpp"
#include "solver/elements/element_pairs.hpp"
#include "solver/io/scene.hpp"
#include "tests/support/newton_driver.hpp"

namespace grip {
namespace {

double wave_force(ContinuumElement element, int n, double poisson) {
  RectangleSpec spec;
  spec.nx = spec.ny = n;
  PlaneMesh mesh = rectangle_mesh(spec, element_shape(element));
  const std::vector<int> top = mesh.sets.at("top");
  ContinuumBody body(mesh, mesh.sets.at("bottom"),
                     {std::make_shared<HookeMaterial>(1.0, poisson, PlaneAnalysis::plane_strain)},
                     {element, ContinuumKinematics::linear, PlaneAnalysis::plane_strain, 1.0});
  std::vector<char> held(body.dof_count(), 0);
  for (int k : mesh.sets.at("bottom")) held[2 * k + 1] = 1;
  for (int k : top) held[2 * k + 1] = 1;
  for (const char* side : {"left", "right"})
    for (int k : mesh.sets.at(side)) held[2 * k] = 1;
  testing::Driver d(body, held);
  d.solve(
      [&](Vector& q) {
        for (int k : top) q[2 * k + 1] = -0.01 * std::cos(M_PI * mesh.nodes[k].x());
      },
      1e-12);
  const Vector f = d.force(nullptr);
  double force = 0.0;
  for (int k : top) force -= f[2 * k + 1] * std::cos(M_PI * mesh.nodes[k].x());
  return force;
}

double poisson_of(double bulk_over_shear) { return (3 * bulk_over_shear - 2) / (2 * (3 * bulk_over_shear + 1)); }

TEST(ElementPairs, PlainQ4AndT3LockWhereTheOthersDoNot) {
  const std::vector<ContinuumElement> kinds = {ContinuumElement::t3, ContinuumElement::q4, ContinuumElement::q4_bbar,
                                               ContinuumElement::t6, ContinuumElement::q8, ContinuumElement::q9};
  std::printf("%-8s %-8s", "nu", "K/G");
  for (ContinuumElement e : kinds) std::printf(" %9s", std::string(element_name(e)).c_str());
  std::printf("   (force on 8 x 8 / q9 on 32 x 32 - 1, %%)\n");
  std::map<double, std::map<ContinuumElement, double>> error;  // by K / G
  for (double ratio : {2.17, 9.67, kLockingBulkOverShear, 49.7, 499.7, 4999.7}) {
    const double nu = poisson_of(ratio), reference = wave_force(ContinuumElement::q9, 32, nu);
    std::printf("%-8.4f %-8.1f", nu, ratio);
    for (ContinuumElement e : kinds) {
      error[ratio][e] = wave_force(e, 8, nu) / reference - 1;
      std::printf(" %+9.2f", 100 * error[ratio][e]);
    }
    std::printf("\n");
  }
  // Below the refusal threshold the plain q4 is within a few per cent; above it, it locks.
  EXPECT_LT(std::abs(error[9.67][ContinuumElement::q4]), 0.03);
  EXPECT_GT(error[kLockingBulkOverShear][ContinuumElement::q4], 0.02);
  EXPECT_GT(error[49.7][ContinuumElement::q4], 0.10);
  EXPECT_GT(error[49.7][ContinuumElement::t3], 0.25);
  EXPECT_GT(error[4999.7][ContinuumElement::q4], 5.0);
  // The accepted pairs stay within a few per cent at any K / G.
  for (ContinuumElement e :
       {ContinuumElement::q4_bbar, ContinuumElement::t6, ContinuumElement::q8, ContinuumElement::q9})
    for (const auto& [ratio, by_kind] : error)
      EXPECT_LT(std::abs(by_kind.at(e)), 0.04) << element_name(e) << " " << ratio;
}

// The pointer and the detail of a scene's first issue; "(read)" if it reads.
std::pair<std::string, std::string> refusal(const nlohmann::json& j) {
  try {
    read_scene(j);
  } catch (const SceneErrors& e) {
    if (!e.issues().empty()) return {e.issues()[0].pointer, e.issues()[0].detail};
  }
  return {"(read)", ""};
}

TEST(ElementPairs, SceneRefusesThePairsThatLock) {
  const nlohmann::json base = nlohmann::json::parse(R"({
    "body": {
      "model": "continuum", "kinematics": "linear", "element": "q4",
      "material": {"young": 250, "poisson": 0.3},
      "mesh": {"rectangle": {"size": [4, 1], "divisions": [4, 2]}},
      "supports": [{"set": "top", "fix": ["x", "y"], "values": {"y": -0.01}}]
    },
    "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [10, 0], "to": [-10, 0]}}]
  })");
  struct Case {
    const char* name;
    nlohmann::json edit;       // merged into body
    const char* refused_with;  // a part of the reason; nullptr: the scene reads
  };
  const nlohmann::json rubber = {{"law", "mooney_rivlin"}, {"c10", 0.4}, {"c01", 0.1}, {"bulk", 1e4}};
  const nlohmann::json metal = {{"law", "j2_plasticity"}, {"young", 1000}, {"poisson", 0.3}, {"yield_stress", 1}};
  const std::vector<Case> cases = {
      {"q4 nu 0.47", {{"material", {{"young", 250}, {"poisson", 0.47}}}}, nullptr},
      {"q4 nu 0.49", {{"material", {{"young", 250}, {"poisson", 0.49}}}}, "use q4_bbar"},
      {"t3 nu 0.49", {{"element", "t3"}, {"material", {{"young", 250}, {"poisson", 0.49}}}}, "\"t3\" is refused"},
      {"q4_bbar nu 0.4999", {{"element", "q4_bbar"}, {"material", {{"young", 250}, {"poisson", 0.4999}}}}, nullptr},
      {"q9 nu 0.4999", {{"element", "q9"}, {"material", {{"young", 250}, {"poisson", 0.4999}}}}, nullptr},
      {"q4 plane stress nu 0.4999",
       {{"analysis", "plane_stress"}, {"material", {{"young", 250}, {"poisson", 0.4999}}}},
       nullptr},
      {"q4 axisymmetric nu 0.49",
       {{"analysis", "axisymmetric"}, {"material", {{"young", 250}, {"poisson", 0.49}}}},
       "use t6, q8 or q9"},
      {"finite q4 rubber", {{"kinematics", "finite"}, {"material", rubber}}, "\"f_bar\""},
      {"finite q4 f_bar rubber",
       {{"kinematics", "finite"}, {"incompressibility", "f_bar"}, {"material", rubber}},
       nullptr},
      {"q4 j2", {{"material", metal}}, "plastic flow keeps the volume"},
      {"q4_bbar j2", {{"element", "q4_bbar"}, {"material", metal}}, nullptr},
      {"q4 plane stress j2", {{"analysis", "plane_stress"}, {"material", metal}}, nullptr},
  };
  for (const Case& c : cases) {
    nlohmann::json j = base;
    j["body"].update(c.edit);
    const auto [pointer, detail] = refusal(j);
    if (!c.refused_with) {
      EXPECT_EQ(pointer, "(read)") << c.name << ": " << detail;
    } else {
      EXPECT_EQ(pointer, "/body/element") << c.name << ": " << detail;
      EXPECT_NE(detail.find(c.refused_with), std::string::npos) << c.name << ": " << detail;
    }
  }
}

}  // namespace
}  // namespace grip
