#include "solver/materials/plane_material.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

namespace grip {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// The in-plane Voigt block of a(Ci (x) Ci) + b(Ci_ik Ci_jl + Ci_il Ci_jk) for symmetric Ci.
Mat3 voigt_tangent(const Mat2& Ci, double a, double b) {
  static const int I[3][2] = {{0, 0}, {1, 1}, {0, 1}};
  Mat3 D;
  for (int p = 0; p < 3; ++p)
    for (int q = 0; q < 3; ++q) {
      const int i = I[p][0], j = I[p][1], k = I[q][0], l = I[q][1];
      D(p, q) = a * Ci(i, j) * Ci(k, l) + b * (Ci(i, k) * Ci(j, l) + Ci(i, l) * Ci(j, k));
    }
  return D;
}

Vec3 voigt(const Mat2& A) { return {A(0, 0), A(1, 1), A(0, 1)}; }

}  // namespace

Eigen::Matrix4d PlaneMaterial::small_strain_D4() const {
  const MaterialResponse r = small_strain();
  Eigen::Matrix4d D = Eigen::Matrix4d::Zero();
  D.topLeftCorner<3, 3>() = r.D;
  D.block<1, 3>(3, 0) = r.dS33;
  D.block<3, 1>(0, 3) = r.dS33.transpose();
  D(3, 3) = r.dS33_dE33;
  return D;
}

double PlaneMaterial::bulk_over_shear() const {
  const Eigen::Matrix4d D = small_strain_D4();
  if (D(3, 3) == 0.0) return 0.0;  // plane stress
  // K = (1/9) sum of the normal block (11, 22, 33), G = D_1212.
  double k = 0.0;
  for (int i : {0, 1, 3})
    for (int j : {0, 1, 3}) k += D(i, j) / 9;
  return k / D(2, 2);
}

PointResponse PlaneMaterial::small_strain_response(const Eigen::Vector4d& strain, const PointHistory& committed) const {
  PointResponse r;
  r.D = small_strain_D4();
  r.stress = r.D * strain;
  r.history = committed;
  return r;
}

HoopResponse PlaneMaterial::hoop_response(const Mat2& /*E*/, double /*E33*/) const {
  throw std::logic_error("hoop_response: this law has no finite-strain form");
}

HookeMaterial::HookeMaterial(double young, double poisson, PlaneAnalysis analysis)
    : lame_(Lame::from(young, poisson)), analysis_(analysis) {
  const double l = lame_.lambda, m = lame_.mu;
  D_ << l + 2 * m, l, 0, l, l + 2 * m, 0, 0, 0, m;
  if (analysis_ == PlaneAnalysis::plane_stress) D_.topLeftCorner<2, 2>().array() -= l * l / (l + 2 * m);
}

MaterialResponse HookeMaterial::response(const Mat2& E) const {
  MaterialResponse r;
  const Vec3 e(E(0, 0), E(1, 1), 2 * E(0, 1));
  r.D = D_;
  r.S = D_ * e;
  const double l = lame_.lambda, m = lame_.mu;
  if (analysis_ != PlaneAnalysis::plane_stress) {
    r.dS33 << l, l, 0;
    r.S33 = r.dS33 * e;
    r.dS33_dE33 = l + 2 * m;
  } else {
    r.C33 = 1 - 2 * l / (l + 2 * m) * (e[0] + e[1]);  // 1 + 2 E33, E33 from S33 = 0
  }
  return r;
}

HoopResponse HookeMaterial::hoop_response(const Mat2& E, double E33) const {
  HoopResponse r;
  r.D = small_strain_D4();
  r.S = r.D * Eigen::Vector4d(E(0, 0), E(1, 1), 2 * E(0, 1), E33);
  return r;
}

NeoHookeMaterial::NeoHookeMaterial(double young, double poisson, PlaneAnalysis analysis)
    : lame_(Lame::from(young, poisson)), analysis_(analysis) {}

MaterialResponse NeoHookeMaterial::response(const Mat2& E) const {
  const double l = lame_.lambda, m = lame_.mu;
  const Mat2 C = Mat2::Identity() + 2 * E;
  const double d = C.determinant();
  MaterialResponse r;
  if (analysis_ == PlaneAnalysis::plane_stress) {
    // S33 = 0: m (C33 - 1) + l ln J = 0 with ln J = (ln d + ln C33) / 2. In z = ln C33 the
    // function is convex and increasing, so Newton from a point where it is >= 0 descends
    // monotonically onto the root.
    const double ln_d = std::log(d);
    double z = std::max(0.0, -ln_d);
    for (int it = 0; it < 60; ++it) {
      const double h = m * (std::exp(z) - 1) + 0.5 * l * (ln_d + z);
      const double dz = h / (m * std::exp(z) + 0.5 * l);
      z -= dz;
      if (std::abs(dz) <= 1e-15 * (1 + std::abs(z))) break;
    }
    r.C33 = std::exp(z);
  }
  const Mat2 Ci = C.inverse();
  const double lnJ = 0.5 * std::log(d * r.C33);
  const double b = m - l * lnJ;
  r.S = voigt(m * (Mat2::Identity() - Ci) + l * lnJ * Ci);
  r.D = voigt_tangent(Ci, l, b);
  const Vec3 ci = voigt(Ci);
  if (analysis_ != PlaneAnalysis::plane_stress) {
    r.S33 = l * lnJ;
    r.dS33 = l * ci.transpose();
    r.dS33_dE33 = l + 2 * b;  // at C33 = 1
  } else {
    // Condense E33 out: dS33 = 0 = l/C33 ci . dE + (l + 2 b)/C33^2 dE33.
    r.D -= l * l / (l + 2 * b) * ci * ci.transpose();
  }
  return r;
}

HoopResponse NeoHookeMaterial::hoop_response(const Mat2& E, double E33) const {
  // The 3D law with C = diag(C_plane, C33): S = mu (I - C^-1) + lambda ln J C^-1, J^2 = det C.
  const double l = lame_.lambda, m = lame_.mu;
  const Mat2 C = Mat2::Identity() + 2 * E;
  const double C33 = 1 + 2 * E33;
  const Mat2 Ci = C.inverse();
  const double lnJ = 0.5 * std::log(C.determinant() * C33);
  const double b = m - l * lnJ;
  const Vec3 ci = voigt(Ci);
  HoopResponse r;
  r.S.head<3>() = voigt(m * (Mat2::Identity() - Ci) + l * lnJ * Ci);
  r.S[3] = m * (1 - 1 / C33) + l * lnJ / C33;
  r.D.topLeftCorner<3, 3>() = voigt_tangent(Ci, l, b);
  r.D.block<3, 1>(0, 3) = l / C33 * ci;
  r.D.block<1, 3>(3, 0) = l / C33 * ci.transpose();
  r.D(3, 3) = (l + 2 * b) / (C33 * C33);
  return r;
}

}  // namespace grip
