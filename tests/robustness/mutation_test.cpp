// Issue 33's mutation test: the shipped examples each one or two changes away (mutations.hpp),
// every converged step checked independently (converged_step_sound). A run may fail, with its
// reason; no converged step may break the checks. The whole set (label hard_slow) prints its
// counts for bench/results/robustness.md; a sample of small scenes runs by default (label hard).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>

#include "tests/robustness/mutations.hpp"

namespace grip::testing {
namespace {

struct Counts {
  int solves = 0, completed = 0, failed = 0, rejected = 0;
  int converged_steps = 0, failed_steps = 0, unsound_steps = 0;
  std::map<std::string, int> reasons;  // the failures' reasons, by their first words
};

std::string reason_head(const std::string& reason) {
  const size_t cut = reason.find_first_of(":(0123456789");
  return reason.substr(0, std::min<size_t>(cut == std::string::npos ? reason.size() : cut, 70));
}

void run_variant(const Variant& v, Counts& n) {
  ++n.solves;
  Solved s;
  try {
    s.scene = read_scene(v.scene);
  } catch (const std::exception& e) {
    ++n.rejected;
    std::printf("[mutation] %s: rejected: %s\n", v.name.c_str(), e.what());
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  s.run = run_load_steps(s.scene.problem, s.scene.steps, s.scene.params);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(result_is_finite(s)) << v.name;
  for (const StepRecord& rec : s.run.steps) {
    if (!rec.converged) {
      ++n.failed_steps;
      EXPECT_FALSE(rec.reason.empty()) << v.name << ": step " << rec.index << " failed without a reason";
      continue;
    }
    ++n.converged_steps;
    const auto sound = converged_step_sound(s, rec);
    if (!sound) ++n.unsound_steps;
    EXPECT_TRUE(sound) << v.name;
  }
  if (s.run.completed) {
    ++n.completed;
  } else {
    ++n.failed;
    EXPECT_FALSE(s.run.reason.empty()) << v.name;
    ++n.reasons[reason_head(s.run.reason.substr(s.run.reason.find(':') + 2))];
  }
  std::printf("[mutation] %s: %s, %zu steps, %ld solves, %.2f s%s\n", v.name.c_str(),
              s.run.completed ? "completed" : "failed", s.run.steps.size(), s.run.counters.solves, seconds,
              s.run.completed ? "" : (": " + s.run.reason).c_str());
}

void report(const Counts& n) {
  std::printf(
      "[mutation] solves %d: completed %d, failed with a reason %d, rejected %d; steps converged %d "
      "(failing the checks: %d), failed %d\n",
      n.solves, n.completed, n.failed, n.rejected, n.converged_steps, n.unsound_steps, n.failed_steps);
  for (const auto& [why, count] : n.reasons) std::printf("[mutation]   %3d x %s\n", count, why.c_str());
}

// Small, fast examples: the default run's sample.
TEST(MutationSample, SmallExamplesVariedPassTheChecks) {
  Counts n;
  const std::vector<Variant> all = variants({"sliding-block", "block-held-by-friction", "beam-on-cylinder"});
  // Every few variant of the three: about 20 solves.
  for (size_t k = 0; k < all.size(); k += 5) run_variant(all[k], n);
  report(n);
  EXPECT_GE(n.solves, 18);
  EXPECT_EQ(n.unsound_steps, 0);
}

TEST(MutationSlow, EveryExampleVariedPassesTheChecks) {
  Counts n;
  const std::vector<Variant> all =
      variants({"sliding-block", "block-held-by-friction", "beam-on-cylinder", "cattaneo-mindlin", "hertz",
                "sheet-stretching", "strip-cantilever", "strip-on-cylinder", "two-cylinders", "block-on-foundation"});
  // GRIP_MUTATION_SHARD=k/m runs every m-th variant from the k-th (0-based): the set split over
  // processes; the counts then add up.
  size_t shard = 0, shards = 1;
  if (const char* env = std::getenv("GRIP_MUTATION_SHARD")) std::sscanf(env, "%zu/%zu", &shard, &shards);
  for (size_t k = shard; k < all.size(); k += std::max<size_t>(1, shards)) run_variant(all[k], n);
  report(n);
  EXPECT_GE(n.solves * shards, 300);
  EXPECT_EQ(n.unsound_steps, 0);
}

}  // namespace
}  // namespace grip::testing
