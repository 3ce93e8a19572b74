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
