#pragma once
// One load increment of a rigid parabolic indenter (radius R) pressed with total load P on an
// elastic half-plane or half-space discretized by elements of piecewise constant pressure p and
// tangential shear q: the common core of the independent references for frictional Hertz
// (tests/support/spence_halfplane.hpp, the cylinder; tests/support/sphere_halfspace.hpp, the
// sphere). Contact (u_z = delta - x^2 / 2R) or not (p = 0); within contact, stick (u_t keeps
// its value of the previous increment: the indenter is rigid) or slip (q = s mu p); the active
// sets iterated to a fixed point. Needs only Eigen.
#include <Eigen/Dense>
#include <cmath>
#include <vector>

namespace grip::testing {

// Surface displacements at the elements' collocation points: u_z = Zp p + Zq q (into the body),
// u_t = Tq q + Tp p (tangential).
struct HalfSpaceInfluence {
  Eigen::MatrixXd Zp, Zq, Tq, Tp;
};

struct CoulombState {
  Eigen::VectorXd p, q, ut_prev;
  std::vector<int> contact, stick, sign;  // per element; sign: the slip direction of q

  explicit CoulombState(int n)
      : p(Eigen::VectorXd::Zero(n)), q(Eigen::VectorXd::Zero(n)), ut_prev(Eigen::VectorXd::Zero(n)), contact(n, 0),
        stick(n, 0), sign(n, 0) {}
};

// x: each element's collocation coordinate; weight: its area (sum weight p = P). Returns the
// active-set iterations (200: not settled) and leaves ut_prev at this increment's u_t.
inline int coulomb_increment(const HalfSpaceInfluence& m, const std::vector<double>& x,
                             const std::vector<double>& weight, double R, double P, double mu, CoulombState& st) {
  using Eigen::MatrixXd;
  using Eigen::VectorXd;
  const int N = static_cast<int>(x.size());
  auto& C = st.contact;
  auto& S = st.stick;
  auto& s = st.sign;
  int changes = 1, it = 0;
  for (; changes && it < 200; ++it) {
    MatrixXd M = MatrixXd::Zero(2 * N + 1, 2 * N + 1);  // unknowns p, q, the approach delta
    VectorXd rhs = VectorXd::Zero(2 * N + 1);
    for (int i = 0; i < N; ++i) {
      if (C[i]) {  // u_z = delta - x^2 / 2R
        M.block(i, 0, 1, N) = m.Zp.row(i);
        M.block(i, N, 1, N) = m.Zq.row(i);
        M(i, 2 * N) = -1;
        rhs[i] = -x[i] * x[i] / (2 * R);
        if (S[i]) {
          M.block(N + i, N, 1, N) = m.Tq.row(i);
          M.block(N + i, 0, 1, N) = m.Tp.row(i);
          rhs[N + i] = st.ut_prev[i];
        } else {
          M(N + i, N + i) = 1;
          M(N + i, i) = -s[i] * mu;
        }
      } else {
        M(i, i) = 1;
        M(N + i, N + i) = 1;
      }
    }
    for (int j = 0; j < N; ++j) M(2 * N, j) = weight[j];
    rhs[2 * N] = P;
    const VectorXd sol = M.partialPivLu().solve(rhs);
    st.p = sol.head(N);
    st.q = sol.segment(N, N);
    const double delta = sol[2 * N];
    const VectorXd uz = m.Zp * st.p + m.Zq * st.q, ut = m.Tq * st.q + m.Tp * st.p;
    changes = 0;
    for (int i = 0; i < N; ++i) {
      const double pen = delta - x[i] * x[i] / (2 * R) - uz[i];
      if (C[i] && st.p[i] < 0) {
        C[i] = 0;
        ++changes;
        continue;
      }
      if (!C[i] && pen > 1e-14) {
        C[i] = S[i] = 1;
        ++changes;
        continue;
      }
      if (!C[i]) continue;
      const double du = ut[i] - st.ut_prev[i];
      if (S[i] && std::abs(st.q[i]) > mu * st.p[i]) {
        S[i] = 0;
        s[i] = st.q[i] > 0 ? 1 : -1;
        ++changes;
      } else if (!S[i] && du * s[i] > 1e-15) {
        S[i] = 1;
        ++changes;
      }
    }
  }
  st.ut_prev = m.Tq * st.q + m.Tp * st.p;
  return it;
}

}  // namespace grip::testing
