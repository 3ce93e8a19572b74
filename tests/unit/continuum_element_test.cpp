// Element and material checks of the plane continuum: rigid motions give no force, the
// tangent is the derivative of the force, constant-strain patches are reproduced exactly,
// and the laws agree with Hooke's law at small strain.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <cmath>
#include <numbers>
#include <random>

#include "solver/elements/continuum.hpp"
#include "tests/support/distorted_mesh.hpp"
#include "tests/support/tangent_check.hpp"

namespace grip {
namespace {

struct Variant {
  ContinuumElement element;
  ContinuumKinematics kinematics;
  PlaneAnalysis analysis;
};

std::string name_of(const Variant& v) {
  return std::string(element_name(v.element)) + (v.kinematics == ContinuumKinematics::linear ? "_linear" : "_finite") +
         (v.analysis == PlaneAnalysis::plane_strain ? "_strain" : "_stress");
}

// A 3 x 2 patch of a 2 x 1 rectangle whose interior nodes are moved off the grid (the edges
// stay straight, so that a linear field is representable on the quadratic kinds too).
PlaneMesh distorted_patch(ElementShape shape) {
  RectangleSpec spec;
  spec.size = {2.0, 1.0};
  spec.nx = 3;
  spec.ny = 2;
  return testing::distorted_rectangle(spec, shape, 0.06, 3);
}

std::shared_ptr<const PlaneMaterial> material(PlaneAnalysis analysis, double nu = 0.3) {
  return std::make_shared<NeoHookeMaterial>(1000.0, nu, analysis);
}

ContinuumBody body_of(const Variant& v, double nu = 0.3) {
  const PlaneMesh mesh = distorted_patch(element_shape(v.element));
  ContinuumOptions options{v.element, v.kinematics, v.analysis, 0.5};
  return ContinuumBody(mesh, mesh.sets.at("bottom"), {material(v.analysis, nu)}, options);
}

using testing::assembled_tangent;
using testing::internal_force;

Vector random_state(const Body& body, double size, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> dist(-size, size);
  Vector q(body.dof_count());
  for (int i = 0; i < q.size(); ++i) q[i] = dist(rng);
  return q;
}

// The displacement that moves every node X to R X + d.
Vector rigid_motion(const ContinuumBody& body, double angle, const Vec2& d) {
  const Eigen::Rotation2Dd R(angle);
  Vector q(body.dof_count());
  for (int k = 0; k < body.node_count(); ++k) {
    const Vec2 X = body.mesh().nodes[k];
    q.segment<2>(2 * k) = R * X + d - X;
  }
  return q;
}

// Every variant; the linear ones; the finite ones.
class ContinuumVariants : public ::testing::TestWithParam<Variant> {};
class ContinuumLinear : public ContinuumVariants {};
class ContinuumFinite : public ContinuumVariants {};

TEST_P(ContinuumVariants, RigidTranslationGivesNoForce) {
  const ContinuumBody body = body_of(GetParam());
  const Vector t = body.rigid_translation({0.3, -0.7});
  const Vector q = random_state(body, 0.02, 1);
  const double scale = internal_force(body, q).norm();
  EXPECT_LT(internal_force(body, t).norm(), 1e-12 * scale);
  EXPECT_LT((internal_force(body, q + t) - internal_force(body, q)).norm(), 1e-11 * scale);
}

TEST_P(ContinuumVariants, RigidRotationGivesNoForce) {
  const ContinuumBody body = body_of(GetParam());
  const double scale = internal_force(body, random_state(body, 0.02, 2)).norm();
  if (GetParam().kinematics == ContinuumKinematics::linear) {
    // Infinitesimal rotation: exactly in the kernel of the constant K.
    EXPECT_LT(internal_force(body, 0.01 * body.rigid_rotation()).norm(), 1e-12 * scale);
  } else {
    // A finite rotation (and translation) strains nothing.
    EXPECT_LT(internal_force(body, rigid_motion(body, 0.6, {0.2, 0.1})).norm(), 1e-11 * scale);
  }
}

// Frame indifference of the finite element: rotating a deformed state rotates its forces.
TEST_P(ContinuumFinite, ForceRotatesWithTheBody) {
  const ContinuumBody body = body_of(GetParam());
  const Vector q = random_state(body, 0.05, 3);
  const Eigen::Rotation2Dd R(1.1);
  Vector rotated(q.size());
  for (int k = 0; k < body.node_count(); ++k) {
    const Vec2 X = body.mesh().nodes[k];
    rotated.segment<2>(2 * k) = R * (X + q.segment<2>(2 * k)) - X;
  }
  const Vector f = internal_force(body, q), fr = internal_force(body, rotated);
  double diff = 0.0;
  for (int k = 0; k < body.node_count(); ++k)
    diff = std::max(diff, (fr.segment<2>(2 * k) - R * f.segment<2>(2 * k)).norm());
  EXPECT_LT(diff, 1e-10 * f.norm());
}

TEST_P(ContinuumVariants, TangentEqualsFiniteDifferenceOfForce) {
  const ContinuumBody body = body_of(GetParam());
  const Vector q = random_state(body, 0.05, 4);  // strains of several per cent
  const testing::TangentCheck c = testing::check_tangent(body, q, 1e-6);
  EXPECT_LT(c.error(), 1e-7);
  EXPECT_LT(c.asymmetry(), 1e-12);  // hyperelastic: a potential
}

// Constant strain: with the boundary nodes on a linear field, the interior nodes of a
// distorted patch follow it exactly and every element carries the same stress.
TEST_P(ContinuumLinear, PatchTestIsExact) {
  const ContinuumBody body = body_of(GetParam());
  const Mat2 grad = (Mat2() << 1e-3, 4e-4, -2e-4, -6e-4).finished();
  Vector exact(body.dof_count());
  std::vector<int> interior;
  for (int k = 0; k < body.node_count(); ++k) {
    const Vec2 X = body.mesh().nodes[k];
    exact.segment<2>(2 * k) = grad * X;
    if (X.x() > 1e-9 && X.x() < 2 - 1e-9 && X.y() > 1e-9 && X.y() < 1 - 1e-9) interior.push_back(k);
  }
  ASSERT_FALSE(interior.empty());
  // Solve K_ii u_i = -K_ib u_b for the interior dofs.
  const Matrix K = assembled_tangent(body, Vector::Zero(body.dof_count()));
  std::vector<int> dofs;
  for (int k : interior) dofs.insert(dofs.end(), {2 * k, 2 * k + 1});
  Vector boundary = exact;
  for (int d : dofs) boundary[d] = 0.0;
  const Vector rhs = -(K * boundary);
  Matrix Kii(dofs.size(), dofs.size());
  Vector b(dofs.size());
  for (size_t i = 0; i < dofs.size(); ++i) {
    b[i] = rhs[dofs[i]];
    for (size_t j = 0; j < dofs.size(); ++j) Kii(i, j) = K(dofs[i], dofs[j]);
  }
  const Vector ui = Kii.ldlt().solve(b);
  for (size_t i = 0; i < dofs.size(); ++i) EXPECT_NEAR(ui[i], exact[dofs[i]], 1e-12);
  // Uniform stress, equal to Hooke's law on the strain.
  const Eigen::Vector3d eps(grad(0, 0), grad(1, 1), grad(0, 1) + grad(1, 0));
  const MaterialResponse hooke = material(GetParam().analysis)->small_strain();
  const Eigen::Vector3d s = hooke.D * eps;
  for (int e = 0; e < body.element_count(); ++e) {
    const Eigen::Vector4d c = body.centroid_stress(exact, e);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(c[i], s[i], 1e-10 * s.norm());
    EXPECT_NEAR(c[3], hooke.dS33 * eps, 1e-10 * s.norm());
  }
}

// A homogeneous finite deformation is in equilibrium without interior forces, and every
// element reports the Cauchy stress of the law at that deformation.
TEST_P(ContinuumFinite, HomogeneousDeformationIsExact) {
  const ContinuumBody body = body_of(GetParam());
  const Mat2 F = (Mat2() << 1.15, 0.2, -0.1, 0.85).finished();
  Vector q(body.dof_count());
  for (int k = 0; k < body.node_count(); ++k) q.segment<2>(2 * k) = (F - Mat2::Identity()) * body.mesh().nodes[k];
  const Vector f = internal_force(body, q);
  for (int k = 0; k < body.node_count(); ++k) {
    const Vec2 X = body.mesh().nodes[k];
    if (X.x() > 1e-9 && X.x() < 2 - 1e-9 && X.y() > 1e-9 && X.y() < 1 - 1e-9)
      EXPECT_LT(f.segment<2>(2 * k).norm(), 1e-10 * f.norm()) << "interior node " << k;
  }
  const Eigen::Vector4d expected =
      cauchy_stress(F, material(GetParam().analysis)->response(0.5 * (F.transpose() * F - Mat2::Identity())));
  for (int e = 0; e < body.element_count(); ++e)
    EXPECT_LT((body.centroid_stress(q, e) - expected).norm(), 1e-10 * expected.norm());
}

// Small loads: linear and finite kinematics give the same forces to first order.
TEST_P(ContinuumFinite, AgreesWithLinearForSmallStrain) {
  Variant lin = GetParam(), fin = GetParam();
  lin.kinematics = ContinuumKinematics::linear;
  fin.kinematics = ContinuumKinematics::finite;
  const ContinuumBody a = body_of(lin), b = body_of(fin);
  for (const double size : {1e-3, 1e-5}) {
    const Vector q = random_state(a, size, 5);
    const Vector fa = internal_force(a, q), fb = internal_force(b, q);
    // The difference is second order: relative size ~ strain.
    EXPECT_LT((fa - fb).norm(), 20 * size * fa.norm()) << size;
  }
}

// Newton's linearized stress (docs/algorithm.md#newtons-tangent-the-linearized-stress): the
// tangent about a stress base b differs from the exact one only by the geometric stiffness of
// the stress of -H^T H / 2, H the gradient of q - b: not at all where b = q, and by exactly a
// quarter where q - b halves for Saint Venant-Kirchhoff (its stress is linear in E); symmetric,
// and the force stays the exact one.
TEST_P(ContinuumFinite, LinearizedStressChangesTheTangentAtSecondOrder) {
  const Variant v = GetParam();
  const PlaneMesh mesh = distorted_patch(element_shape(v.element));
  const ContinuumBody body(mesh, mesh.sets.at("bottom"), {std::make_shared<HookeMaterial>(1000.0, 0.3, v.analysis)},
                           ContinuumOptions{v.element, v.kinematics, v.analysis, 0.5});
  const Vector q = random_state(body, 0.05, 6), d = random_state(body, 0.05, 7);
  Vector f, f_base;
  const Matrix K = assembled_tangent(body, q, f);
  EXPECT_EQ(assembled_tangent(body, q, f_base, &q), K);
  const Vector far = q - d, near = q - 0.5 * d;
  const Matrix change = assembled_tangent(body, q, f_base, &far) - K;
  EXPECT_EQ(f_base, f);
  const Matrix quarter = assembled_tangent(body, q, f_base, &near) - K;
  EXPECT_GT(change.norm(), 1e-4 * K.norm());
  EXPECT_LT((change - 4 * quarter).norm(), 1e-10 * change.norm());
  EXPECT_LT((change - change.transpose()).norm(), 1e-12 * change.norm());
}

// t3, t6, q4, q8 and q9 in both analyses and kinematics; q4_bbar (linear plane strain only).
std::vector<Variant> variants(bool linear, bool finite) {
  std::vector<Variant> v;
  for (auto a : {PlaneAnalysis::plane_strain, PlaneAnalysis::plane_stress})
    for (auto k : {ContinuumKinematics::linear, ContinuumKinematics::finite}) {
      if (!(k == ContinuumKinematics::linear ? linear : finite)) continue;
      for (auto e : {ContinuumElement::t3, ContinuumElement::t6, ContinuumElement::q4, ContinuumElement::q8,
                     ContinuumElement::q9})
        v.push_back({e, k, a});
    }
  if (linear) v.push_back({ContinuumElement::q4_bbar, ContinuumKinematics::linear, PlaneAnalysis::plane_strain});
  return v;
}

auto variant_name = [](const auto& info) { return name_of(info.param); };
INSTANTIATE_TEST_SUITE_P(Elements, ContinuumVariants, ::testing::ValuesIn(variants(true, true)), variant_name);
INSTANTIATE_TEST_SUITE_P(Elements, ContinuumLinear, ::testing::ValuesIn(variants(true, false)), variant_name);
INSTANTIATE_TEST_SUITE_P(Elements, ContinuumFinite, ::testing::ValuesIn(variants(false, true)), variant_name);

// ---- materials

Mat2 random_strain(unsigned seed, double size) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> dist(-size, size);
  const double a = dist(rng), b = dist(rng), c = dist(rng);
  return (Mat2() << a, c, c, b).finished();
}

TEST(PlaneMaterial, LawsReduceToHookeAtSmallStrain) {
  const double E = 210.0, nu = 0.3;
  const Lame l = Lame::from(E, nu);
  for (auto analysis : {PlaneAnalysis::plane_strain, PlaneAnalysis::plane_stress}) {
    Eigen::Matrix3d D;
    if (analysis == PlaneAnalysis::plane_strain)
      D << l.lambda + 2 * l.mu, l.lambda, 0, l.lambda, l.lambda + 2 * l.mu, 0, 0, 0, l.mu;
    else
      D << E / (1 - nu * nu), E * nu / (1 - nu * nu), 0, E * nu / (1 - nu * nu), E / (1 - nu * nu), 0, 0, 0,
          E / (2 * (1 + nu));
    const NeoHookeMaterial neo(E, nu, analysis);
    const HookeMaterial hooke(E, nu, analysis);
    EXPECT_LT((neo.small_strain().D - D).norm(), 1e-12 * D.norm());
    EXPECT_LT((hooke.small_strain().D - D).norm(), 1e-12 * D.norm());
    EXPECT_LT((neo.small_strain().dS33 - hooke.small_strain().dS33).norm(), 1e-12 * D.norm());
  }
}

TEST(PlaneMaterial, TangentIsTheDerivativeOfTheStress) {
  for (auto analysis : {PlaneAnalysis::plane_strain, PlaneAnalysis::plane_stress}) {
    const NeoHookeMaterial neo(210.0, 0.45, analysis);
    const HookeMaterial hooke(210.0, 0.45, analysis);
    for (const PlaneMaterial* law :
         {static_cast<const PlaneMaterial*>(&neo), static_cast<const PlaneMaterial*>(&hooke)}) {
      const Mat2 E = random_strain(11, 0.15);
      const MaterialResponse r = law->response(E);
      const double h = 1e-7;
      for (int j = 0; j < 3; ++j) {
        Mat2 dE = Mat2::Zero();
        if (j < 2) dE(j, j) = h;
        else dE(0, 1) = dE(1, 0) = h / 2;  // engineering shear 2 E12 = h
        const MaterialResponse p = law->response(E + dE), m = law->response(E - dE);
        EXPECT_LT(((p.S - m.S) / (2 * h) - r.D.col(j)).norm(), 1e-6 * r.D.norm());
        EXPECT_NEAR((p.S33 - m.S33) / (2 * h), r.dS33[j], 1e-6 * r.D.norm());
      }
      EXPECT_LT((r.D - r.D.transpose()).norm(), 1e-12 * r.D.norm());
    }
  }
}

// Plane stress condenses the 3D neo-Hookean law: with its C33 the 3D S33 vanishes and the
// in-plane stress is the 3D one.
TEST(PlaneMaterial, NeoHookePlaneStressHasNoOutOfPlaneStress) {
  const double E = 210.0, nu = 0.35;
  const Lame l = Lame::from(E, nu);
  const NeoHookeMaterial neo(E, nu, PlaneAnalysis::plane_stress);
  for (unsigned seed : {1u, 2u, 3u}) {
    const Mat2 E2 = random_strain(seed, 0.3);
    const MaterialResponse r = neo.response(E2);
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    C.topLeftCorner<2, 2>() = Mat2::Identity() + 2 * E2;
    C(2, 2) = r.C33;
    const double lnJ = 0.5 * std::log(C.determinant());
    const Eigen::Matrix3d S = l.mu * (Eigen::Matrix3d::Identity() - C.inverse()) + l.lambda * lnJ * C.inverse();
    EXPECT_LT(std::abs(S(2, 2)), 1e-12 * S.norm());
    EXPECT_LT((Eigen::Vector3d(S(0, 0), S(1, 1), S(0, 1)) - r.S).norm(), 1e-12 * S.norm());
    EXPECT_EQ(r.S33, 0.0);
  }
}

// Nearly incompressible plane strain: q4 locks, q4_bbar and q9 do not. A cantilever of
// 10 x 1 under an end shear: the tip deflection of beam theory with shear,
// P L^3 / (3 E' I) + P L / (k G A), E' = E / (1 - nu^2).
TEST(ContinuumLocking, MeanDilatationAndNineNodesDoNotLock) {
  const double E = 1000.0, nu = 0.4999, L = 10.0, H = 1.0, P = 0.01;
  const double Ep = E / (1 - nu * nu), I = H * H * H / 12, G = E / (2 * (1 + nu));
  const double expected = P * L * L * L / (3 * Ep * I) + P * L / (5.0 / 6.0 * G * H);
  auto tip = [&](ContinuumElement element, int nx, int ny) {
    RectangleSpec spec;
    spec.size = {L, H};
    spec.nx = nx;
    spec.ny = ny;
    const PlaneMesh mesh = rectangle_mesh(spec, element_shape(element));
    ContinuumOptions options{element, ContinuumKinematics::linear, PlaneAnalysis::plane_strain, 1.0};
    const ContinuumBody body(mesh, mesh.sets.at("bottom"), {material(PlaneAnalysis::plane_strain, nu)}, options);
    const Matrix K = assembled_tangent(body, Vector::Zero(body.dof_count()));
    // Clamp the left end; shear the right end by a parabolic traction (consistent loads).
    std::vector<char> fixed(body.dof_count(), 0);
    for (int k : mesh.sets.at("left")) fixed[2 * k] = fixed[2 * k + 1] = 1;
    const BoundaryPart right = boundary_part(mesh, element_shape(element), mesh.sets.at("right"));
    Vector f = Vector::Zero(body.dof_count());
    for (size_t k = 0; k < right.nodes.size(); ++k) f[2 * right.nodes[k] + 1] = -P / H * right.lengths[k];
    std::vector<int> free;
    for (int i = 0; i < body.dof_count(); ++i)
      if (!fixed[i]) free.push_back(i);
    Matrix Kf(free.size(), free.size());
    Vector ff(free.size());
    for (size_t i = 0; i < free.size(); ++i) {
      ff[i] = f[free[i]];
      for (size_t j = 0; j < free.size(); ++j) Kf(i, j) = K(free[i], free[j]);
    }
    const Vector u = Kf.ldlt().solve(ff);
    double v = 0.0;
    for (size_t i = 0; i < free.size(); ++i)
      for (int k : right.nodes)
        if (free[i] == 2 * k + 1) v += -u[i] / right.nodes.size();
    return v;
  };
  const double q4 = tip(ContinuumElement::q4, 20, 4);
  const double bbar = tip(ContinuumElement::q4_bbar, 20, 4);
  const double q9 = tip(ContinuumElement::q9, 20, 4);
  std::cout << "tip deflection / beam theory: q4 " << q4 / expected << ", q4_bbar " << bbar / expected << ", q9 "
            << q9 / expected << "\n";
  EXPECT_LT(q4, 0.2 * expected);  // locked
  EXPECT_NEAR(bbar, expected, 0.08 * expected);
  EXPECT_NEAR(q9, expected, 0.08 * expected);
}

// The body's constructor is where a mesh is checked (the scene reader reads the issues off
// its exception): every issue check_mesh finds, the first in what().
TEST(ContinuumBodyMesh, RejectsAFaultyMeshWithAllItsIssues) {
  PlaneMesh mesh = distorted_patch(ElementShape::q4);
  const std::vector<int> bottom = mesh.sets.at("bottom");
  mesh.elements[0][2] = 999;                            // a node that does not exist
  std::swap(mesh.elements[1][1], mesh.elements[1][3]);  // clockwise
  mesh.nodes.push_back({9, 9});                         // in no element
  const std::vector<MeshIssue> expected = check_mesh(mesh, ElementShape::q4);
  ASSERT_EQ(expected.size(), 3u);
  try {
    ContinuumBody(mesh, bottom, {material(PlaneAnalysis::plane_strain)}, ContinuumOptions{});
    FAIL() << "a faulty mesh was accepted";
  } catch (const InvalidMesh& e) {
    ASSERT_EQ(e.issues.size(), expected.size());
    for (size_t k = 0; k < expected.size(); ++k) {
      EXPECT_EQ(e.issues[k].element, expected[k].element);
      EXPECT_EQ(e.issues[k].node, expected[k].node);
      EXPECT_EQ(e.issues[k].detail, expected[k].detail);
    }
    EXPECT_EQ(std::string(e.what()), "element 0 " + expected[0].detail);
  }
}

}  // namespace
}  // namespace grip
