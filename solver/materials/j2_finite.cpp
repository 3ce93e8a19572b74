// J2 plasticity at finite strain (docs/algorithm.md#finite-strain-j2-plasticity): F = Fe Fp,
// Hooke's law on the logarithmic elastic strain and the exponential-map return of Simo (1992),
// in the material form that the total-Lagrangian element needs.
// With U = Cp^-1/2 (Cp^-1 = Fp^-1 Fp^-T committed) and A = U C U, A has the eigenvalues of the
// trial elastic left Cauchy-Green tensor F Cp^-1 F^T, rotated by a rotation: Lambda = log(A) / 2 is
// the trial logarithmic elastic strain there, and the small-strain radial return on it gives
// the Kirchhoff stress tau and the plastic increment dP (coaxial, deviatoric). Then
//   S = U tau A^-1 U,   Cp^-1 <- U exp(-2 dP) U   (det unchanged: tr dP = 0),
// and dS/dE follows by the chain rule through the return's consistent tangent d tau / d Lambda
// and the derivative of the logarithm (symmetric_2x2.hpp).
#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "solver/materials/j2_plasticity.hpp"
#include "solver/materials/symmetric_2x2.hpp"

namespace grip {
namespace {

using Vec4 = Eigen::Vector4d;
using Mat4 = Eigen::Matrix4d;

Mat2 sym(const Mat2& A) { return 0.5 * (A + A.transpose()); }
Mat2 tensor(double a11, double a22, double a12) { return (Mat2() << a11, a12, a12, a22).finished(); }

}  // namespace

FinitePointResponse J2Material::finite_point(const Mat2& E, double E33, const PointHistory& h, Mat4& D) const {
  if (kinematic_ > 0 || hill_) return log_strain_point(E, E33, h, D);
  const Vec4& c = h.plastic_metric_inverse;
  const Mat2 U = sqrt_spd(tensor(c[0], c[1], c[2]));
  const double cpi33 = c[3];
  const Mat2 A = sym(U * (Mat2::Identity() + 2 * E) * U);
  const double A33 = cpi33 * (1 + 2 * E33);
  const Mat2 L = 0.5 * log_spd(A);
  PointHistory start;  // the return from zero plastic strain gives the increment dP
  start.equivalent_plastic_strain = h.equivalent_plastic_strain;
  const PointResponse r = return_map(Vec4(L(0, 0), L(1, 1), 2 * L(0, 1), 0.5 * std::log(A33)), start);
  const Mat2 tau = tensor(r.stress[0], r.stress[1], r.stress[2]);
  const Mat2 Ai = A.inverse();
  const Mat2 S = U * sym(tau * Ai) * U;
  FinitePointResponse out;
  out.law.S = {S(0, 0), S(1, 1), S(0, 1)};
  out.law.S33 = cpi33 * r.stress[3] / A33;
  // Column k of dS/dE: E11, E22, 2 E12, E33 moved by one.
  for (int k = 0; k < 4; ++k) {
    const Mat2 dE = k == 0 ? tensor(1, 0, 0) : k == 1 ? tensor(0, 1, 0) : k == 2 ? tensor(0, 0, 0.5) : Mat2::Zero();
    const Mat2 dA = 2 * U * dE * U;
    const double dA33 = k == 3 ? 2 * cpi33 : 0.0;
    const Mat2 dL = 0.5 * log_spd_derivative(A, dA);
    const Vec4 dtau = r.D * Vec4(dL(0, 0), dL(1, 1), 2 * dL(0, 1), 0.5 * dA33 / A33);
    const Mat2 dS = U * sym(tensor(dtau[0], dtau[1], dtau[2]) * Ai - tau * Ai * dA * Ai) * U;
    D.col(k) << dS(0, 0), dS(1, 1), dS(0, 1), cpi33 * (dtau[3] / A33 - r.stress[3] * dA33 / (A33 * A33));
  }
  out.history = h;
  out.yielding = r.yielding;
  if (r.yielding) {
    const Vec4& dp = r.history.plastic_strain;  // dP with the engineering shear
    const Mat2 Cpi = sym(U * exp_symmetric(-2 * tensor(dp[0], dp[1], 0.5 * dp[2])) * U);
    out.history.plastic_metric_inverse = {Cpi(0, 0), Cpi(1, 1), Cpi(0, 1), cpi33 * std::exp(-2 * dp[3])};
    out.history.equivalent_plastic_strain = r.history.equivalent_plastic_strain;
  }
  return out;
}

// Kinematic hardening and Hill's anisotropy: the small-strain return on the Lagrangian log strain
// eps = log(C) / 2 (eps33 = log(C33) / 2), eps_p, the back stress and alpha its history; T the
// stress conjugate to eps, S = P^T T with P = d eps / dE, and
// dS/dE = P^T (dT / d eps) P + T : d^2 eps / dE^2.
FinitePointResponse J2Material::log_strain_point(const Mat2& E, double E33, const PointHistory& h, Mat4& D) const {
  const Mat2 C = Mat2::Identity() + 2 * E;
  const double C33 = 1 + 2 * E33;
  const Mat2 eps = 0.5 * log_spd(C);
  const PointResponse r = return_map(Vec4(eps(0, 0), eps(1, 1), 2 * eps(0, 1), 0.5 * std::log(C33)), h);
  // d eps = dlog(C)[dE]: columns E11, E22, 2 E12 (strains with the engineering shear), and E33.
  const Mat2 directions[3] = {tensor(1, 0, 0), tensor(0, 1, 0), tensor(0, 0, 0.5)};
  Mat4 P = Mat4::Zero();
  for (int k = 0; k < 3; ++k) {
    const Mat2 d = log_spd_derivative(C, directions[k]);
    P.col(k) << d(0, 0), d(1, 1), 2 * d(0, 1), 0.0;
  }
  P(3, 3) = 1 / C33;
  const Vec4 S = P.transpose() * r.stress;
  D = P.transpose() * r.D * P;
  const Vec4& T = r.stress;  // (11, 22, 12, 33)
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) {
      const Mat2 d2 = 2 * log_spd_second_derivative(C, directions[k], directions[l]);
      D(k, l) += T[0] * d2(0, 0) + T[1] * d2(1, 1) + 2 * T[2] * d2(0, 1);
    }
  D(3, 3) -= 2 * T[3] / (C33 * C33);
  D = 0.5 * (D + D.transpose());
  FinitePointResponse out;
  out.law.S = S.head<3>();
  out.law.S33 = S[3];
  out.history = r.history;
  out.yielding = r.yielding;
  return out;
}

FiniteHoopResponse J2Material::finite_hoop_response(const Mat2& E, double E33, const PointHistory& committed) const {
  if (analysis_ != PlaneAnalysis::axisymmetric)
    throw std::logic_error("j2_plasticity: finite_hoop_response is the axisymmetric response");
  FiniteHoopResponse out;
  const FinitePointResponse r = finite_point(E, E33, committed, out.law.D);
  out.law.S << r.law.S, r.law.S33;
  out.history = r.history;
  out.yielding = r.yielding;
  return out;
}

FinitePointResponse J2Material::finite_response(const Mat2& E, const PointHistory& committed) const {
  if (analysis_ == PlaneAnalysis::axisymmetric)
    throw std::logic_error("j2_plasticity: the axisymmetric response needs the hoop strain (finite_hoop_response)");
  Mat4 D;
  if (analysis_ == PlaneAnalysis::plane_strain) {
    FinitePointResponse out = finite_point(E, 0.0, committed, D);
    out.law.D = D.topLeftCorner<3, 3>();
    out.law.dS33 = D.block<1, 3>(3, 0);
    out.law.dS33_dE33 = D(3, 3);
    return out;
  }
  // Plane stress: tau33 = C33 S33 = 0 for z = ln C33; tau33 increases with z, nearly linearly
  // (the elastic log strain moves by dz / 2). Newton's method from the volume of an isochoric
  // motion (plastic flow dominates), kept inside the bracket found on the way.
  double z = -std::log((Mat2::Identity() + 2 * E).determinant());
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  // tau33 is known to the round-off of the stiffness times the strain's resolution.
  const double round_off = 16 * std::numeric_limits<double>::epsilon() * (lame_.lambda + 2 * lame_.mu);
  FinitePointResponse out;
  for (int it = 0;; ++it) {
    const double C33 = std::exp(z);
    out = finite_point(E, 0.5 * (C33 - 1), committed, D);
    const double tau33 = C33 * out.law.S33;
    if (std::abs(tau33) <= 1e-13 * (C33 * out.law.S.norm() + yield_stress_) + round_off) break;
    if (it == 60) throw std::runtime_error("j2_plasticity: the plane-stress return did not find S33 = 0");
    (tau33 > 0 ? hi : lo) = z;
    double next = z - tau33 / (C33 * (0.5 * C33 * D(3, 3) + out.law.S33));
    if (!(next > lo && next < hi) && std::isfinite(lo) && std::isfinite(hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - z) <= 1e-15 * (1 + std::abs(z))) break;  // at the root to round-off
    z = next;
  }
  out.law.D = D.topLeftCorner<3, 3>() - D.block<3, 1>(0, 3) * D.block<1, 3>(3, 0) / D(3, 3);
  out.law.S33 = 0.0;
  out.law.C33 = std::exp(z);
  return out;
}

}  // namespace grip
