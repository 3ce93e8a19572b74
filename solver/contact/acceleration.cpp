#include "solver/contact/acceleration.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace grip {
namespace {

void check_level_args(double eps1, int n) {
  // Written so that NaN fails too.
  if (!(eps1 > 0.0 && eps1 <= 1.0))
    throw std::invalid_argument("acceleration: eps1 must be in (0, 1], got " + std::to_string(eps1));
  if (n < 1) throw std::invalid_argument("acceleration: level n must be >= 1, got " + std::to_string(n));
}

// One level of the normalized bound: [e, 1] -> [e / w, 1]. 4e / (1 + e)^2 <= 1 always,
// and stays representable for any e in (0, 1] (no omega_n to underflow).
double next_eps(double e) {
  const double b = 1.0 + e;
  return std::min(1.0, e / (b * b / 4.0));
}

}  // namespace

AcceleratedStep accelerate(const Matrix& C1, double eps1, int n) {
  check_level_args(eps1, n);
  if (C1.rows() != C1.cols())
    throw std::invalid_argument("acceleration: C1 must be square, got " + std::to_string(C1.rows()) + " x " +
                                std::to_string(C1.cols()));
  const Eigen::Index size = C1.rows();
  Matrix C = C1;
  Matrix M = Matrix::Identity(size, size);
  double e = eps1;
  for (int level = 2; level <= n; ++level) {
    const double b = 1.0 + e;
    const double w = b * b / 4.0;
    Matrix B = -C;
    B.diagonal().array() += b;
    M = (B * M) / w;
    C = (C * B) / w;
    // C and B commute in exact arithmetic, so C B is symmetric; keep it so.
    C = (0.5 * (C + C.transpose())).eval();
    e = next_eps(e);
  }
  AcceleratedStep out;
  out.alpha = 2.0 / (1.0 + e);
  out.step_matrix = out.alpha * M;
  out.eps_n = e;
  out.n = n;
  return out;
}

std::vector<double> level_conditions(double eps1, int n) {
  check_level_args(eps1, n);
  std::vector<double> kappa;
  kappa.reserve(static_cast<std::size_t>(n));
  double e = eps1;
  for (int level = 1; level <= n; ++level) {
    kappa.push_back(1.0 / e);
    e = next_eps(e);
  }
  return kappa;
}

int auto_level(double eps1, double target, int max_n) {
  check_level_args(eps1, 1);
  if (!(target >= 1.0)) throw std::invalid_argument("auto_level: target must be >= 1");
  if (max_n < 1) throw std::invalid_argument("auto_level: max_n must be >= 1");
  double e = eps1;
  for (int level = 1; level < max_n; ++level) {
    if (1.0 / e <= target) return level;
    e = next_eps(e);
  }
  return max_n;
}

double smallest_eigenvalue(const Matrix& C1) {
  if (C1.rows() != C1.cols() || C1.rows() == 0)
    throw std::invalid_argument("smallest_eigenvalue: C1 must be square and non-empty");
  Eigen::SelfAdjointEigenSolver<Matrix> solver(C1, Eigen::EigenvaluesOnly);
  if (solver.info() != Eigen::Success)
    throw std::invalid_argument("smallest_eigenvalue: eigenvalues of C1 did not converge (non-finite entries?)");
  const double lambda = solver.eigenvalues()(0);  // ascending order
  return std::max(lambda, kMinEpsilon);
}

double warmup_epsilon(const std::vector<double>& v_norms, double alpha, int first, int last) {
  if (!(alpha > 0.0)) throw std::invalid_argument("warmup_epsilon: alpha must be > 0");
  if (first < 1 || last < first) throw std::invalid_argument("warmup_epsilon: need 1 <= first <= last");
  if (v_norms.size() <= static_cast<std::size_t>(first))
    throw std::invalid_argument("warmup_epsilon: history of " + std::to_string(v_norms.size()) +
                                " norms does not reach iteration " + std::to_string(first));
  const std::size_t end = std::min(v_norms.size() - 1, static_cast<std::size_t>(last));
  double eps = std::numeric_limits<double>::infinity();
  for (std::size_t m = static_cast<std::size_t>(first); m <= end; ++m) {
    const double prev = v_norms[m - 1], now = v_norms[m];
    if (!(std::isfinite(prev) && std::isfinite(now) && prev >= 0.0 && now >= 0.0))
      throw std::invalid_argument("warmup_epsilon: norms must be finite and non-negative");
    if (prev == 0.0) continue;  // already converged: this ratio says nothing
    eps = std::min(eps, (1.0 - now / prev) / alpha);
  }
  // No usable ratio (all converged) also falls to the floor: the conservative bound.
  if (!std::isfinite(eps)) return kMinEpsilon;
  return std::clamp(eps, kMinEpsilon, 1.0);
}

}  // namespace grip
