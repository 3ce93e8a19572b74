#pragma once
// Polynomial acceleration of the contact error vector update (Lee & Kim, eq. 13 with
// Appendix C, eq. C.3-C.7; alpha from eq. 29, contraction eq. 27, epsbar_1 from eq. 30).
//
// Everything here acts on the active block only: C1 = C'_EE / ||C'||_inf, the rows and
// columns of the compliance C' = E C E whose contact error components are not identically
// zero (E = 1), divided by the infinity norm, so C1 is symmetric positive definite with
// eigenvalues in (0, 1]. The update of eq. 13 on that block is
//     p_E <- p_E - step_matrix * v_E / ||C'||_inf,   step_matrix = alpha * M_n,
// and its linearization E s(m) ~= (I - alpha C_n) v(m-1) (eq. 23) with C_n = C1 M_n.
//
// Each level maps the eigenvalue interval [eps, omega] of C_(n-1) to [eps*omega, b^2/4]
// (b = eps + omega), so the condition number kappa becomes (1 + kappa)^2 / (4 kappa).
// The recursion is normalized so that every level's upper bound is 1
// (docs/algorithm.md#the-accelerated-multiplier-update): the paper's omega_n underflows past n ~ 9,
// the normalized form is the same alpha * M_n without that.
#include <vector>

#include "solver/model/types.hpp"

namespace grip {

// Floor for an eigenvalue bound that came out zero or negative (a singular or nearly
// singular active block, or a warm-up that did not contract): tiny, so that the
// acceleration level, not a wrong bound, pays for it.
inline constexpr double kMinEpsilon = 1e-15;

// The accelerated step of eq. 13 on the active block: step = alpha * M_n * v / ||C'||_inf.
struct AcceleratedStep {
  Matrix step_matrix;  // alpha * M_n, normalized as above, on the active block
  double alpha = 1.0;  // 2 / (1 + e_n) in the normalized form (eq. 29)
  double eps_n = 1.0;  // normalized lower eigenvalue bound of C1 * M_n after n levels (upper bound 1)
  int n = 1;           // acceleration level used
};

// Builds alpha * M_n for C1 (symmetric positive definite, eigenvalues in (0, 1]) with
// eps1 a lower bound of its smallest eigenvalue (exact or eq. 30). n = 1 gives
// M = I and alpha = 2 / (1 + eps1). Costs 2 (n - 1) dense products of C1's size.
// Throws std::invalid_argument unless n >= 1, 0 < eps1 <= 1 and C1 is square.
AcceleratedStep accelerate(const Matrix& C1, double eps1, int n);

// Condition numbers kappa_1..kappa_n of the levels, kappa_1 = 1 / eps1 and
// kappa_(k+1) = (1 + kappa_k)^2 / (4 kappa_k); level k contracts the contact error by
// (kappa_k - 1) / (kappa_k + 1) per iteration (eq. 27 with eq. 29's alpha).
std::vector<double> level_conditions(double eps1, int n);

// The "auto" acceleration level: the smallest n whose condition number is at most
// target, capped at max_n. Needs target >= 1 and max_n >= 1.
int auto_level(double eps1, double target = 1.1, int max_n = 30);

// Exact smallest eigenvalue of the symmetric C1 (a small dense eigenproblem), clamped
// below at kMinEpsilon. Throws std::invalid_argument for an empty or non-square C1.
double smallest_eigenvalue(const Matrix& C1);

// eq. 30: epsbar_1 = min over first <= m <= last of (1 - r_m / r_(m-1)) / alpha, where
// v_norms[m] = ||v(m)||_2 (index 0 = before the first iteration) from a warm-up run with
// n = 1 and this alpha (the paper: 1.99, I = 3, J = 10). A history shorter than `last`
// uses what it has from `first` on. The result is clamped below at kMinEpsilon: a ratio
// >= 1 (no contraction seen) makes the min non-positive and so gives the floor, the
// conservative bound. Throws std::invalid_argument unless alpha > 0,
// 1 <= first <= last and v_norms reaches index first.
double warmup_epsilon(const std::vector<double>& v_norms, double alpha, int first = 3, int last = 10);

}  // namespace grip
