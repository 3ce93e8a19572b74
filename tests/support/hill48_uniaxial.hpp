#pragma once
// Uniaxial stress of one plane-stress j2_plasticity point at an angle to the sheet's rolling
// direction, and Hill's factor of that direction (j2_hill48_test, j2_hill48_kinematic_test,
// j2_finite_log_strain_test).
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>

#include "solver/materials/j2_plasticity.hpp"
#include "tests/support/j2_laws.hpp"

namespace grip::testing {

// The Hill tests' anisotropy: a steel-like sheet (r0 < r90, r45 the lowest) in plane stress, its
// r0 and r90 in plane strain, a normal r in axisymmetry.
inline const Hill48 kSheet{2.1, 1.6, 2.6};
inline const Hill48 kSection{2.1, 2.1, 2.6};
inline const Hill48 kNormal{1.8, 1.8, 1.8};
inline Hill48 anisotropy(PlaneAnalysis a) {
  return a == PlaneAnalysis::plane_stress ? kSheet : a == PlaneAnalysis::plane_strain ? kSection : kNormal;
}

inline const PlaneAnalysis kAnalyses[] = {PlaneAnalysis::plane_strain, PlaneAnalysis::plane_stress,
                                          PlaneAnalysis::axisymmetric};
inline const char* analysis_name(PlaneAnalysis a) {
  return a == PlaneAnalysis::plane_strain   ? "plane strain"
         : a == PlaneAnalysis::plane_stress ? "plane stress"
                                            : "axisymmetric";
}

// Hill's factor k of uniaxial stress at angle t to the rolling direction: sigma_bar = k sigma,
// k^2 = F s^4 + G c^4 + H (c^2 - s^2)^2 + 2 N c^2 s^2 (1 at t = 0).
inline double hill_factor(const Hill48& h, double t) {
  const double F = h.r0 / (h.r90 * (1 + h.r0)), G = 1 / (1 + h.r0), H = h.r0 / (1 + h.r0);
  const double N = (h.r0 + h.r90) * (1 + 2 * h.r45) / (2 * h.r90 * (1 + h.r0));
  const double c = std::cos(t), s = std::sin(t);
  return std::sqrt(F * std::pow(s, 4) + G * std::pow(c, 4) + H * std::pow(c * c - s * s, 2) + 2 * N * c * c * s * s);
}

// Uniaxial stress at angle t of one plane-stress point, the strain along it prescribed: the
// strain e n (x) n + b t (x) t + c sym(n (x) t) with b, c from sigma_tt = sigma_nt = 0
// (Newton's method on the consistent tangent); commits like a body.
struct UniaxialPoint {
  const J2Material& m;
  double angle;
  PointHistory history;
  PointResponse response;
  double b = 0.0, c = 0.0;

  Eigen::Vector2d n() const { return {std::cos(angle), std::sin(angle)}; }
  Eigen::Vector2d t() const { return {-std::sin(angle), std::cos(angle)}; }
  static Eigen::Vector4d voigt(const Mat2& E) { return {E(0, 0), E(1, 1), 2 * E(0, 1), 0.0}; }

  // The stress along the direction at strain e along it.
  double stretch(double e) {
    const Mat2 nn = n() * n().transpose(), tt = t() * t().transpose();
    const Mat2 nt = 0.5 * (n() * t().transpose() + t() * n().transpose());
    for (int it = 0;; ++it) {
      response = m.small_strain_response(voigt(e * nn + b * tt + c * nt), history);
      const Eigen::Vector4d& s = response.stress;
      const Mat2 S = (Mat2() << s[0], s[2], s[2], s[1]).finished();
      const Eigen::Vector2d residual(t().dot(S * t()), n().dot(S * t()));
      if (residual.norm() <= 1e-12 * j2::kYield) break;
      EXPECT_LT(it, 30) << "the uniaxial point did not converge";
      if (it == 30) break;
      // d sigma_tt and d sigma_nt per d b and d c.
      Eigen::Matrix2d J;
      for (int k = 0; k < 2; ++k) {
        const Eigen::Vector4d ds = response.D * voigt(k == 0 ? tt : nt);
        const Mat2 dS = (Mat2() << ds[0], ds[2], ds[2], ds[1]).finished();
        J.col(k) << t().dot(dS * t()), n().dot(dS * t());
      }
      const Eigen::Vector2d step = J.partialPivLu().solve(-residual);
      b += step[0];
      c += step[1];
    }
    history = response.history;
    const Eigen::Vector4d& s = response.stress;
    return n().dot((Mat2() << s[0], s[2], s[2], s[1]).finished() * n());
  }

  // The plastic strain's width (t t) to thickness (33) ratio.
  double r_value() const {
    const Eigen::Vector4d& ep = history.plastic_strain;
    const double width = t()[0] * t()[0] * ep[0] + t()[1] * t()[1] * ep[1] + t()[0] * t()[1] * ep[2];
    return width / ep[3];
  }
};

}  // namespace grip::testing
