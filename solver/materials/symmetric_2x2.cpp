#include "solver/materials/symmetric_2x2.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace grip {
namespace {

// m = tr A / 2 and r^2 = ((A11 - A22) / 2)^2 + A12^2: the eigenvalues are m +- r.
struct Spectrum {
  double m, r;
  explicit Spectrum(const Mat2& A)
      : m(0.5 * A.trace()), r(std::hypot(0.5 * (A(0, 0) - A(1, 1)), 0.5 * (A(0, 1) + A(1, 0)))) {}
};

// With x = r / m in [0, 1): h = atanh(x) / x and k = h'(x) / x, both even and smooth in x (their
// series where the closed forms cancel).
void atanh_ratios(double x, double& h, double& k) {
  if (x < 0.1) {
    h = k = 0.0;
    double p = 1.0;
    for (int i = 0; i < 20; ++i, p *= x * x) {
      h += p / (2 * i + 1);
      k += p * (2.0 * (i + 1)) / (2 * i + 3);
    }
    return;
  }
  const double t = std::atanh(x);
  h = t / x;
  k = (x / (1 - x * x) - t) / (x * x * x);
}

// l = k'(x) / x, even and smooth in x: 2 / (x^2 (1 - x^2)^2) - 3 k / x^2, or its series
// sum 4 (i + 1) (i + 2) x^2i / (2 i + 5) where the closed form cancels.
double atanh_ratio_slope(double x, double k) {
  if (x < 0.3) {
    double l = 0.0, p = 1.0;
    for (int i = 0; i < 60; ++i, p *= x * x) l += p * 4.0 * (i + 1) * (i + 2) / (2 * i + 5);
    return l;
  }
  const double q = 1 - x * x;
  return (2 / (q * q) - 3 * k) / (x * x);
}

}  // namespace

// log A = alpha I + beta (A - m I): alpha = (ln(m + r) + ln(m - r)) / 2 = ln(det A) / 2 and
// beta = (ln(m + r) - ln(m - r)) / (2 r) = atanh(r / m) / r = h(x) / m.
Mat2 log_spd(const Mat2& A) {
  const Spectrum s(A);
  double h, k;
  atanh_ratios(s.r / s.m, h, k);
  return 0.5 * std::log(A.determinant()) * Mat2::Identity() + h / s.m * (A - s.m * Mat2::Identity());
}

// d alpha = tr(A^-1 dA) / 2; beta(m, r^2) with d beta / dm = -(h + x^2 k) / m^2 and
// d beta / d(r^2) = k / (2 m^3).
Mat2 log_spd_derivative(const Mat2& A, const Mat2& dA) {
  const Spectrum s(A);
  const double x = s.r / s.m;
  double h, k;
  atanh_ratios(x, h, k);
  const double dm = 0.5 * dA.trace();
  const double ds = 0.5 * (A(0, 0) - A(1, 1)) * (dA(0, 0) - dA(1, 1)) + 2 * A(0, 1) * dA(0, 1);
  const double d_alpha = 0.5 * (A.inverse() * dA).trace();
  const double d_beta = -(h + x * x * k) / (s.m * s.m) * dm + k / (2 * s.m * s.m * s.m) * ds;
  const Mat2 I = Mat2::Identity();
  return d_alpha * I + d_beta * (A - s.m * I) + h / s.m * (dA - dm * I);
}

// The derivative of log_spd_derivative: with s = r^2 (quadratic in A), d^2 alpha =
// -tr(A^-1 dB A^-1 dA) / 2 and beta's second derivatives in (m, s):
//   beta_mm = (2 h + 5 x^2 k + x^4 l) / m^3, beta_ms = -(3 k + x^2 l) / (2 m^4),
//   beta_ss = l / (4 m^5), with l = k'(x) / x.
Mat2 log_spd_second_derivative(const Mat2& A, const Mat2& dA, const Mat2& dB) {
  const Spectrum sp(A);
  const double m = sp.m, x = sp.r / m;
  double h, k;
  atanh_ratios(x, h, k);
  const double l = atanh_ratio_slope(x, k);
  const auto ds = [&](const Mat2& X) {
    return 0.5 * (A(0, 0) - A(1, 1)) * (X(0, 0) - X(1, 1)) + 2 * A(0, 1) * X(0, 1);
  };
  const double dmA = 0.5 * dA.trace(), dmB = 0.5 * dB.trace(), dsA = ds(dA), dsB = ds(dB);
  const double d2s = 0.5 * (dA(0, 0) - dA(1, 1)) * (dB(0, 0) - dB(1, 1)) + 2 * dA(0, 1) * dB(0, 1);
  const double bm = -(h + x * x * k) / (m * m), bs = k / (2 * m * m * m);
  const double bmm = (2 * h + 5 * x * x * k + x * x * x * x * l) / (m * m * m);
  const double bms = -(3 * k + x * x * l) / (2 * m * m * m * m), bss = l / (4 * m * m * m * m * m);
  const Mat2 Ai = A.inverse(), I = Mat2::Identity();
  const double d2_alpha = -0.5 * (Ai * dB * Ai * dA).trace();
  const double d2_beta = bmm * dmA * dmB + bms * (dmA * dsB + dsA * dmB) + bss * dsA * dsB + bs * d2s;
  const double dbA = bm * dmA + bs * dsA, dbB = bm * dmB + bs * dsB;
  return d2_alpha * I + d2_beta * (A - m * I) + dbA * (dB - dmB * I) + dbB * (dA - dmA * I);
}

// exp M = e^m (cosh r I + sinh(r) / r (M - m I)).
Mat2 exp_symmetric(const Mat2& M) {
  const Spectrum s(M);
  const double sinhc = s.r > 1e-8 ? std::sinh(s.r) / s.r : 1 + s.r * s.r / 6;
  return std::exp(s.m) * (std::cosh(s.r) * Mat2::Identity() + sinhc * (M - s.m * Mat2::Identity()));
}

// sqrt A = (A + sqrt(det A) I) / sqrt(tr A + 2 sqrt(det A)) (Cayley-Hamilton).
Mat2 sqrt_spd(const Mat2& A) {
  const double d = std::sqrt(A.determinant());
  return (A + d * Mat2::Identity()) / std::sqrt(A.trace() + 2 * d);
}

}  // namespace grip
