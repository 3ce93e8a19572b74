// Hill's 1948 anisotropy with linear kinematic hardening (j2_plasticity, docs/algorithm.md#hill-1948-anisotropy):
// - r = 1 gives the von Mises kinematic law's stresses, back stress and alpha to round-off on a
//   mixed path (loaded, turned, reversed, unloaded), plane strain, plane stress and axisymmetric,
//   small strain and finite strain (the return on the log strain);
// - uniaxial stress of a sheet at 0, 45 and 90 degrees to the rolling direction, tension then
//   compression then tension, against the one-dimensional closed form below: the stress, alpha,
//   the back stress, the r-value of the plastic strain (kept), and the reverse-yield stress
//   2 sigma_y(alpha) / k below the peak (Bauschinger);
// - the point's consistent tangent against central differences of the return, and symmetric.
// Newton's rate and the body's tangent: j2_hill48_test.cpp (small strain) and
// j2_finite_log_strain_test.cpp (finite strain).
//
// The closed form. Uniaxial stress sigma u (u = n (x) n, n at angle t to the rolling direction),
// Hill's factor k = sigma_bar(u). Ziegler's rule d b = H_k d gamma dev(s - b) keeps the back
// stress along dev u: b = B dev u, so s - b = (sigma - B) u + a hydrostatic part, which M does
// not see, and sigma_bar(s - b) = k |sigma - B|. The flow d eps_p = d gamma (sigma - B) M u has
// the part u . d eps_p = d gamma (sigma - B) k^2 along the direction, while d alpha =
// d gamma sigma_bar = d gamma k |sigma - B|: d eps_p(along) = k d alpha sign(sigma - B), and
// d B = H_k d gamma (sigma - B) = (H_k / k^2) d eps_p(along). So, with eps_p the plastic strain along
// the direction:
//   sigma = E (eps - eps_p),  |sigma - B| <= sigma_y(alpha) / k,  B = (H_k / k^2) eps_p,
//   d alpha = |d eps_p| / k,
// the yield stress sigma_y / k of the direction and its kinematic modulus H_k / k^2 (with linear
// isotropic hardening H the plastic slope (H + H_k) / k^2). Reverse flow starts where
// sigma - B = -sigma_y(alpha) / k, 2 sigma_y(alpha) / k below the peak. The plastic strain stays
// along M u, so the r-value of each direction is kept through the cycle.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "solver/materials/j2_plasticity.hpp"
#include "tests/support/hill48_uniaxial.hpp"
#include "tests/support/j2_laws.hpp"

namespace grip {
namespace {

using namespace testing::j2;
using testing::hill_factor;
using testing::UniaxialPoint;
using testing::analysis_name;
using testing::anisotropy;
using testing::kAnalyses;
using testing::kSheet;

constexpr double kKinematic = 10000.0;  // H_k: 5 % of E
// Laws with isotropic hardening and one with kinematic hardening alone.
std::vector<Law> kinematic_laws() {
  std::vector<Law> all = laws();
  all.push_back({"none", IsotropicHardening{}});
  return all;
}

// A mixed path in units of `size`: loaded, turned (shear, the other normal strains), reversed
// and unloaded, ten steps between its corners; (11, 22, 2 x 12, 33), 33 unused in plane strain.
std::vector<Eigen::Vector4d> mixed_path(double size, PlaneAnalysis a) {
  const Eigen::Vector4d corners[] = {{0, 0, 0, 0},         {1, -0.3, 0.8, 0.2}, {-0.5, 1, -1, 0.3},
                                     {-1, 0.2, 0.5, -0.6}, {0.4, -0.2, 0, 0.1}, {0, 0, 0, 0}};
  std::vector<Eigen::Vector4d> path;
  for (int c = 1; c < 6; ++c)
    for (int s = 1; s <= 10; ++s) {
      Eigen::Vector4d e = size * (corners[c - 1] + 0.1 * s * (corners[c] - corners[c - 1]));
      if (a == PlaneAnalysis::plane_strain) e[3] = 0.0;
      path.push_back(e);
    }
  return path;
}

// The differences of two points' answers along a path: stress and back stress over sigma_y,
// alpha absolute; the peaks of alpha and |back stress| of the second.
struct Gap {
  double stress = 0.0, back = 0.0, alpha = 0.0, peak_alpha = 0.0, peak_back = 0.0;
  void add(const Eigen::Vector4d& s1, const Eigen::Vector4d& s2, const PointHistory& h1, const PointHistory& h2) {
    stress = std::max(stress, (s1 - s2).cwiseAbs().maxCoeff() / kYield);
    back = std::max(back, (h1.back_stress - h2.back_stress).cwiseAbs().maxCoeff() / kYield);
    alpha = std::max(alpha, std::abs(h1.equivalent_plastic_strain - h2.equivalent_plastic_strain));
    peak_alpha = std::max(peak_alpha, h2.equivalent_plastic_strain);
    peak_back = std::max(peak_back, h2.back_stress.norm());
  }
};

TEST(Hill48Kinematic, RValuesOfOneAreTheVonMisesKinematicLaw) {
  for (bool finite : {false, true})
    for (PlaneAnalysis a : kAnalyses)
      for (const Law& law : kinematic_laws()) {
        const std::string name = std::string(law.name) + " " + analysis_name(a) + (finite ? " finite" : " small");
        SCOPED_TRACE(name);
        const auto mises = material(law, a, 1.0, std::nullopt, kKinematic);
        const auto hill = material(law, a, 1.0, Hill48{}, kKinematic);
        PointHistory hm, hh;
        Gap gap;
        int flowing = 0;
        // Six yield strains at small strain; 0.05 of Green-Lagrange strain at finite strain.
        for (const Eigen::Vector4d& e : mixed_path(finite ? 0.05 : 6 * kYield / kYoung, a)) {
          Eigen::Vector4d sm, sh;
          PointHistory nm, nh;
          bool ym = false, yh = false;
          if (!finite) {
            const PointResponse rm = mises->small_strain_response(e, hm), rh = hill->small_strain_response(e, hh);
            sm = rm.stress, sh = rh.stress, nm = rm.history, nh = rh.history, ym = rm.yielding, yh = rh.yielding;
          } else {
            const Mat2 E = (Mat2() << e[0], 0.5 * e[2], 0.5 * e[2], e[1]).finished();
            if (a == PlaneAnalysis::axisymmetric) {
              const FiniteHoopResponse rm = mises->finite_hoop_response(E, e[3], hm);
              const FiniteHoopResponse rh = hill->finite_hoop_response(E, e[3], hh);
              sm = rm.law.S, sh = rh.law.S, nm = rm.history, nh = rh.history, ym = rm.yielding, yh = rh.yielding;
            } else {
              const FinitePointResponse rm = mises->finite_response(E, hm), rh = hill->finite_response(E, hh);
              sm << rm.law.S, rm.law.S33;
              sh << rh.law.S, rh.law.S33;
              nm = rm.history, nh = rh.history, ym = rm.yielding, yh = rh.yielding;
            }
          }
          EXPECT_EQ(ym, yh);
          flowing += ym;
          gap.add(sh, sm, nh, nm);
          hm = nm;
          hh = nh;
        }
        EXPECT_GT(flowing, 10);
        EXPECT_GT(gap.peak_back, 0.1 * kYield);
        EXPECT_LT(gap.stress, 1e-10);
        EXPECT_LT(gap.back, 1e-10);
        EXPECT_LT(gap.alpha, 1e-10 * gap.peak_alpha);
        std::printf(
            "hill48 + kinematic r = 1 %-28s: |sigma - von Mises| / sigma_y <= %.1e, |b - b_vM| / sigma_y <= %.1e "
            "(|b| to %.0f), alpha %.1e of %.4f; %d of 50 steps flowing\n",
            name.c_str(), gap.stress, gap.back, gap.peak_back, gap.alpha, gap.peak_alpha, flowing);
      }
}

// The one-dimensional closed form above along a direction of Hill's factor k.
struct Closed {
  const J2Material& m;
  double k;
  double eps_p = 0.0, alpha = 0.0, B = 0.0;
  bool yielding = false;

  double stress(double e) {
    const double hk = kKinematic / (k * k);
    const double xi = kYoung * (e - eps_p) - B;
    yielding = k * std::abs(xi) > m.yield_stress(alpha) * (1 + 1e-12);
    if (yielding) {
      // alpha moves by d: |xi| falls by (E + hk) k d to sigma_y(alpha + d) / k (bisection: the
      // power law's root is implicit).
      double lo = 0.0, hi = std::abs(xi) / ((kYoung + hk) * k);
      for (int it = 0; it < 200; ++it) {
        const double d = 0.5 * (lo + hi);
        (std::abs(xi) - (kYoung + hk) * k * d > m.yield_stress(alpha + d) / k ? lo : hi) = d;
      }
      const double d = 0.5 * (lo + hi);
      eps_p += std::copysign(k * d, xi);
      B += std::copysign(hk * k * d, xi);
      alpha += d;
    }
    return kYoung * (e - eps_p);
  }
};

// The strain at which `p` (at a peak, strain e_peak) starts to flow backwards, by bisection on
// the strain; returns the stress there.
double reverse_yield(const UniaxialPoint& p, double e_peak, double e_low) {
  double lo = e_low, hi = e_peak, sigma = 0.0;
  for (int it = 0; it < 60; ++it) {
    UniaxialPoint q = p;
    const double e = 0.5 * (lo + hi);
    sigma = q.stretch(e);
    (q.response.yielding ? lo : hi) = e;
  }
  return sigma;
}

TEST(Hill48Kinematic, UniaxialCycleAcrossTheSheetFollowsTheClosedForm) {
  const double r_of[] = {kSheet.r0, kSheet.r45, kSheet.r90};
  for (const Law& law : kinematic_laws())
    for (int d = 0; d < 3; ++d) {
      const double angle = 0.25 * std::numbers::pi * d;
      SCOPED_TRACE(std::string(law.name) + " at " + std::to_string(45 * d) + " degrees");
      const auto m = material(law, PlaneAnalysis::plane_stress, 1.0, kSheet, kKinematic);
      const double k = hill_factor(kSheet, angle), ey = kYield / (k * kYoung);
      UniaxialPoint p{*m, angle};
      Closed closed{*m, k};
      // dev(n (x) n) as (11, 22, 12, 33): the closed form's back stress is B times it.
      const double c = std::cos(angle), s = std::sin(angle);
      const Eigen::Vector4d dev_u = Eigen::Vector4d(c * c, s * s, c * s, 0) - Eigen::Vector4d(1, 1, 0, 1) / 3;
      // Steps of 0.3 yield strains: to 12, to -12 and back to 12.
      std::vector<double> path;
      for (int i = 1; i <= 40; ++i) path.push_back(0.3 * i * ey);
      for (int i = 1; i <= 80; ++i) path.push_back((12 - 0.3 * i) * ey);
      for (int i = 1; i <= 80; ++i) path.push_back((-12 + 0.3 * i) * ey);
      double worst = 0.0, worst_back = 0.0, worst_r = 0.0, worst_reverse = 0.0, peak = 0.0, reverse = 0.0;
      double e_prev = 0.0, sigma_prev = 0.0;
      for (size_t i = 0; i < path.size(); ++i) {
        const double e = path[i];
        // At each turn of the strain (the peaks 12 and -12), the reverse-yield stress.
        if (i == 40 || i == 120) {
          const double expected = sigma_prev - std::copysign(2 * m->yield_stress(closed.alpha) / k, sigma_prev);
          const double found = reverse_yield(p, e_prev, e_prev - 2 * (e_prev - e) * 20);
          worst_reverse = std::max(worst_reverse, std::abs(found - expected) / kYield);
          if (i == 40) peak = sigma_prev, reverse = found;
        }
        const double sigma = p.stretch(e), expected = closed.stress(e);
        worst = std::max(worst, std::abs(sigma - expected) / kYield);
        EXPECT_NEAR(p.history.equivalent_plastic_strain, closed.alpha, 1e-12);
        EXPECT_EQ(p.response.yielding, closed.yielding) << "step " << i;
        worst_back = std::max(worst_back, (p.history.back_stress - closed.B * dev_u).cwiseAbs().maxCoeff() / kYield);
        if (closed.alpha > 0) worst_r = std::max(worst_r, std::abs(p.r_value() - r_of[d]) / r_of[d]);
        e_prev = e;
        sigma_prev = sigma;
      }
      EXPECT_GT(closed.alpha, 20 * ey);
      EXPECT_LT(worst, 1e-10);
      EXPECT_LT(worst_back, 1e-10);
      EXPECT_LT(worst_r, 1e-9);
      EXPECT_LT(worst_reverse, 1e-9);
      std::printf(
          "hill48 + kinematic %-6s %2d deg: sigma_y / k %.2f, H_k / k^2 %.0f; |sigma - closed form| / sigma_y <= "
          "%.1e, back stress %.1e, r %.7f (given %.1f, within %.1e); peak %.2f, reverse flow from %.2f (peak - 2 "
          "sigma_y(alpha) / k within %.1e sigma_y); alpha %.5f\n",
          law.name, 45 * d, kYield / k, kKinematic / (k * k), worst, worst_back, p.r_value(), r_of[d], worst_r, peak,
          reverse, worst_reverse, closed.alpha);
    }
}

TEST(Hill48Kinematic, PointTangentIsTheDerivativeOfTheReturnAndSymmetric) {
  for (PlaneAnalysis a : kAnalyses)
    for (const Law& law : kinematic_laws()) {
      SCOPED_TRACE(std::string(law.name) + " " + analysis_name(a));
      const auto m = material(law, a, 1.0, anisotropy(a), kKinematic);
      // A committed history from a mixed path, then a plastic step beyond it.
      PointHistory h;
      const std::vector<Eigen::Vector4d> path = mixed_path(6 * kYield / kYoung, a);
      for (size_t i = 0; i < 25; ++i) h = m->small_strain_response(path[i], h).history;
      Eigen::Vector4d strain = path[24] + kYield / kYoung * Eigen::Vector4d(-0.7, 0.4, 0.9, 0.3);
      if (a == PlaneAnalysis::plane_strain) strain[3] = 0.0;
      const PointResponse r = m->small_strain_response(strain, h);
      EXPECT_TRUE(r.yielding);
      const int n = a == PlaneAnalysis::axisymmetric ? 4 : 3;  // 33 a strain of axisymmetry only
      const double step = 1e-6 * kYield / kYoung;
      Eigen::Matrix4d fd = Eigen::Matrix4d::Zero();
      for (int j = 0; j < n; ++j) {
        Eigen::Vector4d e = strain;
        e[j] += step;
        const Eigen::Vector4d up = m->small_strain_response(e, h).stress;
        e[j] -= 2 * step;
        fd.col(j) = (up - m->small_strain_response(e, h).stress) / (2 * step);
      }
      const Eigen::MatrixXd D = r.D.topLeftCorner(n, n), F = fd.topLeftCorner(n, n);
      const double error = (D - F).norm() / D.norm(), asymmetry = (D - D.transpose()).norm() / D.norm();
      EXPECT_LT(error, 1e-7);
      EXPECT_LT(asymmetry, 1e-12);
      std::printf("hill48 + kinematic tangent %-6s %-12s: |D - D_fd| / |D| = %.1e, asymmetry %.1e\n", law.name,
                  analysis_name(a), error, asymmetry);
    }
}

}  // namespace
}  // namespace grip
