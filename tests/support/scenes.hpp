#pragma once
// Loading the shipped example scenes in tests, with edits.
#include <fstream>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "solver/io/scene.hpp"

namespace grip::testing {

inline nlohmann::json example_scene(const std::string& name) {
  std::ifstream in(std::string(GRIP_SOURCE_DIR) + "/schemas/examples/" + name + ".json");
  return nlohmann::json::parse(in);
}

struct Solved {
  Scene scene;
  RunResult run;
};

// The paper's sheet (schemas/examples/sheet-stretching.json) with `elements` elements.
inline nlohmann::json sheet(int elements, double mu) {
  nlohmann::json j = example_scene("sheet-stretching");
  j["body"]["mesh"]["elements"] = elements;
  j["body"]["supports"][1]["node"] = elements;
  j["obstacles"][0]["friction"] = mu;
  j["obstacles"][1]["friction"] = mu;
  return j;
}

// schemas/examples/block-held-by-friction.json (a 20 x 10 block on a flat, mu 0.3, no
// supports: a pressure N / 20 on its top, then a shear traction raised through Q / (mu N) =
// 0.25 ... 0.95) with a last stage to 1.05, beyond what friction can hold.
inline nlohmann::json block_under_shear() {
  nlohmann::json j = example_scene("block-held-by-friction");
  j["stages"].push_back({{"steps", 1}, {"factors", {{"press", 1}, {"shear", 1.05}}}});
  return j;
}

inline Solved solve_scene(const nlohmann::json& j) {
  Solved s{read_scene(j), {}};
  s.run = run_load_steps(s.scene.problem, s.scene.steps, s.scene.params);
  return s;
}

}  // namespace grip::testing

#include "tests/support/contact_checks.hpp"

namespace grip::testing {

// The Coulomb cone holds to 1e-9 of the largest normal force where the friction bound moves
// with p_eta inside the iteration (cev's default, ssn); to the tau-pass tolerance with tau passes.
inline InvariantTolerances tolerances_of(const Scene& scene) {
  const ContactParams& c = scene.params.contact;
  const bool bound_moves = c.method == ContactMethod::ssn || (c.method == ContactMethod::cev &&
                                                               c.loop == ContactLoop::inner &&
                                                               c.friction_loop == FrictionLoop::inner);
  return {c.tolerance * scene.problem.body->characteristic_length(), bound_moves ? 1e-9 : c.tau_tolerance};
}

// Every step converged, satisfies the contact invariants, and lowers ||v|| monotonically.
inline void expect_every_step_sound(const Solved& s) {
  EXPECT_TRUE(s.run.completed) << s.run.reason;
  for (const StepRecord& rec : s.run.steps) {
    EXPECT_TRUE(step_invariants(s.scene.problem, rec, tolerances_of(s.scene)));
    EXPECT_TRUE(monotone_contact_error(rec));
  }
}

}  // namespace grip::testing
