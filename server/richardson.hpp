#pragma once
// Richardson extrapolation of a quantity computed on a sequence of meshes (a refinement study,
// docs/design.md#studies): the observed order of convergence, the extrapolated value and each
// level's estimated error, by the procedure of Celik et al. (J. Fluids Eng. 130, 2008, the
// "GCI" procedure) that also takes ratios of refinement that differ between levels.
// Header-only: the server's studies and a unit test use it.
#include <cmath>
#include <optional>
#include <vector>

namespace grip::server {

// Successive observed orders within this fraction of each other: the asymptotic range.
inline constexpr double kAsymptoticSpread = 0.1;

struct Richardson {
  // Of each three consecutive levels (coarse to fine): the observed order, none where the
  // differences change sign (oscillating) or one of them is zero.
  std::vector<std::optional<double>> orders;
  std::optional<double> order;         // of the three finest levels
  std::optional<double> order_ratio;   // the finest order over the one before (four levels or more)
  std::optional<bool> asymptotic;      // order_ratio within kAsymptoticSpread of 1
  std::optional<double> extrapolated;  // from the three finest levels
  // Per level: |value - extrapolated| / |extrapolated| (absolute where extrapolated is 0).
  std::vector<std::optional<double>> estimated_error;
};

// The order p of three values f1, f2, f3 on sizes h1 > h2 > h3 (coarse to fine): with e21 =
// f2 - f1, e32 = f3 - f2, r21 = h1 / h2, r32 = h2 / h3 and s = sign(e21 / e32), the root of
//   p ln r32 = |ln |e21 / e32| + ln((r32^p - s) / (r21^p - s))|,
// found by fixed-point iteration (exact in one step for r21 = r32: p = ln(e21 / e32) / ln r).
inline std::optional<double> observed_order(double f1, double f2, double f3, double h1, double h2, double h3) {
  const double e21 = f2 - f1, e32 = f3 - f2;
  if (e21 == 0 || e32 == 0 || !std::isfinite(e21 / e32) || e21 / e32 < 0) return std::nullopt;
  const double r21 = h1 / h2, r32 = h2 / h3;
  if (!(r21 > 1 && r32 > 1)) return std::nullopt;
  const double s = 1.0;  // monotone: the differences keep their sign
  double p = std::abs(std::log(e21 / e32)) / std::log(r32);
  for (int k = 0; k < 200; ++k) {
    const double q = std::log((std::pow(r32, p) - s) / (std::pow(r21, p) - s));
    const double next = std::abs(std::log(e21 / e32) + q) / std::log(r32);
    if (!std::isfinite(next)) return std::nullopt;
    if (std::abs(next - p) <= 1e-12 * std::max(1.0, p)) return next;
    p = next;
  }
  return p;
}

// The estimated error of a value: |value - extrapolated| / |extrapolated| (absolute where the
// extrapolated value is 0).
inline double error_against(double value, double extrapolated) {
  return std::abs(value - extrapolated) / (extrapolated != 0 ? std::abs(extrapolated) : 1.0);
}

// values[k] on mesh size h[k], coarse to fine (h decreasing).
inline Richardson richardson(const std::vector<double>& values, const std::vector<double>& h) {
  Richardson out;
  const size_t n = std::min(values.size(), h.size());
  out.estimated_error.assign(n, std::nullopt);
  for (size_t k = 2; k < n; ++k)
    out.orders.push_back(observed_order(values[k - 2], values[k - 1], values[k], h[k - 2], h[k - 1], h[k]));
  if (n < 3) return out;
  const double fine = values[n - 1], medium = values[n - 2], coarse = values[n - 3];
  out.order = out.orders.back();
  if (out.order) {
    out.extrapolated = fine + (fine - medium) / (std::pow(h[n - 2] / h[n - 1], *out.order) - 1);
  } else if (fine == medium && medium == coarse) {
    out.extrapolated = fine;  // converged to the last digit: nothing left to extrapolate
  }
  if (out.orders.size() >= 2 && out.orders[out.orders.size() - 2] && out.order) {
    out.order_ratio = *out.order / *out.orders[out.orders.size() - 2];
    out.asymptotic = std::abs(*out.order_ratio - 1) <= kAsymptoticSpread;
  }
  if (out.extrapolated && std::isfinite(*out.extrapolated))
    for (size_t k = 0; k < n; ++k) out.estimated_error[k] = error_against(values[k], *out.extrapolated);
  else out.extrapolated.reset();
  return out;
}

}  // namespace grip::server
