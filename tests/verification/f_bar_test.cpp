// F-bar (docs/algorithm.md#f-bar), q4, finite kinematics, plane strain:
// - a homogeneous deformation is seen unchanged (J0 = J at every point): the same internal
//   force as the plain element;
// - the tangent against central differences of the internal force, and its symmetry (the
//   element's energy is sum W(F_bar) dV);
// - Cook's membrane and a cantilever at nu = 0.4999: tests/verification/locking_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "solver/elements/continuum.hpp"
#include "solver/io/scene.hpp"
#include "tests/support/tangent_check.hpp"

namespace grip {
namespace {

std::shared_ptr<const PlaneMaterial> rubber(double poisson) {
  return std::make_shared<NeoHookeMaterial>(250.0, poisson, PlaneAnalysis::plane_strain);
}

ContinuumBody body_of(PlaneMesh mesh, ContinuumElement element, Incompressibility inc, double poisson) {
  const std::vector<int> contact = mesh.sets.at("bottom");
  return ContinuumBody(std::move(mesh), contact, {rubber(poisson)},
                       {element, ContinuumKinematics::finite, PlaneAnalysis::plane_strain, 1.0, inc});
}

PlaneMesh distorted_block() {
  RectangleSpec spec;
  spec.size = {3.0, 2.0};
  spec.nx = 3;
  spec.ny = 2;
  PlaneMesh mesh = rectangle_mesh(spec, ElementShape::q4);
  for (size_t k = 0; k < mesh.nodes.size(); ++k) mesh.nodes[k] += 0.15 * Vec2(std::sin(1.3 * k), std::cos(2.1 * k));
  return mesh;
}

TEST(FBar, HomogeneousDeformationIsSeenUnchanged) {
  const PlaneMesh mesh = distorted_block();
  const ContinuumBody plain = body_of(mesh, ContinuumElement::q4, Incompressibility::none, 0.45);
  const ContinuumBody f_bar = body_of(mesh, ContinuumElement::q4, Incompressibility::f_bar, 0.45);
  Mat2 G;
  G << 0.05, 0.02, -0.03, -0.04;
  Vector q(plain.dof_count());
  for (int k = 0; k < plain.node_count(); ++k) q.segment<2>(2 * k) = G * mesh.nodes[k];
  Vector a = Vector::Zero(q.size()), b = Vector::Zero(q.size());
  plain.internal_force(q, a, nullptr);
  f_bar.internal_force(q, b, nullptr);
  EXPECT_LT((a - b).norm(), 1e-12 * a.norm());
}

TEST(FBar, TangentMatchesDifferencesAndIsSymmetric) {
  for (double poisson : {0.3, 0.4999}) {
    const PlaneMesh mesh = distorted_block();
    const ContinuumBody body = body_of(mesh, ContinuumElement::q4, Incompressibility::f_bar, poisson);
    Vector q(body.dof_count());
    for (int i = 0; i < q.size(); ++i) q[i] = 0.05 * std::sin(0.7 + 2.3 * i);
    const auto c = testing::check_tangent(body, q, 1e-6);
    EXPECT_LT(c.error(), 1e-7) << "nu " << poisson;
    EXPECT_LT(c.asymmetry(), 1e-12) << "nu " << poisson;
  }
}

}  // namespace
}  // namespace grip

namespace grip {
namespace {

std::string refused_at(const nlohmann::json& j) {
  try {
    read_scene(j);
  } catch (const SceneErrors& e) {
    return e.issues().empty() ? "" : e.issues()[0].pointer;
  }
  return "(read)";
}

TEST(FBar, SceneNamesItAndRefusesWhatItDoesNotCover) {
  nlohmann::json j = nlohmann::json::parse(R"({
    "body": {
      "model": "continuum", "kinematics": "finite", "element": "q4", "incompressibility": "f_bar",
      "material": {"young": 250, "poisson": 0.4999},
      "mesh": {"rectangle": {"size": [4, 1], "divisions": [4, 2]}},
      "supports": [{"set": "top", "fix": ["x", "y"], "values": {"y": -0.01}}]
    },
    "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [10, 0], "to": [-10, 0]}}]
  })");
  EXPECT_EQ(refused_at(j), "(read)");
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"kinematics", "linear"}, {"element", "q9"}, {"analysis", "plane_stress"}}) {
    nlohmann::json bad = j;
    bad["body"][key] = value;
    EXPECT_EQ(refused_at(bad), "/body/incompressibility") << key;
  }
  j["body"]["incompressibility"] = "mixed";
  EXPECT_EQ(refused_at(j), "/body/incompressibility");
}

}  // namespace
}  // namespace grip
