#pragma once
// Functions of symmetric 2 x 2 tensors in closed form, without eigenvectors (so that equal
// eigenvalues need no special case): with m = tr A / 2 and r = |A - m I| / sqrt(2) the
// eigenvalues are m +- r, and every isotropic function is a I + b (A - m I).
// The finite-strain J2 law (j2_finite.cpp) uses them for the logarithmic (Hencky) strain.
#include "solver/model/types.hpp"

namespace grip {

// log A of a symmetric positive definite A.
Mat2 log_spd(const Mat2& A);
// The derivative of log A in the direction dA (symmetric): d/dt log(A + t dA) at t = 0.
Mat2 log_spd_derivative(const Mat2& A, const Mat2& dA);
// The second derivative of log A in the directions dA and dB (symmetric):
// d^2/(ds dt) log(A + s dA + t dB) at 0, symmetric in dA and dB.
Mat2 log_spd_second_derivative(const Mat2& A, const Mat2& dA, const Mat2& dB);
// exp M of a symmetric M.
Mat2 exp_symmetric(const Mat2& M);
// The symmetric positive definite square root of a symmetric positive definite A.
Mat2 sqrt_spd(const Mat2& A);

}  // namespace grip
