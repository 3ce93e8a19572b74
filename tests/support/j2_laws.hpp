#pragma once
// The J2 tests' material: steel-like (E 200e3, nu 0.3, sigma_y 250) with linear or Swift power
// isotropic hardening (and kinematic hardening); shared by the finite-strain, axisymmetric and Hill 1948 tests.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "solver/materials/j2_plasticity.hpp"

namespace grip::testing::j2 {

constexpr double kYoung = 200e3, kPoisson = 0.3, kYield = 250.0;

struct Law {
  const char* name;
  IsotropicHardening hardening;
};

// Linear and power hardening, their moduli scaled with the yield stress by `scale`.
inline std::vector<Law> laws(double scale = 1.0) {
  IsotropicHardening linear;
  linear.modulus = 2000.0 * scale;
  IsotropicHardening power;
  power.kind = IsotropicHardening::Kind::power;
  power.K = 600.0 * scale;
  power.n = 0.2;
  return {{"linear", linear}, {"power", power}};
}

// The law with Hill's anisotropy `hill` (von Mises without) and the kinematic hardening modulus
// `kinematic` (scaled with the yield stress too).
inline std::shared_ptr<J2Material> material(const Law& law, PlaneAnalysis analysis, double scale = 1.0,
                                            std::optional<Hill48> hill = std::nullopt, double kinematic = 0.0) {
  return std::make_shared<J2Material>(kYoung, kPoisson, kYield * scale, law.hardening, kinematic * scale, analysis,
                                      hill);
}

// The largest differences between two runs' element fields (columns 0-3 the stresses, 4 the
// equivalent plastic strain alpha): stresses over the second run's peak stress, alpha absolute
// (with the second run's peak alpha beside it).
struct FieldGap {
  double stress = 0.0, alpha = 0.0, peak_alpha = 0.0;

  template <class Rows>
  void add(const Rows& a, const Rows& b) {
    double peak = 0.0;
    for (const auto& row : b)
      for (int c = 0; c < 4; ++c) peak = std::max(peak, std::abs(row[c]));
    for (std::size_t e = 0; e < a.size(); ++e) {
      for (int c = 0; c < 4; ++c) stress = std::max(stress, std::abs(a[e][c] - b[e][c]) / peak);
      alpha = std::max(alpha, std::abs(a[e][4] - b[e][4]));
      peak_alpha = std::max(peak_alpha, b[e][4]);
    }
  }
};

}  // namespace grip::testing::j2
