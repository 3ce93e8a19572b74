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

#include "solver/elements/straight_beam.hpp"

namespace grip {

enum class BeamElement { b2, b3 };

class ReissnerBeam final : public StraightBeam {
 public:
  // Node abscissae are the element ends; a b3 adds a mid node in each element.
  ReissnerBeam(std::vector<double> node_x, double y0, BeamSection section, BeamElement element);

  int dof_count() const override { return 3 * (node_count() + mid_node_count()); }
  void internal_force(const Vector& q, Vector& force, TangentSink* tangent) const override;
  SurfacePoint surface_point(const VectorRef& q, int site, int side) const override;

  Vector rigid_translation(const Vec2& d) const override;
  Vector rigid_rotation() const override;
  // The rigid turn of the current shape: (-y, x) at each node, theta -1 (its strains stay).
  Vector own_rotation_at(const Vector& q) const override;
  Traits traits() const override { return {true, false, false}; }
  // A force at an end node that turns with its section: `force` at theta = 0, of load case
  // `load_case`, applied at height z (0: the axis; +-h/2: a face), whose arm turns with it.
  struct FollowerLoad {
    int node;
    Vec2 force;
    double z;
    int load_case;
  };
  void add_follower_load(const FollowerLoad& load) { followers_.push_back(load); }
  // A distributed load that turns and stretches with the axis: `traction` [along, across] per
  // unit length at the reference state, (t_along x' + t_across x'^perp) per unit length of the
  // undeformed axis with x' = (1 + u', w'): a pressure across stays normal to the deformed
  // axis and acts on its current length. Over the abscissae [from, to], of load case `load_case`.
  struct FollowerTraction {
    Vec2 traction;
    double from, to;
    int load_case;
  };
  void add_follower_traction(const FollowerTraction& t) { follower_tractions_.push_back(t); }
  bool has_follower_loads() const override { return !followers_.empty() || !follower_tractions_.empty(); }
  void follower_load(const Vector& q, const std::vector<double>& factors, Vector& force,
                     Triplets* tangent) const override;

  // The mid values (mid_dof) of a b3 are its mid node's u, w, theta.
  int mid_node_count() const { return element_ == BeamElement::b3 ? element_count() : 0; }
  SectionForces section_forces(const Vector& q, int element) const override;
  int axis_shape(int element, double xi, int* slots, double* N, double* dN_dxi) const override;

 private:
  // The element's nodes in local order (ends, then the mid node of a b3) and their abscissae.
  int element_nodes(int e, int* nodes, double* x) const;

  BeamElement element_;
  std::vector<FollowerLoad> followers_;
  std::vector<FollowerTraction> follower_tractions_;
};

}  // namespace grip
