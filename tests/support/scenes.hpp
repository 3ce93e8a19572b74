#pragma once
// Loading the shipped example scenes in tests, with edits.
#include <cmath>
#include <fstream>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "solver/io/scene.hpp"
#include "tests/support/contact_checks.hpp"

namespace grip::testing {

inline nlohmann::json example_scene(const std::string& name) {
  std::ifstream in(std::string(GRIP_SOURCE_DIR) + "/schemas/examples/" + name + ".json");
  return nlohmann::json::parse(in);
}

// The bulging block's quarter without friction: a 2 x 2 block, [0, 1] x [0, 1] on n x n elements
// (symmetric about x = 0 and y = 0), compressed 10 % by a frictionless plate in 4 steps, the top
// nodes' x held (sticking without a friction coefficient).
inline nlohmann::json compressed_block(const std::string& element, const std::string& incompressibility,
                                       const nlohmann::json& material, int n, const nlohmann::json& contact) {
  return {
      {"body",
       {{"model", "continuum"},
        {"element", element},
        {"incompressibility", incompressibility},
        {"material", material},
        {"mesh", {{"rectangle", {{"size", {1, 1}}, {"divisions", {n, n}}}}}},
        {"contact_set", "top"},
        {"supports",
         {{{"set", "left"}, {"fix", {"x"}}}, {{"set", "bottom"}, {"fix", {"y"}}}, {{"set", "top"}, {"fix", {"x"}}}}}}},
      {"obstacles",
       {{{"name", "plate"},
         {"shape", {{"type", "segment"}, {"from", {-1, 1}}, {"to", {3, 1}}}},
         {"motion", {{"translation", {0, -0.1}}}}}}},
      {"steps", 4},
      {"solver", {{"contact", contact}}}};
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

// A disc (R = 10, an elliptic grid) between two flats with friction 0.3; the upper flat moves
// down by `delta`. No supports: only the two contacts hold it (friction its sideways motion and
// rotation). nu = 0.49 (with the mean-dilatation q4_bbar): friction on a rigid flat narrows the
// contact of a compressible body below Hertz's width (with nu = 0.3 by 6 % here), which the
// closed form neglects; the coupling vanishes as nu -> 1/2 (as in cattaneo-mindlin.json).
inline nlohmann::json disc_between_flats(int n, double delta) {
  using nlohmann::json;
  json nodes = json::array(), elements = json::array(), rim = json::array();
  auto id = [n](int i, int k) { return k * (n + 1) + i; };
  for (int k = 0; k <= n; ++k)
    for (int i = 0; i <= n; ++i) {
      const double u = -1 + 2.0 * i / n, v = -1 + 2.0 * k / n;  // the square mapped onto the disc
      nodes.push_back({10 * u * std::sqrt(1 - v * v / 2), 10 * v * std::sqrt(1 - u * u / 2)});
      if (i == 0 || k == 0 || i == n || k == n) rim.push_back(id(i, k));
    }
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < n; ++i) elements.push_back({id(i, k), id(i + 1, k), id(i + 1, k + 1), id(i, k + 1)});
  json j = {{"body",
             {{"model", "continuum"},
              {"kinematics", "linear"},
              {"analysis", "plane_strain"},
              {"element", "q4_bbar"},
              {"thickness", 1},
              {"material", {{"young", 200000}, {"poisson", 0.49}}},
              {"mesh", {{"nodes", nodes}, {"elements", elements}, {"sets", {{"rim", rim}}}}},
              {"contact_set", "rim"}}},
            {"obstacles", json::array({{{"name", "lower"},
                                        {"shape", {{"type", "segment"}, {"from", {40, -10}}, {"to", {-40, -10}}}},
                                        {"friction", 0.3}},
                                       {{"name", "upper"},
                                        {"shape", {{"type", "segment"}, {"from", {-40, 10}}, {"to", {40, 10}}}},
                                        {"friction", 0.3},
                                        {"motion", {{"translation", {0, -delta}}}}}})},
            {"steps", 1},
            {"solver", {{"contact", {{"method", "cev"}, {"tolerance", 1e-8}, {"reach", 1.0}}}}}};
  return j;
}

// A Timoshenko beam (20 elements) lying on a flat (mu 0.3) with no supports, pressed by nodal
// forces (N = 200), then pushed along x at its end through Q / (mu N) = 0.28, 0.56, 0.83 and
// 1.17 (load cases press and push). von Karman kinematics hold theta at the middle node (a
// finite rotation is no null mode of a stressed beam): only the translations are free.
inline nlohmann::json beam_lying_on_a_flat(const std::string& kinematics) {
  using nlohmann::json;
  json loads = json::array();
  for (int n = 0; n <= 20; ++n)
    loads.push_back({{"node", n}, {"force", {0.0, n == 0 || n == 20 ? -5.0 : -10.0}}, {"case", "press"}});
  loads.push_back({{"node", 0}, {"force", {20.0, 0.0}}, {"case", "push"}});
  json j = {{"body",
             {{"model", "timoshenko_beam"},
              {"kinematics", kinematics},
              {"material", {{"young", 210000}, {"poisson", 0.3}}},
              {"section", {{"width", 2}, {"depth", 2}}},
              {"mesh", {{"origin", {0, 0}}, {"length", 20}, {"elements", 20}}},
              {"loads", loads}}},
            {"obstacles", json::array({{{"name", "flat"},
                                        {"shape", {{"type", "segment"}, {"from", {100, -1}}, {"to", {-100, -1}}}},
                                        {"friction", 0.3}}})},
            {"stages", json::array({{{"steps", 1}, {"factors", {{"press", 1}}}},
                                    {{"steps", 3}, {"factors", {{"press", 1}, {"push", 2.5}}}},
                                    {{"steps", 1}, {"factors", {{"press", 1}, {"push", 3.5}}}}})},
            {"solver", {{"contact", {{"method", "cev"}, {"tolerance", 1e-8}}}}}};
  if (kinematics == "von_karman") j["body"]["supports"] = json::array({{{"node", 10}, {"fix", {"theta"}}}});
  return j;
}

// Solved, with the step checks of every converged step held to their limits (issue 33.1).
inline Solved solve_read_scene(Scene scene) {
  Solved s{std::move(scene), {}};
  s.run = run_load_steps(s.scene.problem, s.scene.steps, s.scene.params);
  const ContactParams& c = s.scene.params.contact;
  const bool moving_bound =
      c.method == ContactMethod::ssn ||
      (c.method == ContactMethod::cev && c.loop == ContactLoop::inner && c.friction_loop == FrictionLoop::inner);
  for (const StepRecord& rec : s.run.steps) {
    if (!rec.converged) continue;
    EXPECT_TRUE(step_checks_within_limits(s.scene.problem, rec,
                                          c.tolerance * s.scene.problem.body->characteristic_length(),
                                          moving_bound ? 1e-9 : c.tau_tolerance));
  }
  return s;
}
inline Solved solve_scene(const nlohmann::json& j, const MeshResolver& meshes = {}) {
  return solve_read_scene(read_scene(j, meshes));
}

// A scene's first refusal as "pointer: detail", or "accepted" when it reads and runs.
inline std::string first_refusal(const nlohmann::json& j) {
  try {
    solve_scene(j);
  } catch (const SceneErrors& e) {
    return e.issues().at(0).pointer + ": " + e.issues().at(0).detail;
  }
  return "accepted";
}
// A shipped example as a user runs it: its mesh files read beside it.
inline Solved solve_example(const std::string& name) {
  return solve_read_scene(read_scene_file(std::string(GRIP_SOURCE_DIR) + "/schemas/examples/" + name + ".json"));
}

}  // namespace grip::testing

#include "tests/support/contact_checks.hpp"

namespace grip::testing {

// The Coulomb cone holds to 1e-9 of the largest normal force where the friction bound moves
// with p_eta inside the iteration (cev's default, ssn); to the tau-pass tolerance with tau passes.
inline bool friction_bound_moves(const ContactParams& c) {
  return c.method == ContactMethod::ssn ||
         (c.method == ContactMethod::cev && c.loop == ContactLoop::inner && c.friction_loop == FrictionLoop::inner);
}

inline InvariantTolerances tolerances_of(const Scene& scene) {
  const ContactParams& c = scene.params.contact;
  return {c.tolerance * scene.problem.body->characteristic_length(), friction_bound_moves(c) ? 1e-9 : c.tau_tolerance};
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
