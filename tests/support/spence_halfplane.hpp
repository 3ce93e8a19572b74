#pragma once
// The frictional Hertz loading (Spence 1975) on an elastic half-plane by a boundary-element
// model, the reference for the Spence check (tests/support/spence.hpp): a rigid cylinder R = 1
// pressed by a load raised in `increments` equal steps to Hertz's a = 1, nu and mu given.
// Piecewise constant p and q on elements of width 1 / per_a over |x| < 1.3, the surface
// displacements of Johnson's eqs. 2.19 and 2.22 with the coupling beta both ways (`coupled`)
// or only from p into u_x (coupled = false: the effect of q on the pressure neglected, as in
// the relation beta / mu = K'(c/a) / K(c/a)); Coulomb friction with stick measured from the
// previous increment, active sets iterated to a fixed point. `Rc` > 0 adds the surface stretch
// of a finite cylinder of radius Rc (the full disc's uniform tension P / (pi Rc) at its load
// point), to mimic the half-disc scene. Needs only Eigen.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "tests/support/coulomb_active_set.hpp"

namespace grip::testing {

struct HalfPlaneSpence {
  double a = 0;        // contact half-width (outer edge of the last element that presses)
  double c_stick = 0;  // stick half-width: between the last sticking element and the next
  double c_rule = 0;   // the same by the rule |q| < 0.99 mu p
  double peak = 0;     // largest pressure over Hertz's p0
  int iterations = 0;  // active-set iterations of the last increment (200: not settled)
};

inline HalfPlaneSpence spence_half_plane(double mu, double nu, int per_a, int increments, bool coupled, double Rc = 0) {
  using Eigen::MatrixXd;
  using Eigen::VectorXd;
  const double pi = std::numbers::pi;
  const double beta = (1 - 2 * nu) / (2 * (1 - nu)), A = 1, R = 1, L = 1.3, h = 1.0 / per_a;
  const int N = 2 * static_cast<int>(std::lround(L / h));
  std::vector<double> x(N);
  for (int i = 0; i < N; ++i) x[i] = -L + (i + 0.5) * h;
  auto F = [](double t) { return t == 0 ? 0.0 : t * std::log(std::abs(t)) - t; };
  MatrixXd Lg(N, N), Sg(N, N);  // int ln|x-s|, int sgn(x-s) over element j at x_i
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) {
      const double lo = x[j] - h / 2, hi = x[j] + h / 2;
      Lg(i, j) = F(x[i] - lo) - F(x[i] - hi);
      Sg(i, j) = std::abs(x[i] - lo) - std::abs(x[i] - hi);
    }
  // u_z = Zp p + Zq q, u_x = Xq q + Xp p
  const MatrixXd Zp = -(A / pi) * Lg, Zq = (coupled ? A * beta / 2 : 0.0) * Sg, Xq = -(A / pi) * Lg;
  MatrixXd Xp = -(A * beta / 2) * Sg;
  // A finite cylinder: the surface stretched by sigma_xx = P / (pi Rc), eps_xx = (A / 2) sigma_xx.
  if (Rc > 0)
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) Xp(i, j) += x[i] * (A / 2) * h / (pi * Rc);
  CoulombState st(N);
  for (int i = 0; i < N; ++i)
    if (std::abs(x[i]) < h) st.contact[i] = st.stick[i] = 1;
  const HalfSpaceInfluence m{Zp, Zq, Xq, Xp};
  const std::vector<double> weight(N, h);
  HalfPlaneSpence out;
  double P = 0;
  for (int k = 1; k <= increments; ++k) {
    P = pi / (2 * A * R) * double(k) / increments;
    out.iterations = coulomb_increment(m, x, weight, R, P, mu, st);
  }
  const VectorXd &p = st.p, &q = st.q;
  const std::vector<int> &C = st.contact, &S = st.stick;
  for (int i = 0; i < N; ++i)
    if (p[i] > 0) out.a = std::max(out.a, std::abs(x[i]) + h / 2);
  const int centre = N / 2;
  int hi = centre;
  while (hi + 1 < N && std::abs(q[hi + 1]) < 0.99 * mu * p[hi + 1]) ++hi;
  int hs = centre;
  while (hs + 1 < N && S[hs + 1] && C[hs + 1]) ++hs;
  out.c_rule = 0.5 * (x[hi] + x[hi + 1]);
  out.c_stick = 0.5 * (x[hs] + x[hs + 1]);
  out.peak = p.maxCoeff() / (2 * P / pi);  // Hertz's p0 = 2 P / (pi a) with a = 1
  return out;
}

}  // namespace grip::testing
