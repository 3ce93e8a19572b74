#include "solver/solve/free_block_solver.hpp"

#include <algorithm>
#include <cmath>

namespace grip {

bool FreeBlockSolver::factorize(const Triplets& triplets, const std::vector<int>& free_index,
                                int free_count, double near_symmetric_tolerance) {
  bool same = triplets.size() == rows_.size();
  for (size_t k = 0; same && k < triplets.size(); ++k)
    same = triplets[k].row() == rows_[k] && triplets[k].col() == cols_[k];
  if (!same) {
    // New pattern: build it, remember where every triplet lands, analyse it once.
    rows_.resize(triplets.size());
    cols_.resize(triplets.size());
    Triplets pattern;
    for (size_t k = 0; k < triplets.size(); ++k) {
      rows_[k] = triplets[k].row();
      cols_[k] = triplets[k].col();
      const int i = free_index[rows_[k]], j = free_index[cols_[k]];
      if (i >= 0 && j >= 0) pattern.emplace_back(i, j, 1.0);
    }
    matrix_.resize(free_count, free_count);
    matrix_.setFromTriplets(pattern.begin(), pattern.end());
    matrix_.makeCompressed();
    slot_.assign(triplets.size(), -1);
    for (size_t k = 0; k < triplets.size(); ++k) {
      const int i = free_index[rows_[k]], j = free_index[cols_[k]];
      if (i >= 0 && j >= 0) slot_[k] = static_cast<int>(&matrix_.coeffRef(i, j) - matrix_.valuePtr());
    }
    // Where each entry's transpose lives (the pattern of a tangent is symmetric).
    mirror_.assign(matrix_.nonZeros(), -1);
    for (int col = 0; col < matrix_.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(matrix_, col); it; ++it) {
        const double* t = &matrix_.coeffRef(it.col(), it.row());
        mirror_[&it.valueRef() - matrix_.valuePtr()] = static_cast<int>(t - matrix_.valuePtr());
      }
    lu_analysed_ = llt_analysed_ = false;
  }
  std::fill(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros(), 0.0);
  for (size_t k = 0; k < triplets.size(); ++k)
    if (slot_[k] >= 0) matrix_.valuePtr()[slot_[k]] += triplets[k].value();
  const double* v = matrix_.valuePtr();
  double scale = 0.0, skew = 0.0;
  for (int k = 0; k < matrix_.nonZeros(); ++k) {
    scale = std::max(scale, std::abs(v[k]));
    skew = std::max(skew, std::abs(v[k] - v[mirror_[k]]));
  }
  symmetric_ = skew <= std::max(1e-13, near_symmetric_tolerance) * scale;
  if (symmetric_ && skew > 0) {
    double* w = matrix_.valuePtr();
    for (int k = 0; k < matrix_.nonZeros(); ++k)
      if (mirror_[k] > k) w[k] = w[mirror_[k]] = 0.5 * (w[k] + w[mirror_[k]]);
  }
  if (symmetric_) {
    if (!llt_analysed_) llt_.analyzePattern(matrix_);  // the ordering: once per pattern
    llt_analysed_ = true;
    llt_.factorize(matrix_);
    // Not positive definite, or a pivot at round-off (the supports do not hold the body):
    // (min/max diag L)^2 is the min/max of LDL^T's D.
    ok_ = llt_.info() == Eigen::Success && llt_.rcond() > 1e-14;
    if (ok_) return true;
    symmetric_ = false;  // fall back to LU
  }
  if (!lu_analysed_) lu_.analyzePattern(matrix_);
  lu_analysed_ = true;
  lu_.factorize(matrix_);
  ok_ = lu_.info() == Eigen::Success;
  return ok_;
}

}  // namespace grip
