#pragma once
// The small continuum bodies that the tests of material laws drive: one q4 on the unit square
// (a uniform state against a closed form), and a 4 x 1 block bent by its tip (a yielded zone
// beside an elastic one: tangents and Newton's rate).
#include <memory>
#include <utility>
#include <vector>

#include "solver/elements/continuum.hpp"
#include "solver/elements/plane_mesh.hpp"
#include "tests/support/newton_driver.hpp"

namespace grip::testing {

// One q4 on [0, 1]^2, its bottom side the set "bottom".
inline PlaneMesh unit_square() {
  PlaneMesh m;
  m.nodes = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.elements = {{0, 1, 2, 3}};
  m.sets["bottom"] = {0, 1};
  return m;
}

inline ContinuumOptions finite(PlaneAnalysis analysis, ContinuumElement element = ContinuumElement::q4,
                               Incompressibility incompressibility = Incompressibility::none) {
  return {element, ContinuumKinematics::finite, analysis, 1.0, incompressibility};
}

inline ContinuumOptions small_strain(PlaneAnalysis analysis, ContinuumElement element = ContinuumElement::q4) {
  return {element, ContinuumKinematics::linear, analysis, 1.0};
}

// A 4 x 1 block of 4 x 2 elements (R from 1 in axisymmetry: an annular plate) held on its left
// side, its right side (`tip`) held in y so that a prescribed deflection bends it.
struct Bent {
  std::unique_ptr<ContinuumBody> body;
  std::vector<char> held;
  std::vector<int> tip;
};

inline Bent bent_block(std::shared_ptr<const PlaneMaterial> m, const ContinuumOptions& options) {
  RectangleSpec spec;
  spec.origin = {options.analysis == PlaneAnalysis::axisymmetric ? 1.0 : 0.0, 0.0};
  spec.size = {4.0, 1.0};
  spec.nx = 4;
  spec.ny = 2;
  PlaneMesh mesh = rectangle_mesh(spec, element_shape(options.element));
  Bent b;
  b.tip = mesh.sets.at("right");
  b.body = std::make_unique<ContinuumBody>(mesh, mesh.sets.at("bottom"),
                                           std::vector<std::shared_ptr<const PlaneMaterial>>{std::move(m)}, options);
  b.held.assign(b.body->dof_count(), 0);
  for (int n : mesh.sets.at("left")) b.held[2 * n] = b.held[2 * n + 1] = 1;
  for (int n : b.tip) b.held[2 * n + 1] = 1;
  return b;
}

// Solves for the tip deflected by `tip`.
inline void bend(Driver& d, const Bent& b, double tip, double tolerance) {
  d.solve(
      [&](Vector& q) {
        for (int n : b.tip) q[2 * n + 1] = tip;
      },
      tolerance);
}

}  // namespace grip::testing
