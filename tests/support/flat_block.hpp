#pragma once
// The block of bench/scaling.py's block_scene: width 1, linear plane strain, `nodes` contact
// nodes on its bottom and `rows` rows of square elements, pressed onto a rigid flat with
// friction mu by a prescribed top displacement in 4 steps.
#include <nlohmann/json.hpp>

namespace grip::testing {

inline nlohmann::json flat_block(int nodes, int rows, double mu = 0.3) {
  const int nx = nodes - 1;
  const double height = static_cast<double>(rows) / nx;
  return {
      {"units", {{"force", "N"}, {"length", "mm"}}},
      {"body",
       {{"model", "continuum"},
        {"kinematics", "linear"},
        {"analysis", "plane_strain"},
        {"element", "q4"},
        {"thickness", 1},
        {"material", {{"young", 200000}, {"poisson", 0.3}}},
        {"mesh", {{"rectangle", {{"origin", {0, 0}}, {"size", {1, height}}, {"divisions", {nx, rows}}}}}},
        {"supports", {{{"set", "top"}, {"fix", {"x", "y"}}, {"values", {{"y", -1e-4 * height}}}}}}}},
      {"obstacles",
       {{{"name", "flat"}, {"shape", {{"type", "segment"}, {"from", {2, 0}}, {"to", {-1, 0}}}}, {"friction", mu}}}},
      {"steps", 4},
  };
}

}  // namespace grip::testing
