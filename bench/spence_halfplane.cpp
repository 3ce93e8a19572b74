// Issue 15, the frictional Hertz check: the same problem on an elastic half-plane by a
// boundary-element model, to tell the finite cylinder's effect from the relation's. Piecewise
// constant p and q on elements of width a/per_a, the surface displacements of Johnson's
// eqs. 2.19 and 2.22 (the coupling beta both ways, or only q's, `coupled` = 0), a rigid
// cylinder R = 1 pressed by a load raised in `increments` equal steps to Hertz's a = 1, Coulomb
// friction with stick measured from the previous increment, active sets iterated to a fixed
// point. `Rc` > 0 adds the surface stretch of a finite cylinder of radius Rc (the full disc's
// uniform tension P / (pi Rc) at its load point). Prints c/a by the 0.99 mu p rule (as the
// tests read it) and by the stick set.
//   build/tests/bench/spence_halfplane mu per_a increments coupled Rc   (built with the project)
//   e.g. build/tests/bench/spence_halfplane 0.3 80 100 1 20
// Measured (nu = 0.3, mu = 0.3, a/h = 80, 100 increments; a/h = 120 and 160 the same):
//   uncoupled, half-plane:  stick set 0.750 (a/h 160: 0.744 = K'/K relation), 0.99 rule 0.713
//   coupled, half-plane:    stick set 0.692, 0.99 rule 0.667; a 2.5 % below Hertz, peak +8 %
//   coupled, Rc = 20 (the FE scene's R / a): stick set 0.744, 0.99 rule 0.718
//   coupled, Rc = 10: stick set 0.795, 0.99 rule 0.769
#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>
using Eigen::MatrixXd; using Eigen::VectorXd;
int main(int argc, char** argv) {
  const double nu = 0.3, mu = argc > 1 ? atof(argv[1]) : 0.3;
  const int per_a = argc > 2 ? atoi(argv[2]) : 40, inc = argc > 3 ? atoi(argv[3]) : 50;
  const bool coupled = argc > 4 ? atoi(argv[4]) : 1;
  const double beta = (1 - 2 * nu) / (2 * (1 - nu)), A = 1, R = 1, L = 1.3, h = 1.0 / per_a;
  const int N = 2 * int(std::lround(L / h));
  std::vector<double> x(N);
  for (int i = 0; i < N; ++i) x[i] = -L + (i + 0.5) * h;
  auto F = [](double t) { return t == 0 ? 0.0 : t * std::log(std::abs(t)) - t; };
  MatrixXd Lg(N, N), Sg(N, N);  // int ln|x-s|, int sgn(x-s) over element j at x_i
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) {
      const double a = x[j] - h / 2, b = x[j] + h / 2;
      Lg(i, j) = F(x[i] - a) - F(x[i] - b);
      Sg(i, j) = std::abs(x[i] - a) - std::abs(x[i] - b);
    }
  // u_z = Zp p + Zq q, u_x = Xq q + Xp p
  const MatrixXd Zp = -(A / M_PI) * Lg, Zq = (coupled ? A * beta / 2 : 0.0) * Sg, Xq = -(A / M_PI) * Lg;
  MatrixXd Xp = -(A * beta / 2) * Sg;
  // A finite cylinder of radius Rc: the surface stretched by sigma_xx = P / (pi Rc) (the full
  // disc's uniform tension at its load point), eps_xx = (A / 2) sigma_xx.
  const double Rc = argc > 5 ? atof(argv[5]) : 0.0;
  if (Rc > 0) for (int i = 0; i < N; ++i) for (int j = 0; j < N; ++j) Xp(i, j) += x[i] * (A / 2) * h / (M_PI * Rc);
  VectorXd p = VectorXd::Zero(N), q = VectorXd::Zero(N), ux_prev = VectorXd::Zero(N);
  std::vector<int> C(N, 0), S(N, 0), s(N, 0);  // contact, stick, slip sign
  double delta = 0;
  for (int i = 0; i < N; ++i) if (std::abs(x[i]) < h) { C[i] = 1; S[i] = 1; }
  for (int k = 1; k <= inc; ++k) {
    const double P = M_PI / (2 * A * R) * double(k) / inc;
    int changes = 1, it = 0;
    for (; changes && it < 200; ++it) {
      // unknowns: p (N), q (N), delta
      MatrixXd M = MatrixXd::Zero(2 * N + 1, 2 * N + 1);
      VectorXd r = VectorXd::Zero(2 * N + 1);
      for (int i = 0; i < N; ++i) {
        if (C[i]) {  // u_z = delta - x^2/2R
          M.block(i, 0, 1, N) = Zp.row(i); M.block(i, N, 1, N) = Zq.row(i); M(i, 2 * N) = -1; r[i] = -x[i] * x[i] / (2 * R);
          if (S[i]) { M.block(N + i, N, 1, N) = Xq.row(i); M.block(N + i, 0, 1, N) = Xp.row(i); r[N + i] = ux_prev[i]; }
          else { M(N + i, N + i) = 1; M(N + i, i) = -s[i] * mu; }
        } else { M(i, i) = 1; M(N + i, N + i) = 1; }
      }
      for (int j = 0; j < N; ++j) M(2 * N, j) = h;
      r[2 * N] = P;
      const VectorXd sol = M.partialPivLu().solve(r);
      p = sol.head(N); q = sol.segment(N, N); delta = sol[2 * N];
      const VectorXd uz = Zp * p + Zq * q, ux = Xq * q + Xp * p;
      changes = 0;
      for (int i = 0; i < N; ++i) {
        const double pen = delta - x[i] * x[i] / (2 * R) - uz[i];
        if (C[i] && p[i] < 0) { C[i] = 0; ++changes; continue; }
        if (!C[i] && pen > 1e-14) { C[i] = 1; S[i] = 1; ++changes; continue; }
        if (!C[i]) continue;
        const double du = ux[i] - ux_prev[i];
        if (S[i] && std::abs(q[i]) > mu * p[i]) { S[i] = 0; s[i] = q[i] > 0 ? 1 : -1; ++changes; }
        else if (!S[i] && du * s[i] > 1e-15) { S[i] = 1; ++changes; }
      }
    }
    ux_prev = Xq * q + Xp * p;
    if (k == inc) {
      double a = 0; for (int i = 0; i < N; ++i) if (p[i] > 0) a = std::max(a, std::abs(x[i]) + h / 2);
      int centre = N / 2; int hi = centre; while (hi + 1 < N && std::abs(q[hi + 1]) < 0.99 * mu * p[hi + 1]) ++hi;
      double c = 0.5 * (x[hi] + x[hi + 1]);
      int hs = centre; while (hs + 1 < N && S[hs + 1] && C[hs + 1]) ++hs;
      std::printf("  stick set: c/a %.4f\n", (0.5 * (x[hs] + x[hs + 1])) / a);
      const double peak = p.maxCoeff(), p0 = 2 * P / M_PI;  // Hertz's a = 1
      std::printf("active-set iterations %d (200: not settled): a %.4f (Hertz 1), c %.4f, c/a %.4f by the 0.99 rule; "
                  "peak %.4f of Hertz's p0\n", it, a, c, c / a, peak / p0);
    }
  }
}
