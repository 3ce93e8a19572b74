// The free block assembled in place (FreeBlockSolver::assemble): element blocks and single
// entries added straight into the values of a pattern kept from the last assembly, a sequence
// that departs from it recorded from there; the block, its factorization and |K|_inf must be
// those of the same entries summed densely, whatever the assembly departed at.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "solver/equilibrium/free_block_solver.hpp"

namespace grip {
namespace {

// A chain of 3-dof elements (dofs 2e .. 2e + 2) over 2 * elements + 1 dofs, each block SPD,
// then (with springs) single entries, a spring at every `spring_every`-th dof, scaled by
// `scale`; dof 0 is prescribed. The entries emitted, in order, also as (row, col, value).
struct Chain {
  int elements = 6, spring_every = 3;
  bool springs = true;
  double scale = 1.0;
  int dofs() const { return 2 * elements + 1; }
  void emit(TangentSink& sink, Triplets& seen) const {
    for (int e = 0; e < elements; ++e) {
      const int d[3] = {2 * e, 2 * e + 1, 2 * e + 2};
      Matrix k(3, 3);
      k << 4, -1, -2, -1, 3, -1, -2, -1, 5;
      k *= scale * (1.0 + 0.1 * e);
      sink.add_block(d, k);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) seen.emplace_back(d[i], d[j], k(i, j));
    }
    for (int d = 0; springs && d < dofs(); d += spring_every) {
      sink.add(d, d, 0.5 * scale);
      seen.emplace_back(d, d, 0.5 * scale);
    }
  }
};

struct Free {
  std::vector<int> index;
  int count = 0;
  explicit Free(int dofs) : index(dofs) {
    for (int d = 0; d < dofs; ++d) index[d] = d == 0 ? -1 : count++;
  }
};

// The free block of the entries, summed densely.
Matrix dense_block(const Triplets& seen, const Free& free) {
  Matrix k = Matrix::Zero(free.count, free.count);
  for (const auto& t : seen)
    if (free.index[t.row()] >= 0 && free.index[t.col()] >= 0) k(free.index[t.row()], free.index[t.col()]) += t.value();
  return k;
}

// Assembles `chain` into `solver`, factorizes it and checks the block and a solve against the
// dense sum.
void assemble_and_check(FreeBlockSolver& solver, const Chain& chain) {
  const Free free(chain.dofs());
  Triplets seen;
  chain.emit(solver.assemble(free.index, free.count), seen);
  ASSERT_TRUE(solver.factorize());
  const Matrix expected = dense_block(seen, free);
  EXPECT_EQ((Matrix(solver.matrix().toDense()) - expected).cwiseAbs().maxCoeff(), 0.0);
  const Vector b = Vector::LinSpaced(free.count, 1.0, 2.0);
  const Vector x = solver.solve(b), exact = expected.ldlt().solve(b);
  EXPECT_LT((x - exact).norm(), 1e-13 * exact.norm());
}

TEST(BlockAssembly, InPlaceAssemblyIsTheDenseSumWhereverTheSequenceDeparts) {
  FreeBlockSolver solver;
  Chain chain;
  assemble_and_check(solver, chain);  // no pattern yet: recorded, pattern built
  chain.scale = 2.0;
  assemble_and_check(solver, chain);  // the pattern's sequence: straight into the values
  chain.spring_every = 2;             // departs after the elements: other single entries
  assemble_and_check(solver, chain);
  chain.springs = false;  // ends early: the pattern's tail dropped
  assemble_and_check(solver, chain);
  chain.springs = true;
  chain.elements = 7;  // departs after the sixth element: the first six keep their sums
  assemble_and_check(solver, chain);
  chain.elements = 4;  // departs at the fifth piece (a spring where an element was)
  assemble_and_check(solver, chain);
  EXPECT_EQ(solver.matrix().rows(), 8);
  EXPECT_EQ(solver.factorizations(), 6);
}

TEST(BlockAssembly, RowSumNormSumsTheEntriesMagnitudesAsEmitted) {
  Chain chain;
  const Free free(chain.dofs());
  Vector scales = Vector::Ones(chain.dofs());
  for (int d = 1; d < chain.dofs(); d += 2) scales[d] = 0.25;  // every other dof a rotation
  FreeBlockSolver solver;
  for (int pass = 0; pass < 2; ++pass) {  // recorded, then in place
    Triplets seen;
    chain.emit(solver.assemble(free.index, free.count, &scales), seen);
    Vector rows = Vector::Zero(free.count);
    for (const auto& t : seen)
      if (free.index[t.row()] >= 0 && free.index[t.col()] >= 0)
        rows[free.index[t.row()]] += std::abs(t.value()) / (scales[t.row()] * scales[t.col()]);
    EXPECT_EQ(solver.row_sum_norm(), rows.maxCoeff());
    EXPECT_GT(solver.row_sum_norm(), 16.0 * 4.0);  // a rotation row: 1 / 0.25^2 on its diagonal
    ASSERT_TRUE(solver.factorize());
  }
}

}  // namespace
}  // namespace grip
