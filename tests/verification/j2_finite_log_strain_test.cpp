// J2 plasticity at finite strain with kinematic hardening and with Hill's 1948 anisotropy: the
// small-strain return on the Lagrangian log strain log(C) / 2 (docs/algorithm.md#finite-strain-j2-plasticity).
// - kinematic hardening: a plane-stress square pulled to log strain 0.3, pushed back to -0.2 and
//   pulled again to 0.1, against the one-dimensional return in Kirchhoff stress against log
//   strain with the back stress b = H_k eps_p (|tau - b| = sigma_y(alpha) while it flows: the
//   Bauschinger effect), the lateral log strain and alpha;
// - Hill: the same square pulled to log strain 0.3 along the rolling direction and across it:
//   tau = sigma_y(alpha) / k with alpha = k eps_p (k Hill's factor), and the r-value of the
//   plastic log strains, width over thickness, the given r at every step;
// - the consistent tangent against central differences and Newton's quadratic convergence on a
//   plastic step, plane strain, plane stress and axisymmetric, plain, mixed and F-bar elements,
//   kinematic hardening, Hill's anisotropy and the two together;
// - at a tiny yield strain the small-strain law's answer (the finite measures at small strain).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>

#include "solver/elements/continuum.hpp"
#include "solver/materials/j2_plasticity.hpp"
#include "tests/support/continuum_blocks.hpp"
#include "tests/support/hill48_uniaxial.hpp"
#include "tests/support/j2_laws.hpp"
#include "tests/support/newton_driver.hpp"
#include "tests/support/tangent_check.hpp"

namespace grip {
namespace {

using testing::Bent;
using testing::bend;
using testing::bent_block;
using testing::Driver;
using testing::finite;
using testing::unit_square;
using testing::kSheet;
using namespace testing::j2;

constexpr double kKinematic = 10000.0;  // H_k: 5 % of E

// The one-dimensional return in Kirchhoff stress against log strain x: tau = E (x - eps_p),
// |tau - b| <= sigma_y(alpha), b = H_k eps_p; a plastic step moves eps_p by d and alpha by |d|
// (bisection: the power law's closed form is implicit).
struct Uniaxial {
  const J2Material& m;
  double hk;
  double eps_p = 0.0, alpha = 0.0;

  double tau(double x) {
    const double xi = kYoung * (x - eps_p) - hk * eps_p;
    if (std::abs(xi) <= m.yield_stress(alpha)) return kYoung * (x - eps_p);
    double lo = 0.0, hi = std::abs(xi) / (kYoung + hk);
    for (int it = 0; it < 200; ++it) {
      const double d = 0.5 * (lo + hi);
      (std::abs(xi) - (kYoung + hk) * d > m.yield_stress(alpha + d) ? lo : hi) = d;
    }
    const double d = 0.5 * (lo + hi);
    eps_p += std::copysign(d, xi);
    alpha += d;
    return kYoung * (x - eps_p);
  }
};

// The square's dofs: x held on the left (nodes 0, 3), y at the bottom (nodes 0, 1); pulled along
// x (the right side, dofs 2 and 4) or along y (the top, dofs 5 and 7).
struct Pulled {
  std::unique_ptr<ContinuumBody> body;
  std::unique_ptr<Driver> driver;
  bool along_y;

  std::array<int, 2> pulled_dofs() const { return along_y ? std::array<int, 2>{5, 7} : std::array<int, 2>{2, 4}; }

  Pulled(std::shared_ptr<const PlaneMaterial> m, bool y) : along_y(y) {
    body = std::make_unique<ContinuumBody>(unit_square(), std::vector<int>{0, 1},
                                           std::vector<std::shared_ptr<const PlaneMaterial>>{std::move(m)},
                                           finite(PlaneAnalysis::plane_stress));
    std::vector<char> held(8, 0);
    for (int dof : {0, 6, 1, 3}) held[dof] = 1;
    for (int dof : pulled_dofs()) held[dof] = 1;
    driver = std::make_unique<Driver>(*body, held);
  }
  // To log strain x along the pull; returns the Cauchy stress along it.
  double pull(double x) {
    driver->solve(
        [&](Vector& q) {
          for (int dof : pulled_dofs()) q[dof] = std::exp(x) - 1;
        },
        1e-9 * kYield);
    return driver->element_row(0)[along_y ? 1 : 0];
  }
  double lateral_log_strain() const { return std::log(1 + driver->q[along_y ? 2 : 5]); }
  double alpha() const { return driver->element_row(0)[4]; }
};

TEST(J2FiniteLogStrain, KinematicHardeningCycleFollowsTheClosedForm) {
  for (const Law& law : laws()) {
    SCOPED_TRACE(law.name);
    const auto m = material(law, PlaneAnalysis::plane_stress, 1.0, std::nullopt, kKinematic);
    Pulled p(m, false);
    Uniaxial closed{*m, kKinematic};
    std::vector<double> path;
    for (int k = 1; k <= 15; ++k) path.push_back(0.02 * k);         // to 0.3
    for (int k = 1; k <= 25; ++k) path.push_back(0.3 - 0.02 * k);   // back to -0.2
    for (int k = 1; k <= 15; ++k) path.push_back(-0.2 + 0.02 * k);  // on to 0.1
    double worst = 0.0, worst_lateral = 0.0, reverse_yield = 0.0, peak = 0.0;
    bool reversed = false;
    for (double x : path) {
      const double before = closed.alpha;
      const double tau = closed.tau(x);
      const double sigma = p.pull(x);
      const double cauchy = tau * std::exp(-(1 - 2 * kPoisson) * tau / kYoung);
      worst = std::max(worst, std::abs(sigma - cauchy) / kYield);
      worst_lateral =
          std::max(worst_lateral, std::abs(p.lateral_log_strain() - (-kPoisson * tau / kYoung - 0.5 * closed.eps_p)));
      EXPECT_NEAR(p.alpha(), closed.alpha, 1e-9);
      if (x == 0.3) peak = tau;
      // The first flow after the peak: tau there is below the peak by less than 2 sigma_y(alpha).
      if (peak > 0 && x < 0.3 && !reversed && closed.alpha > before) {
        reversed = true;
        reverse_yield = tau;
      }
    }
    EXPECT_TRUE(reversed);
    // Bauschinger: the reverse yield lies within 2 sigma_y of the peak, far above -peak.
    EXPECT_GT(reverse_yield, -0.9 * peak);
    EXPECT_LT(worst, 1e-9);
    EXPECT_LT(worst_lateral, 1e-9);
    std::printf(
        "kinematic %-6s: |sigma - closed form| / sigma_y <= %.1e, lateral log strain %.1e; peak tau %.1f, reverse "
        "flow from tau %.1f (isotropic alone: %.1f), alpha %.4f\n",
        law.name, worst, worst_lateral, peak, reverse_yield, -peak, closed.alpha);
  }
}

TEST(J2FiniteLogStrain, HillUniaxialTensionKeepsTheRValuesToLargeStrain) {
  for (const Law& law : laws())
    for (bool across : {false, true}) {
      SCOPED_TRACE(std::string(law.name) + (across ? " at 90 degrees" : " at 0 degrees"));
      const auto m = material(law, PlaneAnalysis::plane_stress, 1.0, kSheet);
      const double k = testing::hill_factor(kSheet, across ? 0.5 * std::numbers::pi : 0.0),
                   r_given = across ? kSheet.r90 : kSheet.r0;
      Pulled p(m, across);
      double worst = 0.0, worst_r = 0.0, alpha = 0.0;
      for (int s = 1; s <= 15; ++s) {
        const double x = 0.02 * s;
        const double sigma = p.pull(x);
        // tau = E (x - k alpha) = sigma_y(alpha) / k once it flows (x > sigma_y / (k E) here).
        double lo = 0.0, hi = x / k;
        for (int it = 0; it < 200; ++it) {
          const double a = 0.5 * (lo + hi);
          (m->yield_stress(a) / k > kYoung * (x - k * a) ? hi : lo) = a;
        }
        alpha = 0.5 * (lo + hi);
        const double tau = m->yield_stress(alpha) / k;
        const double cauchy = tau * std::exp(-(1 - 2 * kPoisson) * tau / kYoung);
        worst = std::max(worst, std::abs(sigma - cauchy) / kYield);
        EXPECT_NEAR(p.alpha(), alpha, 1e-9);
        // Plastic log strains: along x - tau / E, across the width w + nu tau / E, and the
        // thickness from the volume: r = width / thickness.
        const double along = x - tau / kYoung, width = p.lateral_log_strain() + kPoisson * tau / kYoung;
        worst_r = std::max(worst_r, std::abs(width / -(along + width) - r_given) / r_given);
      }
      EXPECT_LT(worst, 1e-9);
      EXPECT_LT(worst_r, 1e-8);
      std::printf(
          "hill48 finite %-6s %2d deg: |sigma - closed form| / sigma_y <= %.1e, r within %.1e of %.2f, alpha %.4f\n",
          law.name, across ? 90 : 0, worst, worst_r, r_given, alpha);
    }
}

struct Case {
  const char* name;
  ContinuumOptions options;
  bool hill, kinematic;
};

std::shared_ptr<J2Material> law_of(const Case& c, const Law& law, double scale = 1.0) {
  const PlaneAnalysis a = c.options.analysis;
  std::optional<Hill48> hill;
  if (c.hill) hill = testing::anisotropy(a);
  return material(law, a, scale, hill, c.kinematic ? kKinematic : 0.0);
}

const Case kCases[] = {
    {"kinematic q8 plane strain", finite(PlaneAnalysis::plane_strain, ContinuumElement::q8), false, true},
    {"kinematic q4 plane stress", finite(PlaneAnalysis::plane_stress), false, true},
    {"kinematic q9 mixed plane strain",
     finite(PlaneAnalysis::plane_strain, ContinuumElement::q9, Incompressibility::mixed), false, true},
    {"kinematic q9 axisymmetric", finite(PlaneAnalysis::axisymmetric, ContinuumElement::q9), false, true},
    {"kinematic q4 f_bar axisymmetric",
     finite(PlaneAnalysis::axisymmetric, ContinuumElement::q4, Incompressibility::f_bar), false, true},
    {"hill q8 plane strain", finite(PlaneAnalysis::plane_strain, ContinuumElement::q8), true, false},
    {"hill q8 plane stress", finite(PlaneAnalysis::plane_stress, ContinuumElement::q8), true, false},
    {"hill t6 mixed plane strain", finite(PlaneAnalysis::plane_strain, ContinuumElement::t6, Incompressibility::mixed),
     true, false},
    {"hill q9 axisymmetric", finite(PlaneAnalysis::axisymmetric, ContinuumElement::q9), true, false},
    {"hill+kinematic q8 plane strain", finite(PlaneAnalysis::plane_strain, ContinuumElement::q8), true, true},
    {"hill+kinematic q8 plane stress", finite(PlaneAnalysis::plane_stress, ContinuumElement::q8), true, true},
    {"hill+kinematic q9 axisymmetric", finite(PlaneAnalysis::axisymmetric, ContinuumElement::q9), true, true},
};

TEST(J2FiniteLogStrain, TangentMatchesDifferencesAndNewtonConvergesQuadratically) {
  for (const Case& c : kCases)
    for (const Law& law : laws()) {
      SCOPED_TRACE(std::string(law.name) + " " + c.name);
      Bent b = bent_block(law_of(c, law), c.options);
      Driver d(*b.body, b.held);
      // The plain Newton overshoots on the mixed elements and on q4 in plane stress (the residual
      // stalls near 1); the driver's line search leaves full steps near the solution.
      d.line_search =
          c.options.incompressibility == Incompressibility::mixed || c.options.analysis == PlaneAnalysis::plane_stress;
      for (int k = 1; k <= 6; ++k) bend(d, b, 0.025 * k, 1e-10 * kYield);
      const std::vector<double> r = d.residuals;
      EXPECT_GE(testing::expect_quadratic(r), 1);
      EXPECT_LE(r.size(), 10u);
      const auto check = testing::check_tangent_beyond(*b.body, d.q, 0.004);
      EXPECT_GT(check.flowing, 0);
      EXPECT_LT(check.error(), 1e-6);
      EXPECT_LT(check.asymmetry(), 1e-9);
      const std::string line = testing::relative_residuals(r);
      std::printf("%-6s %-32s |K - K_fd| / |K| = %.1e (%d of %zu flowing); Newton:%s\n", law.name, c.name,
                  check.error(), check.flowing, check.elements, line.c_str());
    }
}

TEST(J2FiniteLogStrain, SmallStrainLimitIsTheSmallStrainLaw) {
  const double scale = 1e-5;  // yield strain 1.25e-8
  for (const Case& c : kCases) {
    if (c.options.incompressibility != Incompressibility::none) continue;  // linear kinematics has none
    for (const Law& law : laws(scale)) {
      SCOPED_TRACE(std::string(law.name) + " " + c.name);
      const auto m = law_of(c, law, scale);
      ContinuumOptions linear = c.options;
      linear.kinematics = ContinuumKinematics::linear;
      Bent fin = bent_block(m, c.options), lin = bent_block(m, linear);
      Driver df(*fin.body, fin.held), dl(*lin.body, lin.held);
      FieldGap gap;
      // Out to 12 steps of 5e-8, back and reversed (kinematic hardening's reverse flow).
      std::vector<double> path;
      for (int k = 1; k <= 12; ++k) path.push_back(5e-8 * k);
      for (int k = 1; k <= 20; ++k) path.push_back(6e-7 - 5e-8 * k);
      // The finite measures lose ~1e-9 of these strains to round-off (F^T F - I); the
      // axisymmetric forces carry 2 pi R (R to 5), and their floor with them.
      const double tolerance = 1e-7 * kYield * scale * (c.options.analysis == PlaneAnalysis::axisymmetric ? 100 : 1);
      for (double tip : path) {
        bend(df, fin, tip, tolerance);
        bend(dl, lin, tip, tolerance);
        gap.add(fin.body->element_fields(df.q).rows, lin.body->element_fields(dl.q).rows);
      }
      EXPECT_GT(gap.peak_alpha, 1e-8);
      EXPECT_LT(gap.stress, 3e-6);
      EXPECT_LT(gap.alpha, 1e-6 * gap.peak_alpha);
      std::printf("small-strain limit %-6s %-26s: |sigma_finite - sigma_small| / peak <= %.1e, alpha %.1e of %.1e\n",
                  law.name, c.name, gap.stress, gap.alpha, gap.peak_alpha);
    }
  }
}

}  // namespace
}  // namespace grip
