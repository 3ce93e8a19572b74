#pragma once
// Variants of the shipped examples (issue 33's mutation test): each one or two changes away from
// its original (friction, steps, tolerance, method, force unit, stiffness, load level,
// indentation), and an independent check of every converged step of their runs.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/support/result_checks.hpp"
#include "tests/support/scenes.hpp"

namespace grip::testing {

struct Variant {
  std::string name;  // example__change(s)
  nlohmann::json scene;
};

// Multiplies every number under a key in `keys` (at any depth; arrays of numbers too).
inline bool scale_keys(nlohmann::json& j, const std::vector<std::string>& keys, double f, bool under = false) {
  bool changed = false;
  if (j.is_number() && under) {
    j = j.get<double>() * f;
    return true;
  }
  if (j.is_array()) {
    for (auto& e : j) changed |= scale_keys(e, keys, f, under);
  } else if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      const bool hit = std::find(keys.begin(), keys.end(), it.key()) != keys.end();
      changed |= scale_keys(it.value(), keys, f, under || hit);
    }
  }
  return changed;
}

// Sets every `key` (at any depth) whose value is a number, or a map of numbers, to `value`.
inline bool set_keys(nlohmann::json& j, const std::string& key, double value) {
  bool changed = false;
  if (j.is_array()) {
    for (auto& e : j) changed |= set_keys(e, key, value);
  } else if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (it.key() == key && it.value().is_number()) {
        it.value() = value;
        changed = true;
      } else if (it.key() == key && it.value().is_object()) {
        for (auto& v : it.value()) v = value;
        changed = true;
      } else {
        changed |= set_keys(it.value(), key, value);
      }
    }
  }
  return changed;
}

// The load steps: every "steps" count times f (at least 1).
inline bool scale_steps(nlohmann::json& j, double f) {
  auto one = [f](nlohmann::json& s) {
    const int before = s.get<int>();
    s = std::max(1, static_cast<int>(std::lround(before * f)));
    return s.get<int>() != before;
  };
  bool changed = false;
  if (j.contains("steps") && j["steps"].is_number_integer()) changed |= one(j["steps"]);
  if (j.contains("stages"))
    for (auto& st : j["stages"]) changed |= one(st["steps"]);
  return changed;
}

// The changes, each a name and an edit (false: it does not apply to that scene).
using Change = std::pair<std::string, std::function<bool(nlohmann::json&)>>;

inline std::vector<Change> single_changes() {
  using nlohmann::json;
  auto contact = [](json& j) -> json& { return j["solver"]["contact"]; };
  auto method = [contact](const std::string& m, json extra = json::object()) {
    return [contact, m, extra](json& j) {
      json& c = contact(j);
      c["method"] = m;
      for (auto it = extra.begin(); it != extra.end(); ++it) c[it.key()] = it.value();
      return true;
    };
  };
  auto tolerance = [contact](double t) {
    return [contact, t](json& j) {
      contact(j)["tolerance"] = t;
      return true;
    };
  };
  auto loads = [](double f) { return [f](json& j) { return scale_keys(j, {"force", "traction", "moment"}, f); }; };
  auto stiffness = [](double f) { return [f](json& j) { return scale_keys(j, {"young"}, f); }; };
  // Prescribed displacements and obstacle motions (the membrane's start-up depth with them).
  auto indentation = [](double f) {
    return [f](json& j) {
      bool changed = scale_keys(j, {"values", "translation"}, f);
      if (j.contains("solver") && j["solver"].contains("start"))
        changed |= scale_keys(j["solver"]["start"], {"value"}, f);
      return changed;
    };
  };
  return {
      {"mu0", [](json& j) { return set_keys(j, "friction", 0.0); }},
      {"mu0.1", [](json& j) { return set_keys(j, "friction", 0.1); }},
      {"mu0.3", [](json& j) { return set_keys(j, "friction", 0.3); }},
      {"mu0.6", [](json& j) { return set_keys(j, "friction", 0.6); }},
      {"steps_x2", [](json& j) { return scale_steps(j, 2.0); }},
      {"steps_half", [](json& j) { return scale_steps(j, 0.5); }},
      {"tol1e-4", tolerance(1e-4)},
      {"tol1e-6", tolerance(1e-6)},
      {"tol1e-9", tolerance(1e-9)},
      {"tol1e-11", tolerance(1e-11)},
      {"ssn", method("ssn")},
      {"ssn_r0.01", method("ssn", {{"augmentation", 0.01}})},
      {"penalty", method("penalty")},
      {"penalty_tol1e-3", method("penalty", {{"tolerance", 1e-3}})},
      {"passes", method("cev", {{"friction_loop", "passes"}})},
      {"uzawa", method("uzawa", {{"max_iterations", 200}})},
      // The force unit N -> kN: every force and stress / 1000 (the displacements are the same).
      {"kN",
       [](json& j) {
         return scale_keys(j, {"force", "traction", "moment", "young", "H"}, 1e-3);
       }},
      {"E_x1e6", stiffness(1e6)},
      {"E_x1e3", stiffness(1e3)},
      {"E_x1e-2", stiffness(1e-2)},
      {"load_x1e-6", loads(1e-6)},
      {"load_x1e-3", loads(1e-3)},
      {"load_x2", loads(2.0)},
      {"disp_x1e-4", indentation(1e-4)},
      {"disp_x1e-2", indentation(1e-2)},
      {"disp_x2", indentation(2.0)},
  };
}

// Every example with each change, then with a strategy and a level change together.
inline std::vector<Variant> variants(const std::vector<std::string>& examples) {
  std::vector<Variant> out;
  const std::vector<Change> changes = single_changes();
  auto find = [&](const std::string& name) {
    for (const Change& c : changes)
      if (c.first == name) return c.second;
    return std::function<bool(nlohmann::json&)>{};
  };
  for (const std::string& ex : examples) {
    const nlohmann::json base = example_scene(ex);
    for (const Change& c : changes) {
      nlohmann::json j = base;
      if (c.second(j)) out.push_back({ex + "__" + c.first, std::move(j)});
    }
    for (const std::string m : {"ssn", "penalty_tol1e-3", "passes"})
      for (const std::string level : {"E_x1e6", "load_x1e-6", "disp_x1e-4", "tol1e-11"}) {
        nlohmann::json j = base;
        if (find(level)(j) && find(m)(j)) out.push_back({ex + "__" + m + "_" + level, std::move(j)});
      }
  }
  return out;
}

// The largest displacement of q (a rotation times its length scale), at most the body's length.
inline double displacement_scale(const Problem& problem, const Vector& q) {
  const Vector ls = problem.body->dof_length_scales();
  double d = 0.0;
  for (int j = 0; j < q.size() && j < ls.size(); ++j) d = std::max(d, std::abs(q[j]) * ls[j]);
  return std::min(d, problem.body->characteristic_length());
}

// The gaps of a converged step against its tolerance relative to its displacement, computed here
// from the state: a gap or penetration within tolerance x D of every pressing point, with the
// round-off of the coordinates (eps x their size, 10 x per component) as the floor.
inline double relative_length(const Scene& scene, const StepRecord& rec) {
  const Problem& problem = scene.problem;
  double size = 0.0;
  for (const PairedPoint& pp : rec.state.points)
    size = std::max({size, pp.point.x.cwiseAbs().maxCoeff(), pp.projection.point.cwiseAbs().maxCoeff(),
                     std::abs(pp.projection.zeta)});
  const double floor = 10 * 4 * std::numeric_limits<double>::epsilon() * size *
                       std::sqrt(static_cast<double>(std::max(1, problem.component_count)));
  // A step that says it stopped at the precision its solves allow (at_round_off) is held to the
  // bound it states.
  return std::max({scene.params.contact.tolerance * displacement_scale(problem, rec.state.q), floor,
                   rec.at_round_off ? rec.bound : 0.0});
}

// Every converged step: finite, on Coulomb's law (no tension, the cone, friction against the
// slip, sticking points not slipping), its gaps within the tolerance relative to its
// displacement, and the body (held or supported) in balance with its loads and reactions.
inline ::testing::AssertionResult converged_step_sound(const Solved& s, const StepRecord& rec) {
  InvariantTolerances tol = tolerances_of(s.scene);
  tol.length = relative_length(s.scene, rec);
  return step_invariants(s.scene.problem, rec, tol);
}

}  // namespace grip::testing
