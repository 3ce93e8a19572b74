// The polynomial accelerator of Appendix C (solver/contact/acceleration.hpp) on its own:
// a linear SPD fixed-point problem C1 p = s iterated as eq. 13 does,
// p <- p - step_matrix (C1 p - s), whose error contracts by eq. 27 per iteration.
#include "solver/contact/acceleration.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

namespace grip {
namespace {

// Eigenvalues log-spaced from lo to 1.
Vector log_spaced(double lo, int count) {
  Vector lambda(count);
  for (int i = 0; i < count; ++i) lambda(i) = std::pow(10.0, std::log10(lo) * (1.0 - double(i) / (count - 1)));
  return lambda;
}

// Q diag(lambda) Q^T with a seeded random orthogonal Q (Eigen's Random is not seedable).
Matrix spd_with_spectrum(const Vector& lambda, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal;
  Matrix A(lambda.size(), lambda.size());
  for (Eigen::Index i = 0; i < A.rows(); ++i)
    for (Eigen::Index j = 0; j < A.cols(); ++j) A(i, j) = normal(gen);
  Eigen::HouseholderQR<Matrix> qr(A);
  const Matrix Q = qr.householderQ();
  const Matrix C = Q * lambda.asDiagonal() * Q.transpose();
  return 0.5 * (C + C.transpose());
}

// C1 = C / ||C||_inf as the scheme forms it; its eigenvalues are then in (0, 1].
Matrix normalized(const Matrix& C) { return C / C.cwiseAbs().rowwise().sum().maxCoeff(); }

Vector random_vector(Eigen::Index size, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal;
  Vector v(size);
  for (auto& x : v) x = normal(gen);
  return v;
}

// Sorted eigenvalues of a product of commuting symmetric matrices (symmetric up to round-off).
Vector sym_eigenvalues(const Matrix& A) {
  const Matrix S = 0.5 * (A + A.transpose());
  return Eigen::SelfAdjointEigenSolver<Matrix>(S, Eigen::EigenvaluesOnly).eigenvalues();
}

// Independent of the library: the paper's condition number recursion.
double next_condition(double kappa) { return (1.0 + kappa) * (1.0 + kappa) / (4.0 * kappa); }
double contraction(double kappa) { return (kappa - 1.0) / (kappa + 1.0); }

TEST(AccelerationLevels, KnownSequenceFromKappa1000) {
  const std::vector<double> kappa = level_conditions(1e-3, 8);
  ASSERT_EQ(kappa.size(), 8u);
  EXPECT_NEAR(kappa[0], 1000.0, 1e-9);
  double expected = 1000.0;
  for (std::size_t k = 1; k < kappa.size(); ++k) {
    expected = next_condition(expected);
    EXPECT_NEAR(kappa[k], expected, 1e-12 * expected) << "level " << k + 1;
  }
  EXPECT_NEAR(kappa[1], 250.50025, 1e-9);  // (1001)^2 / 4000
  // docs/algorithm.md#the-accelerated-multiplier-update quotes 250.5, 63.1, 16.3, 4.59, 1.70,
  // 1.07; these rounded values hold within 5 %.
  const std::vector<double> approx = {250.0, 63.0, 16.0, 4.6, 1.70, 1.05};
  for (std::size_t k = 0; k < approx.size(); ++k)
    EXPECT_NEAR(kappa[k + 1], approx[k], 0.05 * approx[k]) << "level " << k + 2;
  EXPECT_NEAR(kappa[5], 1.7012, 1e-4);
  EXPECT_NEAR(kappa[6], 1.0723, 1e-4);
}

TEST(AccelerationLevels, DecreaseMonotonicallyToOneWithoutOverflow) {
  const std::vector<double> kappa = level_conditions(1e-300, 600);
  for (std::size_t k = 0; k < kappa.size(); ++k) {
    ASSERT_TRUE(std::isfinite(kappa[k])) << "level " << k + 1;
    ASSERT_GE(kappa[k], 1.0);
    if (k > 0) {
      ASSERT_LE(kappa[k], kappa[k - 1]);
    }
  }
  EXPECT_EQ(kappa.back(), 1.0);
  EXPECT_EQ(level_conditions(1.0, 5), std::vector<double>(5, 1.0));
}

TEST(AccelerationLevels, AutoLevelPicksSmallestReachingTarget) {
  for (double eps1 : {1.0, 0.5, 1e-2, 1e-3, 1e-7, 1e-12}) {
    for (double target : {1.1, 1.01, 2.0}) {
      const int n = auto_level(eps1, target);
      const std::vector<double> kappa = level_conditions(eps1, n);
      EXPECT_LE(kappa.back(), target) << eps1 << " " << target;
      if (n > 1) {
        EXPECT_GT(kappa[n - 2], target) << eps1 << " " << target;
      }
    }
  }
  EXPECT_EQ(auto_level(1.0), 1);
  EXPECT_EQ(auto_level(1e-3), 7);           // 1.0723 <= 1.1 < 1.7012
  EXPECT_EQ(auto_level(1e-12, 1.1, 5), 5);  // capped
  // docs/algorithm.md#the-accelerated-multiplier-update: about log4(cond) + 2 levels.
  EXPECT_NEAR(auto_level(1e-7), std::log(1e7) / std::log(4.0) + 2.0, 1.0);
}

TEST(AccelerationStep, LevelOneIsScaledIdentity) {
  const Matrix C1 = normalized(spd_with_spectrum(log_spaced(1e-3, 12), 1));
  const AcceleratedStep step = accelerate(C1, 0.25, 1);
  EXPECT_EQ(step.n, 1);
  EXPECT_DOUBLE_EQ(step.alpha, 2.0 / 1.25);
  EXPECT_DOUBLE_EQ(step.eps_n, 0.25);
  EXPECT_TRUE(step.step_matrix == step.alpha * Matrix::Identity(12, 12));
}

// The normalized recursion is the paper's C.3-C.7 and eq. 29, rescaled: same alpha * M_n
// while the paper's omega_n is still representable.
TEST(AccelerationStep, MatchesPaperFormWhileItDoesNotUnderflow) {
  const Matrix C1 = normalized(spd_with_spectrum(log_spaced(1e-3, 30), 2));
  const double eps1 = smallest_eigenvalue(C1);
  const Matrix E = Matrix::Identity(30, 30);
  Matrix C = C1, M = E;
  double omega = 1.0, eps = eps1;
  for (int n = 1; n <= 6; ++n) {
    if (n >= 2) {
      const double b = eps + omega;
      const Matrix B = b * E - C;
      M = B * M;
      C = C * B;
      eps = eps * omega;
      omega = b * b / 4.0;
    }
    const Matrix paper = 2.0 / (omega + eps) * M;
    const AcceleratedStep step = accelerate(C1, eps1, n);
    EXPECT_LE((step.step_matrix - paper).norm(), 1e-9 * paper.norm()) << "n = " << n;
    EXPECT_NEAR(step.eps_n, eps / omega, 1e-12) << "n = " << n;
  }
  // Why the code normalizes: the paper's omega_n underflows a few levels later.
  double w = 1.0, e = eps1;
  for (int n = 2; n <= 12; ++n) {
    const double b = e + w;
    e *= w;
    w = b * b / 4.0;
  }
  EXPECT_LT(w, 1e-300);
}

// Level by level, C1 * M_n (alpha-free) has the eigenvalues of the scalar map of C1's,
// inside [e_n, 1] with e_n attained when eps1 is exact.
TEST(AccelerationStep, EigenvaluesFollowScalarMap) {
  for (double lo : {1e-3, 1e-6}) {
    const Matrix C1 = normalized(spd_with_spectrum(log_spaced(lo, 40), 3));
    const double eps1 = smallest_eigenvalue(C1);
    Vector mapped = sym_eigenvalues(C1);
    double e = eps1;
    for (int n = 1; n <= 10; ++n) {
      if (n >= 2) {
        const double b = 1.0 + e, w = b * b / 4.0;
        mapped = (mapped.array() * (b - mapped.array()) / w).eval();
        e = e / w;
      }
      const AcceleratedStep step = accelerate(C1, eps1, n);
      const Vector lambda = sym_eigenvalues(C1 * step.step_matrix / step.alpha);
      Vector expected = mapped;
      std::sort(expected.begin(), expected.end());
      EXPECT_LE((lambda - expected).cwiseAbs().maxCoeff(), 1e-10) << "lo " << lo << " n " << n;
      EXPECT_NEAR(lambda.minCoeff(), step.eps_n, 1e-8 * step.eps_n) << "lo " << lo << " n " << n;
      EXPECT_LE(lambda.maxCoeff(), 1.0 + 1e-12);
      EXPECT_NEAR(step.eps_n, 1.0 / level_conditions(eps1, n).back(), 1e-14);
      EXPECT_NEAR(step.alpha, 2.0 / (1.0 + step.eps_n), 1e-15);
    }
  }
}

// A spectrum that attains both ends of every level's interval (it holds eps1, 1 and, for
// each level, a point that the earlier levels carry to that level's midpoint, which the
// next level sends to 1): cond(C1 M_n) is then exactly kappa_n, and equals
// (1 + k)^2 / (4 k) of the previous level's measured k.
TEST(AccelerationStep, ConditionNumberPerLevelIsExact) {
  const double eps1 = 1e-3;
  const int levels = 8;
  std::vector<double> e(levels + 1, eps1);
  for (int k = 1; k <= levels; ++k) {
    const double b = 1.0 + e[k - 1];
    e[k] = e[k - 1] / (b * b / 4.0);
  }
  std::vector<double> lambda = {eps1, 1.0};
  // e[k] is the lower bound at level k + 1. That level's map x (b - x) / w sends its
  // midpoint b / 2 to 1, so level k + 2 reaches 1 if level k + 1 holds b / 2. Pull each
  // midpoint back to C1 through the lower inverse x = (b / 2)(1 - sqrt(1 - y)).
  for (int k = levels - 2; k >= 0; --k) {
    double y = (1.0 + e[k]) / 2.0;
    for (int j = k - 1; j >= 0; --j) y = (1.0 + e[j]) / 2.0 * (1.0 - std::sqrt(1.0 - y));
    lambda.push_back(y);
  }
  const Vector filler = log_spaced(eps1, 20);
  lambda.insert(lambda.end(), filler.begin(), filler.end());
  const Matrix C1 = spd_with_spectrum(Eigen::Map<Vector>(lambda.data(), Eigen::Index(lambda.size())), 4);

  const std::vector<double> kappa = level_conditions(eps1, levels);
  double previous = 0.0;
  for (int n = 1; n <= levels; ++n) {
    const AcceleratedStep step = accelerate(C1, eps1, n);
    const Vector mu = sym_eigenvalues(C1 * step.step_matrix / step.alpha);
    const double cond = mu.maxCoeff() / mu.minCoeff();
    EXPECT_NEAR(mu.maxCoeff(), 1.0, 1e-10) << "n " << n;
    EXPECT_NEAR(cond, kappa[n - 1], 1e-8 * kappa[n - 1]) << "n " << n;
    if (n > 1) {
      EXPECT_NEAR(cond, next_condition(previous), 1e-8 * cond) << "n " << n;
    }
    previous = cond;
  }
}

struct RateCase {
  double lo;  // smallest eigenvalue of C before normalization (largest is 1)
  int n;
};

// eq. 27: rho(I - step C1) = (kappa_n - 1) / (kappa_n + 1), and a run of eq. 13 on the
// linear problem contracts the residual at that rate. Each n is measured on a spectrum
// where its rate is neither ~1 (too slow to run out) nor ~0 (gone in 3 iterations).
TEST(AccelerationIteration, ContractionMatchesEq27) {
  const std::vector<RateCase> cases = {{1e-3, 1}, {1e-3, 2}, {1e-3, 4}, {1e-6, 4}, {1e-6, 8}};
  const int size = 40;
  for (const RateCase& c : cases) {
    const Matrix C1 = normalized(spd_with_spectrum(log_spaced(c.lo, size), 5));
    const double eps1 = smallest_eigenvalue(C1);
    const AcceleratedStep step = accelerate(C1, eps1, c.n);
    const double predicted = contraction(level_conditions(eps1, c.n).back());

    const Matrix iteration = Matrix::Identity(size, size) - step.step_matrix * C1;
    const double rho = Eigen::EigenSolver<Matrix>(iteration, false).eigenvalues().cwiseAbs().maxCoeff();
    EXPECT_NEAR(rho, predicted, 1e-8 * predicted) << "lo " << c.lo << " n " << c.n;

    // Iterate until the residual fell by 1e-10 (the round-off floor, ~1e-16 ||p|| / ||s||,
    // is ~1e-11 for the 1e-6 spectrum), measure the rate over the second half.
    const Vector s = random_vector(size, 6);
    Vector p = Vector::Zero(size);
    Vector r = C1 * p - s;
    std::vector<double> history = {r.norm()};
    while (history.back() > 1e-10 * history.front() && history.size() < 2000000) {
      p -= step.step_matrix * r;
      r = C1 * p - s;
      history.push_back(r.norm());
    }
    const std::size_t last = history.size() - 1, mid = last / 2;
    ASSERT_GT(last - mid, 2u);
    const double measured = std::pow(history[last] / history[mid], 1.0 / double(last - mid));
    std::printf("[ rate     ] lo %g n %d kappa_n %.6g eq.27 %.6f spectral %.6f measured %.6f (%zu iterations)\n", c.lo,
                c.n, level_conditions(eps1, c.n).back(), predicted, rho, measured, last);
    EXPECT_NEAR(measured, predicted, 0.03 * predicted) << "lo " << c.lo << " n " << c.n;
    // The convergence speed too, not only the rate (which is ~1 for small n). Looser: in
    // a finite run, modes just inside the interval still weigh in.
    EXPECT_NEAR(std::log(measured) / std::log(predicted), 1.0, 0.1) << "lo " << c.lo << " n " << c.n;
    EXPECT_LE(measured, predicted * (1.0 + 1e-6));
    EXPECT_LE((C1 * p - s).norm(), 1e-10 * s.norm());
  }
}

TEST(AccelerationStep, DeepLevelsStayFinite) {
  for (double lo : {1e-12, 1e-3}) {
    const Matrix C1 = normalized(spd_with_spectrum(log_spaced(lo, 25), 7));
    const AcceleratedStep step = accelerate(C1, 1e-12, 30);
    EXPECT_EQ(step.n, 30);
    EXPECT_TRUE(step.step_matrix.allFinite());
    EXPECT_TRUE(std::isfinite(step.alpha));
    EXPECT_GT(step.eps_n, 0.0);
    EXPECT_LE(step.eps_n, 1.0);
    EXPECT_GE(step.alpha, 1.0);
    EXPECT_LT(step.alpha, 2.0);
    // eps1 below the true smallest eigenvalue is a safe bound: still a contraction.
    const Vector mu = sym_eigenvalues(C1 * step.step_matrix);
    EXPECT_GT(mu.minCoeff(), 0.0);
    EXPECT_LT(mu.maxCoeff(), 2.0);
  }
  const std::vector<double> kappa = level_conditions(1e-12, 30);
  for (double k : kappa) EXPECT_TRUE(std::isfinite(k));
}

TEST(AccelerationEigenvalue, ExactSmallestAndFloor) {
  const Matrix C1 = spd_with_spectrum(log_spaced(1e-4, 15), 8);
  EXPECT_NEAR(smallest_eigenvalue(C1), 1e-4, 1e-12);
  Matrix singular = Matrix::Zero(3, 3);
  singular(0, 0) = 1.0;
  EXPECT_EQ(smallest_eigenvalue(singular), kMinEpsilon);
}

TEST(AccelerationWarmup, KnownRatios) {
  const double alpha = 1.99;
  // Index 0 is before the first iteration; ratios r_m / r_(m-1) for m = 1..10.
  const std::vector<double> ratios = {1.5, 0.2, 0.99, 0.995, 0.98, 0.999, 0.97, 0.99, 0.99, 0.99, 1.2};
  std::vector<double> norms = {1.0};
  for (double q : ratios) norms.push_back(norms.back() * q);
  // m = 1, 2 (a rise and a fast drop) and m = 11 lie outside I = 3, J = 10.
  EXPECT_NEAR(warmup_epsilon(norms, alpha), (1.0 - 0.999) / alpha, 1e-12);
  EXPECT_NEAR(warmup_epsilon(norms, alpha, 3, 5), (1.0 - 0.995) / alpha, 1e-12);
  // A history that stops at m = 5 uses m = 3..5.
  EXPECT_NEAR(warmup_epsilon(std::vector<double>(norms.begin(), norms.begin() + 6), alpha), (1.0 - 0.995) / alpha,
              1e-12);
  // A ratio >= 1 inside the window: no contraction seen, the floor.
  EXPECT_EQ(warmup_epsilon(norms, alpha, 1, 10), kMinEpsilon);
  EXPECT_EQ(warmup_epsilon(norms, alpha, 3, 11), kMinEpsilon);
  EXPECT_EQ(warmup_epsilon({1.0, 1.0, 1.0, 1.0}, alpha), kMinEpsilon);
}

// On the linear problem, eq. 30 with n = 1 and alpha = 1.99 bounds the smallest
// eigenvalue from above (docs/algorithm.md#the-accelerated-multiplier-update:
// it overestimates).
TEST(AccelerationWarmup, OverestimatesOnLinearProblem) {
  const Matrix C1 = normalized(spd_with_spectrum(log_spaced(1e-3, 30), 9));
  const double alpha = 1.99;
  const Vector s = random_vector(30, 10);
  Vector p = Vector::Zero(30);
  Vector v = C1 * p - s;
  std::vector<double> norms = {v.norm()};
  for (int m = 1; m <= 10; ++m) {
    p -= alpha * v;
    v = C1 * p - s;
    norms.push_back(v.norm());
  }
  const double estimate = warmup_epsilon(norms, alpha);
  const double exact = smallest_eigenvalue(C1);
  EXPECT_GE(estimate, exact * (1.0 - 1e-12));
  EXPECT_LE(estimate, 1.0);
}

TEST(AccelerationArgs, InvalidArgumentsThrow) {
  const Matrix C1 = Matrix::Identity(3, 3);
  EXPECT_THROW(accelerate(C1, 0.5, 0), std::invalid_argument);
  EXPECT_THROW(accelerate(C1, 0.0, 2), std::invalid_argument);
  EXPECT_THROW(accelerate(C1, -0.1, 2), std::invalid_argument);
  EXPECT_THROW(accelerate(C1, 1.5, 2), std::invalid_argument);
  EXPECT_THROW(accelerate(C1, std::nan(""), 2), std::invalid_argument);
  EXPECT_THROW(accelerate(Matrix::Identity(3, 2), 0.5, 2), std::invalid_argument);
  EXPECT_NO_THROW(accelerate(C1, 1.0, 3));
  EXPECT_THROW(level_conditions(0.0, 3), std::invalid_argument);
  EXPECT_THROW(level_conditions(0.5, 0), std::invalid_argument);
  EXPECT_THROW(auto_level(2.0), std::invalid_argument);
  EXPECT_THROW(auto_level(0.5, 0.9), std::invalid_argument);
  EXPECT_THROW(auto_level(0.5, 1.1, 0), std::invalid_argument);
  EXPECT_THROW(smallest_eigenvalue(Matrix(0, 0)), std::invalid_argument);
  EXPECT_THROW(smallest_eigenvalue(Matrix::Identity(2, 3)), std::invalid_argument);
  const std::vector<double> norms = {1, 0.5, 0.4, 0.3, 0.2};
  EXPECT_THROW(warmup_epsilon(norms, 0.0), std::invalid_argument);
  EXPECT_THROW(warmup_epsilon(norms, 1.99, 0, 3), std::invalid_argument);
  EXPECT_THROW(warmup_epsilon(norms, 1.99, 4, 3), std::invalid_argument);
  EXPECT_THROW(warmup_epsilon(norms, 1.99, 5, 10), std::invalid_argument);  // no index 5
  EXPECT_THROW(warmup_epsilon({1, 0.5, 0.4, -0.3}, 1.99), std::invalid_argument);
}

}  // namespace
}  // namespace grip
