// J2 plasticity at finite strain (docs/algorithm.md#finite-strain-j2-plasticity), through the
// total-Lagrangian continuum body:
// - one q4 in uniaxial tension (plane stress) to 50 % logarithmic strain against the closed
//   form in true stress against log strain: the Kirchhoff stress tau = sigma_y(alpha) with
//   alpha = eps - tau / E (the small-strain curve, in log strain), the Cauchy stress tau / J with
//   J = exp((1 - 2 nu) tau / E), the lateral log strain -nu tau / E - alpha / 2; linear, Swift
//   and tabulated hardening (the table through all its segments and past its last point); det Fp = 1; released, the element keeps the plastic stretch exp(alpha);
// - plane-strain simple shear to gamma = 1: the mean stress stays K ln Je = 0 (isochoric flow),
//   the yield condition holds at every plastic state, det Fp = 1; released, C = Cp (Fe is a
//   rotation: unloading takes back exactly the elastic part);
// - the consistent tangent against central differences of the internal force (q4 and q8 in
//   plane strain, q4 in plane stress, q4 with F-bar, q9 and t6 mixed) and Newton's quadratic convergence on a
//   plastic step;
// - the small-strain limit: a bent block at strains of a few 1e-7 as the small-strain law, to 1e-6.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <cmath>
#include <cstdio>

#include "solver/elements/continuum.hpp"
#include "solver/materials/j2_plasticity.hpp"
#include "tests/support/continuum_blocks.hpp"
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
using testing::small_strain;
using testing::unit_square;

// Isotropic hardening (kinematic hardening and Hill: j2_finite_log_strain_test.cpp).
using namespace testing::j2;

// The uniaxial Kirchhoff stress at log strain eps: tau = sigma_y(eps - tau / E) on the plastic
// branch (bisection on alpha; for the table, on the segment [a_k, a_k+1) of slope h_k,
// alpha = (E eps - s_k + h_k a_k) / (E + h_k), which the bisection finds to round-off), with the
// law's curve from its data (Law::yield_stress), not the material's.
double uniaxial_kirchhoff(const Law& m, double eps) {
  if (eps * kYoung <= kYield) return kYoung * eps;
  double lo = 0.0, hi = eps;
  for (int it = 0; it < 200; ++it) {
    const double a = 0.5 * (lo + hi);
    (m.yield_stress(a) > kYoung * (eps - a) ? hi : lo) = a;
  }
  return kYoung * (eps - 0.5 * (lo + hi));
}

Mat2 tensor(const Eigen::Vector4d& v) { return (Mat2() << v[0], v[2], v[2], v[1]).finished(); }

// The largest |det Fp - 1| = |det Cp^-1 - 1| over the body's points.
double worst_plastic_volume(const ContinuumBody& body) {
  double worst = 0.0;
  for (const PointHistory& h : body.committed_history())
    worst = std::max(worst, std::abs(tensor(h.plastic_metric_inverse).determinant() * h.plastic_metric_inverse[3] - 1));
  return worst;
}

TEST(J2Finite, UniaxialTensionToHalfLogStrainFollowsTheClosedForm) {
  for (const Law& law : laws()) {
    SCOPED_TRACE(law.name);
    const auto m = material(law, PlaneAnalysis::plane_stress);
    ContinuumBody body(unit_square(), {0, 1}, {m}, finite(PlaneAnalysis::plane_stress));
    // x held on the left, y at the bottom; the right side pulled along x.
    std::vector<char> held(8, 0);
    for (int dof : {0, 6, 1, 3, 2, 4}) held[dof] = 1;
    Driver d(body, held);
    double worst = 0.0, worst_lateral = 0.0, tau = 0.0, eps = 0.0;
    const int steps = 25;
    for (int k = 1; k <= steps; ++k) {
      eps = 0.5 * k / steps;
      d.solve([&](Vector& q) { q[2] = q[4] = std::exp(eps) - 1; }, 1e-9 * kYield);
      tau = uniaxial_kirchhoff(law, eps);
      const double cauchy = tau * std::exp(-(1 - 2 * kPoisson) * tau / kYoung);
      const std::vector<double> row = d.element_row(0);
      worst = std::max(worst, std::abs(row[0] - cauchy) / cauchy);
      EXPECT_NEAR(row[1], 0.0, 1e-9 * kYield);
      EXPECT_NEAR(row[3], 0.0, 1e-9 * kYield);
      const double lateral = -kPoisson * tau / kYoung - 0.5 * (eps - tau / kYoung);
      worst_lateral = std::max(worst_lateral, std::abs(std::log(1 + d.q[5]) - lateral));
    }
    EXPECT_LT(worst, 1e-9);
    EXPECT_LT(worst_lateral, 1e-9);
    const double alpha = eps - tau / kYoung;
    EXPECT_NEAR(d.element_row(0)[4], alpha, 1e-9);
    const double volume_error = worst_plastic_volume(body);
    EXPECT_LT(volume_error, 1e-12);
    // Released (only the supports held): the elastic part comes back, the plastic stretch stays.
    std::vector<char> supports(8, 0);
    for (int dof : {0, 6, 1, 3}) supports[dof] = 1;
    Driver release(body, supports);
    release.q = d.q;
    release.solve([](Vector&) {}, 1e-9 * kYield);
    const std::vector<double> row = release.element_row(0);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(row[k], 0.0, 1e-8 * kYield);
    EXPECT_NEAR(std::log(1 + release.q[2]), alpha, 1e-9);
    EXPECT_NEAR(std::log(1 + release.q[5]), -alpha / 2, 1e-9);
    std::printf(
        "uniaxial %-6s to log strain 0.5: worst |sigma - closed form| / sigma = %.1e, lateral log strain %.1e, "
        "sigma = %.2f, alpha = %.4f, |det Fp - 1| = %.1e\n",
        law.name, worst, worst_lateral, tau * std::exp(-(1 - 2 * kPoisson) * tau / kYoung), alpha, volume_error);
  }
}

TEST(J2Finite, SimpleShearKeepsTheVolumeAndReleasesTheElasticPart) {
  for (const Law& law : laws()) {
    SCOPED_TRACE(law.name);
    const auto m = material(law, PlaneAnalysis::plane_strain);
    ContinuumBody body(unit_square(), {0, 1}, {m}, finite(PlaneAnalysis::plane_strain));
    Driver d(body, std::vector<char>(8, 1));  // u = gamma y, v = 0 at every node
    double worst_mean = 0.0, worst_yield = 0.0, alpha = 0.0;
    for (int k = 1; k <= 20; ++k) {
      const double gamma = 0.05 * k;
      d.solve([&](Vector& q) { q[4] = q[6] = gamma; }, 1e-9 * kYield);
      const std::vector<double> row = d.element_row(0);
      EXPECT_GT(row[4], alpha);  // the plastic strain grows on every step
      alpha = row[4];
      const double mean = (row[0] + row[1] + row[3]) / 3;
      worst_mean = std::max(worst_mean, std::abs(mean) / kYield);
      // J = 1: Cauchy = Kirchhoff, whose von Mises stress is sigma_y(alpha) while it flows.
      const double s[3][3] = {{row[0] - mean, row[2], 0}, {row[2], row[1] - mean, 0}, {0, 0, row[3] - mean}};
      double ss = 0.0;
      for (const auto& r : s)
        for (double v : r) ss += v * v;
      worst_yield = std::max(worst_yield, std::abs(std::sqrt(1.5 * ss) - law.yield_stress(alpha)) / kYield);
    }
    EXPECT_LT(worst_mean, 1e-9);
    EXPECT_LT(worst_yield, 1e-9);
    const double volume_error = worst_plastic_volume(body);
    EXPECT_LT(volume_error, 1e-12);
    // Released, one node held and one y: stress free, so F^T F = Cp at every point.
    std::vector<char> pinned(8, 0);
    pinned[0] = pinned[1] = pinned[3] = 1;
    Driver release(body, pinned);
    release.q = d.q;
    release.solve([](Vector&) {}, 1e-9 * kYield);
    const std::vector<double> row = release.element_row(0);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(row[k], 0.0, 1e-8 * kYield);
    const Mat2 F = Mat2::Identity() + (Mat2() << release.q[2] - release.q[0], release.q[6] - release.q[0],
                                       release.q[3] - release.q[1], release.q[7] - release.q[1])
                                          .finished();
    const PointHistory& h = body.committed_history()[0];
    const double mismatch = (tensor(h.plastic_metric_inverse) * F.transpose() * F - Mat2::Identity()).norm();
    EXPECT_LT(mismatch, 1e-9);
    std::printf(
        "simple shear %-6s to gamma 1: |mean stress| / sigma_y <= %.1e, |q_mises - sigma_y| / sigma_y <= %.1e, "
        "alpha = %.4f, |det Fp - 1| = %.1e; released |Cp^-1 C - I| = %.1e\n",
        law.name, worst_mean, worst_yield, alpha, volume_error, mismatch);
  }
}

// Bent in steps of 0.025 to 0.4 (plane strain: strains of ~4 %, 30 times the yield strain) or
// 0.2 (plane stress). The driver's plain Newton (no line search, a predictor on the last
// tangent) fails on q8 with steps of 0.05, as it does with the small-strain law; in plane
// stress beyond 0.25 on q4, and on q8 from 0.075 on with either law: a question of the driver,
// which the tests of the law need not answer.
void bend_far(Driver& d, const Bent& b, PlaneAnalysis analysis, double tolerance) {
  const int steps = analysis == PlaneAnalysis::plane_strain ? 16 : 8;
  for (int k = 1; k <= steps; ++k) bend(d, b, 0.025 * k, tolerance);
}

struct Case {
  const char* name;
  PlaneAnalysis analysis;
  ContinuumElement element;
  Incompressibility incompressibility;
};

const Case kCases[] = {
    {"q4 plane strain", PlaneAnalysis::plane_strain, ContinuumElement::q4, Incompressibility::none},
    {"q8 plane strain", PlaneAnalysis::plane_strain, ContinuumElement::q8, Incompressibility::none},
    {"q4 plane stress", PlaneAnalysis::plane_stress, ContinuumElement::q4, Incompressibility::none},
    {"q4 f_bar plane strain", PlaneAnalysis::plane_strain, ContinuumElement::q4, Incompressibility::f_bar},
    {"q9 mixed plane strain", PlaneAnalysis::plane_strain, ContinuumElement::q9, Incompressibility::mixed},
    {"t6 mixed plane strain", PlaneAnalysis::plane_strain, ContinuumElement::t6, Incompressibility::mixed},
};

// The mixed q9 overshoots with the plain Newton on the third step of 0.025 (the residual stalls
// at 8e-2), and converges in 6 to 9 iterations with the driver's line search, which leaves full
// steps near the solution (where the rate is read).
bool needs_line_search(const Case& c) { return c.incompressibility == Incompressibility::mixed; }

TEST(J2Finite, ConsistentTangentMatchesDifferencesOfTheForce) {
  for (const Case& c : kCases)
    for (const Law& law : laws()) {
      SCOPED_TRACE(std::string(law.name) + " " + c.name);
      Bent b = bent_block(material(law, c.analysis), finite(c.analysis, c.element, c.incompressibility));
      Driver d(*b.body, b.held);
      d.line_search = needs_line_search(c);
      bend_far(d, b, c.analysis, 1e-9 * kYield);  // a committed plastic history
      const auto check = testing::check_tangent_beyond(*b.body, d.q, 0.01);
      EXPECT_GT(check.flowing, 0);
      const double error = check.error();
      EXPECT_LT(error, 1e-6);
      EXPECT_LT(check.asymmetry(), 1e-9);
      std::printf("tangent %-6s %-22s |K - K_fd| / |K| = %.1e (%d of %zu elements flowing)\n", law.name, c.name, error,
                  check.flowing, check.elements);
    }
}

TEST(J2Finite, NewtonConvergesQuadraticallyOnAPlasticStep) {
  for (const Case& c : kCases)
    for (const Law& law : laws()) {
      SCOPED_TRACE(std::string(law.name) + " " + c.name);
      Bent b = bent_block(material(law, c.analysis), finite(c.analysis, c.element, c.incompressibility));
      Driver d(*b.body, b.held);
      d.line_search = needs_line_search(c);
      bend_far(d, b, c.analysis, 1e-10 * kYield);
      const std::vector<double>& r = d.residuals;
      const std::string line = testing::relative_residuals(r);
      std::printf("Newton %-6s %-22s relative residuals:%s\n", law.name, c.name, line.c_str());
      // Near the solution (e_k < 1e-3): e_{k+1} <= c e_k^2 (relative to the first residual), c = 10;
      // 20 for t6 mixed, whose constant is 14 (1.4e-4, 2.7e-7, 1.1e-12). Below 1e-11 the
      // residual is round-off.
      const double c2 = c.element == ContinuumElement::t6 ? 20 : 10;
      int quadratic = 0;
      for (size_t k = 1; k + 1 < r.size(); ++k) {
        const double ek = r[k] / r[0], next = r[k + 1] / r[0];
        if (ek >= 1e-3) continue;
        EXPECT_LE(next, std::max(c2 * ek * ek, 1e-11)) << "iteration " << k;
        quadratic += c2 * ek * ek >= 1e-11;
      }
      EXPECT_GE(quadratic, 1);
      EXPECT_LE(r.size(), 10u);
      EXPECT_LT(worst_plastic_volume(*b.body), 1e-12);
    }
}

TEST(J2Finite, SmallStrainLimitIsTheSmallStrainLaw) {
  // Yield strain 1.25e-8: the block yields at strains where the finite and small measures
  // differ by 1e-7 relative.
  const double scale = 1e-5;
  for (PlaneAnalysis analysis : {PlaneAnalysis::plane_strain, PlaneAnalysis::plane_stress})
    for (const Law& law : laws(scale)) {
      SCOPED_TRACE(std::string(law.name) +
                   (analysis == PlaneAnalysis::plane_strain ? " plane strain" : " plane stress"));
      const auto m = material(law, analysis, scale);
      Bent fin = bent_block(m, finite(analysis, ContinuumElement::q8));
      Bent lin = bent_block(m, small_strain(analysis, ContinuumElement::q8));
      Driver df(*fin.body, fin.held), dl(*lin.body, lin.held);
      FieldGap gap;
      // Loading to 6e-7 (4.5 times the tip deflection at first yield), unloading and reversing to -4e-7.
      std::vector<double> path;
      for (int k = 1; k <= 12; ++k) path.push_back(5e-8 * k);
      for (int k = 1; k <= 20; ++k) path.push_back(6e-7 - 5e-8 * k);
      for (double tip : path) {
        // The finite measures lose ~1e-9 of these strains to round-off (F^T F - I).
        bend(df, fin, tip, 1e-7 * kYield * scale);
        bend(dl, lin, tip, 1e-7 * kYield * scale);
        gap.add(fin.body->element_fields(df.q).rows, lin.body->element_fields(dl.q).rows);
      }
      EXPECT_GT(gap.peak_alpha, 1e-8);
      // Measured 5e-7 to 6.6e-7; the table in plane stress 1.05e-6 (not traced further: its
      // hardening is real at this scale, the other laws' moduli are scaled to nearly perfect plasticity).
      const bool table = law.hardening.kind == IsotropicHardening::Kind::table;
      EXPECT_LT(gap.stress, table ? 1.5e-6 : 1e-6);
      EXPECT_LT(gap.alpha, 1e-6 * gap.peak_alpha);
      std::printf("small-strain limit %-6s %s: |sigma_finite - sigma_small| / peak <= %.1e, alpha %.1e of %.1e\n",
                  law.name, analysis == PlaneAnalysis::plane_strain ? "plane strain" : "plane stress", gap.stress,
                  gap.alpha, gap.peak_alpha);
    }
}

}  // namespace
}  // namespace grip
