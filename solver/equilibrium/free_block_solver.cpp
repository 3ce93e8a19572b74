#include "solver/equilibrium/free_block_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace grip {

namespace {

// A second factorization of the same block in nested-dissection order: short elimination-tree
// paths where the fill-reducing order of a thin strip is nearly banded.
void order_by_nested_dissection(CholmodFactor& dissected) {
  dissected.cholmod().nmethods = 1;
  dissected.cholmod().method[0].ordering = CHOLMOD_NESDIS;
}

void factorize_dissected(CholmodFactor& dissected, const Eigen::SparseMatrix<double>& matrix) {
  order_by_nested_dissection(dissected);
  dissected.compute(matrix);
}

// Marks a separator of the block's graph (1; the rest 0): the level of a breadth-first search
// from a pseudo-peripheral row that leaves the rows on either side most nearly equal in number.
std::vector<int> level_separator(const Eigen::SparseMatrix<double>& m) {
  const int n = static_cast<int>(m.rows());
  const int* ap = m.outerIndexPtr();
  const int* ai = m.innerIndexPtr();
  std::vector<int> level(n), queue(n);
  const auto search = [&](int start) {  // levels from start; returns the number of levels
    std::fill(level.begin(), level.end(), -1);
    int head = 0, tail = 0;
    queue[tail++] = start;
    level[start] = 0;
    while (head < tail) {
      const int v = queue[head++];
      for (int p = ap[v]; p < ap[v + 1]; ++p)
        if (level[ai[p]] < 0) {
          level[ai[p]] = level[v] + 1;
          queue[tail++] = ai[p];
        }
    }
    return tail == n ? level[queue[n - 1]] + 1 : -1;  // -1: not connected
  };
  int start = 0, depth = search(start);
  for (int round = 0; round < 4 && depth > 0; ++round) {
    const int far = queue[n - 1];
    const int d = search(far);
    if (d <= depth) {
      search(start);
      break;
    }
    start = far;
    depth = d;
  }
  std::vector<int> member(n, 0);
  if (depth < 3) return member;
  std::vector<int> count(depth, 0);
  for (int v = 0; v < n; ++v) ++count[level[v]];
  int best = -1, before = 0;
  long gap = n;
  for (int l = 0; l < depth; ++l) {
    const long after = n - before - count[l];
    if (l > 0 && l + 1 < depth && std::abs(after - before) < gap) {
      gap = std::abs(after - before);
      best = l;
    }
    before += count[l];
  }
  for (int v = 0; v < n; ++v) member[v] = level[v] == best ? 1 : 0;
  return member;
}

}  // namespace

TangentSink& FreeBlockSolver::assemble(const std::vector<int>& free_index, int free_count,
                                       const Vector* length_scales) {
  free_index_ = &free_index;
  free_count_ = free_count;
  length_scales_ = length_scales;
  unit_scales_ = !length_scales || (length_scales->array() == 1.0).all();
  row_sums_.setZero(length_scales ? free_count : 0);
  next_piece_ = matched_ = 0;
  following_ = !pieces_.empty();  // no pattern yet: every piece is recorded
  finished_ = false;
  recorded_.clear();
  recorded_dofs_.clear();
  recorded_values_.clear();
  if (following_) std::fill(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros(), 0.0);
  assembly_.stress_base = nullptr;  // the exact tangent unless the caller says otherwise
  return assembly_;
}

void FreeBlockSolver::Assembly::add(int row, int col, double value) {
  FreeBlockSolver& o = owner_;
  const int dofs[2] = {row, col};
  if (o.following_ && o.next_piece_ < o.pieces_.size()) {
    const Piece& p = o.pieces_[o.next_piece_];
    if (p.size == 0 && o.dofs_[p.dofs] == row && o.dofs_[p.dofs + 1] == col) {
      ++o.next_piece_;
      if (const int slot = o.slots_[p.slots]; slot >= 0) o.matrix_.valuePtr()[slot] += value;
      if (o.length_scales_) o.add_magnitudes(0, dofs, &value);
      return;
    }
  }
  o.depart();
  o.record(0, dofs, &value);
}

namespace {

// An m x m block added column by column, a node's two rows at a time, at the slots `pair`
// (one per node pair and column); with kSums each row's magnitudes summed too.
template <bool kSums>
void scatter_by_pairs(double* v, const int* pair, const double* x, int m, double* sums) {
  const int h = m / 2;
  for (int j = 0; j < m; ++j, x += m, pair += h)
    for (int a = 0; a < h; ++a) {
      double* t = v + pair[a];
      const double x0 = x[2 * a], x1 = x[2 * a + 1];
      t[0] += x0;
      t[1] += x1;
      if constexpr (kSums) {
        sums[2 * a] += std::abs(x0);
        sums[2 * a + 1] += std::abs(x1);
      }
    }
}

}  // namespace

void FreeBlockSolver::Assembly::add_block(const int* dofs, const Matrix& block) {
  FreeBlockSolver& o = owner_;
  const int m = static_cast<int>(block.rows());
  if (o.following_ && o.next_piece_ < o.pieces_.size()) {
    const Piece& p = o.pieces_[o.next_piece_];
    if (p.size == m && std::equal(dofs, dofs + m, o.dofs_.data() + p.dofs)) {
      ++o.next_piece_;
      double* v = o.matrix_.valuePtr();
      if (p.pairs >= 0 && (!o.length_scales_ || o.unit_scales_)) {
        // Column by column, a node's two rows at a time: the entries are distinct slots, so the
        // order within the block changes no sum, and each row's magnitudes are still summed
        // with increasing column.
        const int* pair = o.pair_slots_.data() + p.pairs;
        if (!o.length_scales_) {
          scatter_by_pairs<false>(v, pair, block.data(), m, nullptr);
          return;
        }
        const std::vector<int>& free = *o.free_index_;
        double sums[kMaxPairedBlock];
        for (int i = 0; i < m; ++i) sums[i] = o.row_sums_[free[dofs[i]]];
        scatter_by_pairs<true>(v, pair, block.data(), m, sums);
        for (int i = 0; i < m; ++i) o.row_sums_[free[dofs[i]]] = sums[i];
        return;
      }
      const int* slot = o.slots_.data() + p.slots;
      if (!o.length_scales_) {
        for (int i = 0; i < m; ++i)  // row by row, as the pattern was built
          for (int j = 0; j < m; ++j, ++slot)
            if (*slot >= 0) v[*slot] += block(i, j);
        return;
      }
      // The magnitudes on the way (a slot: a free row and column), as add_magnitudes sums them.
      const std::vector<int>& free = *o.free_index_;
      const Vector& scale = *o.length_scales_;
      for (int i = 0; i < m; ++i) {
        const int row = free[dofs[i]];
        double sum = row >= 0 ? o.row_sums_[row] : 0.0;
        for (int j = 0; j < m; ++j, ++slot)
          if (*slot >= 0) {
            const double x = block(i, j);
            v[*slot] += x;
            sum += o.unit_scales_ ? std::abs(x) : std::abs(x) / (scale[dofs[i]] * scale[dofs[j]]);
          }
        if (row >= 0) o.row_sums_[row] = sum;
      }
      return;
    }
  }
  o.depart();
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows = block;
  o.record(m, dofs, rows.data());
}

void FreeBlockSolver::depart() {
  if (following_) matched_ = next_piece_;
  following_ = false;
}

void FreeBlockSolver::record(int size, const int* dofs, const double* values) {
  const int count = size ? size : 2, entries = size ? size * size : 1;
  recorded_.push_back({size, static_cast<int>(recorded_dofs_.size()), static_cast<int>(recorded_values_.size())});
  recorded_dofs_.insert(recorded_dofs_.end(), dofs, dofs + count);
  recorded_values_.insert(recorded_values_.end(), values, values + entries);
  if (length_scales_) {
    if (size == 0) add_magnitudes(0, dofs, values);
    else {  // add_magnitudes reads a block column by column
      Matrix block(size, size);
      for (int i = 0; i < size; ++i)
        for (int j = 0; j < size; ++j) block(i, j) = values[i * size + j];
      add_magnitudes(size, dofs, block.data());
    }
  }
}

void FreeBlockSolver::add_magnitudes(int size, const int* dofs, const double* values) {
  const std::vector<int>& free = *free_index_;
  const Vector& scale = *length_scales_;
  if (size == 0) {
    const int i = free[dofs[0]], j = free[dofs[1]];
    if (i >= 0 && j >= 0) row_sums_[i] += std::abs(values[0]) / (scale[dofs[0]] * scale[dofs[1]]);
    return;
  }
  for (int a = 0; a < size; ++a) {  // values: column-major, size x size
    const int i = free[dofs[a]];
    if (i < 0) continue;
    double sum = row_sums_[i];
    for (int b = 0; b < size; ++b)
      if (free[dofs[b]] >= 0)
        sum += unit_scales_ ? std::abs(values[a + b * size])
                            : std::abs(values[a + b * size]) / (scale[dofs[a]] * scale[dofs[b]]);
    row_sums_[i] = sum;
  }
}

double FreeBlockSolver::row_sum_norm() {
  finish_assembly();
  return row_sums_.size() ? row_sums_.maxCoeff() : 0.0;
}

void FreeBlockSolver::finish_assembly() {
  if (finished_) return;
  finished_ = true;
  if (following_ && next_piece_ == pieces_.size()) return;  // the pattern's sequence: values in place
  depart();
  // The first matched_ pieces followed the pattern: they stay, with their sums (each entry's
  // whole sum so far sits at its slot); the recorded ones follow them, in the order emitted.
  const bool rest = matched_ < pieces_.size();
  const int prefix_dofs = rest ? pieces_[matched_].dofs : static_cast<int>(dofs_.size());
  const int prefix_slots = rest ? pieces_[matched_].slots : static_cast<int>(slots_.size());
  const std::vector<int> old_slots(slots_.begin(), slots_.begin() + prefix_slots);
  std::vector<double> old_values;
  if (matched_) old_values.assign(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros());
  if (matched_ == 0) {  // all recorded: their offsets are the pattern's
    pieces_.swap(recorded_);
    dofs_.swap(recorded_dofs_);
  } else {
    pieces_.resize(matched_);
    dofs_.resize(prefix_dofs);
    for (const Piece& p : recorded_) pieces_.push_back({p.size, prefix_dofs + p.dofs, prefix_slots + p.slots});
    dofs_.insert(dofs_.end(), recorded_dofs_.begin(), recorded_dofs_.end());
  }
  build_pattern();
  double* v = matrix_.valuePtr();
  std::fill(v, v + matrix_.nonZeros(), 0.0);
  for (int e = 0; e < prefix_slots; ++e)
    if (old_slots[e] >= 0 && slots_[e] >= 0) v[slots_[e]] = old_values[old_slots[e]];
  for (size_t e = 0; e < recorded_values_.size(); ++e)
    if (const int slot = slots_[prefix_slots + e]; slot >= 0) v[slot] += recorded_values_[e];
  recorded_.clear();
  recorded_dofs_.clear();
  recorded_values_.clear();
}

void FreeBlockSolver::build_pattern() {
  const std::vector<int>& free = *free_index_;
  const auto each_entry = [&](const auto& use) {  // (index in slots_, row, column) of every entry
    for (const Piece& p : pieces_) {
      if (p.size == 0) {
        use(p.slots, dofs_[p.dofs], dofs_[p.dofs + 1]);
        continue;
      }
      for (int i = 0; i < p.size; ++i)
        for (int j = 0; j < p.size; ++j) use(p.slots + i * p.size + j, dofs_[p.dofs + i], dofs_[p.dofs + j]);
    }
  };
  int count = 0;
  for (const Piece& p : pieces_) count += p.size ? p.size * p.size : 1;
  Triplets pattern;
  pattern.reserve(count);
  each_entry([&](int, int row, int col) {
    if (free[row] >= 0 && free[col] >= 0) pattern.emplace_back(free[row], free[col], 1.0);
  });
  matrix_.resize(free_count_, free_count_);
  matrix_.setFromTriplets(pattern.begin(), pattern.end());
  matrix_.makeCompressed();
  slots_.assign(count, -1);
  each_entry([&](int k, int row, int col) {
    if (free[row] >= 0 && free[col] >= 0)
      slots_[k] = static_cast<int>(&matrix_.coeffRef(free[row], free[col]) - matrix_.valuePtr());
  });
  // Where each entry's transpose lives (the pattern of a tangent is symmetric).
  mirror_.assign(matrix_.nonZeros(), -1);
  for (int col = 0; col < matrix_.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(matrix_, col); it; ++it) {
      const double* t = &matrix_.coeffRef(it.col(), it.row());
      mirror_[&it.valueRef() - matrix_.valuePtr()] = static_cast<int>(t - matrix_.valuePtr());
    }
  // The blocks taken by pairs (Piece::pairs).
  pair_slots_.clear();
  std::vector<int> sorted;
  for (Piece& p : pieces_) {
    p.pairs = -1;
    const int m = p.size;
    if (m == 0 || m % 2 || m > kMaxPairedBlock) continue;
    const int* slot = slots_.data() + p.slots;  // row by row
    sorted.assign(slot, slot + m * m);
    std::sort(sorted.begin(), sorted.end());
    if (sorted.front() < 0 || std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) continue;
    bool paired = true;
    for (int j = 0; paired && j < m; ++j)
      for (int a = 0; paired && a < m / 2; ++a) paired = slot[(2 * a + 1) * m + j] == slot[2 * a * m + j] + 1;
    if (!paired) continue;
    p.pairs = static_cast<int>(pair_slots_.size());
    for (int j = 0; j < m; ++j)
      for (int a = 0; a < m / 2; ++a) pair_slots_.push_back(slot[2 * a * m + j]);
  }
  lu_analysed_ = llt_analysed_ = dissected_analysed_ = llt_dissected_ = false;
  dissected_fails_at_ = 0;
  coupled_ = starts_.size() < 3;  // one body
  for (int col = 0; !coupled_ && col < matrix_.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(matrix_, col); it; ++it)
      if (block_of(static_cast<int>(it.row())) != block_of(col)) coupled_ = true;
}

void FreeBlockSolver::check_symmetry(double near_symmetric_tolerance) {
  double* v = matrix_.valuePtr();
  double scale = 0.0, skew = 0.0;
  for (int k = 0; k < matrix_.nonZeros(); ++k) {
    scale = std::max(scale, std::abs(v[k]));
    skew = std::max(skew, std::abs(v[k] - v[mirror_[k]]));
  }
  symmetric_ = skew <= std::max(1e-13, near_symmetric_tolerance) * scale;
  if (symmetric_ && skew > 0)
    for (int k = 0; k < matrix_.nonZeros(); ++k)
      if (mirror_[k] > k) v[k] = v[mirror_[k]] = 0.5 * (v[k] + v[mirror_[k]]);
}

bool FreeBlockSolver::factorize(const Triplets& triplets, const std::vector<int>& free_index, int free_count,
                                double near_symmetric_tolerance) {
  TangentSink& sink = assemble(free_index, free_count);
  for (const auto& t : triplets) sink.add(t.row(), t.col(), t.value());
  return factorize(near_symmetric_tolerance);
}

bool FreeBlockSolver::factorize(double near_symmetric_tolerance) {
  finish_assembly();
  ++factorizations_;
  split_ = !coupled_;
  if (split_) {
    check_symmetry(near_symmetric_tolerance);
    return factorize_parts(near_symmetric_tolerance);
  }
  if (!llt_analysed_) {  // the ordering: once per pattern
    analyse_ordered();
    ++analyses_;
  }
  llt_analysed_ = true;
  // The ordered triangle's values, and the symmetry check on the way: each pair of entries is
  // one entry of the triangle and its transpose.
  double* w = ordered_.valuePtr();
  const double* v = matrix_.valuePtr();
  double scale = 0.0, skew = 0.0;
  for (size_t k = 0; k < gather_.size(); ++k) {
    const double a = v[gather_[k]], b = v[transposed_[k]];
    scale = std::max(scale, std::max(std::abs(a), std::abs(b)));
    skew = std::max(skew, std::abs(a - b));
    w[k] = a;
  }
  symmetric_ = skew <= std::max(1e-13, near_symmetric_tolerance) * scale;
  if (symmetric_ && skew > 0) {  // matrix_ too: LU's fallback and the dissected factor read it
    double* m = matrix_.valuePtr();
    for (size_t k = 0; k < gather_.size(); ++k)
      w[k] = m[gather_[k]] = m[transposed_[k]] = 0.5 * (w[k] + m[transposed_[k]]);
  }
  if (symmetric_) {
    // The team from kParallelRows rows on, as for the bodies' tasks.
    llt_.factorize_ordered(ordered_, ordered_stype_, matrix_.rows() >= kParallelRows ? parallel_ : ParallelFor());
    // Not positive definite, or a pivot at round-off (the supports do not hold the body):
    // (min/max diag L)^2 is the min/max of LDL^T's D.
    ok_ = llt_.info() == Eigen::Success && llt_.rcond() > 1e-14;
    if (ok_) return true;
    symmetric_ = false;  // fall back to LU
  }
  if (!lu_analysed_) {
    lu_.analyzePattern(matrix_);
    ++analyses_;
  }
  lu_analysed_ = true;
  lu_.factorize(matrix_);
  ok_ = lu_.info() == Eigen::Success;
  return ok_;
}

void FreeBlockSolver::analyse_ordered() {
  // CHOLMOD's own choice: supernodal where dense blocks pay (2D continua), simplicial for banded
  // blocks (beams, membranes), where the supernodal BLAS calls on tiny blocks cost more than the
  // arithmetic (the beam's compliance: 30 % of its time in dtrsm). L L^T either way
  // (inverse_block reads L). The probe's order includes CHOLMOD's postordering.
  CholmodFactor probe;
  probe.cholmod().supernodal = CHOLMOD_AUTO;
  probe.cholmod().nmethods = 0;  // CHOLMOD's default choice of ordering
  if (llt_dissected_) order_by_nested_dissection(probe);
  probe.analyzePattern(matrix_);
  const cholmod_factor* L = probe.factor();
  const int n = static_cast<int>(matrix_.rows());
  // A large simplicial block: the same fill-reducing order, but with a separator of the block's
  // graph ordered last where that costs at most 5 % more flops. The elimination tree then
  // splits below the separator into two halves that the factorization can take at once
  // (CholmodFactor::factorize_ordered); a thin strip's own order is nearly banded, one long
  // path. Chosen by the pattern alone, so the factor is the same on any number of threads.
  cholmod_factor* separated = nullptr;
  if (!llt_dissected_ && L && !L->is_super && n >= kParallelRows) {
    std::vector<int> member = level_separator(matrix_), perm(n);
    cholmod_sparse A = Eigen::viewAsCholmod(matrix_);
    A.stype = 1;
    cholmod_common& common = probe.cholmod();
    const double flops = common.fl;
    if (std::count(member.begin(), member.end(), 1) > 0 &&
        cholmod_camd(&A, nullptr, 0, member.data(), perm.data(), &common)) {
      common.nmethods = 1;
      common.method[0].ordering = CHOLMOD_GIVEN;
      common.postorder = 1;
      separated = cholmod_analyze_p(&A, perm.data(), nullptr, 0, &common);
      if (separated && !separated->is_super && common.fl <= kSeparatedFlops * flops) L = separated;
    }
  }
  order_.resize(n);
  const int* perm = L ? static_cast<const int*>(L->Perm) : nullptr;
  for (int k = 0; k < n; ++k) order_.indices()[perm ? perm[k] : k] = k;
  ordered_stype_ = L && L->is_super ? -1 : 1;
  // The triangle, each entry's value taken from matrix_'s lower one (gather_). Simplicial: the
  // upper triangle with its columns in the order cholmod_transpose_sym gives them (CHOLMOD's
  // row factorization sums in that order: the same factor, bit for bit, as with the permuted
  // lower triangle CHOLMOD transposed itself). Supernodal: the lower, columns sorted.
  const int* ap = matrix_.outerIndexPtr();
  const int* ai = matrix_.innerIndexPtr();
  const auto& position = order_.indices();
  std::vector<int> start(n + 1, 0), inner;
  gather_.clear();
  if (ordered_stype_ > 0) {
    const auto each_lower = [&](const auto& use) {  // (column of the triangle, row, source)
      for (int j = 0; j < n; ++j) {
        const int jold = perm ? perm[j] : j;
        for (int p = ap[jold]; p < ap[jold + 1]; ++p)
          if (ai[p] >= jold) {
            const int i = position[ai[p]];
            use(std::max(i, j), std::min(i, j), p);
          }
      }
    };
    each_lower([&](int col, int, int) { ++start[col + 1]; });
    for (int j = 0; j < n; ++j) start[j + 1] += start[j];
    std::vector<int> next(start.begin(), start.end() - 1);
    inner.resize(start[n]);
    gather_.resize(start[n]);
    each_lower([&](int col, int row, int p) {
      inner[next[col]] = row;
      gather_[next[col]++] = p;
    });
  } else {
    for (int jold = 0; jold < n; ++jold)  // count, then fill by increasing row
      for (int p = ap[jold]; p < ap[jold + 1]; ++p)
        if (ai[p] >= jold) ++start[std::min(position[ai[p]], position[jold]) + 1];
    for (int j = 0; j < n; ++j) start[j + 1] += start[j];
    std::vector<std::vector<std::pair<int, int>>> columns(n);  // (row, source)
    for (int jold = 0; jold < n; ++jold)
      for (int p = ap[jold]; p < ap[jold + 1]; ++p)
        if (ai[p] >= jold) {
          const int i = position[ai[p]], j = position[jold];
          columns[std::min(i, j)].emplace_back(std::max(i, j), p);
        }
    for (auto& column : columns) {
      std::sort(column.begin(), column.end());
      for (const auto& [row, p] : column) {
        inner.push_back(row);
        gather_.push_back(p);
      }
    }
  }
  ordered_ = Eigen::SparseMatrix<double>(n, n);  // compressed; filled through its arrays
  ordered_.resizeNonZeros(static_cast<Eigen::Index>(inner.size()));
  std::copy(start.begin(), start.end(), ordered_.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), ordered_.innerIndexPtr());
  transposed_.resize(gather_.size());
  for (size_t k = 0; k < gather_.size(); ++k) transposed_[k] = mirror_[gather_[k]];
  if (separated) cholmod_free_factor(&separated, &probe.cholmod());
  llt_.cholmod().supernodal = CHOLMOD_AUTO;
  llt_.cholmod().final_ll = 1;
  llt_.analyze_ordered(ordered_, ordered_stype_);
}

// The rows of a simplicial factor split for two threads. CHOLMOD's row factorization computes
// row k of L from the columns of k's descendants in the elimination tree only, so two groups of
// disjoint subtrees can be computed at once (cholmod_rowfac on row ranges: a postordered tree's
// subtrees are ranges), each with CHOLMOD workspace of its own, and the rows above them after.
struct CholmodFactor::Subtrees {
  bool planned = false;                             // for the current analysis
  std::vector<std::pair<int, int>> groups[2], top;  // row ranges [begin, end)
  static constexpr int kMaxTopRows = 256;
  static constexpr double kMaxShare = 0.75;
  cholmod_common second{};
  bool second_started = false;
  ~Subtrees() {
    if (second_started) cholmod_finish(&second);
  }
  // From a numeric factor's pattern: each row's work is that of its updates (row k takes column
  // j's t - 1 entries above it when k is column j's t-th entry), a subtree's the sum of its rows'.
  // The subtrees' roots come down from the tree's roots, the largest subtree's root at a time,
  // into the top rows, as long as the two groups' larger one (by largest first into the
  // lighter) and the top rows together take less; kept where that is at most 0.75 of the whole.
  void plan(const cholmod_factor& L);
};

void CholmodFactor::Subtrees::plan(const cholmod_factor& L) {
  planned = true;
  groups[0].clear();
  groups[1].clear();
  top.clear();
  const int n = static_cast<int>(L.n);
  if (L.is_super || L.xtype == CHOLMOD_PATTERN) return;
  const int* lp = static_cast<const int*>(L.p);
  const int* li = static_cast<const int*>(L.i);
  const int* lnz = static_cast<const int*>(L.nz);
  std::vector<int> parent(n, -1), size(n, 1), first(n);
  std::vector<double> work(n, 1.0);
  for (int j = 0; j < n; ++j) {
    if (lnz[j] > 1) parent[j] = li[lp[j] + 1];
    for (int t = 1; t < lnz[j]; ++t) work[li[lp[j] + t]] += t;
  }
  std::iota(first.begin(), first.end(), 0);
  std::vector<double> subtree(work);
  std::vector<std::vector<int>> children(n);
  for (int j = 0; j < n; ++j)
    if (parent[j] >= 0) {
      if (parent[j] <= j) return;  // not an elimination tree's order
      subtree[parent[j]] += subtree[j];
      size[parent[j]] += size[j];
      first[parent[j]] = std::min(first[parent[j]], first[j]);
      children[parent[j]].push_back(j);
    }
  for (int j = 0; j < n; ++j)
    if (first[j] != j - size[j] + 1) return;  // not postordered: subtrees are not ranges
  const double total = std::accumulate(work.begin(), work.end(), 0.0);
  const auto larger = [&](int a, int b) { return subtree[a] < subtree[b]; };
  std::vector<int> roots;  // the candidates, as a max-heap by subtree work
  for (int j = 0; j < n; ++j)
    if (parent[j] < 0) roots.push_back(j);
  std::make_heap(roots.begin(), roots.end(), larger);
  std::vector<int> tops, best_tops, sorted, best_roots;
  double top_work = 0.0, best = total;
  for (int step = 0; step < kMaxTopRows && !roots.empty() && top_work < best; ++step) {
    sorted = roots;
    std::sort(sorted.begin(), sorted.end(), [&](int a, int b) { return subtree[a] > subtree[b]; });
    double bins[2] = {0.0, 0.0};
    for (int r : sorted) bins[bins[0] <= bins[1] ? 0 : 1] += subtree[r];
    if (const double cost = std::max(bins[0], bins[1]) + top_work; cost < best) {
      best = cost;
      best_roots = sorted;
      best_tops = tops;
    }
    std::pop_heap(roots.begin(), roots.end(), larger);
    const int r = roots.back();
    roots.pop_back();
    tops.push_back(r);
    top_work += work[r];
    for (int c : children[r]) {
      roots.push_back(c);
      std::push_heap(roots.begin(), roots.end(), larger);
    }
  }
  if (best > kMaxShare * total) return;
  const auto add = [](std::vector<std::pair<int, int>>& ranges, int begin, int end) {
    if (!ranges.empty() && ranges.back().second == begin) ranges.back().second = end;
    else ranges.emplace_back(begin, end);
  };
  double bins[2] = {0.0, 0.0};
  std::vector<std::pair<int, int>> assigned[2];
  for (int r : best_roots) {
    const int b = bins[0] <= bins[1] ? 0 : 1;
    bins[b] += subtree[r];
    assigned[b].emplace_back(first[r], r + 1);
  }
  for (int b = 0; b < 2; ++b) {
    std::sort(assigned[b].begin(), assigned[b].end());
    for (const auto& [begin, end] : assigned[b]) add(groups[b], begin, end);
  }
  std::sort(best_tops.begin(), best_tops.end());
  for (int r : best_tops) add(top, r, r + 1);
}

CholmodFactor::CholmodFactor() { cholmod().print = 0; }

CholmodFactor::~CholmodFactor() {
  cholmod_free_dense(&solve_x_, &cholmod());
  cholmod_free_dense(&solve_y_, &cholmod());
  cholmod_free_dense(&solve_e_, &cholmod());
}

bool CholmodFactor::factorize_subtrees(cholmod_sparse& A, const ParallelFor& parallel) {
  cholmod_factor* L = m_cholmodFactor;
  if (!parallel || L->is_super || L->xtype == CHOLMOD_PATTERN || A.stype <= 0) return false;
  if (!subtrees_) subtrees_ = std::make_unique<Subtrees>();
  Subtrees& plan = *subtrees_;
  if (!plan.planned) plan.plan(*L);
  if (plan.groups[0].empty() || plan.groups[1].empty()) return false;
  if (!plan.second_started) {
    cholmod_start(&plan.second);
    plan.second.print = 0;
    plan.second_started = true;
  }
  // As CHOLMOD's refactorization of all rows starts: every column holds its diagonal only.
  const int n = static_cast<int>(L->n);
  L->minor = L->n;
  L->is_ll = cholmod().final_ll ? 1 : 0;
  std::fill(static_cast<int*>(L->nz), static_cast<int*>(L->nz) + n, 1);
  size_t minor[2] = {L->n, L->n};
  bool ok[2] = {true, true};
  parallel(2, [&](int b) {
    cholmod_factor part = *L;  // L's arrays (each group writes its own columns), a minor of its own
    cholmod_common* common = b == 0 ? &cholmod() : &plan.second;
    for (const auto& [begin, end] : plan.groups[b])
      ok[b] = ok[b] && cholmod_rowfac(&A, nullptr, m_shiftOffset, begin, end, &part, common);
    minor[b] = part.minor;
  });
  L->minor = std::min(minor[0], minor[1]);
  bool done = ok[0] && ok[1];
  for (const auto& [begin, end] : plan.top)
    done = done && cholmod_rowfac(&A, nullptr, m_shiftOffset, begin, end, L, &cholmod());
  if (!done) L->minor = std::min(L->minor, L->n - 1);  // CHOLMOD failed: no factor
  return true;
}

bool CholmodFactor::solve_kept(const double* b, double* x) const {
  if (!m_cholmodFactor) return false;
  const size_t n = m_cholmodFactor->n;
  cholmod_dense B{};  // a view of b
  B.nrow = B.nzmax = B.d = n;
  B.ncol = 1;
  B.x = const_cast<double*>(b);
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  cholmod_common* cc = &const_cast<CholmodFactor*>(this)->cholmod();  // Eigen's is mutable, its accessor not const
  // A simplicial factor's workspace Y is 4 x n (leading dimension 4: up to four right-hand sides
  // at a time), which cholmod_solve2 leaves shaped for the one it solved (1 x n); its
  // cholmod_ensure_dense reallocates a Y of any other shape. The shape restored, Y is kept.
  if (solve_y_ && !m_cholmodFactor->is_super && solve_y_->nzmax >= 4 * n) {
    solve_y_->nrow = solve_y_->d = 4;
    solve_y_->ncol = n;
  }
  if (!cholmod_solve2(CHOLMOD_A, m_cholmodFactor, &B, nullptr, &solve_x_, nullptr, &solve_y_, &solve_e_, cc))
    return false;
  const double* solved = static_cast<const double*>(solve_x_->x);
  std::copy(solved, solved + n, x);
  return true;
}

void CholmodFactor::analyze_ordered(const Eigen::SparseMatrix<double>& triangle, int stype) {
  if (m_cholmodFactor) cholmod_free_factor(&m_cholmodFactor, &cholmod());
  cholmod().nmethods = 1;
  cholmod().method[0].ordering = CHOLMOD_NATURAL;
  cholmod().postorder = 0;  // the order is final: CHOLMOD then neither permutes nor transposes
  cholmod_sparse A = Eigen::viewAsCholmod(triangle);
  A.stype = stype;
  A.sorted = 0;  // the upper triangle's columns in cholmod_transpose_sym's order
  m_cholmodFactor = cholmod_analyze(&A, &cholmod());
  if (subtrees_) subtrees_->planned = false;
  m_isInitialized = true;
  m_info = m_cholmodFactor ? Eigen::Success : Eigen::InvalidInput;
  m_analysisIsOk = m_cholmodFactor != nullptr;
  m_factorizationIsOk = false;
}

void CholmodFactor::factorize_ordered(const Eigen::SparseMatrix<double>& triangle, int stype,
                                      const ParallelFor& parallel) {
  if (!m_cholmodFactor) return;
  cholmod_sparse A = Eigen::viewAsCholmod(triangle);
  A.stype = stype;
  A.sorted = 0;
  rows_split_ = factorize_subtrees(A, parallel);
  if (!rows_split_) cholmod_factorize_p(&A, m_shiftOffset, nullptr, 0, m_cholmodFactor, &cholmod());
  m_info = m_cholmodFactor->minor == m_cholmodFactor->n ? Eigen::Success : Eigen::NumericalIssue;
  m_factorizationIsOk = true;
}

// A simplicial factor tells beforehand whether the partial solves pay: the solve from row k
// reaches the path from k to the root of the elimination tree (parent of column j: its first
// row below the diagonal), so their work, |rows|^2 x the mean path length, is known without
// copying the factor (a beam's or a membrane's banded block: the dense solves win).
namespace {

bool partial_solves_pay(const cholmod_factor* L, const std::vector<int>& rows) {
  if (L->is_super) return true;  // sampled in inverse_block
  const int n = static_cast<int>(L->n);
  const int *lp = static_cast<const int*>(L->p), *li = static_cast<const int*>(L->i),
            *lnz = static_cast<const int*>(L->nz), *perm = static_cast<const int*>(L->Perm);
  std::vector<int> path(n, 1), position(n);
  double nnz_l = 0.0;
  for (int j = n - 1; j >= 0; --j) {  // a parent's index is larger than its child's
    int parent = n;
    for (int t = lp[j] + 1; t < lp[j] + lnz[j]; ++t) parent = std::min(parent, li[t]);
    if (parent < n) path[j] = path[parent] + 1;
    nnz_l += lnz[j];
  }
  for (int k = 0; k < n; ++k) position[perm ? perm[k] : k] = k;
  double reach = 0.0;
  for (int r : rows) reach += path[position[r]];
  const double s = static_cast<double>(rows.size());
  return s * reach <= 2.0 * nnz_l * s;
}

}  // namespace

bool FreeBlockSolver::inverse_block(const std::vector<int>& rows, Matrix& G, const ParallelFor& parallel) {
  if (!ok_ || !symmetric_) return false;
  if (split_) {  // K^-1 is block diagonal: each body's rows from its own factor
    std::vector<std::vector<int>> local(parts_.size()), at(parts_.size());
    for (size_t a = 0; a < rows.size(); ++a) {
      const int b = block_of(rows[a]);
      local[b].push_back(rows[a] - starts_[b]);
      at[b].push_back(static_cast<int>(a));
    }
    std::vector<Matrix> blocks(parts_.size());
    std::vector<char> ok(parts_.size(), 1);
    for_each_part([&](int b) {
      if (!local[b].empty()) ok[b] = parts_[b]->inverse_block(local[b], blocks[b]);
    });
    if (!std::all_of(ok.begin(), ok.end(), [](char c) { return c != 0; })) return false;
    G.setZero(static_cast<int>(rows.size()), static_cast<int>(rows.size()));
    for (size_t b = 0; b < parts_.size(); ++b)
      for (size_t i = 0; i < at[b].size(); ++i)
        for (size_t j = 0; j < at[b].size(); ++j) G(at[b][i], at[b][j]) = blocks[b](i, j);
    return true;
  }
  std::vector<int> ordered_rows(rows.size());
  for (size_t a = 0; a < rows.size(); ++a) ordered_rows[a] = order_.indices()[rows[a]];
  if (llt_.inverse_block(ordered_rows, G, parallel)) return true;
  // More rows only lengthen the partial solves against the same factor's pattern.
  if (dissected_fails_at_ && rows.size() >= dissected_fails_at_) return false;
  if (!dissected_analysed_) {
    order_by_nested_dissection(dissected_);
    dissected_.analyzePattern(matrix_);
    dissected_analysed_ = true;
    ++analyses_;
  }
  ++dissected_factorizations_;
  dissected_.factorize(matrix_);
  if (dissected_.info() == Eigen::Success && dissected_.inverse_block(rows, G, parallel)) {
    // From now on the block's own factor takes this order: one factorization serves the solves
    // and G (the dissected order costs the solves little more on a thin strip's block).
    if (!llt_dissected_) llt_analysed_ = false;
    llt_dissected_ = true;
    return true;
  }
  dissected_fails_at_ = dissected_fails_at_ ? std::min(dissected_fails_at_, rows.size()) : rows.size();
  return false;
}

bool CholmodFactor::forward_solves(const Eigen::SparseMatrix<double>& columns,
                                   const std::function<bool(int, const int*, const double*, int)>& use) {
  if (!m_cholmodFactor) return false;
  cholmod_common* cc = &cholmod();
  // The partial solve makes a supernodal factor simplicial: on a copy. A simplicial one it only
  // reads (no copy of L, megabytes of fresh pages, at every G).
  cholmod_factor* copy = m_cholmodFactor->is_super ? cholmod_copy_factor(m_cholmodFactor, cc) : nullptr;
  cholmod_factor* L = m_cholmodFactor->is_super ? copy : m_cholmodFactor;
  if (!L) return false;
  const int n = static_cast<int>(L->n);
  std::vector<int> position(n);  // row of P b that b's entry f lands in
  const int* perm = static_cast<const int*>(L->Perm);
  for (int k = 0; k < n; ++k) position[perm ? perm[k] : k] = k;
  int most = 1;
  for (int a = 0; a < columns.outerSize(); ++a)
    most = std::max(most, static_cast<int>(columns.outerIndexPtr()[a + 1] - columns.outerIndexPtr()[a]));
  cholmod_dense* B = cholmod_zeros(n, 1, CHOLMOD_REAL, cc);
  cholmod_sparse* bset = cholmod_allocate_sparse(n, 1, most, true, true, 0, CHOLMOD_PATTERN, cc);
  cholmod_dense *X = nullptr, *Y = nullptr, *E = nullptr;
  cholmod_sparse* xset = nullptr;
  bool ok = B && bset;
  std::vector<int> pattern;
  for (int a = 0; ok && a < columns.outerSize(); ++a) {
    pattern.clear();
    for (Eigen::SparseMatrix<double>::InnerIterator it(columns, a); it; ++it) {
      static_cast<double*>(B->x)[position[it.row()]] = it.value();
      pattern.push_back(position[it.row()]);
    }
    if (pattern.empty()) {  // a column without entries in this block: x = 0
      ok = use(a, nullptr, nullptr, 0);
      continue;
    }
    std::sort(pattern.begin(), pattern.end());
    static_cast<int*>(bset->p)[0] = 0;
    static_cast<int*>(bset->p)[1] = static_cast<int>(pattern.size());
    std::copy(pattern.begin(), pattern.end(), static_cast<int*>(bset->i));
    ok = cholmod_solve2(CHOLMOD_L, L, B, bset, &X, &xset, &Y, &E, cc);
    for (int k : pattern) static_cast<double*>(B->x)[k] = 0.0;
    if (!ok) break;
    const int* xi = static_cast<const int*>(xset->i);
    ok = use(a, xi, static_cast<const double*>(X->x), static_cast<const int*>(xset->p)[1]);
  }
  cholmod_free_dense(&B, cc);
  cholmod_free_dense(&X, cc);
  cholmod_free_dense(&Y, cc);
  cholmod_free_dense(&E, cc);
  cholmod_free_sparse(&bset, cc);
  cholmod_free_sparse(&xset, cc);
  if (copy) cholmod_free_factor(&copy, cc);
  return ok;
}

bool CholmodFactor::inverse_block(const std::vector<int>& rows, Matrix& G, const ParallelFor& parallel) {
  if (!m_cholmodFactor || !partial_solves_pay(m_cholmodFactor, rows)) return false;
  const cholmod_factor* L = m_cholmodFactor;
  const int n = static_cast<int>(L->n), s = static_cast<int>(rows.size());
  Eigen::SparseMatrix<double> units(n, s);  // the unit columns of the rows
  std::vector<Eigen::Triplet<double>> ones;
  for (int a = 0; a < s; ++a) ones.emplace_back(rows[a], a, 1.0);
  units.setFromTriplets(ones.begin(), ones.end());
  // W's columns as the solves give them, then its rows (the storage kept from G to G).
  w_.column_start.assign(1, 0);
  w_.column_rows.clear();
  w_.column_values.clear();
  w_.row_start.assign(n + 1, 0);  // the count of row k at k + 1 until the sums below
  // W^T W costs sum |row|^2 <= s^2 x (mean column length) multiply-adds; dense solves would
  // cost 4 nnz(L) per row. Where W is not sparse enough (thin strips: long elimination-tree
  // paths), give up after a few columns.
  double nnz_l = 0.0;  // the entries a solve goes through (supernodal: its dense blocks)
  if (L->is_super) nnz_l = static_cast<double>(L->xsize);
  else
    for (int j = 0; j < n; ++j) nnz_l += static_cast<const int*>(L->nz)[j];
  const double budget = 2.0 * nnz_l * s;  // half the dense solves' flops
  double pairs = 0.0, reach = 0.0;
  constexpr int kSample = 8;
  const bool ok = forward_solves(units, [&](int a, const int* xi, const double* xv, int count) {
    reach += count;
    if (a + 1 == std::min(s, kSample) && static_cast<double>(s) * s * reach / (a + 1) > budget) return false;
    for (int t = 0; t < count; ++t)
      if (const int k = xi[t]; xv[k] != 0.0) {
        pairs += 2.0 * w_.row_start[k + 1] + 1.0;
        ++w_.row_start[k + 1];
        w_.column_rows.push_back(k);
        w_.column_values.push_back(xv[k]);
      }
    w_.column_start.push_back(static_cast<int>(w_.column_rows.size()));
    return pairs < budget;
  });
  if (!ok) return false;
  // W by rows, each row's columns in increasing order.
  for (int k = 0; k < n; ++k) w_.row_start[k + 1] += w_.row_start[k];
  w_.next.assign(w_.row_start.begin(), w_.row_start.end() - 1);
  w_.row_columns.resize(w_.column_rows.size());
  w_.row_values.resize(w_.column_rows.size());
  for (int a = 0; a < s; ++a)
    for (int e = w_.column_start[a]; e < w_.column_start[a + 1]; ++e) {
      const int at = w_.next[w_.column_rows[e]]++;
      w_.row_columns[at] = a;
      w_.row_values[at] = w_.column_values[e];
    }
  // G = W^T W row by row of W (k increasing, the order of every entry's sum), its upper
  // triangle only, then mirrored: G(a, b) would sum the same products w_kb w_ka in the same
  // order, so the mirror is that sum to the last bit. Through `parallel`, tasks take column
  // ranges of equal work (entry i of a row costs column col[i] i + 1 products): each entry is
  // summed by one task in the same order, so G is the same to the last bit on any thread count.
  G.setZero(s, s);
  std::vector<int> bounds{0, s};
  if (parallel && s >= kParallelColumns) {
    std::vector<double> work(s, 0.0);
    for (int k = 0; k < n; ++k)
      for (int i = 0; i < w_.row_start[k + 1] - w_.row_start[k]; ++i)
        work[w_.row_columns[w_.row_start[k] + i]] += i + 1;
    const double total = std::accumulate(work.begin(), work.end(), 0.0);
    bounds.assign(1, 0);
    double sum = 0.0;
    for (int a = 0; a < s; ++a) {
      sum += work[a];
      if (sum >= total * static_cast<double>(bounds.size()) / kSumTasks && a + 1 < s) bounds.push_back(a + 1);
    }
    bounds.push_back(s);
  }
  // Runs of rows of W with the same columns (a chain of the elimination tree: every path that
  // reaches its first row goes through all of it; a separator's rows in nested dissection):
  // [group_start[g], group_start[g + 1]). For a run, the entries (j <= i) of G's column col[i]
  // are gathered once, the run's rows added in a contiguous (vectorized) loop over j, k
  // increasing, and scattered back once, instead of one scatter per row: each entry gets the
  // same products added in the same order as row by row, so G is the same to the last bit.
  std::vector<int> group_start{0};
  for (int k = 1; k < n; ++k) {
    const int len = w_.row_start[k + 1] - w_.row_start[k];
    const bool same =
        len > 0 && len == w_.row_start[k] - w_.row_start[k - 1] &&
        std::equal(w_.row_columns.begin() + w_.row_start[k], w_.row_columns.begin() + w_.row_start[k] + len,
                   w_.row_columns.begin() + w_.row_start[k - 1]);
    if (!same) group_start.push_back(k);
  }
  group_start.push_back(n);
  run_each(parallel, static_cast<int>(bounds.size()) - 1, [&](int task) {
    const int lo = bounds[task], hi = bounds[task + 1];
    std::vector<double> acc(s);
    for (size_t g = 0; g + 1 < group_start.size(); ++g) {
      const int k = group_start[g], rows_in = group_start[g + 1] - k;
      if (rows_in > 1) {
        const int* col = w_.row_columns.data() + w_.row_start[k];
        const int m = w_.row_start[k + 1] - w_.row_start[k];
        for (int i = static_cast<int>(std::lower_bound(col, col + m, lo) - col); i < m && col[i] < hi; ++i) {
          double* column = &G(0, col[i]);
          for (int j = 0; j <= i; ++j) acc[j] = column[col[j]];
          for (int t = 0; t < rows_in; ++t) {
            const double* v = w_.row_values.data() + w_.row_start[k + t];
            const double vi = v[i];
            for (int j = 0; j <= i; ++j) acc[j] += vi * v[j];
          }
          for (int j = 0; j <= i; ++j) column[col[j]] = acc[j];
        }
        continue;
      }
      const int* col = w_.row_columns.data() + w_.row_start[k];
      const double* val = w_.row_values.data() + w_.row_start[k];
      const int m = w_.row_start[k + 1] - w_.row_start[k];
      // The row's columns increase: this task's entries are a contiguous range of it.
      const int first = static_cast<int>(std::lower_bound(col, col + m, lo) - col);
      // Four entries of the row at a time share the loads of the entries j before them (each
      // entry of G still gets one product per k, in the same order), then their triangle.
      int i = first;
      for (; i + 3 < m && col[i + 3] < hi; i += 4) {
        double *c0 = &G(0, col[i]), *c1 = &G(0, col[i + 1]), *c2 = &G(0, col[i + 2]), *c3 = &G(0, col[i + 3]);
        const double v0 = val[i], v1 = val[i + 1], v2 = val[i + 2], v3 = val[i + 3];
        for (int j = 0; j <= i; ++j) {
          const int r = col[j];
          const double w = val[j];
          c0[r] += v0 * w;
          c1[r] += v1 * w;
          c2[r] += v2 * w;
          c3[r] += v3 * w;
        }
        c1[col[i + 1]] += v1 * val[i + 1];
        c2[col[i + 1]] += v2 * val[i + 1];
        c2[col[i + 2]] += v2 * val[i + 2];
        c3[col[i + 1]] += v3 * val[i + 1];
        c3[col[i + 2]] += v3 * val[i + 2];
        c3[col[i + 3]] += v3 * val[i + 3];
      }
      for (; i < m && col[i] < hi; ++i) {
        double* column = &G(0, col[i]);
        const double va = val[i];
        for (int j = 0; j <= i; ++j) column[col[j]] += va * val[j];
      }
    }
  });
  for (int a = 0; a < s; ++a)
    for (int b = 0; b < a; ++b) G(a, b) = G(b, a);
  return true;
}

bool CholmodFactor::quadratic_forms(const Eigen::SparseMatrix<double>& t, Vector& out, double max_mean_reach) {
  out.setZero(t.cols());
  double reach = 0.0;
  constexpr int kSample = 8;
  return forward_solves(t, [&](int a, const int* xi, const double* xv, int count) {
    reach += count;
    if (max_mean_reach > 0 && a + 1 == std::min(static_cast<int>(t.cols()), kSample) &&
        reach / (a + 1) > max_mean_reach)
      return false;
    double sum = 0.0;
    for (int k = 0; k < count; ++k) sum += xv[xi[k]] * xv[xi[k]];
    out[a] = sum;
    return true;
  });
}

Vector FreeBlockSolver::quadratic_forms(const Eigen::SparseMatrix<double>& t) {
  Vector out;
  if (!ok_ || !symmetric_) return Vector();
  if (split_) {  // t^T K^-1 t summed over the bodies, each with its rows of t
    std::vector<Triplets> local(parts_.size());
    for (int col = 0; col < t.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(t, col); it; ++it) {
        const int b = block_of(static_cast<int>(it.row()));
        local[b].emplace_back(static_cast<int>(it.row()) - starts_[b], col, it.value());
      }
    std::vector<Vector> forms(parts_.size());
    for_each_part([&](int b) {
      Eigen::SparseMatrix<double> tb(starts_[b + 1] - starts_[b], t.cols());
      tb.setFromTriplets(local[b].begin(), local[b].end());
      forms[b] = parts_[b]->quadratic_forms(tb);
    });
    out.setZero(t.cols());
    for (const Vector& f : forms) {
      if (f.size() != t.cols()) return Vector();
      out += f;
    }
    return out;
  }
  // A path through more than 1/32 of the rows on average: the nested-dissection order instead.
  const Eigen::SparseMatrix<double> ordered_t = order_ * t;
  if (llt_.quadratic_forms(ordered_t, out, matrix_.rows() / 32.0)) return out;
  CholmodFactor dissected;
  ++dissected_factorizations_;
  ++analyses_;  // compute(): an analysis and a factorization
  factorize_dissected(dissected, matrix_);
  if (dissected.info() == Eigen::Success && dissected.quadratic_forms(t, out, 0.0)) return out;
  return Vector();
}

long FreeBlockSolver::analyses() const {
  long count = analyses_;
  for (const auto& part : parts_) count += part->analyses();
  return count;
}

long FreeBlockSolver::dissected_factorizations() const {
  long count = dissected_factorizations_;
  for (const auto& part : parts_) count += part->dissected_factorizations();
  return count;
}

void FreeBlockSolver::set_blocks(std::vector<int> starts, ParallelFor parallel) {
  starts_ = std::move(starts);
  parallel_ = std::move(parallel);
  parts_.clear();
  for (size_t b = 0; b + 1 < starts_.size(); ++b) parts_.push_back(std::make_unique<FreeBlockSolver>());
  forget_pattern();
}

int FreeBlockSolver::block_of(int row) const {
  return static_cast<int>(std::upper_bound(starts_.begin(), starts_.end(), row) - starts_.begin()) - 1;
}

void FreeBlockSolver::for_each_part(const std::function<void(int)>& task) const {
  const int count = static_cast<int>(parts_.size());
  run_each(matrix_.rows() >= kParallelRows ? parallel_ : ParallelFor(), count, task);
}

bool FreeBlockSolver::factorize_parts(double near_symmetric_tolerance) {
  const int largest = static_cast<int>(matrix_.rows());
  if (static_cast<int>(identity_.size()) < largest) {
    identity_.resize(largest);
    for (int k = 0; k < largest; ++k) identity_[k] = k;
  }
  std::vector<char> ok(parts_.size(), 0);
  for_each_part([&](int b) {  // each body's block, column by column (no entry lies outside them)
    TangentSink& part = parts_[b]->assemble(identity_, starts_[b + 1] - starts_[b]);
    for (int col = starts_[b]; col < starts_[b + 1]; ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(matrix_, col); it; ++it)
        part.add(static_cast<int>(it.row()) - starts_[b], col - starts_[b], it.value());
    ok[b] = parts_[b]->factorize(near_symmetric_tolerance);
  });
  ok_ = std::all_of(ok.begin(), ok.end(), [](char c) { return c != 0; });
  symmetric_ = ok_;
  for (const auto& part : parts_) symmetric_ = symmetric_ && part->symmetric();
  return ok_;
}

Vector FreeBlockSolver::solve(const Vector& b) const {
  if (!split_)
    return symmetric_ ? Vector(order_.transpose() * Vector(llt_.solve(Vector(order_ * b)))) : Vector(lu_.solve(b));
  Vector x(b.size());
  for_each_part([&](int k) {
    const int s = starts_[k], n = starts_[k + 1] - s;
    x.segment(s, n) = parts_[k]->solve(Vector(b.segment(s, n)));
  });
  return x;
}

void FreeBlockSolver::solve_into(const Vector& b, Vector& x) const {
  if (split_ || !symmetric_) {
    x = solve(b);
    return;
  }
  // order_ * b, the solve, order_^T * x: solve()'s permutations, entry by entry.
  const int n = static_cast<int>(b.size());
  const int* position = order_.indices().data();
  permuted_.resize(n);
  for (int i = 0; i < n; ++i) permuted_[position[i]] = b[i];
  x.resize(n);
  double* y = permuted_.data();
  if (!llt_.solve_kept(y, y)) {
    x.setConstant(std::numeric_limits<double>::quiet_NaN());
    return;
  }
  for (int i = 0; i < n; ++i) x[i] = y[position[i]];
}

Matrix FreeBlockSolver::solve(const Matrix& b) const {
  if (!split_)
    return symmetric_ ? Matrix(order_.transpose() * Matrix(llt_.solve(Matrix(order_ * b)))) : Matrix(lu_.solve(b));
  Matrix x(b.rows(), b.cols());
  for_each_part([&](int k) {
    const int s = starts_[k], n = starts_[k + 1] - s;
    x.middleRows(s, n) = parts_[k]->solve(Matrix(b.middleRows(s, n)));
  });
  return x;
}

}  // namespace grip
