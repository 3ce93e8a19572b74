#include "solver/solve/band_cholesky.hpp"

#include <algorithm>
#include <cmath>

namespace grip {

int BandCholesky::analyse(const Eigen::SparseMatrix<double>& A) {
  n_ = static_cast<int>(A.rows());
  std::vector<std::vector<int>> adjacent(n_);
  for (int j = 0; j < A.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it)
      if (it.row() != j) adjacent[j].push_back(static_cast<int>(it.row()));
  auto degree = [&](int i) { return adjacent[i].size(); };
  // Cuthill-McKee: breadth-first from a row of least degree, neighbours by increasing degree;
  // each unconnected part in turn.
  order_.clear();
  std::vector<char> seen(n_, 0);
  std::vector<int> by_degree(n_);
  for (int i = 0; i < n_; ++i) by_degree[i] = i;
  std::stable_sort(by_degree.begin(), by_degree.end(), [&](int a, int b) { return degree(a) < degree(b); });
  for (int root : by_degree) {
    if (seen[root]) continue;
    seen[root] = 1;
    for (size_t head = order_.size(), tail = (order_.push_back(root), order_.size()); head < tail;
         ++head, tail = order_.size()) {
      std::vector<int> next;
      for (int k : adjacent[order_[head]])
        if (!seen[k]) {
          seen[k] = 1;
          next.push_back(k);
        }
      std::stable_sort(next.begin(), next.end(), [&](int a, int b) { return degree(a) < degree(b); });
      order_.insert(order_.end(), next.begin(), next.end());
    }
  }
  std::reverse(order_.begin(), order_.end());
  position_.assign(n_, 0);
  for (int k = 0; k < n_; ++k) position_[order_[k]] = k;
  b_ = 0;
  for (int i = 0; i < n_; ++i)
    for (int k : adjacent[i]) b_ = std::max(b_, std::abs(position_[i] - position_[k]));
  return b_;
}

bool BandCholesky::factorize(const Eigen::SparseMatrix<double>& A) {
  const int w = b_ + 1;
  l_.assign(static_cast<size_t>(n_) * w, 0.0);
  rcond_ = 0.0;
  for (int j = 0; j < A.outerSize(); ++j)  // the lower band of P A P^T
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it) {
      const int r = position_[it.row()], c = position_[j];
      if (r >= c) l_[static_cast<size_t>(c) * w + (r - c)] = it.value();
    }
  double lo = 0.0, hi = 0.0;
  for (int j = 0; j < n_; ++j) {
    double* col = &l_[static_cast<size_t>(j) * w];
    // Left-looking: subtract the columns k < j whose band reaches row j.
    for (int k = std::max(0, j - b_); k < j; ++k) {
      const double* ck = &l_[static_cast<size_t>(k) * w];
      const double ljk = ck[j - k];
      if (ljk == 0.0) continue;
      const int last = std::min(k + b_, n_ - 1);
      for (int i = j; i <= last; ++i) col[i - j] -= ck[i - k] * ljk;
    }
    if (!(col[0] > 0.0)) return false;
    // The diagonal is kept as 1 / L(j, j): a division costs some 15 multiplications.
    const double d = std::sqrt(col[0]), inverse = 1.0 / d;
    col[0] = inverse;
    for (int i = 1; i < w; ++i) col[i] *= inverse;
    lo = j ? std::min(lo, d) : d;
    hi = std::max(hi, d);
  }
  rcond_ = n_ ? (lo / hi) * (lo / hi) : 1.0;
  return true;
}

void BandCholesky::forward(double* x, int first) const {
  const int w = b_ + 1;
  for (int j = first; j < n_; ++j) {
    const double* col = &l_[static_cast<size_t>(j) * w];
    const double y = x[j] *= col[0];
    if (y == 0.0) continue;
    const int last = std::min(j + b_, n_ - 1);
    for (int i = j + 1; i <= last; ++i) x[i] -= col[i - j] * y;
  }
}

void BandCholesky::backward(double* x) const {
  const int w = b_ + 1;
  for (int j = n_ - 1; j >= 0; --j) {
    const double* col = &l_[static_cast<size_t>(j) * w];
    const int last = std::min(j + b_, n_ - 1);
    double s = x[j];
    for (int i = j + 1; i <= last; ++i) s -= col[i - j] * x[i];
    x[j] = s * col[0];
  }
}

Vector BandCholesky::solve(const Vector& b) const {
  Vector y(n_);
  for (int k = 0; k < n_; ++k) y[k] = b[order_[k]];
  forward(y.data(), 0);
  backward(y.data());
  Vector x(n_);
  for (int k = 0; k < n_; ++k) x[order_[k]] = y[k];
  return x;
}

Matrix BandCholesky::solve(const Matrix& b) const {
  // All columns at once, row by row (G's unit columns come 64 at a time): each row operation
  // runs over contiguous memory, where one column at a time is a chain of dependent scalars.
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  RowMajor y(n_, b.cols());
  for (int k = 0; k < n_; ++k) y.row(k) = b.row(order_[k]);
  const int w = b_ + 1;
  for (int j = 0; j < n_; ++j) {
    const double* col = &l_[static_cast<size_t>(j) * w];
    y.row(j) *= col[0];
    const int last = std::min(j + b_, n_ - 1);
    for (int i = j + 1; i <= last; ++i)
      if (col[i - j] != 0.0) y.row(i) -= col[i - j] * y.row(j);
  }
  for (int j = n_ - 1; j >= 0; --j) {
    const double* col = &l_[static_cast<size_t>(j) * w];
    const int last = std::min(j + b_, n_ - 1);
    for (int i = j + 1; i <= last; ++i)
      if (col[i - j] != 0.0) y.row(j) -= col[i - j] * y.row(i);
    y.row(j) *= col[0];
  }
  Matrix x(n_, b.cols());
  for (int k = 0; k < n_; ++k) x.row(order_[k]) = y.row(k);
  return x;
}

Vector BandCholesky::quadratic_forms(const Eigen::SparseMatrix<double>& t) const {
  Vector out = Vector::Zero(t.cols());
  Vector y(n_);
  for (int c = 0; c < t.outerSize(); ++c) {
    y.setZero();
    int first = n_;
    for (Eigen::SparseMatrix<double>::InnerIterator it(t, c); it; ++it) {
      y[position_[it.row()]] = it.value();
      first = std::min(first, position_[it.row()]);
    }
    forward(y.data(), first);
    out[c] = y.squaredNorm();
  }
  return out;
}

}  // namespace grip
