#pragma once
// Distorted patches for patch tests: the interior corner nodes of a generated rectangle moved
// off the grid, the sides kept straight (mid-side nodes in the middle of their sides, a q9's
// centre at the mean of its corners), so that a linear field is representable by every kind.
#include <random>

#include "solver/elements/plane_mesh.hpp"

namespace grip::testing {

inline PlaneMesh distorted_rectangle(const RectangleSpec& spec, ElementShape shape, double shift, unsigned seed) {
  PlaneMesh mesh = rectangle_mesh(spec, shape);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> move(-shift, shift);
  const Vec2 lo = spec.origin, hi = spec.origin + spec.size;
  for (Vec2& x : mesh.nodes) {
    const bool boundary = std::abs(x.x() - lo.x()) < 1e-12 || std::abs(x.x() - hi.x()) < 1e-12 ||
                          std::abs(x.y() - lo.y()) < 1e-12 || std::abs(x.y() - hi.y()) < 1e-12;
    if (!boundary) x += Vec2(move(rng), move(rng));
  }
  for (const auto& el : mesh.elements) {
    for (const auto& side : element_sides(shape))
      if (side.size() == 3) mesh.nodes[el[side[1]]] = 0.5 * (mesh.nodes[el[side[0]]] + mesh.nodes[el[side[2]]]);
    if (shape == ElementShape::q9)
      mesh.nodes[el[8]] = 0.25 * (mesh.nodes[el[0]] + mesh.nodes[el[1]] + mesh.nodes[el[2]] + mesh.nodes[el[3]]);
  }
  return mesh;
}

// The axisymmetric patch: a distorted 3 x 2 section whose left side lies on the axis.
inline PlaneMesh axis_section(ElementShape shape) {
  RectangleSpec spec;
  spec.size = {3.0, 2.0};
  spec.nx = 4;
  spec.ny = 3;
  return distorted_rectangle(spec, shape, 0.15, 7);
}

}  // namespace grip::testing
