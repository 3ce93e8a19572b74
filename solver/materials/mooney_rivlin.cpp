#include "solver/materials/mooney_rivlin.hpp"

#include <array>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <utility>

namespace grip {
namespace {

using Complex = std::complex<double>;

// S = 2 dW/dC for the block-diagonal C = (C11, C22, C12 | C33):
//   S = 2 c10 J^(-2/3) (I - I1/3 C^-1) + 2 c01 J^(-4/3) (I1 I - C - 2/3 I2 C^-1) + bulk (J - 1) J C^-1,
// returned as (S11, S22, S12, S33).
template <class T>
std::array<T, 4> stress(double c10, double c01, double bulk, T C11, T C22, T C12, T C33) {
  const T d2 = C11 * C22 - C12 * C12;  // the in-plane determinant
  const T J = std::sqrt(d2 * C33);
  const T I1 = C11 + C22 + C33;
  const T I2 = d2 + (C11 + C22) * C33;  // (I1^2 - tr C^2) / 2 for the block-diagonal C
  const T Ci11 = C22 / d2, Ci22 = C11 / d2, Ci12 = -C12 / d2, Ci33 = T(1.0) / C33;
  const T a = 2.0 * c10 * std::pow(J, -2.0 / 3.0), b = 2.0 * c01 * std::pow(J, -4.0 / 3.0);
  const T p = bulk * (J - 1.0) * J;
  // S = a (I - I1/3 Ci) + b (I1 I - C - 2/3 I2 Ci) + p Ci
  const T ci = -a * I1 / 3.0 - b * 2.0 * I2 / 3.0 + p;  // the factor of C^-1
  return {a + b * (I1 - C11) + ci * Ci11, a + b * (I1 - C22) + ci * Ci22, -b * C12 + ci * Ci12,
          a + b * (I1 - C33) + ci * Ci33};
}

}  // namespace

std::string mooney_rivlin_data_issue(double c10, double c01, double bulk) {
  for (const auto& [name, c] : {std::pair{"c10", c10}, std::pair{"c01", c01}})
    if (!(c >= 0 && std::isfinite(c)))
      return std::string(name) + ": must be >= 0 (a negative constant loses stability in some stretch)";
  if (!(c10 + c01 > 0)) return "c10: c10 + c01 must be positive (the shear modulus is 2 (c10 + c01))";
  if (!(bulk >= 2 * (c10 + c01) && std::isfinite(bulk)))
    return "bulk: must be at least the shear modulus 2 (c10 + c01) (a nearly incompressible law has bulk >> "
           "shear)";
  return {};
}

MooneyRivlinMaterial::MooneyRivlinMaterial(double c10, double c01, double bulk, PlaneAnalysis analysis)
    : c10_(c10), c01_(c01), bulk_(bulk), analysis_(analysis) {
  if (const std::string why = mooney_rivlin_data_issue(c10, c01, bulk); !why.empty())
    throw std::invalid_argument("mooney_rivlin: " + why);
}

// dS/dE (4 x 4, E as (E11, E22, 2 E12, E33)) at C: column k is Im S(C + i h dC_k) / h, the
// complex step h = 1e-30, dC = 2 dE.
Eigen::Matrix4d MooneyRivlinMaterial::tangent(double C11, double C22, double C12, double C33) const {
  const double h = 1e-30;
  const Complex ih(0, h);
  Eigen::Matrix4d D;
  for (int k = 0; k < 4; ++k) {
    const auto s = stress<Complex>(c10_, c01_, bulk_, C11 + (k == 0 ? 2.0 : 0.0) * ih, C22 + (k == 1 ? 2.0 : 0.0) * ih,
                                   C12 + (k == 2 ? 1.0 : 0.0) * ih, C33 + (k == 3 ? 2.0 : 0.0) * ih);
    for (int i = 0; i < 4; ++i) D(i, k) = s[i].imag() / h;
  }
  return D;
}

HoopResponse MooneyRivlinMaterial::hoop_response(const Mat2& E, double E33) const {
  const double C11 = 1 + 2 * E(0, 0), C22 = 1 + 2 * E(1, 1), C12 = E(0, 1) + E(1, 0), C33 = 1 + 2 * E33;
  const auto s = stress<double>(c10_, c01_, bulk_, C11, C22, C12, C33);
  return {Eigen::Vector4d(s[0], s[1], s[2], s[3]), tangent(C11, C22, C12, C33)};
}

MaterialResponse MooneyRivlinMaterial::response(const Mat2& E) const {
  const double C11 = 1 + 2 * E(0, 0), C22 = 1 + 2 * E(1, 1), C12 = E(0, 1) + E(1, 0);
  const auto tangent = [&](double C33) { return this->tangent(C11, C22, C12, C33); };
  MaterialResponse r;
  double C33 = 1.0;
  if (analysis_ == PlaneAnalysis::plane_stress) {
    // S33(C33) = 0, increasing in C33: Newton's method from the isochoric guess 1 / det C.
    C33 = 1 / (C11 * C22 - C12 * C12);
    for (int it = 0;; ++it) {
      const double s33 = stress<double>(c10_, c01_, bulk_, C11, C22, C12, C33)[3];
      const double slope = tangent(C33)(3, 3) / 2;  // dS33 / dC33
      const double step = s33 / slope;
      C33 = std::max(C33 - step, 0.5 * C33);
      if (std::abs(step) <= 1e-15 * C33) break;
      if (it == 60) throw std::runtime_error("mooney_rivlin: the plane-stress state S33 = 0 was not found");
    }
  }
  const auto s = stress<double>(c10_, c01_, bulk_, C11, C22, C12, C33);
  const Eigen::Matrix4d D = tangent(C33);
  r.S = {s[0], s[1], s[2]};
  r.C33 = C33;
  if (analysis_ == PlaneAnalysis::plane_stress) {
    r.D = D.topLeftCorner<3, 3>() - D.block<3, 1>(0, 3) * D.block<1, 3>(3, 0) / D(3, 3);
  } else {
    r.D = D.topLeftCorner<3, 3>();
    r.S33 = s[3];
    r.dS33 = D.block<1, 3>(3, 0);
    r.dS33_dE33 = D(3, 3);
  }
  return r;
}

}  // namespace grip
