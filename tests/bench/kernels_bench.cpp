// grip_kernels_bench: what a Newton iteration costs beside one numeric factorization of the
// stiffness (issue 39; bench/results/kernels.md). For a scene file: the whole solve's CPU
// seconds over its Newton iterations, and, at the reference state, the median CPU time of the
// body's internal force with its tangent (the element kernels and the triplets) and of one
// numeric factorization of the free block (FreeBlockSolver::factorize, pattern and ordering
// already analysed: the scatter of the triplets and CHOLMOD's numeric factorization).
// CPU time of this process (one thread), which the load of other work inflates least.
//   build/tests/bench/grip_kernels_bench SCENE.json [repeats, default 20]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
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

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: grip_kernels_bench SCENE.json [repeats]\n");
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
  grip::Vector force(n);
  grip::Triplets triplets;
  const auto assemble = [&] {
    triplets.clear();
    force.setZero();
    body.internal_force(q, force, &triplets);
  };
  assemble();  // integration points, first allocation of the triplets
  const double assemble_ms = median_cpu_ms(repeats, assemble);
  grip::FreeBlockSolver solver;
  if (!solver.factorize(triplets, free_index, free_count)) std::fprintf(stderr, "singular reference stiffness\n");
  const double factorize_ms = median_cpu_ms(repeats, [&] { solver.factorize(triplets, free_index, free_count); });
  const double start = cpu_seconds();
  const grip::RunResult run = grip::run_load_steps(scene.problem, scene.steps, scene.params);
  const double run_s = cpu_seconds() - start;
  const grip::EquilibriumCounters& c = run.counters;
  std::printf(
      "{\"dofs\": %d, \"free\": %d, \"triplets\": %zu, \"assemble_ms\": %.4f, \"factorize_ms\": %.4f, "
      "\"solve_cpu_s\": %.4f, \"completed\": %s, \"real_solves\": %ld, \"newton_iterations\": %ld, "
      "\"factorizations\": %ld, \"newton_factorizations\": %ld, \"body_factorizations\": %ld, "
      "\"dissected_factorizations\": %ld, \"ms_per_newton_iteration\": %.4f}\n",
      n, free_count, triplets.size(), assemble_ms, factorize_ms, run_s, run.completed ? "true" : "false", c.solves,
      c.newton_iterations, c.factorizations, c.newton_factorizations, c.body_factorizations, c.dissected_factorizations,
      c.newton_iterations ? 1e3 * run_s / c.newton_iterations : 0.0);
}
