// Hill's 1948 anisotropy of j2_plasticity at small strain (docs/algorithm.md#hill-1948-anisotropy;
// at finite strain: j2_finite_log_strain_test.cpp):
// - uniaxial tension of a sheet (plane stress) at 0, 45 and 90 degrees to the rolling direction,
//   one point driven along the direction with the two other stresses zero: the yield stress
//   sigma_y / k, k^2 = F s^4 + G c^4 + H (c^2 - s^2)^2 + 2 N c^2 s^2 (Hill's formula with
//   F, G, H, N from r0, r45, r90), the plastic branch sigma = sigma_y(alpha) / k with the strain
//   along the direction sigma / E + k alpha (work-conjugate alpha), and the width to thickness
//   plastic strain ratio r of each direction, linear and Swift hardening;
// - r = 1 gives the von Mises law's numbers (a bent block, plane strain, plane stress and
//   axisymmetric, loaded, unloaded and reversed) to 1e-10;
// - the consistent tangent against central differences of the internal force, and Newton's
//   quadratic convergence on a plastic step, with planar anisotropy (plane stress, plane strain)
//   and normal anisotropy (axisymmetric), with and without kinematic hardening (its closed
//   forms: j2_hill48_kinematic_test.cpp);
// - bad data refused with its pointer: r <= 0, r45 in plane strain, planar anisotropy in
//   axisymmetry, a negative kinematic hardening modulus; kinematic hardening itself accepted.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>

#include "solver/elements/continuum.hpp"
#include "solver/materials/j2_plasticity.hpp"
#include "tests/support/continuum_blocks.hpp"
#include "tests/support/hill48_uniaxial.hpp"
#include "tests/support/j2_laws.hpp"
#include "tests/support/newton_driver.hpp"
#include "tests/support/scenes.hpp"
#include "tests/support/tangent_check.hpp"

namespace grip {
namespace {

using testing::Bent;
using testing::bend;
using testing::bent_block;
using testing::Driver;
using testing::small_strain;
using testing::hill_factor;
using testing::UniaxialPoint;
using testing::analysis_name;
using testing::anisotropy;
using testing::kAnalyses;
using testing::kSheet;

using namespace testing::j2;

std::shared_ptr<J2Material> material(const Law& law, PlaneAnalysis analysis, std::optional<Hill48> hill,
                                     double kinematic = 0.0) {
  return testing::j2::material(law, analysis, 1.0, hill, kinematic);
}

// The closed form along the direction: sigma = E e (elastic) or E (e - k alpha) = sigma_y(alpha) / k.
double uniaxial_closed_form(const J2Material& m, double k, double e, double* alpha) {
  *alpha = 0.0;
  if (kYoung * e <= m.yield_stress(0) / k) return kYoung * e;
  double lo = 0.0, hi = e / k;
  for (int it = 0; it < 200; ++it) {
    const double a = 0.5 * (lo + hi);
    (m.yield_stress(a) / k > kYoung * (e - k * a) ? hi : lo) = a;
  }
  *alpha = 0.5 * (lo + hi);
  return m.yield_stress(*alpha) / k;
}

TEST(Hill48, UniaxialTensionAlongTheSheetGivesHillsYieldStressAndTheRValues) {
  const double r_of[] = {kSheet.r0, kSheet.r45, kSheet.r90};
  for (const Law& law : laws())
    for (int d = 0; d < 3; ++d) {
      const double angle = 0.25 * std::numbers::pi * d;
      SCOPED_TRACE(std::string(law.name) + " at " + std::to_string(45 * d) + " degrees");
      const auto m = material(law, PlaneAnalysis::plane_stress, kSheet);
      const double k = hill_factor(kSheet, angle), first_yield = kYield / k;
      UniaxialPoint p{*m, angle};
      double worst = 0.0, alpha = 0.0, e = 0.0;
      bool yielded = false;
      // Through first yield in small steps, then on to 20 yield strains.
      for (int s = 1; s <= 40; ++s) {
        e = (s <= 20 ? 0.1 * s : 2.0 + 0.9 * (s - 20)) * first_yield / kYoung;
        const double sigma = p.stretch(e);
        const double expected = uniaxial_closed_form(*m, k, e, &alpha);
        worst = std::max(worst, std::abs(sigma - expected) / kYield);
        EXPECT_NEAR(p.history.equivalent_plastic_strain, alpha, 1e-12);
        // Elastic up to sigma_y / k, flowing beyond.
        EXPECT_EQ(p.response.yielding, kYoung * e > first_yield * (1 + 1e-12));
        yielded |= p.response.yielding;
      }
      EXPECT_TRUE(yielded);
      EXPECT_LT(worst, 1e-10);
      const Eigen::Vector4d& ep = p.history.plastic_strain;
      const double r = p.r_value();
      EXPECT_NEAR(r, r_of[d], 1e-9 * r_of[d]);
      // Plastic flow keeps the volume.
      EXPECT_NEAR(ep[0] + ep[1] + ep[3], 0.0, 1e-12 * alpha);
      std::printf(
          "hill48 %-6s %2d deg: first yield %.3f (sigma_y / k), |sigma - closed form| / sigma_y <= %.1e, r = %.6f "
          "(given %.2f), alpha = %.5f\n",
          law.name, 45 * d, first_yield, worst, r, r_of[d], alpha);
    }
}

TEST(Hill48, RValuesOfOneAreVonMises) {
  for (PlaneAnalysis analysis : kAnalyses)
    for (const Law& law : laws()) {
      SCOPED_TRACE(std::string(law.name) + " " + analysis_name(analysis));
      Bent mises = bent_block(material(law, analysis, std::nullopt), small_strain(analysis, ContinuumElement::q8));
      Bent hill = bent_block(material(law, analysis, Hill48{}), small_strain(analysis, ContinuumElement::q8));
      Driver dm(*mises.body, mises.held), dh(*hill.body, hill.held);
      double worst = 0.0, worst_alpha = 0.0, peak_alpha = 0.0;
      for (double tip : {0.01, 0.02, 0.03, 0.015, 0.0, -0.02}) {
        bend(dm, mises, tip, 1e-10 * kYield);
        bend(dh, hill, tip, 1e-10 * kYield);
        const auto rm = mises.body->element_fields(dm.q).rows, rh = hill.body->element_fields(dh.q).rows;
        for (size_t e = 0; e < rm.size(); ++e) {
          for (int c = 0; c < 4; ++c) worst = std::max(worst, std::abs(rm[e][c] - rh[e][c]) / kYield);
          worst_alpha = std::max(worst_alpha, std::abs(rm[e][4] - rh[e][4]));
          peak_alpha = std::max(peak_alpha, rm[e][4]);
          EXPECT_EQ(rm[e][5], rh[e][5]);
        }
      }
      EXPECT_GT(peak_alpha, 2e-4);
      EXPECT_LT(worst, 1e-10);
      EXPECT_LT(worst_alpha, 1e-10 * peak_alpha);
      std::printf("hill48 r = 1 %-6s %-12s: |sigma - von Mises| / sigma_y <= %.1e, alpha %.1e of %.4f\n", law.name,
                  analysis_name(analysis), worst, worst_alpha, peak_alpha);
    }
}

TEST(Hill48, ConsistentTangentMatchesDifferencesAndNewtonConvergesQuadratically) {
  // q8 and t6, and q8 with kinematic hardening (H_k 5 % of E).
  const std::pair<ContinuumElement, double> kinds[] = {
      {ContinuumElement::q8, 0.0}, {ContinuumElement::t6, 0.0}, {ContinuumElement::q8, 10000.0}};
  for (PlaneAnalysis analysis : kAnalyses)
    for (const auto& [element, kinematic] : kinds)
      for (const Law& law : laws()) {
        const std::string name = std::string(element_name(element)) + (kinematic > 0 ? "+Hk" : "");
        SCOPED_TRACE(std::string(law.name) + " " + name + " " + analysis_name(analysis));
        Bent b = bent_block(material(law, analysis, anisotropy(analysis), kinematic), small_strain(analysis, element));
        Driver d(*b.body, b.held);
        bend(d, b, 0.01, 1e-10 * kYield);
        // With kinematic hardening, and with the table (q8 in plane strain: 4.9e-6 to 5.7e-13), a
        // longer step: from 0.03 Newton reaches round-off from ~6e-6 in one step, leaving its rate unseen.
        const bool longer = kinematic > 0 || law.hardening.kind == IsotropicHardening::Kind::table;
        bend(d, b, longer ? 0.05 : 0.03, 1e-10 * kYield);
        const std::vector<double> r = d.residuals;
        EXPECT_GE(testing::expect_quadratic(r), 1);
        EXPECT_LE(r.size(), 8u);
        const auto c = testing::check_tangent_beyond(*b.body, d.q, 0.004);
        EXPECT_GT(c.flowing, 0);
        EXPECT_LT(c.error(), 1e-6);
        EXPECT_LT(c.asymmetry(), 1e-12);
        const std::string line = testing::relative_residuals(r);
        std::printf("hill48 %-6s %-6s %-12s |K - K_fd| / |K| = %.1e, asymmetry %.0e (%d of %zu flowing); Newton:%s\n",
                    law.name, name.c_str(), analysis_name(analysis), c.error(), c.asymmetry(), c.flowing, c.elements,
                    line.c_str());
      }
}

TEST(Hill48, BadDataIsRefusedWithItsPointer) {
  const auto scene = [](const std::string& analysis, const nlohmann::json& hill) {
    nlohmann::json j = testing::example_scene("hertz");
    j["body"]["element"] = "q8";
    j["body"]["analysis"] = analysis;
    j["body"]["material"].update(
        {{"law", "j2_plasticity"}, {"yield_stress", 2000.0}, {"hardening", {{"linear", 20000.0}}}, {"hill48", hill}});
    return j;
  };
  const auto pointer = [](const nlohmann::json& j) {
    const std::string refusal = testing::first_refusal(j);
    return refusal.substr(0, refusal.find(':'));
  };
  EXPECT_EQ(pointer(scene("plane_stress", {{"r0", 0.0}, {"r45", 1.0}, {"r90", 1.2}})), "/body/material/hill48/r0");
  EXPECT_EQ(pointer(scene("plane_stress", {{"r0", 1.0}, {"r45", -1.0}, {"r90", 1.2}})), "/body/material/hill48/r45");
  EXPECT_EQ(pointer(scene("plane_strain", {{"r", 0.0}})), "/body/material/hill48/r");
  EXPECT_EQ(pointer(scene("plane_stress", {{"r0", 1.0}, {"r90", 1.2}})), "/body/material/hill48/r45");
  EXPECT_EQ(pointer(scene("plane_strain", {{"r0", 1.0}, {"r45", 1.0}, {"r90", 1.2}})), "/body/material/hill48/r45");
  EXPECT_EQ(pointer(scene("plane_strain", {{"r", 1.0}, {"r0", 1.2}})), "/body/material/hill48/r0");
  // Kinematic hardening goes with Hill's anisotropy; a negative modulus does not, nor does r45
  // in plane strain with it.
  nlohmann::json kinematic = scene("plane_strain", {{"r", 1.5}});
  kinematic["body"]["material"]["kinematic_hardening"] = 1000.0;
  EXPECT_EQ(testing::first_refusal(kinematic), "accepted");
  kinematic["body"]["material"]["kinematic_hardening"] = -1000.0;
  EXPECT_EQ(pointer(kinematic), "/body/material/kinematic_hardening");
  kinematic["body"]["material"]["kinematic_hardening"] = 1000.0;
  kinematic["body"]["material"]["hill48"] = {{"r0", 1.0}, {"r45", 1.1}, {"r90", 1.2}};
  EXPECT_EQ(pointer(kinematic), "/body/material/hill48/r45");
  nlohmann::json elastic = scene("plane_strain", {{"r", 1.5}});
  elastic["body"]["material"] = {{"young", 2e5}, {"poisson", 0.3}, {"hill48", {{"r", 1.5}}}};
  EXPECT_EQ(pointer(elastic), "/body/material/hill48");
  // The material itself refuses the same.
  EXPECT_EQ(hill48_data_issue({1.0, 1.0, 0.0}, PlaneAnalysis::plane_stress).rfind("hill48/r90:", 0), 0u);
  EXPECT_EQ(hill48_data_issue({1.0, 1.2, 1.0}, PlaneAnalysis::axisymmetric).rfind("hill48:", 0), 0u);
  EXPECT_THROW(material(laws()[0], PlaneAnalysis::plane_stress, Hill48{-1.0, 1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(material(laws()[0], PlaneAnalysis::plane_stress, kSheet, -1.0), std::invalid_argument);
  EXPECT_NO_THROW(material(laws()[0], PlaneAnalysis::plane_stress, kSheet, 1000.0));
  // A good one reads and runs.
  EXPECT_EQ(testing::first_refusal(scene("plane_strain", {{"r0", 2.1}, {"r90", 2.6}})), "accepted");
}

}  // namespace
}  // namespace grip
