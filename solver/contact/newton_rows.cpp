#include "solver/contact/newton_rows.hpp"

#include "solver/contact/saddle_rows.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/QR>
#include <optional>

namespace grip {

// A Cholesky factorization of C_BB on a base set B of rows, and the capacitance of the last
// Newton system solved with it. The system's matrix on U = B + N (N: active rows not in B) is
//     M_U = Q + A_E B_E^T,   Q = diag(C_BB, diag(C_NN)),
// with one rank-one term per row of B that left the active set (its row becomes y_k = 0), two
// per row that joined (its row and its column) and one per slip row (c C_{A,xi} added to the
// column of its normal); then M_U^-1 b = z - Z (I + B_E^T Z)^-1 B_E^T z with z = Q^-1 b and
// Z = Q^-1 A_E (Woodbury).
struct ComplianceFactor {
  std::vector<int> base;
  Matrix l;  // C_BB, then its factor in place
  std::optional<Eigen::LLT<Eigen::Ref<Matrix>>> llt;
  bool ok = false;
  // The last system's capacitance.
  std::vector<int> active;
  std::vector<SlipRow> slip;
  std::vector<int> u_of;   // block row -> index in U, -1 outside
  std::vector<int> added;  // N, block rows
  Vector added_diagonal;
  Matrix Z, Bt;
  Eigen::PartialPivLU<Matrix> capacitance;
};

namespace {

// Beyond this many active rows the reduced system is not factorized afresh per Newton iteration.
constexpr int kDenseRows = 256;

Matrix gather(const Matrix& C, const std::vector<int>& rows, const std::vector<int>& cols) {
  Matrix B(rows.size(), cols.size());
  for (size_t j = 0; j < cols.size(); ++j)
    for (size_t i = 0; i < rows.size(); ++i) B(i, j) = C(rows[i], cols[j]);
  return B;
}

// Q^-1 V for V with |U| rows.
Matrix apply_q_inverse(const ComplianceFactor& f, const Matrix& V) {
  const int nb = static_cast<int>(f.base.size());
  Matrix out(V.rows(), V.cols());
  out.topRows(nb) = f.llt->solve(V.topRows(nb));
  out.bottomRows(V.rows() - nb) = f.added_diagonal.cwiseInverse().asDiagonal() * V.bottomRows(V.rows() - nb);
  return out;
}

// The rank of the correction that the active rows and slip rows need against f's base.
int correction_rank(const ComplianceFactor& f, const std::vector<char>& in_active, const NewtonRows& rows,
                    const std::vector<char>& in_base) {
  int rank = static_cast<int>(rows.slip.size());
  for (int k : f.base) rank += in_active[k] ? 0 : 1;
  for (int k : rows.active) rank += in_base[k] ? 0 : 2;
  return rank;
}

void build_capacitance(const Matrix& C, ComplianceFactor& f, const NewtonRows& rows,
                       const std::vector<char>& in_active) {
  const int m = static_cast<int>(C.rows()), nb = static_cast<int>(f.base.size());
  f.active = rows.active;
  f.slip = rows.slip;
  f.u_of.assign(m, -1);
  f.added.clear();
  for (int i = 0; i < nb; ++i) f.u_of[f.base[i]] = i;
  for (int k : rows.active)
    if (f.u_of[k] < 0) {
      f.u_of[k] = nb + static_cast<int>(f.added.size());
      f.added.push_back(k);
    }
  const int nu = nb + static_cast<int>(f.added.size());
  auto comp = [&](int u) { return u < nb ? f.base[u] : f.added[u - nb]; };
  f.added_diagonal.resize(f.added.size());
  for (size_t t = 0; t < f.added.size(); ++t) f.added_diagonal[t] = C(f.added[t], f.added[t]);
  std::vector<int> removed;
  for (int u = 0; u < nb; ++u)
    if (!in_active[f.base[u]]) removed.push_back(u);
  const int r = static_cast<int>(removed.size() + 2 * f.added.size() + rows.slip.size());
  Matrix A = Matrix::Zero(nu, r), B = Matrix::Zero(nu, r);
  int col = 0;
  for (int u : removed) {  // row u becomes e_u
    A(u, col) = 1.0;
    for (int v = 0; v < nb; ++v) B(v, col) = -C(f.base[u], f.base[v]);
    B(u, col) += 1.0;
    ++col;
  }
  for (size_t t = 0; t < f.added.size(); ++t) {
    const int k = f.added[t], uk = nb + static_cast<int>(t);
    A(uk, col) = 1.0;  // its row over the active columns, in place of diag(C_NN)
    for (int v = 0; v < nu; ++v)
      if (in_active[comp(v)]) B(v, col) = C(k, comp(v));
    B(uk, col) -= f.added_diagonal[t];
    ++col;
    for (int v = 0; v < nb; ++v)  // its column over the base's active rows
      if (in_active[f.base[v]]) A(v, col) = C(f.base[v], k);
    B(uk, col) = 1.0;
    ++col;
  }
  for (const SlipRow& sr : rows.slip) {
    for (int v = 0; v < nu; ++v)
      if (in_active[comp(v)]) A(v, col) = sr.c * C(comp(v), sr.xi);
    B(f.u_of[sr.eta], col) = 1.0;
    ++col;
  }
  f.Z = apply_q_inverse(f, A);
  f.Bt = B.transpose();
  if (r > 0) f.capacitance.compute(Matrix::Identity(r, r) + f.Bt * f.Z);
}

}  // namespace

Vector solve_newton_rows(const Compliance& C, const Vector& F, const Vector& s, const NewtonRows& rows,
                         NewtonRowStats& stats) {
  if (C.sparse()) return solve_saddle_rows(C, F, s, rows, stats);
  const Matrix& Cb = C.block;
  const int m = static_cast<int>(F.size()), n = static_cast<int>(rows.active.size());
  Vector d = -F;
  for (int k : rows.active) d[k] = 0.0;
  for (const SlipRow& r : rows.slip) d[r.xi] += r.c * F[r.eta];
  if (n == 0) return d;
  std::vector<int> pos(m, -1);
  for (int i = 0; i < n; ++i) pos[rows.active[i]] = i;
  // b = -s_A - (C d)_A, over d's non-zeros by whole columns.
  Vector cd = Vector::Zero(m);
  for (int j = 0; j < m; ++j)
    if (d[j] != 0.0) cd.noalias() += d[j] * Cb.col(j);
  Vector b(n);
  for (int i = 0; i < n; ++i) b[i] = -s[rows.active[i]] - cd[rows.active[i]];
  auto spread = [&](const Vector& y) {  // d + P y
    Vector dx = d;
    for (int i = 0; i < n; ++i) dx[rows.active[i]] = y[i];
    for (const SlipRow& r : rows.slip) dx[r.xi] += r.c * y[pos[r.eta]];
    return dx;
  };
  auto dense = [&] {
    ++stats.dense;
    Matrix M = gather(Cb, rows.active, rows.active);
    for (const SlipRow& r : rows.slip)
      for (int a = 0; a < n; ++a) M(a, pos[r.eta]) += r.c * Cb(rows.active[a], r.xi);
    Vector y = Eigen::PartialPivLU<Matrix>(M).solve(b);
    // Singular where every point slips along a free rigid motion held by contact
    // (docs/algorithm.md#bodies-held-only-by-contact: its amplitude's column vanishes): the
    // least-squares step, still a descent direction.
    if (!y.allFinite()) y = M.completeOrthogonalDecomposition().solve(b);
    return spread(y);
  };
  if (n <= kDenseRows || C.bordered) return dense();

  std::vector<char> in_active(m, 0), in_base(m, 0);
  for (int k : rows.active) in_active[k] = 1;
  if (C.factor)
    for (int k : C.factor->base) in_base[k] = 1;
  // A correction of rank r costs about 2 r n^2, a new factorization n^3 / 3.
  if (!C.factor || !C.factor->ok || correction_rank(*C.factor, in_active, rows, in_base) > n / 6) {
    ++stats.factorizations;
    C.factor = std::make_shared<ComplianceFactor>();
    C.factor->base = rows.active;
    C.factor->l = gather(Cb, rows.active, rows.active);
    C.factor->llt.emplace(C.factor->l);
    C.factor->ok = C.factor->llt->info() == Eigen::Success;
    if (!C.factor->ok || static_cast<int>(rows.slip.size()) > n / 6) return dense();
  }
  ComplianceFactor& f = *C.factor;
  if (f.active != rows.active || !(f.slip == rows.slip)) {
    ++stats.capacitances;
    build_capacitance(Cb, f, rows, in_active);
  }
  Vector bu = Vector::Zero(f.base.size() + f.added.size());
  for (int i = 0; i < n; ++i) bu[f.u_of[rows.active[i]]] = b[i];
  const Vector z = apply_q_inverse(f, bu);
  Vector yu = z;
  if (f.Z.cols() > 0) yu -= f.Z * f.capacitance.solve(f.Bt * z);
  Vector y(n);
  for (int i = 0; i < n; ++i) y[i] = yu[f.u_of[rows.active[i]]];
  return spread(y);
}

}  // namespace grip
