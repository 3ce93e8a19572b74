#include "solver/materials/j2_plasticity.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace grip {
namespace {

using Vec4 = Eigen::Vector4d;
using Mat4 = Eigen::Matrix4d;

const double kSqrt23 = std::sqrt(2.0 / 3.0);
const Vec4 kOne(1, 1, 0, 1);  // the identity tensor in (11, 22, 12, 33)

// |t| of a symmetric tensor given as (11, 22, 12, 33).
double tensor_norm(const Vec4& t) { return std::sqrt(t[0] * t[0] + t[1] * t[1] + t[3] * t[3] + 2 * t[2] * t[2]); }

// The deviatoric projector from a strain (engineering shear) to a tensor (11, 22, 12, 33).
Mat4 deviator() {
  Mat4 P;
  P << 2, -1, 0, -1, -1, 2, 0, -1, 0, 0, 1.5, 0, -1, -1, 0, 2;
  return P / 3;
}

std::string text(double v) { return std::to_string(v); }

}  // namespace

std::string j2_data_issue(double yield_stress, const IsotropicHardening& h, double kinematic_modulus) {
  if (!(yield_stress > 0 && std::isfinite(yield_stress))) return "yield_stress: must be positive";
  if (!(kinematic_modulus >= 0 && std::isfinite(kinematic_modulus)))
    return "kinematic_hardening: must be >= 0 (softening makes the tangent singular)";
  switch (h.kind) {
    case IsotropicHardening::Kind::linear:
      if (!(h.modulus >= 0 && std::isfinite(h.modulus)))
        return "hardening/linear: must be >= 0 (softening makes the tangent singular and the answer mesh-dependent)";
      return {};
    case IsotropicHardening::Kind::power:
      if (!(h.K > 0 && std::isfinite(h.K))) return "hardening/power/K: must be positive";
      if (!(h.n > 0 && h.n <= 1)) return "hardening/power/n: must be in (0, 1]";
      return {};
    case IsotropicHardening::Kind::table: {
      if (h.table.empty()) return "hardening/table: needs at least the point [0, yield_stress]";
      for (size_t k = 0; k < h.table.size(); ++k) {
        const auto [a, s] = h.table[k];
        const std::string at = "hardening/table/" + std::to_string(k);
        if (!std::isfinite(a) || !std::isfinite(s)) return at + ": is not a pair of finite numbers";
        if (k == 0 && a != 0) return at + "/0: the first point is at equivalent plastic strain 0";
        if (k == 0 && s != yield_stress)
          return at + "/1: " + text(s) + " differs from yield_stress " + text(yield_stress) +
                 " (the table starts at the initial yield stress)";
        if (k > 0 && !(a > h.table[k - 1].first)) return at + "/0: equivalent plastic strains must increase";
        if (k > 0 && !(s >= h.table[k - 1].second))
          return at + "/1: the yield stress must not decrease (softening makes the tangent singular)";
      }
      return {};
    }
  }
  return {};
}

J2Material::J2Material(double young, double poisson, double yield_stress, IsotropicHardening hardening,
                       double kinematic_modulus, PlaneAnalysis analysis, std::optional<Hill48> hill)
    : elastic_(young, poisson, analysis), lame_(Lame::from(young, poisson)), analysis_(analysis),
      yield_stress_(yield_stress), hardening_(std::move(hardening)), kinematic_(kinematic_modulus), hill_(hill) {
  if (const std::string why = j2_data_issue(yield_stress_, hardening_, kinematic_); !why.empty())
    throw std::invalid_argument("j2_plasticity: " + why);
  if (hill_) {
    if (const std::string why = hill48_data_issue(*hill_, analysis_); !why.empty())
      throw std::invalid_argument("j2_plasticity: " + why);
    hill_metric_ = hill48_metric(*hill_, analysis_);
  }
  if (hardening_.kind == IsotropicHardening::Kind::power)
    alpha0_ = std::pow(yield_stress_ / hardening_.K, 1 / hardening_.n);
}

MaterialResponse J2Material::response(const Mat2& E) const { return elastic_.response(E); }

double J2Material::yield_stress(double alpha) const {
  switch (hardening_.kind) {
    case IsotropicHardening::Kind::linear:
      return yield_stress_ + hardening_.modulus * alpha;
    case IsotropicHardening::Kind::power:
      return hardening_.K * std::pow(alpha0_ + alpha, hardening_.n);
    case IsotropicHardening::Kind::table: {
      const auto& t = hardening_.table;
      for (size_t k = 1; k < t.size(); ++k)
        if (alpha < t[k].first)
          return t[k - 1].second +
                 (t[k].second - t[k - 1].second) * (alpha - t[k - 1].first) / (t[k].first - t[k - 1].first);
      return t.back().second;
    }
  }
  return yield_stress_;
}

double J2Material::hardening_slope(double alpha) const {
  switch (hardening_.kind) {
    case IsotropicHardening::Kind::linear:
      return hardening_.modulus;
    case IsotropicHardening::Kind::power:
      return hardening_.n * hardening_.K * std::pow(alpha0_ + alpha, hardening_.n - 1);
    case IsotropicHardening::Kind::table: {
      const auto& t = hardening_.table;
      for (size_t k = 1; k < t.size(); ++k)
        if (alpha < t[k].first) return (t[k].second - t[k - 1].second) / (t[k].first - t[k - 1].first);
      return 0.0;
    }
  }
  return 0.0;
}

PointResponse J2Material::return_map(const Vec4& strain, const PointHistory& h) const {
  if (hill_) return hill_return(strain, h);
  const double G = lame_.mu, K = lame_.lambda + 2 * G / 3, Hk = kinematic_;
  const Mat4 P = deviator();
  const Vec4 ee = strain - h.plastic_strain;
  const double volumetric = K * (ee[0] + ee[1] + ee[3]);
  const Vec4 s_trial = 2 * G * (P * ee);
  const Vec4 xi = s_trial - h.back_stress;
  const double q = tensor_norm(xi);
  const double a0 = h.equivalent_plastic_strain;
  PointResponse r;
  r.history = h;
  const Mat4 elastic = K * kOne * kOne.transpose() + 2 * G * P;
  if (q - kSqrt23 * yield_stress(a0) <= 1e-12 * yield_stress_) {
    r.stress = s_trial + volumetric * kOne;
    r.D = elastic;
    return r;
  }
  // g(dg) = q - (2G + 2/3 Hk) dg - sqrt(2/3) sigma_y(a0 + sqrt(2/3) dg) decreases from g(0) > 0
  // to g(q / 2G) < 0: Newton's method kept inside the bracket (bisection where it leaves it; a
  // table's kinks).
  double lo = 0.0, hi = q / (2 * G), dg = 0.0;
  for (int it = 0; it < 100; ++it) {
    const double alpha = a0 + kSqrt23 * dg;
    const double g = q - (2 * G + 2 * Hk / 3) * dg - kSqrt23 * yield_stress(alpha);
    if (std::abs(g) <= 1e-14 * q) break;
    (g > 0 ? lo : hi) = dg;
    const double slope = 2 * G + 2 * (Hk + hardening_slope(alpha)) / 3;
    double next = dg + g / slope;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (hi - lo <= 1e-16 * (q / (2 * G))) break;
    dg = next;
  }
  const Vec4 n = xi / q;
  const double alpha = a0 + kSqrt23 * dg;
  r.yielding = true;
  r.history.equivalent_plastic_strain = alpha;
  r.history.back_stress += 2 * Hk / 3 * dg * n;
  r.history.plastic_strain += dg * Vec4(n[0], n[1], 2 * n[2], n[3]);
  r.stress = s_trial - 2 * G * dg * n + volumetric * kOne;
  const double theta = 1 - 2 * G * dg / q;
  const double theta_bar = 1 / (1 + (hardening_slope(alpha) + Hk) / (3 * G)) - (1 - theta);
  r.D = K * kOne * kOne.transpose() + 2 * G * theta * P - 2 * G * theta_bar * n * n.transpose();
  return r;
}

PointResponse J2Material::small_strain_response(const Vec4& strain, const PointHistory& committed) const {
  if (analysis_ != PlaneAnalysis::plane_stress) return return_map(strain, committed);
  // Plane stress: s33(eps33) increases (its slope D33 > 0 for nonnegative hardening); Newton's
  // method from the elastic guess, kept inside the bracket found on the way.
  const double l = lame_.lambda, m = lame_.mu;
  const Vec4& ep = committed.plastic_strain;
  Vec4 e = strain;
  e[3] = ep[3] - l / (l + 2 * m) * (e[0] - ep[0] + e[1] - ep[1]);
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  PointResponse r;
  for (int it = 0;; ++it) {
    r = return_map(e, committed);
    const double s33 = r.stress[3];
    if (std::abs(s33) <= 1e-13 * (tensor_norm(r.stress) + yield_stress_)) break;
    if (it == 100) throw std::runtime_error("j2_plasticity: the plane-stress return did not find s33 = 0");
    (s33 > 0 ? hi : lo) = e[3];
    double next = e[3] - s33 / r.D(3, 3);
    if (!(next > lo && next < hi) && std::isfinite(lo) && std::isfinite(hi)) next = 0.5 * (lo + hi);
    e[3] = next;
  }
  const Mat4 D = r.D;
  r.D.setZero();
  r.D.topLeftCorner<3, 3>() = D.topLeftCorner<3, 3>() - D.block<3, 1>(0, 3) * D.block<1, 3>(3, 0) / D(3, 3);
  r.stress[3] = 0.0;
  return r;
}

}  // namespace grip
