#pragma once
// The contact compliance C = T^T K^-1 T (Equilibrium::compliance, compliance.cpp).
#include <Eigen/SparseCore>
#include <limits>
#include <memory>
#include <vector>

#include "solver/equilibrium/free_block_solver.hpp"
#include "solver/model/types.hpp"

namespace grip {

// Factorizations of blocks of a compliance, kept by the inner contact solver (coulomb_model.cpp)
// for as long as the compliance stays the same: dense (C's active block) or sparse (the
// saddle-point systems of the sparse form).
struct ComplianceFactor;
struct SaddleFactor;

// The contact compliance C = T^T K^-1 T on a subset of the components (the ones that can
// take part in this iteration); zero elsewhere. Dense (`block`) or, for large contact zones,
// sparse: T on the free dofs and the body's factorization, C z = T^T K^-1 T z by one sparse
// solve, nothing of size components^2 (Equilibrium::compliance).
struct Compliance {
  std::vector<int> position;  // component -> row of `block` (or column of `t`), -1 where not computed
  Matrix block;               // the dense form; empty in the sparse form
  mutable std::shared_ptr<ComplianceFactor> factor;  // reset whenever `block` changes
  // With the rigid amplitudes' border [C G; G^T 0] (docs/algorithm.md#bodies-held-only-by-contact): indefinite, no Cholesky.
  // Dense form only.
  bool bordered = false;
  // The sparse form: `body` is the body's factorization of K (free dofs), `t` is T on the free
  // dofs (free dofs x rows), `diagonal` is C's diagonal.
  const FreeBlockSolver* body = nullptr;
  Eigen::SparseMatrix<double> t;
  Vector diagonal_entries;
  std::vector<int> normal_of;                    // row -> the row of its candidate's normal (tangent rows), else -1
  mutable std::shared_ptr<SaddleFactor> saddle;  // reset whenever `t` or `body` changes

  bool sparse() const { return body != nullptr; }
  int size() const { return sparse() ? static_cast<int>(t.cols()) : static_cast<int>(block.rows()); }
  double diagonal(int i) const { return sparse() ? diagonal_entries[i] : block(i, i); }
  // C z over the rows (one sparse solve in the sparse form).
  Vector apply(const Vector& z) const;
  // The same, for a finite `block` (the caller knows it is): the columns where z is zero are
  // skipped (the Coulomb model's changes x - x0 are zero on its open rows).
  Vector apply_finite(const Vector& z) const;
  // Dense form only:
  double operator()(int a, int b) const {
    const int i = position[a], j = position[b];
    return i < 0 || j < 0 ? 0.0 : block(i, j);
  }
  // C restricted to the given components, in their order.
  Matrix sub(const std::vector<int>& components) const;
};

// Never the sparse form (Equilibrium::compliance's `sparse_from`).
inline constexpr int kDenseCompliance = std::numeric_limits<int>::max();

}  // namespace grip
