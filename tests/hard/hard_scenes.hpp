#pragma once
// Small scenes the hard cases share, built as JSON (the shipped examples cover the rest).
#include <string>

#include <nlohmann/json.hpp>

#include "tests/support/scenes.hpp"

namespace grip::testing {

// A beam of length 10 (depth 0.5) clamped at x = 0, lying on a rigid flat at its lower surface
// (y = -0.25), under a total downward load of 19.5 spread over its free nodes (half at the tip),
// as in tests/verification/beam_on_flat_test.cpp but with any number of elements.
inline nlohmann::json beam_on_flat(int elements, double mu, const std::string& kinematics = "linear") {
  nlohmann::json loads = nlohmann::json::array();
  const double per_node = 20.0 / elements;
  for (int i = 1; i <= elements; ++i)
    loads.push_back({{"node", i}, {"force", {0, i == elements ? -0.5 * per_node : -per_node}}});
  return {{"body",
           {{"model", "timoshenko_beam"},
            {"kinematics", kinematics},
            {"material", {{"young", 2e5}, {"poisson", 0.3}}},
            {"section", {{"width", 1}, {"depth", 0.5}}},
            {"mesh", {{"length", 10}, {"elements", elements}}},
            {"supports", {{{"node", 0}, {"fix", {"u", "w", "theta"}}}}},
            {"loads", loads}}},
          {"obstacles",
           {{{"name", "flat"},
             {"shape", {{"type", "segment"}, {"from", {12, -0.25}}, {"to", {-2, -0.25}}}},
             {"friction", mu}}}},
          {"steps", 4},
          {"solver", {{"contact", {{"method", "cev"}, {"tolerance", 1e-8}}}}}};
}

// The paper's beam bent round a cylinder (schemas/examples/beam-on-cylinder.json) with friction mu.
inline nlohmann::json beam_on_cylinder(double mu) {
  nlohmann::json j = example_scene("beam-on-cylinder");
  j["obstacles"][0]["friction"] = mu;
  return j;
}

}  // namespace grip::testing
