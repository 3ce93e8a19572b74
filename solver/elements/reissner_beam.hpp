#pragma once
// The geometrically exact plane beam of Simo and Reissner (docs/algorithm.md#geometrically-exact-beam).
// The axis lies on y = y0 along x, like the von Karman beam's, with the same node dofs u, w
// (displacements of the axis) and theta, the section's rotation, clockwise: a fibre at height z
// sits at (X + u + z sin theta, y0 + w + z cos theta). With a = 1 + u' and b = w', the strains
//   axial   eps   = a cos(theta) - b sin(theta) - 1,   N = EA eps
//   shear   gamma = a sin(theta) + b cos(theta),       Q = kGA gamma
//   bending kappa = theta',                            M = EI kappa
// are exact for any rotation (a rigid turn of the beam leaves them unchanged); for small
// rotations they are the von Karman beam's. Elements: b2 (2 nodes, 1 Gauss point) and b3
// (3 nodes, 2 points): uniform reduced integration, free of shear locking and of spurious modes.
#include <vector>

#include "solver/elements/timoshenko_beam.hpp"
#include "solver/model/body.hpp"

namespace grip {

enum class BeamElement { b2, b3 };

class ReissnerBeam final : public Body {
 public:
  // Node abscissae (element ends) must increase strictly; one element between consecutive nodes.
  ReissnerBeam(std::vector<double> node_x, double y0, BeamSection section, BeamElement element);

  int dof_count() const override { return 3 * (node_count() + mid_node_count()); }
  Vector dof_length_scales() const override;
  void internal_force(const Vector& q, Vector& force, Triplets* tangent) const override;
  int site_count() const override { return node_count(); }
  Vec2 site_reference(int site) const override { return {x_[site], y0_}; }
  SurfacePoint surface_point(const VectorRef& q, int site, int side) const override;
  double tributary_area(int site) const override;
  double characteristic_length() const override { return x_.back() - x_.front(); }

  Vector rigid_translation(const Vec2& d) const override;
  Vector rigid_rotation() const override;
  // The rigid turn of the current shape: (-y, x) at each node, theta -1 (its strains stay).
  Vector own_rotation_at(const Vector& q) const override;
  // Three dofs a node (u, w, theta), the element ends first, then each b3's mid node.
  int dof_node(int dof) const override { return dof / 3; }
  Traits traits() const override { return {true, false, false}; }
  std::vector<std::vector<int>> cells() const override;
  FieldTable site_fields(const Vector& q) const override;
  FieldTable element_fields(const Vector& q) const override;

  int node_count() const override { return static_cast<int>(x_.size()); }
  int element_count() const { return node_count() - 1; }
  int mid_node_count() const { return element_ == BeamElement::b3 ? element_count() : 0; }
  // Global dof of node k: component 0 = u, 1 = w, 2 = theta (the von Karman beam's numbering).
  static int node_dof(int node, int component) { return 3 * node + component; }
  // Global dof of element e's mid node (b3 only).
  int mid_dof(int element, int component) const { return 3 * (node_count() + element) + component; }
  // Section forces at the element's centre.
  SectionForces section_forces(const Vector& q, int element) const;
  const BeamSection& section() const { return section_; }

 private:
  // The element's nodes in local order (ends, then the mid node of a b3) and their abscissae.
  int element_nodes(int e, int* nodes, double* x) const;

  std::vector<double> x_;
  double y0_;
  BeamSection section_;
  BeamElement element_;
};

}  // namespace grip
