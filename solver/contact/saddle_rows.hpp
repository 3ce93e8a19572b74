#pragma once
// The Newton systems of the inner contact problem (newton_rows.hpp) for a compliance in sparse
// form (large contact zones): nothing of size components^2, one sparse LU of a saddle-point
// system with the body's stiffness K, corrected by a low-rank term while few rows change kind.
#include "solver/contact/newton_rows.hpp"

namespace grip {

// dx solving J dx = -F at the kinds `rows`, as solve_newton_rows. With the rows' kinds as
// unknowns' equations, over all m rows of C and u = K^-1 T dx on the free dofs:
//     K u - T dx = 0
//     t_k^T u = -s_k                       active row k (pressing, stick): (C dx)_k = -s_k
//     dx_k = -F_k                          explicit row k (open, no bound)
//     dx_xi - c dx_eta = -F_xi + c F_eta   slip row xi of normal eta
// Its pattern is the same for every kind (explicit zeros keep it), so UMFPACK analyses it once
// per compliance; its LU is kept in C.saddle, and a change of kind of a few rows is a Woodbury
// correction of the kept LU (one extra solve per row, kept for later corrections) instead of a
// new LU, while the rows solved for since the LU stay at most kSaddleCorrectionRows (their
// solves are (free dofs + m) x rows doubles).
Vector solve_saddle_rows(const Compliance& C, const Vector& F, const Vector& s, const NewtonRows& rows,
                         NewtonRowStats& stats);

inline constexpr int kSaddleCorrectionRows = 32;

}  // namespace grip
