// grip_kernels_bench: what a Newton iteration costs beside one numeric factorization of the
// stiffness (issue 39; bench/results/kernels.md). For a scene file: the whole solve's CPU
// seconds over its Newton iterations, and, at the reference state, the median CPU time of the
// body's internal force with its tangent assembled into the free block as Newton does it (the
// element kernels and the entries added into the block's values) and of one numeric
// factorization of the assembled block (FreeBlockSolver::factorize, pattern and ordering already
// analysed: the ordered triangle's gather, the symmetry check and CHOLMOD's numeric factorization).
// With --orderings, the same block's factorization under each fill-reducing order (CHOLMOD's
// AMD, METIS, its nested dissection; a band order by reverse Cuthill-McKee), simplicial and
// supernodal: nnz(L), flops and the median CPU time of CHOLMOD's numeric factorization.
// CPU time of this process (one thread), which the load of other work inflates least.
//   build/tests/bench/grip_kernels_bench SCENE.json [repeats, default 20] [--orderings]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "solver/equilibrium/free_block_solver.hpp"
#include "solver/io/scene.hpp"
#include "solver/stepping/load_stepping.hpp"

namespace {

double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

template <class F>
double median_cpu_ms(int repeats, F&& f) {
  std::vector<double> ms;
  for (int k = 0; k < repeats; ++k) {
    const double start = cpu_seconds();
    f();
    ms.push_back(1e3 * (cpu_seconds() - start));
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

// Reverse Cuthill-McKee on the pattern of a symmetric matrix: breadth first from a far end
// (the last node reached from a node of least degree), neighbours by increasing degree; a
// band order, the natural one for a thin strip. Returns new -> old.
std::vector<int> reverse_cuthill_mckee(const Eigen::SparseMatrix<double>& a) {
  const int n = static_cast<int>(a.rows());
  const auto degree = [&](int j) { return a.outerIndexPtr()[j + 1] - a.outerIndexPtr()[j]; };
  const auto breadth_first = [&](int start) {
    std::vector<int> order, seen(n, 0), next;
    order.push_back(start);
    seen[start] = 1;
    for (size_t k = 0; k < order.size(); ++k) {
      next.clear();
      for (Eigen::SparseMatrix<double>::InnerIterator it(a, order[k]); it; ++it)
        if (!seen[it.row()]) {
          seen[it.row()] = 1;
          next.push_back(static_cast<int>(it.row()));
        }
      std::sort(next.begin(), next.end(), [&](int x, int y) { return degree(x) < degree(y); });
      order.insert(order.end(), next.begin(), next.end());
    }
    return order;
  };
  int start = 0;
  for (int j = 1; j < n; ++j)
    if (degree(j) < degree(start)) start = j;
  std::vector<int> order = breadth_first(breadth_first(start).back());
  std::reverse(order.begin(), order.end());
  return order;
}

// Each order's factorization as FreeBlockSolver does it: the block permuted beforehand, CHOLMOD
// handed the triangle it reads as it is (no transpose at each factorization).
void report_orderings(const Eigen::SparseMatrix<double>& block, int repeats) {
  const int n = static_cast<int>(block.rows());
  using Permutation = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>;
  const auto cholmod_order = [&](int ordering) {
    grip::CholmodFactor probe;
    probe.cholmod().nmethods = 1;
    probe.cholmod().method[0].ordering = ordering;
    probe.analyzePattern(block);
    const int* perm = static_cast<const int*>(probe.factor()->Perm);
    Permutation p(n);
    for (int k = 0; k < n; ++k) p.indices()[perm[k]] = k;
    return p;
  };
  Permutation band(n);
  const std::vector<int> rcm = reverse_cuthill_mckee(block);
  for (int k = 0; k < n; ++k) band.indices()[rcm[k]] = k;
  const std::pair<const char*, Permutation> orders[] = {{"amd", cholmod_order(CHOLMOD_AMD)},
                                                        {"metis", cholmod_order(CHOLMOD_METIS)},
                                                        {"nesdis", cholmod_order(CHOLMOD_NESDIS)},
                                                        {"rcm band", band}};
  for (const auto& [name, order] : orders) {
    Eigen::SparseMatrix<double> permuted;
    permuted = block.twistedBy(order);
    for (const int supernodal : {CHOLMOD_SIMPLICIAL, CHOLMOD_SUPERNODAL}) {
      const int stype = supernodal == CHOLMOD_SUPERNODAL ? -1 : 1;  // the triangle each reads as it is
      Eigen::SparseMatrix<double> triangle;
      if (stype > 0) triangle = permuted.triangularView<Eigen::Upper>();
      else triangle = permuted.triangularView<Eigen::Lower>();
      grip::CholmodFactor f;
      f.cholmod().supernodal = supernodal;
      f.cholmod().final_ll = 1;
      f.analyze_ordered(triangle, stype);
      const double lnz = f.cholmod().lnz, flops = f.cholmod().fl;
      const double ms = median_cpu_ms(repeats, [&] { f.factorize_ordered(triangle, stype); });
      std::printf(
          "{\"ordering\": \"%s\", \"supernodal\": %s, \"ok\": %s, \"nnz_l\": %.0f, \"flops\": %.4g, "
          "\"factorize_ms\": %.4f}\n",
          name, supernodal == CHOLMOD_SUPERNODAL ? "true" : "false", f.info() == Eigen::Success ? "true" : "false", lnz,
          flops, ms);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: grip_kernels_bench SCENE.json [repeats] [--orderings]\n");
    return 2;
  }
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 20;
  grip::Scene scene = grip::read_scene_file(argv[1]);
  const grip::Problem& problem = scene.problem;
  const grip::Body& body = *problem.body;
  const int n = body.dof_count();
  std::vector<int> free_index(n, 0);
  for (const grip::Constraint& c : problem.constraints) free_index[c.dof] = -1;
  int free_count = 0;
  for (int& f : free_index)
    if (f == 0) f = free_count++;
  const grip::Vector q = grip::Vector::Zero(n);
  const grip::Vector scales = body.dof_length_scales();
  grip::Vector force(n);
  grip::FreeBlockSolver solver;
  const auto assemble = [&] {
    force.setZero();
    body.internal_force(q, force, &solver.assemble(free_index, free_count, &scales));
    solver.row_sum_norm();  // Newton's round-off scale, taken at most iterations
  };
  assemble();  // integration points; the pattern
  if (!solver.factorize()) std::fprintf(stderr, "singular reference stiffness\n");
  const double assemble_ms = median_cpu_ms(repeats, assemble);
  const double factorize_ms = median_cpu_ms(repeats, [&] { solver.factorize(); });
  if (argc > 3 && std::strcmp(argv[3], "--orderings") == 0) report_orderings(solver.matrix(), repeats);
  const double start = cpu_seconds();
  const grip::RunResult run = grip::run_load_steps(scene.problem, scene.steps, scene.params);
  const double run_s = cpu_seconds() - start;
  const grip::EquilibriumCounters& c = run.counters;
  std::printf(
      "{\"dofs\": %d, \"free\": %d, \"block_entries\": %ld, \"assemble_ms\": %.4f, \"factorize_ms\": %.4f, "
      "\"solve_cpu_s\": %.4f, \"completed\": %s, \"real_solves\": %ld, \"newton_iterations\": %ld, "
      "\"factorizations\": %ld, \"newton_factorizations\": %ld, \"body_factorizations\": %ld, "
      "\"dissected_factorizations\": %ld, \"ms_per_newton_iteration\": %.4f}\n",
      n, free_count, static_cast<long>(solver.matrix().nonZeros()), assemble_ms, factorize_ms, run_s,
      run.completed ? "true" : "false", c.solves, c.newton_iterations, c.factorizations, c.newton_factorizations,
      c.body_factorizations, c.dissected_factorizations, c.newton_iterations ? 1e3 * run_s / c.newton_iterations : 0.0);
}
