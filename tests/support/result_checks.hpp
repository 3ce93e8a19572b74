#pragma once
// Checks for the hard cases (tests/hard): no NaN or Inf anywhere in the result document, and
// every step either converged (||v|| <= tol, the contact invariants, ||v|| never rising across
// an accepted update) or failed with a stated reason.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "solver/io/result.hpp"
#include "tests/support/scenes.hpp"

namespace grip::testing {

// The JSON pointer of the first non-finite number in `j` ("" if every number is finite).
inline std::string first_non_finite(const nlohmann::json& j, const std::string& at = "") {
  if (j.is_number_float()) return std::isfinite(j.get<double>()) ? "" : (at.empty() ? "/" : at);
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      const std::string found = first_non_finite(it.value(), at + "/" + it.key());
      if (!found.empty()) return found;
    }
  } else if (j.is_array()) {
    for (size_t k = 0; k < j.size(); ++k) {
      const std::string found = first_non_finite(j[k], at + "/" + std::to_string(k));
      if (!found.empty()) return found;
    }
  }
  return "";
}

// Every number of the whole result document (effective scene, summary, every step) is finite.
inline ::testing::AssertionResult result_is_finite(const Solved& s) {
  const std::string at = first_non_finite(result_json(s.scene, s.run));
  if (at.empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "non-finite number at " << at;
}

// A converged step ended with ||v||_2 <= tolerance x length (its last real solve).
inline ::testing::AssertionResult error_within_tolerance(const Solved& s, const StepRecord& rec) {
  const double tol = s.scene.params.contact.tolerance * s.scene.problem.body->characteristic_length();
  if (rec.history.empty()) return ::testing::AssertionFailure() << "step " << rec.index << " has no history";
  const double v = rec.history.back().v2;
  if (std::isfinite(v) && v <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "step " << rec.index << " ends with ||v|| = " << v << " > " << tol;
}

// The issue-9 expectation for a case that must converge at every step.
inline void expect_hard_case_sound(const Solved& s) {
  expect_every_step_sound(s);
  EXPECT_TRUE(result_is_finite(s));
  for (const StepRecord& rec : s.run.steps) EXPECT_TRUE(error_within_tolerance(s, rec));
}

// For a case allowed to fail: the converged steps are sound, and a failure states its reason.
inline void expect_sound_or_stated_failure(const Solved& s) {
  EXPECT_TRUE(result_is_finite(s));
  if (!s.run.completed) EXPECT_FALSE(s.run.reason.empty());
  for (const StepRecord& rec : s.run.steps) {
    if (!rec.converged) {
      EXPECT_FALSE(rec.reason.empty()) << "step " << rec.index << " failed without a reason";
      continue;
    }
    EXPECT_TRUE(step_invariants(s.scene.problem, rec, tolerances_of(s.scene)));
    EXPECT_TRUE(monotone_contact_error(rec));
    EXPECT_TRUE(error_within_tolerance(s, rec));
  }
}

// One line of work for the log: steps, real solves, Newton iterations, seconds.
inline void print_work(const std::string& name, const Solved& s) {
  std::printf("[work] %s: %zu steps, %ld real solves, %ld Newton iterations, %.2f s%s\n", name.c_str(),
              s.run.steps.size(), s.run.counters.solves, s.run.counters.newton_iterations, s.run.seconds,
              s.run.completed ? "" : (" (failed: " + s.run.reason + ")").c_str());
}

}  // namespace grip::testing
