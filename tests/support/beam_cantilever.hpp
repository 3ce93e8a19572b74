#pragma once
// A slender cantilever as a scene (model reissner_beam), and its tip's displacement at a step:
// the setup of the beam verification tests.
#include <string>

#include "solver/elements/straight_beam.hpp"
#include "tests/support/scenes.hpp"

namespace grip::testing {

// A cantilever of length 1 and EI = 1, clamped at node 0, `elements` b3 or b2 elements, a far
// floor that it never touches. Depth t = 1e-3: extension and shear 1e-6 of the bending.
inline nlohmann::json cantilever(int elements, const std::string& element, nlohmann::json load, nlohmann::json steps,
                                 double t = 1e-3) {
  return {{"body",
           {{"model", "reissner_beam"},
            {"element", element},
            {"material", {{"young", 12.0 / (t * t * t)}, {"poisson", 0.3}}},
            {"section", {{"width", 1.0}, {"depth", t}}},
            {"mesh", {{"length", 1.0}, {"elements", elements}}},
            {"supports", {{{"node", 0}, {"fix", {"u", "w", "theta"}}}}},
            {"loads", {load}}}},
          {"obstacles", {{{"name", "floor"}, {"shape", {{"type", "segment"}, {"from", {5, -3}}, {"to", {-5, -3}}}}}}},
          {"steps", steps},
          {"solver", {{"contact", {{"tolerance", 1e-8}}}}}};
}

inline Vec2 tip(const Solved& s, size_t step, int node) {
  const Vector& q = s.run.steps.at(step).state.q;
  return {q[StraightBeam::node_dof(node, 0)], q[StraightBeam::node_dof(node, 1)]};
}

}  // namespace grip::testing
