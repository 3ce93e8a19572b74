#pragma once
// The Newton systems of the inner contact problem (coulomb_model.cpp) reduced to their
// unknown rows and solved without dense cubic work per system where they are large.
//
// The rows of the semismooth Newton system J dx = -F by kind: an explicit row (no force, or no
// bound) gives dx_k = -F_k; an active row (pressing, stick) asks (C dx)_k = -s_k; a slip row is
// explicit once its normal's dx is known (that normal presses, so (C dx)_eta = -s_eta):
//     dx_xi = -F_xi + c (dx_eta + F_eta),   c = -sign(g) mu.
// Only the active rows are unknown: with dx = d + P y (P puts y on the active rows and c y_eta
// on the slip rows), (C P y)_A = -s_A - (C d)_A, a system of the active rows only.
#include <vector>

#include "solver/equilibrium/equilibrium.hpp"

namespace grip {

struct SlipRow {
  int xi, eta;  // rows of the compliance block
  double c;     // -sign(g) mu
  bool operator==(const SlipRow& o) const { return xi == o.xi && eta == o.eta && c == o.c; }
};

struct NewtonRows {
  std::vector<int> active;  // rows of the compliance block, in any order
  std::vector<SlipRow> slip;
};

struct NewtonRowStats {
  int factorizations = 0;  // Cholesky factorizations of C on a set of active rows (sparse: LUs)
  int capacitances = 0;    // low-rank corrections to one (rows joined, left, slipping)
  int dense = 0;           // LU factorizations of a whole reduced system
};

// dx solving J dx = -F at the kinds `rows`, with s = s(x) of the model. A compliance in sparse
// form: solve_saddle_rows (saddle_rows.hpp). Large systems reuse a
// Cholesky factorization of C's block on an earlier active set, kept in C.factor while C stays
// the same, and correct it by a capacitance matrix for the rows that joined or left and for the
// slip coupling (Woodbury): O(rows^2 x changes) instead of O(rows^3).
Vector solve_newton_rows(const Compliance& C, const Vector& F, const Vector& s, const NewtonRows& rows,
                         NewtonRowStats& stats);

}  // namespace grip
