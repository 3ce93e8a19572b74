#pragma once
// Assembles and factorizes the free-dof block of a tangent. The assembly loops emit the same
// entries in the same order at every call (contact terms are emitted even when zero), so the
// block's pattern, where each emitted entry lands in its values and the symbolic analysis are
// computed once, and each assembly adds the entries straight into the values: no triplets, no
// sort. A sequence that departs from the pattern's (a contact candidate added, the free set
// changed) is recorded from there and the pattern built afresh.
// A symmetric positive definite block (the body's own tangent; Newton's without friction on
// curved tools) is factorized by CHOLMOD's Cholesky (simplicial or supernodal, as CHOLMOD
// chooses) in a fill-reducing order fixed once per pattern, many times cheaper than the LU that
// an unsymmetric (or indefinite) one needs.
#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <functional>
#include <memory>
#include <vector>

#include "solver/model/body.hpp"
#include "solver/model/parallel.hpp"
#include "solver/model/tangent_sink.hpp"

namespace grip {

// CHOLMOD's supernodal L L^T, with its reciprocal condition estimate (min/max of diag(L))^2.
class CholmodFactor : public Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> {
 public:
  CholmodFactor();  // quiet: a non-SPD block is a result, not a message
  ~CholmodFactor();
  CholmodFactor(const CholmodFactor&) = delete;
  CholmodFactor& operator=(const CholmodFactor&) = delete;
  double rcond() { return m_cholmodFactor ? cholmod_rcond(m_cholmodFactor, &cholmod()) : 0.0; }
  const cholmod_factor* factor() const { return m_cholmodFactor; }
  // A block already in its fill-reducing order, given as the one triangle (stype +1: upper,
  // -1: lower, in column form) that CHOLMOD's numeric factorization reads as it is: the upper
  // for the simplicial one, the lower for the supernodal one. In any other form CHOLMOD
  // permutes and transposes the block at every factorization (cholmod_transpose_sym).
  void analyze_ordered(const Eigen::SparseMatrix<double>& triangle, int stype);
  // With `parallel`, a simplicial factor's rows in two groups of independent subtrees of the
  // elimination tree at once, then the rows above them: the same arithmetic row by row, so the
  // same factor to the last bit (planned once per analysis, from the first factor's pattern).
  void factorize_ordered(const Eigen::SparseMatrix<double>& triangle, int stype, const ParallelFor& parallel = {});
  // The last factorization took its rows in two groups at once.
  bool rows_split() const { return rows_split_; }
  // K^-1 on the given rows, |rows|^2, as W^T W with W = L^-1 P E: each column of W is a sparse
  // forward solve that touches only the elimination-tree path of its row (CHOLMOD's partial
  // solve, on a simplicial copy of the factor), where a dense solve costs 2 nnz(L) flops per
  // row. False where CHOLMOD fails. W^T W's sums run through `parallel` for many rows.
  bool inverse_block(const std::vector<int>& rows, Matrix& G, const ParallelFor& parallel = {});
  // t_j^T K^-1 t_j = |L^-1 P t_j|^2 for every column of t (free dofs x columns), by partial
  // forward solves. False where CHOLMOD fails, or (with `max_mean_reach` > 0) where the first
  // columns' solves reach more than that many rows on average (long elimination-tree paths).
  bool quadratic_forms(const Eigen::SparseMatrix<double>& t, Vector& out, double max_mean_reach);
  // x = A^-1 b (n values each, b already in the factor's order) by cholmod_solve2 with the
  // solution and workspace kept from call to call: no allocation once sized. The same
  // arithmetic as solve() (cholmod_solve is cholmod_solve2 with workspace of its own). False
  // where CHOLMOD fails.
  bool solve_kept(const double* b, double* x) const;

 private:
  mutable cholmod_dense *solve_x_ = nullptr, *solve_y_ = nullptr, *solve_e_ = nullptr;
  struct Subtrees;  // the rows' split for two threads, and the second thread's CHOLMOD workspace
  std::unique_ptr<Subtrees> subtrees_;
  bool rows_split_ = false;
  bool factorize_subtrees(cholmod_sparse& A, const ParallelFor& parallel);
  // x = L^-1 P b for each sparse column b of `columns` (free dofs), on a simplicial copy of the
  // factor: `use(column, rows of x, values of x, count)` sees each; false from it stops.
  bool forward_solves(const Eigen::SparseMatrix<double>& columns,
                      const std::function<bool(int, const int*, const double*, int)>& use);
  // inverse_block's W = L^-1 P E by columns, then by rows (row k's entries from row_start[k]),
  // kept from call to call: G is formed afresh at every real solve on a curved obstacle.
  // G's sums in tasks of equal work from this many rows on (a thread's start is tens of
  // microseconds; G over 64 rows is a few).
  static constexpr int kParallelColumns = 64, kSumTasks = 4;
  struct SolvedColumns {
    std::vector<int> column_start, column_rows, row_start, next, row_columns;
    std::vector<double> column_values, row_values;
  } w_;
};

class FreeBlockSolver {
 public:
  // Starts an assembly of the block: the sink takes the tangent's entries by dof (free_index:
  // dof -> row of the free block, -1 for a prescribed dof, whose entries are dropped). With
  // `length_scales` (by dof), row_sum_norm() measures what was assembled.
  TangentSink& assemble(const std::vector<int>& free_index, int free_count, const Vector* length_scales = nullptr);
  // Factorizes what was assembled. Returns false if the block is singular.
  // near_symmetric_tolerance > 0: a block whose skew part is below that fraction of its
  // largest entry is symmetrized (Newton's tangent with friction on a curved tool: the
  // residual stays exact, so Newton still converges, and LDL^T serves).
  bool factorize(double near_symmetric_tolerance = 0.0);
  // The triplets assembled, then factorized.
  bool factorize(const Triplets& triplets, const std::vector<int>& free_index, int free_count,
                 double near_symmetric_tolerance = 0.0);
  // |K|_inf of the last assembly in force / length units (each entry over the length scales of
  // its row's and column's dofs), the entries' magnitudes summed as they were emitted (the
  // element by element sums that round-off in the residual comes from); 0 without length_scales.
  double row_sum_norm();
  // Several bodies: free rows [starts[b], starts[b + 1]) are body b's (starts ends with the free
  // count). Where the block has no entry between two bodies (the bodies' own tangent; Newton's
  // where bodies meet rigid tools only, or where a pair's stiffness enters as a low-rank
  // correction), each body's block is factorized and solved on its own, the bodies' tasks run
  // through `parallel` (the solver starts no threads). Else one factorization of the whole.
  void set_blocks(std::vector<int> starts, ParallelFor parallel);
  // One body: `parallel` serves the factorization's independent subtrees (factorize_ordered).
  void set_parallel(ParallelFor parallel) { parallel_ = std::move(parallel); }
  Vector solve(const Vector& b) const;
  Matrix solve(const Matrix& b) const;
  // solve(b) into x, with no allocation once x and the solver's work storage are sized where the
  // block is one Cholesky factor (Newton's loop); the same values bit for bit. A split block or
  // an LU factorization goes through solve(b).
  void solve_into(const Vector& b, Vector& x) const;
  // K^-1 on the given rows where K is Cholesky-factorized (CholmodFactor::inverse_block);
  // false otherwise (then solve() for unit right-hand sides). Where the factor's own ordering
  // gives the rows long elimination-tree paths (thin strips: a fill-reducing ordering there is
  // nearly banded), a second factorization in nested-dissection order, for G only: analysed
  // once per pattern, and not tried again for as many rows or more once it did not pay (a
  // beam's or a membrane's band: its analysis and factorization were 21 % of the beam's time).
  // Where it paid, the block's own later factorizations (a changing tangent's) take that order,
  // and G comes from them without a second one.
  bool inverse_block(const std::vector<int>& rows, Matrix& G, const ParallelFor& parallel = {});
  // t_j^T K^-1 t_j for every column of t (free dofs x columns) where K is Cholesky-factorized
  // (partial forward solves; on a nested-dissection factorization where the body's own gives
  // long elimination-tree paths, as for G); an empty vector otherwise.
  Vector quadratic_forms(const Eigen::SparseMatrix<double>& t);
  bool ok() const { return ok_; }
  // Numeric factorizations so far: of the block (one per factorize(), a split block's parts
  // together), and the second ones in nested-dissection order that serve G or C's diagonal only.
  long factorizations() const { return factorizations_; }
  long dissected_factorizations() const;
  // Symbolic analyses so far, a split block's parts together: the ordered block's (one per
  // pattern, and one more where its order turns to nested dissection), SparseLU's, and those of
  // the nested-dissection factor for G.
  long analyses() const;
  // Factorized body by body (set_blocks).
  bool split() const { return split_; }
  // One Cholesky factor whose rows were taken in two groups at once (set_parallel).
  bool rows_split() const { return ok_ && symmetric_ && !split_ && llt_.rows_split(); }
  // Factorized by Cholesky (symmetric positive definite).
  bool symmetric() const { return ok_ && symmetric_; }
  // The free block as factorized (both triangles).
  const Eigen::SparseMatrix<double>& matrix() const { return matrix_; }
  // The next factorize() builds its pattern afresh (the free set changed).
  void forget_pattern() {
    pieces_.clear();
    dofs_.clear();
    slots_.clear();
    pair_slots_.clear();
    ok_ = false;
    dissected_analysed_ = false;
    dissected_fails_at_ = 0;
    llt_dissected_ = false;
    for (auto& part : parts_) part->forget_pattern();
  }

 private:
  // The bodies' blocks: factorizes each diagonal block of matrix_ on its own (split_), or
  // leaves split_ false where an entry couples two bodies.
  bool factorize_parts(double near_symmetric_tolerance);
  // The assembly's sink: entries into matrix_'s values through slots_ while they follow the
  // pattern's pieces, recorded from the first that does not.
  class Assembly final : public TangentSink {
   public:
    explicit Assembly(FreeBlockSolver& owner) : owner_(owner) {}
    void add(int row, int col, double value) override;
    void add_block(const int* dofs, const Matrix& block) override;

   private:
    FreeBlockSolver& owner_;
  };
  friend class Assembly;
  // An element's block (size m: m dofs, m x m slots row by row) or one entry (size 0: its row
  // and column in dofs_, one slot), in the order emitted.
  // pairs: where every slot of a block is taken (a free row and column), each row pair (2a,
  // 2a + 1) lands on two adjacent values in every column (a node's two dofs) and no two entries
  // share a slot, the index in pair_slots_ of its column-major list of slot(2a, j); else -1.
  struct Piece {
    int size, dofs, slots, pairs = -1;
  };
  // Where the assembly departs from the pattern: the pieces matched so far stay, the rest is
  // recorded.
  void depart();
  void record(int size, const int* dofs, const double* values);
  // |entries| over their length scales into row_sums_ (entries at free rows and columns).
  void add_magnitudes(int size, const int* dofs, const double* values);
  // Completes the assembly: a departed one gets its new pattern (build_pattern) and values.
  void finish_assembly();
  // matrix_'s new pattern from the pieces, slots_, the mirrors, and what depends on them.
  void build_pattern();
  // symmetric_ from the skew part of matrix_ against its largest entry; a near-symmetric
  // matrix_ averaged with its transpose.
  void check_symmetry(double near_symmetric_tolerance);
  int block_of(int row) const;
  // Once per pattern: the fill-reducing order of matrix_ (CHOLMOD's choice, or nested
  // dissection once it paid for G), the triangle of the ordered block that llt_ factorizes and
  // where each of its entries comes from in matrix_; then llt_'s analysis of it.
  void analyse_ordered();
  // The bodies' tasks: through parallel_ where a thread's start (tens of microseconds) is
  // small beside the work (kParallelRows free rows or more), else one after another.
  void for_each_part(const std::function<void(int)>& task) const;
  static constexpr int kParallelRows = 2000;
  static constexpr double kSeparatedFlops = 1.05;  // a separated order's flops over the block's own order's
  std::vector<int> starts_;                        // body b's free rows begin at starts_[b]; empty: one body
  ParallelFor parallel_;
  std::vector<std::unique_ptr<FreeBlockSolver>> parts_;
  std::vector<int> identity_;  // dof -> row for the parts (their triplets are in local rows)
  bool coupled_ = true;        // the pattern has entries between bodies
  bool split_ = false;
  Eigen::SparseMatrix<double> matrix_;
  // The pattern's sequence of pieces, their dofs, and each entry's index in matrix_'s values
  // (-1: dropped, a prescribed row or column).
  std::vector<Piece> pieces_;
  std::vector<int> dofs_, slots_, pair_slots_;
  static constexpr int kMaxPairedBlock = 32;  // the largest block taken by pairs
  // The assembly under way: the next piece expected, whether every one so far followed the
  // pattern, and from where not, the pieces recorded (slots: index in recorded_values_).
  Assembly assembly_{*this};
  size_t next_piece_ = 0, matched_ = 0;
  bool following_ = false, finished_ = true;
  std::vector<Piece> recorded_;
  std::vector<int> recorded_dofs_;
  std::vector<double> recorded_values_;
  const std::vector<int>* free_index_ = nullptr;
  int free_count_ = 0;
  const Vector* length_scales_ = nullptr;
  bool unit_scales_ = true;  // every length scale 1: no division
  Vector row_sums_;
  std::vector<int> mirror_;  // value index -> index of its transpose entry
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu_;
  CholmodFactor llt_;  // of ordered_: rows and columns in order_
  // Free row i is row order_.indices()[i] of the ordered block; ordered_ holds the triangle
  // (ordered_stype_) that llt_ reads, its k-th value matrix_'s value gather_[k], whose
  // transpose is matrix_'s value transposed_[k].
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> order_;
  Eigen::SparseMatrix<double> ordered_;
  std::vector<int> gather_, transposed_;
  int ordered_stype_ = 1;
  CholmodFactor dissected_;  // nested-dissection order, for inverse_block only
  bool lu_analysed_ = false, llt_analysed_ = false, dissected_analysed_ = false;
  long factorizations_ = 0, dissected_factorizations_ = 0, analyses_ = 0;
  mutable Vector permuted_;        // solve_into's right-hand side in the factor's order
  size_t dissected_fails_at_ = 0;  // the fewest rows for which the dissected factor did not pay; 0: none yet
  // The dissected factor paid for G on this pattern: the next factorizations take the
  // nested-dissection order themselves, so that G needs no second factorization.
  bool llt_dissected_ = false;
  bool symmetric_ = false;
  bool ok_ = false;
};

}  // namespace grip
