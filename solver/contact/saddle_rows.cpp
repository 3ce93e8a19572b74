#include "solver/contact/saddle_rows.hpp"

#include <Eigen/LU>
#include <Eigen/UmfPackSupport>
#include <limits>

namespace grip {
namespace {

enum class Kind : char { explicit_row, active, slip };

struct RowKind {
  Kind kind = Kind::explicit_row;
  double c = 0.0;  // slip: -sign(g) mu
  bool operator==(const RowKind& o) const { return kind == o.kind && c == o.c; }
  bool operator!=(const RowKind& o) const { return !(*this == o); }
};

}  // namespace

// The saddle-point matrix S (free dofs, then the m rows of C, each unknown scaled by sigma, K's
// mean diagonal, so that both blocks weigh alike in the pivoting: dx = sigma w) at the kinds
// `base`, its LU, and the correction S_now = S + E D for the rows `changed` whose kind differs
// now (E their unit columns, D their rows' change): S_now^-1 b = z - Z (I + D Z)^-1 D z,
// z = S^-1 b, Z = S^-1 E, whose columns are kept for the next correction on the same LU.
struct SaddleFactor {
  int nf = 0, m = 0;
  double sigma = 1.0;
  Eigen::SparseMatrix<double> matrix;  // S: UMFPACK's solves read it
  Eigen::UmfPackLU<Eigen::SparseMatrix<double>> lu;
  bool ok = false;
  std::vector<RowKind> base, current;
  std::vector<int> changed;
  Eigen::SparseMatrix<double> D;
  Matrix Z;
  Eigen::PartialPivLU<Matrix> capacitance;
  // S^-1 e_(nf + k) for the rows k solved for so far (they depend on S only, not on the kinds).
  std::vector<int> unit_column;  // row k -> column of `units`, -1 if not yet solved
  Matrix units;
};

namespace {

// Row nf + k of S at a kind, over its fixed pattern: T's column k, the diagonal, the normal.
void row_entries(const Compliance& C, const SaddleFactor& f, int k, const RowKind& kind,
                 std::vector<std::pair<int, double>>& out) {
  out.clear();
  const bool active = kind.kind == Kind::active;
  for (Eigen::SparseMatrix<double>::InnerIterator it(C.t, k); it; ++it)
    out.emplace_back(static_cast<int>(it.row()), active ? f.sigma * it.value() : 0.0);
  out.emplace_back(f.nf + k, active ? 0.0 : f.sigma);
  if (C.normal_of[k] >= 0) out.emplace_back(f.nf + C.normal_of[k], kind.kind == Kind::slip ? -f.sigma * kind.c : 0.0);
}

void assemble(const Compliance& C, SaddleFactor& f, const std::vector<RowKind>& kinds) {
  const Eigen::SparseMatrix<double>& K = C.body->matrix();
  Triplets triplets;
  triplets.reserve(K.nonZeros() + 2 * C.t.nonZeros() + 2 * f.m);
  for (int col = 0; col < K.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it)
      triplets.emplace_back(it.row(), it.col(), it.value());
  std::vector<std::pair<int, double>> entries;
  for (int k = 0; k < f.m; ++k) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(C.t, k); it; ++it)
      triplets.emplace_back(it.row(), f.nf + k, -f.sigma * it.value());
    row_entries(C, f, k, kinds[k], entries);
    for (const auto& [col, value] : entries) triplets.emplace_back(f.nf + k, col, value);
  }
  f.matrix.resize(f.nf + f.m, f.nf + f.m);
  f.matrix.setFromTriplets(triplets.begin(), triplets.end());  // explicit zeros stay
  f.matrix.makeCompressed();
}

void factorize(const Compliance& C, SaddleFactor& f, const std::vector<RowKind>& kinds, NewtonRowStats& stats) {
  ++stats.factorizations;
  const bool first = f.matrix.rows() == 0;
  assemble(C, f, kinds);
  if (first) {
    // The pattern is symmetric but for the slip entries: AMD on it, diagonal pivots preferred.
    f.lu.umfpackControl()(UMFPACK_STRATEGY) = UMFPACK_STRATEGY_SYMMETRIC;
    f.lu.analyzePattern(f.matrix);
  }
  f.lu.factorize(f.matrix);
  f.ok = f.lu.info() == Eigen::Success;
  f.base = f.current = kinds;
  f.changed.clear();
  f.unit_column.assign(f.m, -1);
  f.units.resize(f.nf + f.m, 0);
}

void correct(const Compliance& C, SaddleFactor& f, const std::vector<RowKind>& kinds, NewtonRowStats& stats) {
  ++stats.capacitances;
  const int n = f.nf + f.m, r = static_cast<int>(f.changed.size());
  Triplets d;
  std::vector<std::pair<int, double>> now, then;
  std::vector<int> unsolved;
  for (int k : f.changed)
    if (f.unit_column[k] < 0) unsolved.push_back(k);
  if (!unsolved.empty()) {
    const int old_columns = static_cast<int>(f.units.cols()), u = static_cast<int>(unsolved.size());
    Matrix rhs = Matrix::Zero(n, u);
    for (int i = 0; i < u; ++i) {
      rhs(f.nf + unsolved[i], i) = 1.0;
      f.unit_column[unsolved[i]] = old_columns + i;
    }
    f.units.conservativeResize(n, old_columns + u);
    f.units.rightCols(u) = f.lu.solve(rhs);
  }
  f.Z.resize(n, r);
  for (int i = 0; i < r; ++i) f.Z.col(i) = f.units.col(f.unit_column[f.changed[i]]);
  for (int i = 0; i < r; ++i) {
    const int k = f.changed[i];
    row_entries(C, f, k, kinds[k], now);
    row_entries(C, f, k, f.base[k], then);
    for (size_t t = 0; t < now.size(); ++t)
      if (now[t].second != then[t].second) d.emplace_back(i, now[t].first, now[t].second - then[t].second);
  }
  f.D.resize(r, n);
  f.D.setFromTriplets(d.begin(), d.end());
  f.capacitance.compute(Matrix::Identity(r, r) + f.D * f.Z);
  f.current = kinds;
}

}  // namespace

Vector solve_saddle_rows(const Compliance& C, const Vector& F, const Vector& s, const NewtonRows& rows,
                         NewtonRowStats& stats) {
  const int m = C.size();
  std::vector<RowKind> kinds(m);
  for (int k : rows.active) kinds[k].kind = Kind::active;
  for (const SlipRow& r : rows.slip) kinds[r.xi] = {Kind::slip, r.c};
  if (!C.saddle) {
    C.saddle = std::make_shared<SaddleFactor>();
    C.saddle->nf = static_cast<int>(C.t.rows());
    C.saddle->m = m;
    const Eigen::SparseMatrix<double>& K = C.body->matrix();
    C.saddle->sigma = K.rows() ? K.diagonal().cwiseAbs().sum() / static_cast<double>(K.rows()) : 1.0;
    factorize(C, *C.saddle, kinds, stats);
  }
  SaddleFactor& f = *C.saddle;
  if (kinds != f.current) {
    std::vector<int> changed;
    for (int k = 0; k < m; ++k)
      if (kinds[k] != f.base[k]) changed.push_back(k);
    f.changed = std::move(changed);
    if (f.changed.empty())  // back at the factorized kinds
      f.current = kinds;
    else if (f.units.cols() + static_cast<Eigen::Index>(f.changed.size()) > kSaddleCorrectionRows || !f.ok)
      factorize(C, f, kinds, stats);
    else correct(C, f, kinds, stats);
  }
  if (!f.ok) return Vector::Constant(m, std::numeric_limits<double>::quiet_NaN());
  Vector rhs = Vector::Zero(f.nf + m);
  for (int k = 0; k < m; ++k) rhs[f.nf + k] = -F[k];
  for (int k : rows.active) rhs[f.nf + k] = -f.sigma * s[k];
  for (const SlipRow& r : rows.slip) rhs[f.nf + r.xi] = -F[r.xi] + r.c * F[r.eta];
  Vector z = f.lu.solve(rhs);
  if (!f.changed.empty()) z -= f.Z * f.capacitance.solve(f.D * z);
  return f.sigma * z.tail(m);
}

}  // namespace grip
