// Mooney-Rivlin rubber (docs/algorithm.md#mooney-rivlin), nearly incompressible (bulk = 1e4 x
// the shear modulus), through the total-Lagrangian continuum body:
// - one q4 in plane stress stretched uniaxially and equibiaxially to 3 against the closed form
//   of the principal Cauchy stresses, sigma_i = (2/J) [c10 (b_i - I1/3) + c01 (I1 b_i - b_i^2 -
//   2 I2/3)] + bulk (J - 1) with b_i = J^(-2/3) lambda_i^2 (the free stretch found from its
//   sigma = 0 by bisection);
// - the tangent against central differences of the internal force (q4 with and without F-bar,
//   q9; plane strain and plane stress);
// - a block pressed into a volume-keeping wave in plane strain: q4 locks, q4 with F-bar (16 x 16)
//   gives the force of a refined q9 (24 x 24) within 1 %.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <cmath>
#include <cstdio>

#include "solver/elements/continuum.hpp"
#include "solver/materials/mooney_rivlin.hpp"
#include "tests/support/continuum_blocks.hpp"
#include "tests/support/newton_driver.hpp"
#include "tests/support/tangent_check.hpp"

namespace grip {
namespace {

using testing::Driver;
using testing::unit_square;

constexpr double kC10 = 0.4, kC01 = 0.1, kShear = 2 * (kC10 + kC01), kBulk = 1e4 * kShear;

// The principal Cauchy stress i of the decoupled law at principal stretches l.
double principal_stress(const std::array<double, 3>& l, int i) {
  const double J = l[0] * l[1] * l[2];
  std::array<double, 3> b;
  for (int k = 0; k < 3; ++k) b[k] = std::pow(J, -2.0 / 3.0) * l[k] * l[k];
  const double I1 = b[0] + b[1] + b[2], I2 = b[0] * b[1] + b[1] * b[2] + b[0] * b[2];
  return 2 / J * (kC10 * (b[i] - I1 / 3) + kC01 * (I1 * b[i] - b[i] * b[i] - 2 * I2 / 3)) + kBulk * (J - 1);
}

// The stretch x in (0, 1] at which the stress of direction `free` vanishes, the others given by `with`.
double free_stretch(const std::function<std::array<double, 3>(double)>& with, int free) {
  double lo = 1e-3, hi = 1.0;
  for (int it = 0; it < 200; ++it) {
    const double x = 0.5 * (lo + hi);
    (principal_stress(with(x), free) > 0 ? hi : lo) = x;
  }
  return 0.5 * (lo + hi);
}

std::shared_ptr<const PlaneMaterial> rubber(PlaneAnalysis analysis) {
  return std::make_shared<MooneyRivlinMaterial>(kC10, kC01, kBulk, analysis);
}

TEST(MooneyRivlin, UniaxialAndEquibiaxialStretchFollowTheClosedForm) {
  for (bool equibiaxial : {false, true}) {
    SCOPED_TRACE(equibiaxial ? "equibiaxial" : "uniaxial");
    ContinuumBody body(unit_square(), {0, 1}, {rubber(PlaneAnalysis::plane_stress)},
                       {ContinuumElement::q4, ContinuumKinematics::finite, PlaneAnalysis::plane_stress, 1.0});
    // x held on the left, y at the bottom; pulled along x on the right (and along y at the top).
    std::vector<char> held(8, 0);
    for (int dof : {0, 6, 1, 3, 2, 4}) held[dof] = 1;
    if (equibiaxial) held[5] = held[7] = 1;
    Driver d(body, held);
    double worst = 0.0, worst_free = 0.0;
    for (int k = 1; k <= 20; ++k) {
      const double l = 1 + 0.1 * k;  // to 3
      d.solve(
          [&](Vector& q) {
            q[2] = q[4] = l - 1;
            if (equibiaxial) q[5] = q[7] = l - 1;
          },
          1e-10 * kShear);
      std::array<double, 3> stretches;
      if (equibiaxial) {
        const double l3 = free_stretch([&](double x) { return std::array<double, 3>{l, l, x}; }, 2);
        stretches = {l, l, l3};
      } else {
        // The two lateral directions are both free and alike: lambda_2 = lambda_3.
        const double l2 = free_stretch([&](double x) { return std::array<double, 3>{l, x, x}; }, 1);
        stretches = {l, l2, l2};
        worst_free = std::max(worst_free, std::abs(1 + d.q[5] - l2));
      }
      const double expected = principal_stress(stretches, 0);
      const std::vector<double> row = body.element_fields(d.q).rows[0];
      worst = std::max(worst, std::abs(row[0] - expected) / expected);
      EXPECT_NEAR(row[1], equibiaxial ? expected : 0.0, 1e-8 * expected);
      EXPECT_NEAR(row[3], 0.0, 1e-8 * expected);
    }
    EXPECT_LT(worst, 1e-8);
    EXPECT_LT(worst_free, 1e-9);
    std::printf("%s to stretch 3: worst |sigma - closed form| / sigma = %.1e, free stretch %.1e\n",
                equibiaxial ? "equibiaxial" : "uniaxial", worst, worst_free);
  }
}

TEST(MooneyRivlin, TangentMatchesDifferencesOfTheForce) {
  struct Case {
    const char* name;
    PlaneAnalysis analysis;
    ContinuumElement element;
    Incompressibility incompressibility;
  };
  for (const Case& c :
       {Case{"q4 plane strain", PlaneAnalysis::plane_strain, ContinuumElement::q4, Incompressibility::none},
        Case{"q4 f_bar", PlaneAnalysis::plane_strain, ContinuumElement::q4, Incompressibility::f_bar},
        Case{"q9 plane strain", PlaneAnalysis::plane_strain, ContinuumElement::q9, Incompressibility::none},
        Case{"q4 plane stress", PlaneAnalysis::plane_stress, ContinuumElement::q4, Incompressibility::none}}) {
    SCOPED_TRACE(c.name);
    RectangleSpec spec;
    spec.size = {2.0, 1.0};
    spec.nx = 2;
    spec.ny = 1;
    PlaneMesh mesh = rectangle_mesh(spec, element_shape(c.element));
    ContinuumBody body(mesh, mesh.sets.at("bottom"), {rubber(c.analysis)},
                       {c.element, ContinuumKinematics::finite, c.analysis, 1.0, c.incompressibility});
    // A large distortion: a shear and a stretch of 30 % with a wobble on every dof.
    Vector q(body.dof_count());
    for (int n = 0; n < body.node_count(); ++n) {
      const Vec2 X = mesh.nodes[n];
      q[2 * n] = 0.3 * X.y() + 0.3 * X.x() + 0.02 * std::sin(1.0 + 3.7 * n);
      q[2 * n + 1] = -0.1 * X.y() + 0.02 * std::cos(2.0 + 1.3 * n);
    }
    const auto check = testing::check_tangent(body, q, 1e-6);
    const double error = check.error();
    EXPECT_LT(error, 1e-6);
    EXPECT_LT(check.asymmetry(), 1e-9);
    std::printf("tangent %-16s |K - K_fd| / |K| = %.1e\n", c.name, error);
  }
}

// A unit block on rollers (bottom held in y, both sides in x) whose top is pressed into the
// wave u_y = -delta cos(pi x), delta = 0.05 in two steps: the wave keeps the volume, so the
// nearly incompressible block takes it at a load of the shear modulus's size, and its smooth
// deformation (no corner where a held side meets a free one) lets the meshes converge fast.
// The generalized force sum over the top of f_y cos(pi x), the work conjugate of delta.
double wave_force(ContinuumElement element, Incompressibility incompressibility, int n) {
  RectangleSpec spec;
  spec.nx = spec.ny = n;
  PlaneMesh mesh = rectangle_mesh(spec, element_shape(element));
  const std::vector<int> top = mesh.sets.at("top");
  ContinuumBody body(mesh, mesh.sets.at("bottom"), {rubber(PlaneAnalysis::plane_strain)},
                     {element, ContinuumKinematics::finite, PlaneAnalysis::plane_strain, 1.0, incompressibility});
  std::vector<char> held(body.dof_count(), 0);
  for (int k : mesh.sets.at("bottom")) held[2 * k + 1] = 1;
  for (int k : top) held[2 * k + 1] = 1;
  for (const char* side : {"left", "right"})
    for (int k : mesh.sets.at(side)) held[2 * k] = 1;
  Driver d(body, held);
  d.line_search = true;  // q9 and F-bar overshoot into inverted elements on the first iterations
  for (int step = 1; step <= 2; ++step)
    d.solve(
        [&](Vector& q) {
          for (int k : top) q[2 * k + 1] = -0.025 * step * std::cos(M_PI * mesh.nodes[k].x());
        },
        1e-9 * kShear);
  const Vector f = d.force(nullptr);
  double force = 0.0;
  for (int k : top) force -= f[2 * k + 1] * std::cos(M_PI * mesh.nodes[k].x());
  return force;
}

TEST(MooneyRivlin, FBarUnlocksANearlyIncompressibleBlock) {
  const double reference = wave_force(ContinuumElement::q9, Incompressibility::none, 24);
  const double f_bar = wave_force(ContinuumElement::q4, Incompressibility::f_bar, 16);
  const double plain = wave_force(ContinuumElement::q4, Incompressibility::none, 16);
  const double f_bar_coarse = wave_force(ContinuumElement::q4, Incompressibility::f_bar, 8);
  const double q9_coarse = wave_force(ContinuumElement::q9, Incompressibility::none, 8);
  std::printf(
      "block pressed into a wave, bulk = 1e4 shear: force q9 24x24 (reference) %.5f; q4 f_bar 16x16 %+.2f %%, "
      "8x8 %+.2f %%; q4 16x16 %+.0f %%; q9 8x8 %+.2f %%\n",
      reference, 100 * (f_bar / reference - 1), 100 * (f_bar_coarse / reference - 1), 100 * (plain / reference - 1),
      100 * (q9_coarse / reference - 1));
  EXPECT_LT(std::abs(f_bar / reference - 1), 0.01);
  EXPECT_GT(plain / reference, 2.0);  // locked: far stiffer
}

TEST(MooneyRivlin, RefusesBadConstants) {
  EXPECT_EQ(mooney_rivlin_data_issue(-0.1, 0.1, 1e3).rfind("c10:", 0), 0u);
  EXPECT_EQ(mooney_rivlin_data_issue(0.0, 0.0, 1e3).rfind("c10:", 0), 0u);
  EXPECT_EQ(mooney_rivlin_data_issue(0.4, 0.1, 0.5).rfind("bulk:", 0), 0u);
  EXPECT_TRUE(mooney_rivlin_data_issue(0.4, 0.1, 1e4).empty());
  EXPECT_THROW(MooneyRivlinMaterial(0.4, 0.1, 0.1, PlaneAnalysis::plane_strain), std::invalid_argument);
}

}  // namespace
}  // namespace grip
