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
// contact forces), on two meshes: every iteration after a solve's first allocates nothing. The
// first may (the work storage is sized there, and the chord test of a solve's first iterate
// pairs and solves with storage of its own). A `Vector tmp(n)` left in the loop fails it (one
// allocation per iteration: measured, see the commit that added this test).
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
  long count;
};
constexpr int kRecords = 1 << 16;
Record records[kRecords];
int recorded = 0;

void probe(int iteration) {
  if (recorded < kRecords) records[recorded++] = {iteration, allocations.load(std::memory_order_relaxed)};
}

struct Counts {
  long first_iterations = 0, later_iterations = 0;  // iteration windows measured
  long first_allocations = 0, later_allocations = 0, worst_later = 0;
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
    if (records[k].iteration == 1) {
      ++c.first_iterations;
      c.first_allocations += spent;
    } else {
      ++c.later_iterations;
      c.later_allocations += spent;
      c.worst_later = std::max(c.worst_later, spent);
    }
  }
  std::printf(
      "q9 %d x %d: %ld Newton iterations (%ld factorizations); %ld first iterations measured, %ld "
      "allocations (%.1f each); %ld later ones, %ld allocations (at most %ld in one)\n",
      nx, ny, c.newton_iterations, c.newton_factorizations, c.first_iterations, c.first_allocations,
      c.first_iterations ? static_cast<double>(c.first_allocations) / c.first_iterations : 0.0, c.later_iterations,
      c.later_allocations, c.worst_later);
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

// Iterations after a solve's first allocate nothing, on both meshes: no allocation that grows
// with the mesh (nor a constant one) is left in the loop.
TEST(NewtonAllocations, IterationsAfterTheFirstAllocateNothingOnTheFiniteStrip) {
  for (const auto& [nx, ny] : {std::pair{50, 2}, std::pair{100, 4}}) {
    const Counts c = run_strip(nx, ny);
    // Enough iterations past the first for the assertion to mean something, each with its
    // factorization of Newton's tangent (a changing tangent: finite strain).
    EXPECT_GE(c.later_iterations, 20) << nx << " x " << ny;
    EXPECT_GE(c.newton_factorizations, c.later_iterations) << nx << " x " << ny;
    EXPECT_EQ(c.later_allocations, 0) << nx << " x " << ny;
  }
}

}  // namespace
