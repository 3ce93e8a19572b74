#pragma once
// Timoshenko beam of moderately large deflection (paper Appendix B, after Crisfield):
// three-node elements whose mid-node values are hierarchical (eq. B.3),
//   N = EA (b.u + (b.w)^2 / 2)   (von Karman; the square term is dropped for `linear`)
//   Q = k'GA (b.w + h.theta),   M = EI b.theta.
// The beam lies on a straight line y = y0 along x. theta is the rotation that moves a fibre
// at height z axially by z * theta (theta = -dw/dx without shear), so a surface point at
// offset z sits at (X + u + z theta, y0 + z + w): the von Karman moment arm stays vertical.
// Integration: 3-point Gauss for the axial and bending terms, 2-point (reduced) for shear,
// which avoids shear locking. Units are the scene's (consistent) units.
#include <vector>

#include "solver/model/body.hpp"

namespace grip {

enum class Kinematics { linear, von_karman, finite };

struct BeamSection {
  double EA = 0.0;          // axial stiffness
  double EI = 0.0;          // bending stiffness
  double kGA = 0.0;         // shear stiffness, shear correction factor included
  double half_depth = 0.0;  // h: centre line to either surface
  double width = 1.0;       // out-of-plane width, for contact stresses
};

struct SectionForces {
  double N = 0.0, Q = 0.0, M = 0.0;
};

class TimoshenkoBeam final : public Body {
 public:
  // Node abscissae must increase strictly; one element between consecutive nodes.
  TimoshenkoBeam(std::vector<double> node_x, double y0, BeamSection section, Kinematics kinematics);

  int dof_count() const override { return 3 * node_count() + 3 * element_count(); }
  Vector dof_length_scales() const override;
  void internal_force(const Vector& q, Vector& force, Triplets* tangent) const override;
  int site_count() const override { return node_count(); }
  Vec2 site_reference(int site) const override { return {x_[site], y0_}; }
  SurfacePoint surface_point(const VectorRef& q, int site, int side) const override;
  double tributary_area(int site) const override;
  double characteristic_length() const override { return x_.back() - x_.front(); }

  Vector rigid_translation(const Vec2& d) const override;
  Vector rigid_rotation() const override;
  // Its own finite rotation (the von Karman beam's exact null motion): the rigid rotation with -w
  // added to u, nodal and mid values (solver/problem/rigid_modes.cpp, rotation_at).
  Vector own_rotation_at(const Vector& q) const override;
  // Three dofs a node (u, w, theta); each element's mid values three more after the nodes'.
  int dof_node(int dof) const override { return dof / 3; }
  Traits traits() const override;
  // Rotations beyond kModerateRotation: the moment arm of eq. 2 stays at its reference
  // length, so the answer drifts from an exact-rotation model like 0.45 theta^2 (a
  // cantilever's tip against the elastica: 1 % at 0.15 rad, 10 % at 0.46 rad).
  std::string validity_warning(const Vector& q) const override;
  static constexpr double kModerateRotation = 0.15;  // radian
  std::vector<std::vector<int>> cells() const override;
  FieldTable site_fields(const Vector& q) const override;
  FieldTable element_fields(const Vector& q) const override;

  int node_count() const { return static_cast<int>(x_.size()); }
  int element_count() const { return node_count() - 1; }
  // Global dof of node k: component 0 = u, 1 = w, 2 = theta.
  static int node_dof(int node, int component) { return 3 * node + component; }
  // Global dof of element e's hierarchical mid values (0 = du_q, 1 = dw_q, 2 = theta_q).
  int mid_dof(int element, int component) const { return 3 * node_count() + 3 * element + component; }
  // Section forces at the element midpoint.
  SectionForces section_forces(const Vector& q, int element) const;
  const BeamSection& section() const { return section_; }

 private:
  std::vector<double> x_;
  double y0_;
  BeamSection section_;
  Kinematics kinematics_;
};

}  // namespace grip
