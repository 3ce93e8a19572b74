#pragma once
// The J2 tests' material: steel-like (E 200e3, nu 0.3, sigma_y 250) with linear or Swift power
// isotropic hardening; shared by the finite-strain, axisymmetric and Hill 1948 tests.
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

inline std::shared_ptr<J2Material> material(const Law& law, PlaneAnalysis analysis, double scale = 1.0,
                                            std::optional<Hill48> hill = std::nullopt) {
  return std::make_shared<J2Material>(kYoung, kPoisson, kYield * scale, law.hardening, 0.0, analysis, hill);
}

}  // namespace grip::testing::j2
