// Hill's 1948 anisotropy for j2_plasticity (docs/algorithm.md#hill-1948-anisotropy): the yield
// function sigma_bar(s - b) - sigma_y(alpha) with sigma_bar^2 = s . M s and b the back stress,
// associative flow d eps_p = d gamma M (s - b), the equivalent plastic strain d alpha = d gamma
// sigma_bar (work-conjugate: (s - b) . d eps_p = sigma_bar d alpha) and Ziegler's rule
// d b = H_k d gamma dev(s - b) (at r = 1 Prager's 2/3 H_k d eps_p, the von Mises law's; Prager's
// rule itself would turn the flow away from M u in uniaxial tension u and drift the r-values).
// As d b = Kb d eps_p with the kinematic modulus Kb = H_k M^+ (M^+ M the deviatoric projector),
// the backward-Euler return (Simo and Hughes, Computational Inelasticity, sec. 3.4) is the
// closest point in the metric A = (C + Kb)^-1:
//   xi = s - b = Xi(dg) y,  Xi = (A + dg M)^-1,  y = A (C (eps - eps_p) - b),
// with dg the root of g(dg) = sigma_bar(xi(dg)) - sigma_y(alpha + dg sigma_bar); its consistent
// tangent, symmetric,
//   D = Kb - Kb A Kb + Q Xi Q^T - beta (Q Xi n)(Q Xi n)^T / (H' sigma_bar^2 + beta n . Xi n),
// n = M xi, beta = 1 - H' dg, Q = C A = I - Kb A. Without kinematic hardening A = C^-1, Q = I and
// this is s = Xi (eps - eps_p), D = Xi - ...; at r = 1, M is von Mises' and the return the radial one.
#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <string>

#include "solver/materials/j2_plasticity.hpp"

namespace grip {
namespace {

using Vec4 = Eigen::Vector4d;
using Mat4 = Eigen::Matrix4d;

// Hill's F, G, H (normal stresses) and N (the rolling-transverse shear) with the yield stress
// in the rolling direction as sigma_y (G + H = 1).
struct Coefficients {
  double F, G, H, N;
};

Coefficients coefficients(const Hill48& h) {
  return {h.r0 / (h.r90 * (1 + h.r0)), 1 / (1 + h.r0), h.r0 / (1 + h.r0),
          (h.r0 + h.r90) * (1 + 2 * h.r45) / (2 * h.r90 * (1 + h.r0))};
}

}  // namespace

std::string hill48_data_issue(const Hill48& h, PlaneAnalysis analysis) {
  for (const auto& [name, r] : {std::pair{"r0", h.r0}, std::pair{"r45", h.r45}, std::pair{"r90", h.r90}})
    if (!(r > 0 && std::isfinite(r)))
      return std::string("hill48/") + name + ": must be positive (the width to thickness plastic strain ratio)";
  if (analysis == PlaneAnalysis::plane_strain && h.r45 != h.r0)
    return "hill48/r45: has no role in plane strain (the section through the thickness: the sheet-plane shear that "
           "r45 sets is zero); give r0 and r90, or a normal r";
  if (analysis == PlaneAnalysis::axisymmetric && (h.r45 != h.r0 || h.r90 != h.r0))
    return "hill48: axisymmetry takes a normal r only (r0 = r45 = r90): planar anisotropy would vary round the "
           "circle";
  return {};
}

Mat4 hill48_metric(const Hill48& hill, PlaneAnalysis analysis) {
  const auto [F, G, H, N] = coefficients(hill);
  // Indices into s = (11, 22, 12, 33) of the rolling, transverse and normal directions, and
  // the coefficient of the in-plane shear (2 N between rolling and transverse; 3 = 2 x 3/2
  // through the thickness).
  int rolling = 0, transverse = 1, normal = 3;
  double shear = 2 * N;
  if (analysis != PlaneAnalysis::plane_stress) {
    transverse = 3;
    normal = 1;
    shear = 3.0;
  }
  Mat4 M = Mat4::Zero();
  // F (s_t - s_n)^2 + G (s_n - s_r)^2 + H (s_r - s_t)^2 + shear s_12^2.
  const auto add = [&M](int i, int j, double c) {
    M(i, i) += c;
    M(j, j) += c;
    M(i, j) -= c;
    M(j, i) -= c;
  };
  add(transverse, normal, F);
  add(normal, rolling, G);
  add(rolling, transverse, H);
  M(2, 2) = shear;
  return M;
}

PointResponse J2Material::hill_return(const Vec4& strain, const PointHistory& h) const {
  const double G = lame_.mu, K = lame_.lambda + 2 * G / 3;
  const Vec4 one(1, 1, 0, 1);
  Mat4 P;  // the deviatoric projector, strain (engineering shear) to tensor
  P << 2, -1, 0, -1, -1, 2, 0, -1, 0, 0, 1.5, 0, -1, -1, 0, 2;
  const Mat4 C = K * one * one.transpose() + 2 * G * P / 3;
  const Mat4& M = hill_metric_;
  // The kinematic modulus H_k M^+ (zero without kinematic hardening): M^+ M is the deviatoric
  // projector, so a plastic strain d eps_p = dg M xi moves the back stress by H_k dg dev(xi).
  Mat4 Kb = Mat4::Zero();
  if (kinematic_ > 0) {
    const Mat4 hydrostatic = one * one.transpose() / 3;
    Kb = kinematic_ * ((M + hydrostatic).inverse() - hydrostatic);
    Kb = 0.5 * (Kb + Kb.transpose());
  }
  const Mat4 A = (C + Kb).inverse();
  const Vec4 ee = strain - h.plastic_strain;
  const double a0 = h.equivalent_plastic_strain;
  const auto equivalent = [&M](const Vec4& s) { return std::sqrt(std::max(0.0, s.dot(M * s))); };
  PointResponse r;
  r.history = h;
  r.stress = C * ee;
  r.D = C;
  const double trial = equivalent(r.stress - h.back_stress);
  if (trial - yield_stress(a0) <= 1e-12 * yield_stress_) return r;
  // xi = s - b = Xi(dg) y with y = A (C ee - b0) (= ee without a back stress). g(dg) decreases
  // from g(0) > 0 (sigma_bar falls, alpha grows); a bracket [lo, hi] found by doubling from the
  // von Mises estimate, then Newton's method kept inside it.
  const Vec4 y = ee - A * (Kb * ee + h.back_stress);
  Mat4 Xi;
  Vec4 xi;
  double bar = trial;
  const auto evaluate = [&](double dg) {
    Xi = (A + dg * M).inverse();
    xi = Xi * y;
    bar = equivalent(xi);
    return bar - yield_stress(a0 + dg * bar);
  };
  double lo = 0.0, hi = (trial - yield_stress(a0)) / (3 * G * yield_stress(a0));
  for (int it = 0; evaluate(hi) > 0; ++it) {
    if (it == 200) throw std::runtime_error("j2_plasticity: the hill48 return found no bracket");
    lo = hi;
    hi *= 2;
  }
  double dg = lo;
  for (int it = 0; it < 100; ++it) {
    const double g = evaluate(dg);
    if (std::abs(g) <= 1e-14 * trial) break;
    (g > 0 ? lo : hi) = dg;
    const Vec4 n = M * xi;
    const double dbar = -n.dot(Xi * n) / bar;
    const double slope = dbar - hardening_slope(a0 + dg * bar) * (bar + dg * dbar);
    double next = dg - g / slope;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (hi - lo <= 1e-16 * hi) break;
    dg = next;
  }
  evaluate(dg);
  const Vec4 n = M * xi;
  const double alpha = a0 + dg * bar, slope = hardening_slope(alpha), beta = 1 - slope * dg;
  const Mat4 Q = Mat4::Identity() - Kb * A;  // C A
  const Vec4 Xin = Q * (Xi * n);
  r.yielding = true;
  r.history.plastic_strain += dg * n;
  r.history.back_stress += Kb * (dg * n);
  r.history.equivalent_plastic_strain = alpha;
  r.stress = xi + r.history.back_stress;
  r.D = (Kb - Kb * A * Kb) + Q * Xi * Q.transpose() -
        beta * Xin * Xin.transpose() / (slope * bar * bar + beta * n.dot(Xi * n));
  return r;
}

}  // namespace grip
