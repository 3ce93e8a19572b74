// Heap allocations inside Newton's loop (issue 39: "no allocation inside the Newton loop").
// This binary replaces the C allocator's entry points (malloc, calloc, realloc and the aligned
// ones) with counting ones that forward to glibc's own (__libc_malloc, ...): operator new,
// Eigen's dense storage and CHOLMOD (SuiteSparse's default malloc) all come through them, in
// the solver and in the shared libraries alike. Newton's probe (solver/equilibrium/
// newton_probe.hpp) records the count at the start of each iteration, so the allocations of
// iteration k are the count at k + 1 less the count at k within one solve (the iteration that
// converges leaves the loop, and what the solve's answer copies is not the loop's).
//
// The finite-strain strip on a cylinder (schemas/examples/strip-on-cylinder.json: q9, Saint
// Venant-Kirchhoff, Newton's tangent one Cholesky factorization per iteration, cev's given
// contact forces), on two meshes: no iteration allocates, the first of a solve included (its
// chord test pairs and solves in kept storage; the solve's own state is paired before the loop),
// except one in which a sparsity pattern is met for the first time (contact candidates added:
// its pattern, symbolic analysis and factor are sized once; the run's first iteration also
// builds the body's integration data). A `Vector tmp(n)` left in the loop fails it (one
// allocation per iteration: measured, see the commit that added this test); so did the chord
// test's and the solve's pairing in a fresh state before they kept their storage (273 and 525
// allocations in each solve's first iteration on the two meshes).
#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "solver/equilibrium/newton_probe.hpp"
#include "solver/io/scene.hpp"
#include "solver/stepping/load_stepping.hpp"

namespace {

std::atomic<long> allocations{0};

}  // namespace

extern "C" {
void* __libc_malloc(size_t size) noexcept;
void* __libc_calloc(size_t count, size_t size) noexcept;
void* __libc_realloc(void* p, size_t size) noexcept;
void* __libc_memalign(size_t alignment, size_t size) noexcept;
void __libc_free(void* p) noexcept;

void* malloc(size_t size) noexcept {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
void* calloc(size_t count, size_t size) noexcept {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(count, size);
}
void* realloc(void* p, size_t size) noexcept {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, size);
}
void* memalign(size_t alignment, size_t size) noexcept {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(size_t alignment, size_t size) noexcept {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, size_t alignment, size_t size) noexcept {
  allocations.fetch_add(1, std::memory_order_relaxed);
  *out = __libc_memalign(alignment, size);
  return *out ? 0 : ENOMEM;
}
void free(void* p) noexcept { __libc_free(p); }
}

namespace {

// The probe's records (iteration, allocations so far), in storage of their own: the probe
// allocates nothing.
struct Record {
  int iteration;
  long analyses;
  long count;
};
constexpr int kRecords = 1 << 16;
Record records[kRecords];
int recorded = 0;

void probe(int iteration, long analyses) {
  if (recorded < kRecords) records[recorded++] = {iteration, analyses, allocations.load(std::memory_order_relaxed)};
}

struct Counts {
  // Iteration windows measured: a solve's first, the later ones, and those (of either) in which a
  // new sparsity pattern was analysed.
  long first_iterations = 0, later_iterations = 0, new_pattern_iterations = 0;
  long first_allocations = 0, later_allocations = 0, worst = 0;
  long newton_iterations = 0, newton_factorizations = 0;
};

// The strip on the cylinder on a q9 mesh of nx x ny, its 20 steps, Newton's iterations counted.
Counts run_strip(int nx, int ny) {
  std::ifstream in(std::string(GRIP_SOURCE_DIR) + "/schemas/examples/strip-on-cylinder.json");
  nlohmann::json j = nlohmann::json::parse(in);
  j["body"]["mesh"]["rectangle"]["divisions"] = {nx, ny};
  grip::Scene scene = grip::read_scene(j);
  recorded = 0;
  grip::newton_iteration_probe = probe;
  const grip::RunResult run = grip::run_load_steps(scene.problem, scene.steps, scene.params);
  grip::newton_iteration_probe = nullptr;
  EXPECT_TRUE(run.completed) << run.reason;
  EXPECT_LT(recorded, kRecords);
  Counts c;
  c.newton_iterations = run.counters.newton_iterations;
  c.newton_factorizations = run.counters.newton_factorizations;
  for (int k = 0; k + 1 < recorded; ++k) {
    if (records[k + 1].iteration != records[k].iteration + 1) continue;  // the next solve
    const long spent = records[k + 1].count - records[k].count;
    if (records[k + 1].analyses != records[k].analyses) {
      ++c.new_pattern_iterations;
      continue;
    }
    c.worst = std::max(c.worst, spent);
    if (records[k].iteration == 1) {
      ++c.first_iterations;
      c.first_allocations += spent;
    } else {
      ++c.later_iterations;
      c.later_allocations += spent;
    }
  }
  std::printf(
      "q9 %d x %d: %ld Newton iterations (%ld factorizations); %ld with a new sparsity pattern (not counted); "
      "%ld first iterations of a solve, %ld allocations; %ld later ones, %ld allocations (at most %ld in one)\n",
      nx, ny, c.newton_iterations, c.newton_factorizations, c.new_pattern_iterations, c.first_iterations,
      c.first_allocations, c.later_iterations, c.later_allocations, c.worst);
  return c;
}

TEST(NewtonAllocations, TheCountingAllocatorSeesEigenAndOperatorNew) {
  const long before = allocations.load();
  {
    grip::Vector v(1000);
    v.setOnes();
    auto* p = new std::vector<int>(100, 1);
    EXPECT_EQ((*p)[99] + static_cast<int>(v.sum()), 1001);
    delete p;
  }
  EXPECT_EQ(allocations.load() - before, 3);  // the Vector's storage, the vector object, its storage
}

// No iteration allocates, a solve's first included, on both meshes (no allocation that grows
// with the mesh, nor a constant one, is left in the loop), but where a new pattern is analysed.
TEST(NewtonAllocations, IterationsAllocateNothingOnTheFiniteStrip) {
  for (const auto& [nx, ny] : {std::pair{50, 2}, std::pair{100, 4}}) {
    const Counts c = run_strip(nx, ny);
    // Enough iterations of both kinds for the assertion to mean something, each with its
    // factorization of Newton's tangent (a changing tangent: finite strain); new patterns are
    // rare (the contact candidates change a few times in the run).
    EXPECT_GE(c.first_iterations, 10) << nx << " x " << ny;
    EXPECT_GE(c.later_iterations, 20) << nx << " x " << ny;
    EXPECT_LE(c.new_pattern_iterations, 12) << nx << " x " << ny;
    EXPECT_GE(c.newton_factorizations, c.later_iterations) << nx << " x " << ny;
    EXPECT_EQ(c.first_allocations, 0) << nx << " x " << ny;
    EXPECT_EQ(c.later_allocations, 0) << nx << " x " << ny;
  }
}

}  // namespace
