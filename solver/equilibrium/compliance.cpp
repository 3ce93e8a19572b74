// The contact compliance C = T^T K^-1 T, dense (from G = K^-1 on the surface dofs) or sparse,
// with the rigid amplitudes' border, and the displacement change it predicts.
#include "solver/equilibrium/equilibrium.hpp"

#include <algorithm>

#include "solver/problem/rigid_modes.hpp"

namespace grip {

namespace {

// The most surface dofs whose G comes from Newton's factorization (newton_factor_serves): G costs
// one solve per surface dof, and such a G serves its state only, so every later update forms
// one again. The 150 x 4 strip's few hundred: 120 real solves instead of 108 at 3 x the CPU
// with a bound of 400 (bench/results/kernels.md).
constexpr int kNewtonFactorRows = 128;

}  // namespace

Matrix Compliance::sub(const std::vector<int>& components) const {
  Matrix B(components.size(), components.size());
  for (size_t a = 0; a < components.size(); ++a)
    for (size_t b = 0; b < components.size(); ++b) B(a, b) = (*this)(components[a], components[b]);
  return B;
}

void Equilibrium::extend_surface_compliance(const std::vector<int>& added) {
  const int m0 = static_cast<int>(surface_free_.size());
  for (int f : added) {
    surface_row_[f] = static_cast<int>(surface_free_.size());
    surface_free_.push_back(f);
  }
  const int m = static_cast<int>(surface_free_.size());
  counters_.compliance_columns += m - m0;
  const bool sparse_solves = m0 == 0 && !g_from_newton_ && body_lu_.inverse_block(surface_free_, g_, params_.parallel);
  counters_.dissected_factorizations = body_lu_.dissected_factorizations();
  counters_.body_analyses = body_lu_.analyses();
  counters_.newton_analyses = lu_.analyses();
  if (sparse_solves) return;  // a new G: sparse solves
  g_.conservativeResize(m, m);
  // Unit right-hand sides in blocks: the work storage stays (free dofs) x kBlock.
  constexpr int kBlock = 64;
  Matrix rhs;
  for (int start = m0; start < m; start += kBlock) {
    const int cols = std::min(kBlock, m - start);
    rhs.setZero(free_count_, cols);
    for (int c = 0; c < cols; ++c) rhs(surface_free_[start + c], c) = 1.0;
    const Matrix x = g_factor().solve(rhs);
    for (int c = 0; c < cols; ++c)
      for (int r = 0; r < m; ++r) {
        g_(r, start + c) = x(surface_free_[r], c);
        if (r < m0) g_(start + c, r) = g_(r, start + c);
      }
  }
  const Matrix added_block = g_.bottomRightCorner(m - m0, m - m0);
  g_.bottomRightCorner(m - m0, m - m0) = 0.5 * (added_block + added_block.transpose());
}

namespace {

bool same_sparse(const Eigen::SparseMatrix<double>& a, const Eigen::SparseMatrix<double>& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && a.nonZeros() == b.nonZeros() &&
         std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1, b.outerIndexPtr()) &&
         std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr()) &&
         std::equal(a.valuePtr(), a.valuePtr() + a.nonZeros(), b.valuePtr());
}

// T on the given components (columns at `position`), one row per free dof as `row` numbers it.
template <class Row>
Eigen::SparseMatrix<double> contact_map(const Problem& problem, const EquilibriumState& state,
                                        const std::vector<int>& position, const std::vector<int>& free_index, int rows,
                                        int cols, Row row) {
  Triplets ts;
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    const PairedPoint& pp = state.points[i];
    const int eta = position[c.eta], xi = c.xi >= 0 ? position[c.xi] : -1;
    if (eta < 0 && xi < 0) continue;
    for (const auto& j : pp.point.jacobian) {
      const int f = free_index[j.dof];
      if (f < 0) continue;
      if (eta >= 0) ts.emplace_back(row(f), eta, j.dx.dot(pp.eta));
      if (xi >= 0) ts.emplace_back(row(f), xi, j.dx.dot(pp.xi));
    }
  }
  Eigen::SparseMatrix<double> t(rows, cols);
  t.setFromTriplets(ts.begin(), ts.end());
  return t;
}

// The free surface dofs of the candidates among `components`: the rows of G they need.
int surface_dof_count(const Problem& problem, const EquilibriumState& state, const std::vector<int>& components,
                      const std::vector<int>& free_index) {
  std::vector<char> asked(problem.component_count, 0), counted(free_index.size(), 0);
  for (int c : components) asked[c] = 1;
  int count = 0;
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    if (!asked[c.eta] && (c.xi < 0 || !asked[c.xi])) continue;
    for (const auto& j : state.points[i].point.jacobian)
      if (free_index[j.dof] >= 0 && !counted[j.dof]) {
        counted[j.dof] = 1;
        ++count;
      }
  }
  return count;
}

// Newton's tangent is the body's own at `state` plus the stiffness of the contact forces that
// follow the surface (a curved obstacle's or a pair's) and of follower loads. Where those terms
// are not zero its factorization is no compliance of the body: on a membrane wrapped over a
// punch they nearly cancel the tension's transverse stiffness, and a G from it sent the sheet's
// first real solve to a correction of 6e11.
bool only_body_in_newton_tangent(const Problem& problem, const EquilibriumState& state, bool has_pairs) {
  if (has_pairs || problem.body->has_follower_loads() || state.p.size() != problem.component_count) return false;
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    const bool loaded = state.p[c.eta] != 0.0 || (c.xi >= 0 && state.p[c.xi] != 0.0);
    if (loaded && !state.points[i].projection.dnormal_dx.isZero(0.0)) return false;
  }
  return true;
}

}  // namespace

const Compliance& Equilibrium::compliance(const EquilibriumState& state, const std::vector<int>& components,
                                          int sparse_from) {
  const CpuSpan timed(counters_.compliance_cpu_s);
  const int k = static_cast<int>(components.size());
  bool tangent_ok = false;
  if (k > 0) {
    tangent_ok = compliance_tangent(state, surface_dof_count(problem_, state, components, free_index_),
                                    k < sparse_from || problem_.rigid.count() > 0);
    // The border of a body held by contact stays dense (its block is indefinite).
    if (tangent_ok && k >= sparse_from && problem_.rigid.count() == 0 && body_lu_.symmetric())
      return sparse_compliance(state, components);
  }
  std::vector<int> position(problem_.component_count, -1);
  for (int a = 0; a < k; ++a) position[components[a]] = a;
  const bool same_components = position == c_.position;
  c_.position = std::move(position);
  auto empty = [&]() -> const Compliance& {
    c_.block.setZero(k, k);
    c_.factor.reset();
    t_surface_.resize(0, k);
    c_version_ = -1;
    return c_;
  };
  if (components.empty() || !tangent_ok) return empty();
  // The surface dofs of these components that G does not cover yet join it.
  std::vector<int> added;
  std::vector<char> adding(free_count_, 0);
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    if (c_.position[c.eta] < 0 && (c.xi < 0 || c_.position[c.xi] < 0)) continue;
    for (const auto& j : state.points[i].point.jacobian) {
      const int f = free_index_[j.dof];
      if (f >= 0 && surface_row_[f] < 0 && !adding[f]) {
        adding[f] = 1;
        added.push_back(f);
      }
    }
  }
  if (!added.empty()) {
    extend_surface_compliance(added);
    ++g_version_;
  }
  Eigen::SparseMatrix<double> t_surface =
      contact_map(problem_, state, c_.position, free_index_, g_.rows(), k, [&](int f) { return surface_row_[f]; });
  // The same G, components and T_s (a constant tangent, a pairing that did not move): the same
  // C, and the inner solver keeps its factorizations.
  if (same_components && c_version_ == g_version_ && same_sparse(t_surface, t_surface_)) return c_;
  t_surface_ = std::move(t_surface);
  c_version_ = g_version_;
  c_.factor.reset();
  // C = T_s^T G T_s column by column: G t_b from the few non-zeros of t_b (a point's dofs),
  // then its products with the columns a >= b of T_s, mirrored (C symmetric by construction).
  // Eigen's blocked dense-sparse products cost ~2x more here (allocations, zeroed temporaries).
  using Column = Eigen::SparseMatrix<double>::InnerIterator;
  c_.block.resize(k, k);
  Vector gt(g_.rows());
  for (int b = 0; b < k; ++b) {
    gt.setZero();
    for (Column t(t_surface_, b); t; ++t) gt.noalias() += t.value() * g_.col(t.row());
    for (int a = b; a < k; ++a) {
      double sum = 0.0;
      for (Column t(t_surface_, a); t; ++t) sum += t.value() * gt[t.row()];
      c_.block(a, b) = c_.block(b, a) = sum;
    }
  }
  add_rigid_border(state);
  return c_;
}

bool Equilibrium::newton_factor_serves(const EquilibriumState& state, int surface_dofs) const {
  return !constant_tangent_ && !penalty_ && surface_dofs <= kNewtonFactorRows && newton_factor_solve_ >= 0 &&
         only_body_in_newton_tangent(problem_, state, has_pairs_) && newton_factor_solve_ == counters_.solves &&
         lu_.symmetric() && state.q.size() == newton_factor_q_.size() && state.q == newton_factor_q_;
}

bool Equilibrium::compliance_tangent(const EquilibriumState& state, int surface_dofs, bool dense) {
  const bool from_newton = newton_factor_serves(state, surface_dofs);
  // A G from Newton's factorization, or one with the turning contact forces' stiffness (the
  // exact linearization at its state, and only there), serves its own state only (the next
  // real solve factorizes anew); at that state it is kept while the contact zone grows.
  const bool own_state = g_from_newton_ || g_turns_;
  const bool same_state_g = g_valid_ && own_state && from_newton == g_from_newton_ && g_solve_ == counters_.solves &&
                            (!g_turns_ || g_turns_q_ == state.q) && (!g_indefinite_ || (indefinite_turning_ && dense));
  if (!constant_tangent_ && !same_state_g && (!compliance_reuse_ || own_state)) g_valid_ = false;
  compliance_reused_ = g_valid_ && !constant_tangent_ && !own_state;
  if (g_valid_) return g_factor().ok();
  // A new G: from the tangent at this state.
  surface_free_.clear();
  surface_row_.assign(free_count_, -1);
  g_.resize(0, 0);
  g_from_newton_ = from_newton;
  g_turns_ = false;
  g_solve_ = counters_.solves;
  if (!from_newton) {
    const bool turning = turning_ && !problem_.body->has_follower_loads() && state.p.size() == problem_.component_count;
    if (!factorize_body_tangent(state.q, turning ? &state : nullptr, indefinite_turning_ && dense)) return false;
    if (g_turns_) g_turns_q_ = state.q;
    ++counters_.compliance_forms;
    ++tangent_version_;
  }
  ++g_version_;
  g_valid_ = true;
  return true;
}

const Compliance& Equilibrium::sparse_compliance(const EquilibriumState& state, const std::vector<int>& components) {
  const int k = static_cast<int>(components.size());
  std::vector<int> position(problem_.component_count, -1);
  for (int a = 0; a < k; ++a) position[components[a]] = a;
  const bool same_components = position == sparse_.position;
  sparse_.position = std::move(position);
  Eigen::SparseMatrix<double> t =
      contact_map(problem_, state, sparse_.position, free_index_, free_count_, k, [](int f) { return f; });
  // The same tangent, components and T (a constant tangent, a pairing that did not move): the
  // same C, and the inner solver keeps its factorizations.
  if (same_components && sparse_.body && sparse_version_ == tangent_version_ && same_sparse(t, sparse_.t))
    return sparse_;
  sparse_.t = std::move(t);
  sparse_.normal_of.assign(k, -1);
  for (const Candidate& c : problem_.candidates)
    if (c.xi >= 0 && sparse_.position[c.xi] >= 0) sparse_.normal_of[sparse_.position[c.xi]] = sparse_.position[c.eta];
  sparse_.body = &body_lu_;
  sparse_.saddle.reset();
  sparse_version_ = tangent_version_;
  sparse_.diagonal_entries = body_lu_.quadratic_forms(sparse_.t);
  counters_.dissected_factorizations = body_lu_.dissected_factorizations();
  counters_.body_analyses = body_lu_.analyses();
  counters_.newton_analyses = lu_.analyses();
  return sparse_;
}

namespace {

// A z with zeros: A z summed as Eigen's column-major product sums it (the product of a column
// block, added in column order from zero, then added to the result; blocks of 16 columns from
// 128 columns on), without the columns where z is zero. Their products are zeros, which change
// no such sum of finite terms (a sum from +0 never becomes -0): the same vector to the last bit
// for a finite A (Compliance::apply_finite).
Vector product_without_zero_columns(const Matrix& A, const Vector& z) {
  const Eigen::Index cols = A.cols();
  Eigen::Index zeros = 0;
  for (Eigen::Index j = 0; j < cols; ++j) zeros += z[j] == 0.0;
  if (zeros * 8 < cols) return A * z;  // few to skip
  const Eigen::Index block =
      cols < 128 ? cols : (A.outerStride() * static_cast<Eigen::Index>(sizeof(double)) < 32000 ? 16 : 4);
  Vector result = Vector::Zero(A.rows()), sum(A.rows());
  for (Eigen::Index j0 = 0; j0 < cols; j0 += block) {
    const Eigen::Index end = std::min(j0 + block, cols);
    bool any = false;
    for (Eigen::Index j = j0; j < end; ++j)
      if (z[j] != 0.0) {
        if (!any) sum.setZero();
        any = true;
        sum += A.col(j) * z[j];
      }
    if (any) result += sum;
  }
  return result;
}

}  // namespace

Vector Compliance::apply_finite(const Vector& z) const {
  return sparse() ? apply(z) : product_without_zero_columns(block, z);
}

Vector Compliance::apply(const Vector& z) const {
  if (!sparse()) return block * z;
  const Vector force = t * z;
  return t.transpose() * body->solve(force);
}

// The border G = T^T R of the compliance (docs/algorithm.md#bodies-held-only-by-contact), times the amplitudes' scale: the
// rigid motion moves every contact point with it, and the amplitudes' s, the whole body's
// equilibrium, changes with p by G^T. R at the state (rigid_modes_at): for a deformed body free
// to rotate with finite kinematics, about its current shape, where K R = 0 holds only up to
// terms in its stresses (K R is the load's own turn); the model is then approximate there and
// the real solves decide, as for any changing tangent.
void Equilibrium::add_rigid_border(const EquilibriumState& state) {
  const RigidModes& rigid = problem_.rigid;
  c_.bordered = false;
  if (rigid.count() == 0) return;
  const Matrix modes = rigid_modes_at(problem_, state.q);
  for (int k = 0; k < rigid.count(); ++k) {
    const int col = c_.position[rigid.first + k];
    if (col < 0) continue;
    c_.bordered = true;
    for (size_t i = 0; i < problem_.candidates.size(); ++i) {
      const Candidate& c = problem_.candidates[i];
      const PairedPoint& pp = state.points[i];
      const int eta = c_.position[c.eta], xi = c.xi >= 0 ? c_.position[c.xi] : -1;
      double g_eta = 0.0, g_xi = 0.0;
      for (const auto& j : pp.point.jacobian) {
        g_eta += j.dx.dot(pp.eta) * modes(j.dof, k);
        g_xi += j.dx.dot(pp.xi) * modes(j.dof, k);
      }
      if (eta >= 0) c_.block(eta, col) = c_.block(col, eta) = rigid.scale * g_eta;
      if (xi >= 0) c_.block(xi, col) = c_.block(col, xi) = rigid.scale * g_xi;
    }
  }
}

Vector Equilibrium::predicted_change(const Compliance& C, const Vector& dp) const {
  Vector du = Vector::Zero(free_index_.size());
  if (C.sparse()) {  // T on the free dofs; no rigid amplitudes
    Vector dp_block = Vector::Zero(C.size());
    for (size_t j = 0; j < C.position.size(); ++j)
      if (C.position[j] >= 0) dp_block[C.position[j]] = dp[j];
    const Vector du_free = C.body->solve(Vector(C.t * dp_block));
    for (size_t i = 0; i < free_index_.size(); ++i)
      if (free_index_[i] >= 0) du[i] = du_free[free_index_[i]];
    return du;
  }
  if (C.block.rows() == 0 || t_surface_.cols() != C.block.rows() || !g_factor().ok()) return du;
  if (g_from_newton_ && g_solve_ != counters_.solves) return du;  // Newton has factorized since
  Vector dp_block = Vector::Zero(C.block.rows());
  for (size_t j = 0; j < C.position.size(); ++j)
    if (C.position[j] >= 0) dp_block[C.position[j]] = dp[j];
  const Vector force_surface = t_surface_ * dp_block;
  Vector force = Vector::Zero(free_count_);
  for (size_t r = 0; r < surface_free_.size(); ++r) force[surface_free_[r]] = force_surface[r];
  const Vector du_free = g_factor().solve(force);
  for (size_t i = 0; i < free_index_.size(); ++i)
    if (free_index_[i] >= 0) du[i] = du_free[free_index_[i]];
  const RigidModes& rigid = problem_.rigid;
  for (int k = 0; k < rigid.count(); ++k) du += rigid.scale * dp[rigid.first + k] * rigid.modes.col(k);
  return du;
}

}  // namespace grip
