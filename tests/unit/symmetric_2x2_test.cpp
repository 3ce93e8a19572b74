// solver/materials/symmetric_2x2.hpp: log, its first and second derivatives, exp and sqrt of symmetric 2 x 2
// tensors against the eigen-decomposition and central differences, at distinct, close and
// equal eigenvalues (where the closed forms switch to their series).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "solver/materials/symmetric_2x2.hpp"

namespace grip {
namespace {

Mat2 spectral(const Mat2& A, double (*f)(double)) {
  Eigen::SelfAdjointEigenSolver<Mat2> es(A);
  return es.eigenvectors() * es.eigenvalues().unaryExpr(f).asDiagonal() * es.eigenvectors().transpose();
}

Mat2 sym(double a11, double a22, double a12) { return (Mat2() << a11, a12, a12, a22).finished(); }

const Mat2 kCases[] = {sym(3.0, 0.4, 0.7),  sym(1.3, 1.3, 1e-9), sym(2.0, 2.0, 0.0),  sym(1.0, 1.0 + 1e-3, 2e-3),
                       sym(5.0, 0.02, 0.1), sym(1.0, 1.1, 0.05), sym(0.9, 1.25, -0.3)};

TEST(Symmetric2x2, FunctionsMatchTheEigenDecomposition) {
  for (const Mat2& A : kCases) {
    EXPECT_LT((log_spd(A) - spectral(A, [](double x) { return std::log(x); })).norm(), 1e-14 * (1 + A.norm()));
    EXPECT_LT((exp_symmetric(log_spd(A)) - A).norm(), 1e-14 * A.norm());
    EXPECT_LT((sqrt_spd(A) * sqrt_spd(A) - A).norm(), 1e-14 * A.norm());
    EXPECT_LT((sqrt_spd(A) - sqrt_spd(A).transpose()).norm(), 1e-15 * A.norm());
  }
}

TEST(Symmetric2x2, LogDerivativeMatchesDifferences) {
  const Mat2 directions[] = {sym(1, 0, 0), sym(0, 1, 0), sym(0, 0, 1), sym(0.3, -0.2, 0.5)};
  for (const Mat2& A : kCases)
    for (const Mat2& dA : directions) {
      // A step scaled to the smallest eigenvalue: differences accurate to ~1e-9 relative.
      const double h = 1e-5 * Eigen::SelfAdjointEigenSolver<Mat2>(A).eigenvalues()[0];
      const Mat2 fd = (log_spd(A + h * dA) - log_spd(A - h * dA)) / (2 * h);
      const Mat2 exact = log_spd_derivative(A, dA);
      EXPECT_LT((exact - fd).norm(), 1e-7 * exact.norm()) << A << "\n" << dA;
    }
}

TEST(Symmetric2x2, LogSecondDerivativeMatchesDifferencesOfTheDerivative) {
  const Mat2 directions[] = {sym(1, 0, 0), sym(0, 1, 0), sym(0, 0, 1), sym(0.3, -0.2, 0.5)};
  for (const Mat2& A : kCases)
    for (const Mat2& dA : directions)
      for (const Mat2& dB : directions) {
        const double h = 1e-5 * Eigen::SelfAdjointEigenSolver<Mat2>(A).eigenvalues()[0];
        const Mat2 fd = (log_spd_derivative(A + h * dB, dA) - log_spd_derivative(A - h * dB, dA)) / (2 * h);
        const Mat2 exact = log_spd_second_derivative(A, dA, dB);
        EXPECT_LT((exact - fd).norm(), 1e-6 * (exact.norm() + log_spd_derivative(A, dA).norm() / A.norm()))
            << A << "\n"
            << dA << "\n"
            << dB;
        EXPECT_LT((exact - log_spd_second_derivative(A, dB, dA)).norm(), 1e-13 * (1 + exact.norm()));
      }
}

}  // namespace
}  // namespace grip
