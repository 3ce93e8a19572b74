#pragma once
// The elastica of a cantilever under a dead end load (Bisshopp & Drucker 1945; Mattiasson
// 1981 tabulates it): an inextensible, shear-rigid rod of length L, clamped at s = 0, with a
// force F perpendicular to its straight reference axis at s = L. With theta the rotation and
// alpha = F L^2 / EI, in s / L:
//   theta'' = -alpha cos(theta),  theta(0) = 0,  theta'(1) = 0 (no moment at the tip).
// Solved here by shooting on theta'(0) with a fourth-order Runge-Kutta march, to about 1e-9.
#include <cmath>

namespace grip::testing {

struct ElasticaTip {
  double deflection;  // tip displacement along the load, over L
  double shortening;  // tip displacement back toward the clamp, over L
  double rotation;    // tip rotation, radians
};

namespace elastica_detail {

// State (theta, theta', x, y) along s; returns it at s = 1 for theta'(0) = k.
struct Rod {
  double theta, kappa, x, y;
};

inline Rod march(double alpha, double k, int steps = 4000) {
  Rod r{0.0, k, 0.0, 0.0};
  const double h = 1.0 / steps;
  auto rate = [alpha](const Rod& a) {
    return Rod{a.kappa, -alpha * std::cos(a.theta), std::cos(a.theta), std::sin(a.theta)};
  };
  auto add = [](const Rod& a, const Rod& b, double f) {
    return Rod{a.theta + f * b.theta, a.kappa + f * b.kappa, a.x + f * b.x, a.y + f * b.y};
  };
  for (int i = 0; i < steps; ++i) {
    const Rod k1 = rate(r), k2 = rate(add(r, k1, h / 2)), k3 = rate(add(r, k2, h / 2)), k4 = rate(add(r, k3, h));
    r.theta += h / 6 * (k1.theta + 2 * k2.theta + 2 * k3.theta + k4.theta);
    r.kappa += h / 6 * (k1.kappa + 2 * k2.kappa + 2 * k3.kappa + k4.kappa);
    r.x += h / 6 * (k1.x + 2 * k2.x + 2 * k3.x + k4.x);
    r.y += h / 6 * (k1.y + 2 * k2.y + 2 * k3.y + k4.y);
  }
  return r;
}

}  // namespace elastica_detail

// The tip of the elastica for alpha = F L^2 / EI in (0, ~20].
inline ElasticaTip elastica_tip(double alpha) {
  // theta'(0) = alpha x(1) lies in (0, alpha]; theta'(1) falls as theta'(0) rises past the
  // root (a stiffer start over-bends): bisect.
  double lo = 0.0, hi = alpha;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (elastica_detail::march(alpha, mid).kappa > 0 ? hi : lo) = mid;
  }
  const elastica_detail::Rod tip = elastica_detail::march(alpha, 0.5 * (lo + hi));
  return {tip.y, 1.0 - tip.x, tip.theta};
}

}  // namespace grip::testing
