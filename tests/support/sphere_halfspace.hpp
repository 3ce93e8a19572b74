#pragma once
// A rigid sphere pressed into an elastic half-space with friction (the axisymmetric Spence
// problem; Spence 1968 and 1975, Johnson, Contact Mechanics, section 5.4), by a boundary-element
// model of rings, the reference of the frictional sphere (docs/verification.md#frictional-sphere):
// the sphere R = 1 pressed by a load raised in `increments` equal steps to Hertz's a = 1.
// Piecewise constant pressure p and radial shear q (outward on the body) on annuli of width
// 1 / per_a over r < 1.3, collocated at the annuli's mid radii. The surface displacements of
// axisymmetric tractions on a half-space (Hankel transforms of Boussinesq's and Cerruti's
// solutions; shear modulus G, u_z into the body, u_r outward):
//   u_z(r) = (1 - nu) / G int p(s) s K0(r, s) ds - (1 - 2 nu) / (2 G) int_{s > r} q(s) ds,
//   u_r(r) = (1 - nu) / G int q(s) s K1(r, s) ds - (1 - 2 nu) / (2 G r) int_{s < r} p(s) s ds,
// with K_n(r, s) = int_0^inf J_n(k r) J_n(k s) dk = (1 / pi) int_0^pi cos(n t) / |r - s e^it| dt.
// The K0 integral of an annulus is the difference of two discs' (Johnson eq. 3.22, elliptic
// integrals); K1 - K0 is bounded and is integrated by Gauss-Legendre. Coulomb friction with the
// stick measured from the previous increment (the sphere is rigid: a sticking point keeps its
// radial displacement), active sets iterated to a fixed point, as the half-plane model of
// tests/support/spence_halfplane.hpp does for the cylinder. Needs only Eigen.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "tests/support/coulomb_active_set.hpp"

namespace grip::testing {

struct HalfSpaceSphere {
  double a = 0;        // contact radius (outer edge of the last annulus that presses)
  double c_stick = 0;  // stick radius: between the last sticking annulus and the next
  double peak = 0;     // largest pressure over Hertz's p0 = 3 P / (2 pi a^2) with a = 1
  double load = 0;     // P
  int iterations = 0;  // active-set iterations of the last increment (200: not settled)
};

namespace halfspace_detail {

// int_0^c s K0(r, s) ds: the disc of radius c (Johnson eq. 3.22 over (1 - nu) / G).
inline double disc_k0(double r, double c) {
  const double pi = std::numbers::pi;
  if (c <= 0) return 0.0;
  if (r <= c) return 2 * c / pi * std::comp_ellint_2(r / c);
  const double k = c / r;
  return 2 * r / pi * (std::comp_ellint_2(k) - (1 - k * k) * std::comp_ellint_1(k));
}

// (K1 - K0)(r, s) = -(1 / pi) int_0^pi (1 - cos t) / rho dt: bounded, smooth in t.
inline double k1_minus_k0(double r, double s) {
  const double pi = std::numbers::pi;
  static const double x[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                              0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
  static const double w[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                              0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  double sum = 0.0;
  for (int i = 0; i < 8; ++i)
    for (int half = 0; half < 2; ++half) {  // two panels: the integrand bends near t = 0
      const double t = 0.5 * pi * half + 0.25 * pi * (1 + x[i]), weight = 0.25 * pi * w[i];
      const double rho = std::sqrt(r * r + s * s - 2 * r * s * std::cos(t));
      sum += weight * (rho > 0 ? (1 - std::cos(t)) / rho : 0.0);
    }
  return -sum / pi;
}

// int_lo^hi s K1(r, s) ds: the disc difference of K0 plus Gauss on the bounded rest.
inline double annulus_k1(double r, double lo, double hi) {
  static const double x[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static const double w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  double rest = 0.0;
  for (int i = 0; i < 4; ++i) {
    const double s = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x[i];
    rest += 0.5 * (hi - lo) * w[i] * s * k1_minus_k0(r, s);
  }
  return disc_k0(r, hi) - disc_k0(r, lo) + rest;
}

}  // namespace halfspace_detail

inline HalfSpaceSphere sphere_half_space(double mu, double nu, int per_a, int increments) {
  using Eigen::MatrixXd;
  using Eigen::VectorXd;
  using namespace halfspace_detail;
  const double pi = std::numbers::pi, G = 1.0, R = 1.0, L = 1.3, h = 1.0 / per_a;
  const double Estar = 2 * G / (1 - nu);  // E / (1 - nu^2) of the body on a rigid sphere
  const int N = static_cast<int>(std::lround(L / h));
  std::vector<double> r(N), lo(N), hi(N), area(N);
  for (int j = 0; j < N; ++j) {
    lo[j] = j * h;
    hi[j] = (j + 1) * h;
    r[j] = 0.5 * (lo[j] + hi[j]);
    area[j] = pi * (hi[j] * hi[j] - lo[j] * lo[j]);
  }
  // u_z = Zp p + Zq q, u_r = Rq q + Rp p at the mid radii.
  MatrixXd Zp(N, N), Zq = MatrixXd::Zero(N, N), Rq(N, N), Rp = MatrixXd::Zero(N, N);
  const double normal = (1 - nu) / G, cross = (1 - 2 * nu) / (2 * G);
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) {
      Zp(i, j) = normal * (disc_k0(r[i], hi[j]) - disc_k0(r[i], lo[j]));
      Rq(i, j) = normal * annulus_k1(r[i], lo[j], hi[j]);
      // The part of annulus j beyond r_i (shear) and inside r_i (pressure).
      Zq(i, j) = -cross * std::clamp(hi[j] - std::max(lo[j], r[i]), 0.0, h);
      const double inside = std::clamp(r[i], lo[j], hi[j]);
      Rp(i, j) = -cross / r[i] * 0.5 * (inside * inside - lo[j] * lo[j]);
    }
  CoulombState st(N);
  st.contact[0] = st.stick[0] = 1;
  const HalfSpaceInfluence m{Zp, Zq, Rq, Rp};
  HalfSpaceSphere out;
  const double P_end = 4 * Estar / (3 * R);  // a = 1: a^3 = 3 P R / (4 E*)
  for (int k = 1; k <= increments; ++k) {
    out.load = P_end * k / increments;
    out.iterations = coulomb_increment(m, r, area, R, out.load, mu, st);
  }
  const VectorXd& p = st.p;
  const std::vector<int>&C = st.contact, &S = st.stick;
  for (int i = 0; i < N; ++i)
    if (p[i] > 0) out.a = std::max(out.a, hi[i]);
  int hs = 0;
  while (hs + 1 < N && S[hs + 1] && C[hs + 1]) ++hs;
  out.c_stick = hi[hs];
  out.peak = p.maxCoeff() / (3 * out.load / (2 * pi));
  return out;
}

}  // namespace grip::testing
