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

// A 20 x 10 block on a flat (mu 0.3), no supports: a pressure N / 20 on its top, then a shear
// traction on the top raised through Q / (mu N) = 0.25 ... 0.95, then 1.05.
inline nlohmann::json block_under_shear() {
  return nlohmann::json::parse(R"({
    "body": {
      "model": "continuum", "kinematics": "linear", "analysis": "plane_strain", "element": "q4", "thickness": 1,
      "material": {"young": 200000, "poisson": 0.3},
      "mesh": {"rectangle": {"origin": [-10, 0], "size": [20, 10], "divisions": [20, 10]}},
      "contact_set": "bottom",
      "loads": [{"set": "top", "traction": [0, -10], "case": "press"},
                {"set": "top", "traction": [3, 0], "case": "shear"}]
    },
    "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [40, 0], "to": [-40, 0]}, "friction": 0.3}],
    "stages": [
      {"steps": 1, "factors": {"press": 1}},
      {"steps": 1, "factors": {"press": 1, "shear": 0.25}},
      {"steps": 1, "factors": {"press": 1, "shear": 0.5}},
      {"steps": 1, "factors": {"press": 1, "shear": 0.75}},
      {"steps": 1, "factors": {"press": 1, "shear": 0.9}},
      {"steps": 1, "factors": {"press": 1, "shear": 0.95}},
      {"steps": 1, "factors": {"press": 1, "shear": 1.05}}
    ],
    "solver": {"contact": {"method": "cev", "tolerance": 1e-8}}
  })");
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
