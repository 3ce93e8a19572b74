#pragma once
// The J2 tests' material: steel-like (E 200e3, nu 0.3, sigma_y 250) with linear, Swift power or
// tabulated isotropic hardening (and kinematic hardening); shared by the finite-strain,
// axisymmetric and Hill 1948 tests.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "solver/materials/j2_plasticity.hpp"

namespace grip::testing::j2 {

constexpr double kYoung = 200e3, kPoisson = 0.3, kYield = 250.0;

struct Law {
  const char* name;
  IsotropicHardening hardening;
  double initial_yield = kYield;

  // The yield stress at equivalent plastic strain alpha, evaluated here from the law's data and
  // not by J2Material::yield_stress, so that the closed forms built on it fail a material that
  // reads its law wrongly (a table point misplaced, the wrong segment, the wrong end).
  double yield_stress(double alpha) const {
    const IsotropicHardening& h = hardening;
    switch (h.kind) {
      case IsotropicHardening::Kind::linear:
        return initial_yield + h.modulus * alpha;
      case IsotropicHardening::Kind::power:
        return h.K * std::pow(std::pow(initial_yield / h.K, 1 / h.n) + alpha, h.n);
      case IsotropicHardening::Kind::table: {
        // Piecewise linear between the points (a_k, s_k): on [a_k, a_{k+1}),
        // sigma_y = s_k + (s_{k+1} - s_k) (alpha - a_k) / (a_{k+1} - a_k); s_last beyond the last.
        const auto& t = h.table;
        std::size_t k = 0;
        while (k + 1 < t.size() && t[k + 1].first <= alpha) ++k;
        if (k + 1 == t.size()) return t.back().second;
        const double w = (alpha - t[k].first) / (t[k + 1].first - t[k].first);
        return (1 - w) * t[k].second + w * t[k + 1].second;
      }
    }
    return initial_yield;
  }
};

// Linear, power and tabulated hardening, their moduli scaled with the yield stress by `scale`.
// The table (a power-like curve in five segments, perfectly plastic beyond alpha = 0.4) is scaled
// in both alpha and sigma_y: the same curve in units of the yield strain, so its corners stay
// within the reach of the small-strain limits' yield strains of 1.25e-8.
inline std::vector<Law> laws(double scale = 1.0) {
  IsotropicHardening linear;
  linear.modulus = 2000.0 * scale;
  IsotropicHardening power;
  power.kind = IsotropicHardening::Kind::power;
  power.K = 600.0 * scale;
  power.n = 0.2;
  IsotropicHardening table;
  table.kind = IsotropicHardening::Kind::table;
  for (const auto& [a, s] :
       {std::pair{0.0, kYield}, {0.002, 280.0}, {0.01, 320.0}, {0.05, 400.0}, {0.2, 480.0}, {0.4, 520.0}})
    table.table.push_back({a * scale, s * scale});
  return {{"linear", linear, kYield * scale}, {"power", power, kYield * scale}, {"table", table, kYield * scale}};
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
