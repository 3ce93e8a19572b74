#pragma once
// L L^T of a symmetric positive definite block whose pattern, in reverse Cuthill-McKee order,
// keeps within a narrow band of the diagonal: a beam's or a membrane's tangent (half-bandwidth
// 5 and 3 on the paper's beam and sheet). CHOLMOD's fixed cost per call (workspaces, the
// elimination tree, the supernodal or simplicial driver) is there some 100 times the
// arithmetic: ~400k instructions per factorization of the paper's beam (240 rows). On the band
// a factorization costs n b^2 and a solve 4 n b flops.
#include <Eigen/SparseCore>
#include <vector>

#include "solver/core/types.hpp"

namespace grip {

class BandCholesky {
 public:
  // Orders the rows of A's pattern (symmetric) by reverse Cuthill-McKee; returns the
  // half-bandwidth in that order.
  int analyse(const Eigen::SparseMatrix<double>& A);
  // False where A is not positive definite, or a pivot is at round-off (then rcond() is 0).
  // A has the pattern analyse() saw.
  bool factorize(const Eigen::SparseMatrix<double>& A);
  Vector solve(const Vector& b) const;
  Matrix solve(const Matrix& b) const;
  // |L^-1 P t_j|^2 = t_j^T A^-1 t_j for every column of t.
  Vector quadratic_forms(const Eigen::SparseMatrix<double>& t) const;
  // (min / max of diag L)^2: the min / max of the pivots of L D L^T.
  double rcond() const { return rcond_; }

 private:
  void forward(double* x, int first) const;  // x <- L^-1 x (banded order), zero above `first`
  void backward(double* x) const;            // x <- L^-T x
  int n_ = 0, b_ = 0;
  std::vector<int> order_;     // banded row k is A's row order_[k]
  std::vector<int> position_;  // A's row i is banded row position_[i]
  std::vector<double> l_;      // column j holds L(j .. j + b, j), zero-padded past the last row
  double rcond_ = 0.0;
};

}  // namespace grip
