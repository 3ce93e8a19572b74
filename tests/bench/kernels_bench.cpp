// grip_kernels_bench: what a Newton iteration costs beside one numeric factorization of the
// stiffness (issue 39; bench/results/kernels.md). For a scene file: the whole solve's CPU
// seconds over its Newton iterations, the CPU seconds inside Newton's solves alone (their
// residuals, tangents, factorizations, solves and line searches, chord-ended solves included)
// over the same iterations and inside the compliance's forms, and, at the reference state, the median CPU time of the
// body's internal force with its tangent assembled into the free block as Newton does it (the
// element kernels and the entries added into the block's values) and of one numeric
// factorization of the assembled block (FreeBlockSolver::factorize, pattern and ordering already
// analysed: the ordered triangle's gather, the symmetry check and CHOLMOD's numeric factorization).
// With --orderings, the same block's factorization under each fill-reducing order (CHOLMOD's
// AMD, METIS, its nested dissection; a band order by reverse Cuthill-McKee), simplicial and
// supernodal: nnz(L), flops and the median CPU time of CHOLMOD's numeric factorization.
// CPU time of this process (one thread), which the load of other work inflates least. With
// --threads N (N > 1) the element kernels and the solve run on a team of N threads as `grip
// solve --threads N` runs them, and the wall medians of the assembly (with the tangent, and the
// force alone: the line search's residual) are what to compare with one thread.
// --no-solve leaves the whole solve out (the per-call medians only).
//   build/tests/bench/grip_kernels_bench SCENE.json [repeats, default 20] [--orderings] [--threads N] [--no-solve]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "apps/process_tuning.hpp"
#include "apps/thread_team.hpp"
#include "solver/elements/continuum.hpp"
#include "solver/equilibrium/free_block_solver.hpp"
#include "solver/io/scene.hpp"
#include "solver/stepping/load_stepping.hpp"

namespace {

double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The median and the least of `repeats` timings: under other sessions' load the least is when
// every thread had a core.
template <class F>
std::pair<double, double> median_min_ms(int repeats, double (*clock)(), F&& f) {
  std::vector<double> ms;
  for (int k = 0; k < repeats; ++k) {
    const double start = clock();
    f();
    ms.push_back(1e3 * (clock() - start));
  }
  std::sort(ms.begin(), ms.end());
  return {ms[ms.size() / 2], ms.front()};
}

template <class F>
double median_ms(int repeats, double (*clock)(), F&& f) {
  return median_min_ms(repeats, clock, f).first;
}

// The element kernels alone: their tangent blocks handed to nothing.
class DiscardSink final : public grip::TangentSink {
 public:
  void add(int, int, double) override {}
  void add_block(const int*, const grip::Matrix&) override {}
};

template <class F>
double median_cpu_ms(int repeats, F&& f) {
  return median_ms(repeats, cpu_seconds, f);
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
  // As grip solve runs (apps/grip.cpp): without it CHOLMOD's OpenMP team spins beside the
  // solve, CPU time that this process's clock counts (the 50 x 2 strip: 0.29 s against 0.14 s).
  grip::tune_process();
  grip::heap_on_huge_pages();
  std::vector<std::string> args(argv + 1, argv + argc);
  int threads = 1;
  bool orderings = false, no_solve = false;
  for (size_t k = 0; k < args.size(); ++k)
    if (args[k] == "--threads" && k + 1 < args.size()) {
      threads = std::max(1, std::atoi(args[k + 1].c_str()));
      args.erase(args.begin() + static_cast<long>(k), args.begin() + static_cast<long>(k) + 2);
      --k;
    } else if (args[k] == "--orderings" || args[k] == "--no-solve") {
      (args[k] == "--orderings" ? orderings : no_solve) = true;
      args.erase(args.begin() + static_cast<long>(k--));
    }
  if (args.empty()) {
    std::fprintf(stderr, "usage: grip_kernels_bench SCENE.json [repeats] [--orderings] [--threads N] [--no-solve]\n");
    return 2;
  }
  const int repeats = args.size() > 1 ? std::max(1, std::atoi(args[1].c_str())) : 20;
  grip::Scene scene = grip::read_scene_file(args[0]);
  if (threads > 1) {  // as grip solve --threads N
    auto team = std::make_shared<grip::ThreadTeam>(threads);
    scene.params.newton.parallel = [team](int count, const std::function<void(int)>& task) { team->run(count, task); };
    grip::assemble_on(*scene.problem.body, scene.params.newton.parallel);
  }
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
  const auto [assemble_wall_ms, assemble_wall_min_ms] = median_min_ms(repeats, wall_seconds, assemble);
  DiscardSink discard;
  const auto kernels = [&] {
    force.setZero();
    body.internal_force(q, force, &discard);
  };
  const auto [kernels_wall_ms, kernels_wall_min_ms] = median_min_ms(repeats, wall_seconds, kernels);
  const auto force_only = [&] {
    force.setZero();
    body.internal_force(q, force, nullptr);
  };
  const double force_ms = median_cpu_ms(repeats, force_only);
  const auto [force_wall_ms, force_wall_min_ms] = median_min_ms(repeats, wall_seconds, force_only);
  const double factorize_ms = median_cpu_ms(repeats, [&] { solver.factorize(); });
  if (orderings) report_orderings(solver.matrix(), repeats);
  std::printf(
      "{\"threads\": %d, \"dofs\": %d, \"free\": %d, \"block_entries\": %ld, \"assemble_ms\": %.4f, "
      "\"assemble_wall_ms\": %.4f, \"assemble_wall_min_ms\": %.4f, \"kernels_wall_ms\": %.4f, "
      "\"kernels_wall_min_ms\": %.4f, \"force_ms\": %.4f, \"force_wall_ms\": %.4f, \"force_wall_min_ms\": %.4f, "
      "\"factorize_ms\": %.4f",
      threads, n, free_count, static_cast<long>(solver.matrix().nonZeros()), assemble_ms, assemble_wall_ms,
      assemble_wall_min_ms, kernels_wall_ms, kernels_wall_min_ms, force_ms, force_wall_ms, force_wall_min_ms,
      factorize_ms);
  if (no_solve) {
    std::printf("}\n");
    return 0;
  }
  const double start = cpu_seconds(), wall_start = wall_seconds();
  const grip::RunResult run = grip::run_load_steps(scene.problem, scene.steps, scene.params);
  const double run_s = cpu_seconds() - start, run_wall_s = wall_seconds() - wall_start;
  const grip::EquilibriumCounters& c = run.counters;
  std::printf(
      ", \"solve_cpu_s\": %.4f, \"solve_wall_s\": %.4f, \"completed\": %s, \"real_solves\": %ld, "
      "\"newton_iterations\": %ld, \"factorizations\": %ld, \"newton_factorizations\": %ld, "
      "\"body_factorizations\": %ld, \"dissected_factorizations\": %ld, \"ms_per_newton_iteration\": %.4f, "
      "\"newton_cpu_s\": %.4f, \"newton_own_ms_per_iteration\": %.4f, \"compliance_cpu_s\": %.4f, "
      "\"newton_analyses\": %ld, \"body_analyses\": %ld}\n",
      run_s, run_wall_s, run.completed ? "true" : "false", c.solves, c.newton_iterations, c.factorizations,
      c.newton_factorizations, c.body_factorizations, c.dissected_factorizations,
      c.newton_iterations ? 1e3 * run_s / c.newton_iterations : 0.0, c.newton_cpu_s,
      c.newton_iterations ? 1e3 * c.newton_cpu_s / c.newton_iterations : 0.0, c.compliance_cpu_s, c.newton_analyses,
      c.body_analyses);
}
