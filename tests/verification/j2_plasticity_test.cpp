// J2 plasticity at small strain (docs/algorithm.md#j2-plasticity), through the continuum body:
// - one element in uniaxial stress (plane stress: the plane-stress return; axisymmetric: a ring
//   pulled along its axis) and in simple shear (plane strain and plane stress), loaded, unloaded
//   and reloaded, against the closed form of each hardening law: on the plastic branch
//   sigma = sigma_y(alpha) + H_k alpha with eps = sigma / E + alpha (uniaxial; simple shear is
//   the same curve in sqrt(3) tau against gamma / sqrt(3) with E replaced by 3 G); unloading
//   and reloading elastic below the largest stress reached; with kinematic hardening the
//   reversed yield at sigma = H_k eps_p - sigma_y (Bauschinger);
// - the consistent tangent against central differences of the internal force;
// - Newton's quadratic convergence on a plastic step;
// - history: evaluating a state does not change the body, commit does.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <cmath>
#include <functional>

#include "solver/elements/continuum.hpp"
#include "solver/materials/j2_plasticity.hpp"
#include "tests/support/continuum_blocks.hpp"
#include "tests/support/newton_driver.hpp"
#include "tests/support/tangent_check.hpp"

namespace grip {
namespace {

using testing::Bent;
using testing::bend;
using testing::bent_block;
using testing::Driver;
using testing::small_strain;

constexpr double kYoung = 200e3, kPoisson = 0.3, kYield = 250.0;

struct Law {
  const char* name;
  IsotropicHardening hardening;
  double kinematic = 0.0;
};

std::vector<Law> laws() {
  IsotropicHardening linear;
  linear.modulus = 2000.0;
  IsotropicHardening power;
  power.kind = IsotropicHardening::Kind::power;
  power.K = 600.0;
  power.n = 0.2;
  IsotropicHardening table;
  table.kind = IsotropicHardening::Kind::table;
  table.table = {{0.0, kYield}, {0.002, 280.0}, {0.006, 300.0}, {0.02, 320.0}};
  return {{"linear", linear}, {"power", power}, {"table", table}, {"kinematic", IsotropicHardening{}, 5000.0}};
}

// The uniaxial curve's plastic branch: sigma = sigma_y(alpha) + H_k alpha, eps = sigma / E + alpha
// (bisection on alpha: the closed forms of the power law and the table are implicit in sigma).
double monotone_stress(const J2Material& m, double kinematic, double modulus, double eps) {
  if (eps * modulus <= kYield) return modulus * eps;
  double lo = 0.0, hi = eps;
  for (int it = 0; it < 200; ++it) {
    const double a = 0.5 * (lo + hi);
    (m.yield_stress(a) + kinematic * a > modulus * (eps - a) ? hi : lo) = a;
  }
  return modulus * (eps - 0.5 * (lo + hi));
}

std::shared_ptr<J2Material> material(const Law& law, PlaneAnalysis analysis) {
  return std::make_shared<J2Material>(kYoung, kPoisson, kYield, law.hardening, law.kinematic, analysis);
}

PlaneMesh square(double x0) {
  PlaneMesh m;
  m.nodes = {{x0, 0}, {x0 + 1, 0}, {x0 + 1, 1}, {x0, 1}};
  m.elements = {{0, 1, 2, 3}};
  m.sets["bottom"] = {0, 1};
  return m;
}

// A path of total strains: loading beyond yield, unloading, reloading past the largest strain.
struct Point {
  double eps, expected;
};

// Uniaxial: loading to 5 eps_y, unloading by 1.5 of that stress (isotropic hardening: elastic,
// to -sigma_1 / 2; kinematic: through reversed yield), reloading to the same strain and on to 8 eps_y.
std::vector<Point> uniaxial_path(const Law& law, const J2Material& m, double modulus) {
  const double ey = kYield / modulus, Hk = law.kinematic;
  const double e1 = 5 * ey, s1 = monotone_stress(m, Hk, modulus, e1);
  const double e2 = e1 - 1.5 * s1 / modulus * (Hk > 0 ? 2.0 : 1.0);
  double s2 = s1 - modulus * (e1 - e2);
  if (Hk > 0) {
    // The elastic line crosses the reversed yield at H_k eps_p - sigma_y before e2: e2 lies on
    // the reversed branch.
    const double reversed = (Hk * e2 - kYield) / (1 + Hk / modulus);
    EXPECT_GT(reversed, s2);
    s2 = reversed;
  }
  const double e4 = 8 * ey;
  return {{0.5 * ey, 0.5 * kYield},
          {2 * ey, monotone_stress(m, Hk, modulus, 2 * ey)},
          {e1, s1},
          {0.5 * (e1 + e2), s1 - modulus * 0.5 * (e1 - e2)},
          {e2, s2},
          {e1, s1},
          {e4, monotone_stress(m, Hk, modulus, e4)}};
}

TEST(J2Plasticity, UniaxialStressFollowsTheClosedFormOfEachLaw) {
  for (PlaneAnalysis analysis : {PlaneAnalysis::plane_stress, PlaneAnalysis::axisymmetric}) {
    const bool axi = analysis == PlaneAnalysis::axisymmetric;
    for (const Law& law : laws()) {
      SCOPED_TRACE(std::string(law.name) + (axi ? " axisymmetric" : " plane stress"));
      const auto m = material(law, analysis);
      ContinuumBody body(square(axi ? 1.0 : 0.0), {0, 1}, {m},
                         {ContinuumElement::q4, ContinuumKinematics::linear, analysis, 1.0});
      // Plane stress: pulled along x (x held on the left, y at the bottom); axisymmetric: along
      // the axis y (y held at the bottom, pulled at the top), u_r free.
      std::vector<char> held(8, 0);
      const int axial = axi ? 1 : 0;
      const std::vector<int> fixed_nodes = axi ? std::vector<int>{0, 1} : std::vector<int>{0, 3};
      const std::vector<int> pulled = axi ? std::vector<int>{2, 3} : std::vector<int>{1, 2};
      for (int n : fixed_nodes) held[2 * n + axial] = 1;
      for (int n : pulled) held[2 * n + axial] = 1;
      if (!axi) held[2 * 0 + 1] = held[2 * 1 + 1] = 1;
      Driver d(body, held);
      double worst = 0.0;
      for (const Point& p : uniaxial_path(law, *m, kYoung)) {
        d.solve(
            [&](Vector& q) {
              for (int n : pulled) q[2 * n + axial] = p.eps;
            },
            1e-9 * kYield);
        const std::vector<double> row = d.element_row(0);
        const double s = row[axial], lateral = row[1 - axial];
        worst = std::max(worst, std::abs(s - p.expected) / kYield);
        EXPECT_NEAR(lateral, 0.0, 1e-9 * kYield);
        EXPECT_NEAR(row[3], 0.0, 1e-9 * kYield);  // s33 (plane stress) or the hoop stress
      }
      EXPECT_LT(worst, 1e-9);
      std::printf("uniaxial %-9s %-12s worst |sigma - closed form| / sigma_y = %.1e, alpha = %.5f\n", law.name,
                  axi ? "axisymmetric" : "plane_stress", worst, d.element_row(0)[4]);
    }
  }
}

TEST(J2Plasticity, SimpleShearFollowsTheClosedFormOfEachLaw) {
  const double G = kYoung / (2 * (1 + kPoisson));
  for (PlaneAnalysis analysis : {PlaneAnalysis::plane_strain, PlaneAnalysis::plane_stress}) {
    for (const Law& law : laws()) {
      SCOPED_TRACE(std::string(law.name) +
                   (analysis == PlaneAnalysis::plane_strain ? " plane strain" : " plane stress"));
      const auto m = material(law, analysis);
      ContinuumBody body(square(0.0), {0, 1}, {m}, {ContinuumElement::q4, ContinuumKinematics::linear, analysis, 1.0});
      Driver d(body, std::vector<char>(8, 1));  // u = gamma y, v = 0 at every node: simple shear
      double worst = 0.0;
      // In sqrt(3) tau against gamma / sqrt(3), the uniaxial curve with E = 3 G.
      for (const Point& p : uniaxial_path(law, *m, 3 * G)) {
        const double gamma = std::sqrt(3.0) * p.eps;
        d.solve([&](Vector& q) { q[2 * 2] = q[2 * 3] = gamma; }, 1e-9 * kYield);
        const std::vector<double> row = d.element_row(0);
        worst = std::max(worst, std::abs(std::sqrt(3.0) * row[2] - p.expected) / kYield);
        // The shear force on the top side is tau times its length.
        const Vector f = d.force(nullptr);
        EXPECT_NEAR(f[2 * 2] + f[2 * 3], row[2], 1e-9 * kYield);
        for (int k : {0, 1, 3}) EXPECT_NEAR(row[k], 0.0, 1e-9 * kYield);
      }
      EXPECT_LT(worst, 1e-9);
      std::printf("simple shear %-9s %-12s worst |sqrt3 tau - closed form| / sigma_y = %.1e\n", law.name,
                  analysis == PlaneAnalysis::plane_strain ? "plane_strain" : "plane_stress", worst);
    }
  }
}

TEST(J2Plasticity, ConsistentTangentMatchesDifferencesOfTheForce) {
  for (PlaneAnalysis analysis : {PlaneAnalysis::plane_strain, PlaneAnalysis::plane_stress, PlaneAnalysis::axisymmetric})
    for (ContinuumElement element : {ContinuumElement::q4, ContinuumElement::q8, ContinuumElement::t6})
      for (const Law& law : laws()) {
        SCOPED_TRACE(std::string(law.name) + " " + element_name(element) + " analysis " +
                     std::to_string(static_cast<int>(analysis)));
        Bent b = bent_block(material(law, analysis), small_strain(analysis, element));
        Driver d(*b.body, b.held);
        for (double tip : {0.01, 0.03}) bend(d, b, tip, 1e-9 * kYield);  // a committed plastic history
        const auto c = testing::check_tangent_beyond(*b.body, d.q, 0.004);
        EXPECT_GT(c.flowing, 0);
        const double error = c.error();
        EXPECT_LT(error, 1e-6);
        EXPECT_LT(c.asymmetry(), 1e-12);
      }
}

TEST(J2Plasticity, NewtonConvergesQuadraticallyOnAPlasticStep) {
  for (const Law& law : laws()) {
    SCOPED_TRACE(law.name);
    Bent b = bent_block(material(law, PlaneAnalysis::plane_strain),
                        small_strain(PlaneAnalysis::plane_strain, ContinuumElement::q8));
    Driver d(*b.body, b.held);
    bend(d, b, 0.01, 1e-10 * kYield);
    bend(d, b, 0.03, 1e-10 * kYield);
    const std::vector<double>& r = d.residuals;
    const std::string line = testing::relative_residuals(r);
    std::printf("Newton %-9s relative residuals:%s\n", law.name, line.c_str());
    EXPECT_GE(testing::expect_quadratic(r), 1);
    EXPECT_LE(r.size(), 8u);
  }
}

TEST(J2Plasticity, OnlyCommitMovesTheHistory) {
  const Law law = laws()[0];
  Bent b = bent_block(material(law, PlaneAnalysis::plane_strain), small_strain(PlaneAnalysis::plane_strain));
  Driver d(*b.body, b.held);
  bend(d, b, 0.01, 1e-9 * kYield);
  const Vector at_first = d.force(nullptr);
  // An attempt further on (a cut or refused increment evaluates such states) leaves it unchanged.
  Vector further = d.q;
  for (int n : b.tip) further[2 * n + 1] = 0.05;
  Vector f = Vector::Zero(further.size());
  b.body->internal_force(further, f, nullptr);
  EXPECT_EQ(d.force(nullptr), at_first);
  // Committed, the plastic strain stays: back at zero displacement a residual stress remains.
  b.body->commit(further);
  d.q.setZero();
  const auto rows = b.body->element_fields(d.q).rows;
  double residual = 0.0, alpha = 0.0;
  for (const auto& row : rows) {
    for (int k = 0; k < 4; ++k) residual = std::max(residual, std::abs(row[k]));
    alpha = std::max(alpha, row[4]);
  }
  EXPECT_GT(residual, 0.1 * kYield);
  EXPECT_GT(alpha, 1e-3);
}

TEST(J2Plasticity, RefusesBadData) {
  IsotropicHardening soft;
  soft.modulus = -10;
  EXPECT_EQ(j2_data_issue(kYield, soft, 0).rfind("hardening/linear:", 0), 0u);
  EXPECT_EQ(j2_data_issue(0.0, IsotropicHardening{}, 0).rfind("yield_stress:", 0), 0u);
  EXPECT_EQ(j2_data_issue(kYield, IsotropicHardening{}, -1).rfind("kinematic_hardening:", 0), 0u);
  IsotropicHardening table;
  table.kind = IsotropicHardening::Kind::table;
  table.table = {{0.0, kYield}, {0.01, 300.0}, {0.02, 290.0}};
  EXPECT_EQ(j2_data_issue(kYield, table, 0).rfind("hardening/table/2/1:", 0), 0u);
  table.table = {{0.0, 200.0}};
  EXPECT_EQ(j2_data_issue(kYield, table, 0).rfind("hardening/table/0/1:", 0), 0u);
  IsotropicHardening power;
  power.kind = IsotropicHardening::Kind::power;
  power.K = 500;
  power.n = 1.5;
  EXPECT_EQ(j2_data_issue(kYield, power, 0).rfind("hardening/power/n:", 0), 0u);
  EXPECT_THROW(J2Material(kYoung, kPoisson, kYield, soft, 0, PlaneAnalysis::plane_strain), std::invalid_argument);
}

}  // namespace
}  // namespace grip
