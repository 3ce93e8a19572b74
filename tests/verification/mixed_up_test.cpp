// The mixed u-p form (docs/algorithm.md#mixed-u-p) on q9 (linear pressure, Q2/P1) and t6
// (constant pressure, P2/P0), and F-bar on q4 in axisymmetry, finite kinematics:
// - a homogeneous deformation is seen unchanged (the projection of a constant J is J): the same
//   internal force as the plain element, plane strain and axisymmetric;
// - the tangent against central differences of the internal force, and its symmetry (the
//   element's energy is sum W(F_bar) dV), for neo-Hookean and Mooney-Rivlin laws near
//   incompressibility, plane strain and axisymmetric (J2 at finite strain:
//   tests/verification/j2_finite_test.cpp, j2_finite_axisymmetric_test.cpp);
// - the scene names it and refuses the pairs that fail the inf-sup condition at
//   /body/incompressibility, with the reason;
// - the locking table: tests/verification/locking_test.cpp; the O-ring: o_ring_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include "solver/elements/continuum.hpp"
#include "solver/io/scene.hpp"
#include "solver/materials/mooney_rivlin.hpp"
#include "tests/support/tangent_check.hpp"

namespace grip {
namespace {

struct Case {
  const char* name;
  ContinuumElement element;
  Incompressibility incompressibility;
  PlaneAnalysis analysis;
};

const Case kCases[] = {
    {"q9 mixed plane strain", ContinuumElement::q9, Incompressibility::mixed, PlaneAnalysis::plane_strain},
    {"t6 mixed plane strain", ContinuumElement::t6, Incompressibility::mixed, PlaneAnalysis::plane_strain},
    {"q9 mixed axisymmetric", ContinuumElement::q9, Incompressibility::mixed, PlaneAnalysis::axisymmetric},
    {"t6 mixed axisymmetric", ContinuumElement::t6, Incompressibility::mixed, PlaneAnalysis::axisymmetric},
    {"q4 f_bar axisymmetric", ContinuumElement::q4, Incompressibility::f_bar, PlaneAnalysis::axisymmetric},
};

// A 3 x 2 block off the axis (x from 1), its nodes moved so that no element is a parallelogram.
PlaneMesh distorted_block(ElementShape shape) {
  RectangleSpec spec;
  spec.origin = {1.0, 0.0};
  spec.size = {3.0, 2.0};
  spec.nx = 3;
  spec.ny = 2;
  PlaneMesh mesh = rectangle_mesh(spec, shape);
  for (size_t k = 0; k < mesh.nodes.size(); ++k) mesh.nodes[k] += 0.08 * Vec2(std::sin(1.3 * k), std::cos(2.1 * k));
  return mesh;
}

ContinuumBody body_of(const PlaneMesh& mesh, const Case& c, std::shared_ptr<const PlaneMaterial> law,
                      Incompressibility incompressibility) {
  return ContinuumBody(mesh, mesh.sets.at("bottom"), {std::move(law)},
                       {c.element, ContinuumKinematics::finite, c.analysis, 1.0, incompressibility});
}

TEST(MixedUp, HomogeneousDeformationIsSeenUnchanged) {
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.name);
    const PlaneMesh mesh = distorted_block(element_shape(c.element));
    const auto law = std::make_shared<NeoHookeMaterial>(250.0, 0.45, c.analysis);
    const ContinuumBody plain = body_of(mesh, c, law, Incompressibility::none);
    const ContinuumBody mixed = body_of(mesh, c, law, c.incompressibility);
    // u_x = 0.05 x - 0.03 y, u_y = 0.02 x - 0.04 y; in axisymmetry u_r = 0.05 r, u_z = -0.04 z
    // (the hoop stretch 1.05 uniform too).
    Mat2 G;
    if (c.analysis == PlaneAnalysis::axisymmetric) G << 0.05, 0.0, 0.0, -0.04;
    else G << 0.05, -0.03, 0.02, -0.04;
    Vector q(plain.dof_count());
    for (int k = 0; k < plain.node_count(); ++k) q.segment<2>(2 * k) = G * mesh.nodes[k];
    Vector a = Vector::Zero(q.size()), b = Vector::Zero(q.size());
    plain.internal_force(q, a, nullptr);
    mixed.internal_force(q, b, nullptr);
    EXPECT_LT((a - b).norm(), 1e-12 * a.norm());
    // The reported stresses too (the centre sees the same F).
    const FieldTable sa = plain.element_fields(q), sb = mixed.element_fields(q);
    for (size_t e = 0; e < sa.rows.size(); ++e)
      for (size_t k = 0; k < 4; ++k) EXPECT_NEAR(sa.rows[e][k], sb.rows[e][k], 1e-10 * 250);
  }
}

TEST(MixedUp, TangentMatchesDifferencesAndIsSymmetric) {
  for (const Case& c : kCases) {
    const PlaneMesh mesh = distorted_block(element_shape(c.element));
    const std::shared_ptr<const PlaneMaterial> laws[] = {
        std::make_shared<NeoHookeMaterial>(250.0, 0.3, c.analysis),
        std::make_shared<NeoHookeMaterial>(250.0, 0.4999, c.analysis),
        std::make_shared<MooneyRivlinMaterial>(0.4, 0.1, 1e4, c.analysis)};
    for (size_t l = 0; l < 3; ++l) {
      SCOPED_TRACE(std::string(c.name) + ", law " + std::to_string(l));
      const ContinuumBody body = body_of(mesh, c, laws[l], c.incompressibility);
      Vector q(body.dof_count());
      for (int i = 0; i < q.size(); ++i) q[i] = 0.05 * std::sin(0.7 + 2.3 * i);
      const auto check = testing::check_tangent(body, q, 1e-6);
      EXPECT_LT(check.error(), 1e-7);
      EXPECT_LT(check.asymmetry(), 1e-12);
    }
  }
}

// The first issue of a scene that does not read: pointer and detail; empty if it reads.
std::pair<std::string, std::string> refusal(const nlohmann::json& j) {
  try {
    read_scene(j);
  } catch (const SceneErrors& e) {
    return {e.issues().at(0).pointer, e.issues().at(0).detail};
  }
  return {};
}

TEST(MixedUp, SceneNamesItAndRefusesThePairsThatFailInfSup) {
  nlohmann::json j = nlohmann::json::parse(R"({
    "body": {
      "model": "continuum", "kinematics": "finite", "element": "q9", "incompressibility": "mixed",
      "material": {"law": "mooney_rivlin", "c10": 0.4, "c01": 0.1, "bulk": 1e4},
      "mesh": {"rectangle": {"origin": [1, 0], "size": [4, 1], "divisions": [4, 2]}},
      "supports": [{"set": "top", "fix": ["x", "y"], "values": {"y": -0.01}}]
    },
    "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [10, 0], "to": [-10, 0]}}]
  })");
  struct Edit {
    nlohmann::json body;
    const char* refused_with;  // nullptr: the scene reads
  };
  const std::vector<Edit> edits = {
      {{{"element", "q9"}}, nullptr},
      {{{"element", "t6"}}, nullptr},
      {{{"element", "q9"}, {"analysis", "axisymmetric"}}, nullptr},
      {{{"element", "t6"}, {"analysis", "axisymmetric"}}, nullptr},
      {{{"element", "q4"}, {"analysis", "axisymmetric"}, {"incompressibility", "f_bar"}}, nullptr},
      {{{"element", "q8"}}, "fails the inf-sup condition; use q9"},
      {{{"element", "q4"}}, "checkerboard"},
      {{{"element", "t3"}}, "P1/P0) locks"},
      {{{"analysis", "plane_stress"}}, "plane stress does not lock"},
      {{{"kinematics", "linear"}, {"material", {{"young", 250}, {"poisson", 0.3}}}}, "for finite kinematics"},
      {{{"element", "t6"}, {"incompressibility", "f_bar"}}, "use \"mixed\""},
  };
  for (const Edit& e : edits) {
    nlohmann::json scene = j;
    scene["body"].update(e.body);
    const auto [pointer, detail] = refusal(scene);
    if (!e.refused_with) {
      EXPECT_EQ(pointer, "") << e.body << ": " << detail;
    } else {
      EXPECT_EQ(pointer, "/body/incompressibility") << e.body << ": " << detail;
      EXPECT_NE(detail.find(e.refused_with), std::string::npos) << e.body << ": " << detail;
    }
  }
}

}  // namespace
}  // namespace grip
