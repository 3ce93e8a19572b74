#pragma once
// Where a tangent's entries go as the assembly loops produce them: straight into the values of
// a sparse matrix whose pattern was computed once (FreeBlockSolver), or recorded as triplets
// (tests, terms solved by other means). The loops emit the same entries in the same order at
// every call, which is what lets a pattern computed once take them without rows and columns.
#include <Eigen/SparseCore>
#include <vector>

#include "solver/model/types.hpp"

namespace grip {

using Triplets = std::vector<Eigen::Triplet<double>>;

class TangentSink {
 public:
  virtual ~TangentSink() = default;
  // Adds `value` at (row, col).
  virtual void add(int row, int col, double value) = 0;
  // An element's dense block: block(i, j) at (dofs[i], dofs[j]), row by row.
  virtual void add_block(const int* dofs, const Matrix& block) = 0;
  // Where set, a body whose traits say linearized_stress forms its geometric stiffness from the
  // stress of the strain linearized about this state (its own dofs), not from the stress at q
  // (MIP Newton, docs/algorithm.md#newtons-tangent-the-linearized-stress); the force is at q.
  const Vector* stress_base = nullptr;
};

// Records the entries as triplets, appended to `out`.
class TripletSink final : public TangentSink {
 public:
  explicit TripletSink(Triplets& out) : out_(out) {}
  void add(int row, int col, double value) override { out_.emplace_back(row, col, value); }
  void add_block(const int* dofs, const Matrix& block) override {
    const int m = static_cast<int>(block.rows());
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) out_.emplace_back(dofs[i], dofs[j], block(i, j));
  }

 private:
  Triplets& out_;
};

}  // namespace grip
