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

#include "solver/elements/straight_beam.hpp"

namespace grip {

enum class Kinematics { linear, von_karman, finite };

class TimoshenkoBeam final : public StraightBeam {
 public:
  TimoshenkoBeam(std::vector<double> node_x, double y0, BeamSection section, Kinematics kinematics);

  int dof_count() const override { return 3 * node_count() + 3 * element_count(); }
  void internal_force(const Vector& q, Vector& force, TangentSink* tangent) const override;
  SurfacePoint surface_point(const VectorRef& q, int site, int side) const override;

  Vector rigid_translation(const Vec2& d) const override;
  Vector rigid_rotation() const override;
  // Its own finite rotation (the von Karman beam's exact null motion): the rigid rotation with -w
  // added to u, nodal and mid values (solver/problem/rigid_modes.cpp, rotation_at).
  Vector own_rotation_at(const Vector& q) const override;
  Traits traits() const override;
  // Rotations beyond kModerateRotation: the moment arm of eq. 2 stays at its reference
  // length, so the answer drifts from an exact-rotation model like 0.45 theta^2 (a
  // cantilever's tip against the elastica: 1 % at 0.15 rad, 10 % at 0.46 rad).
  std::string validity_warning(const Vector& q) const override;
  static constexpr double kModerateRotation = 0.15;  // radian

  // Mid values (mid_dof) are hierarchical: 0 = du_q, 1 = dw_q, 2 = theta_q.
  SectionForces section_forces(const Vector& q, int element) const override;
  int axis_shape(int element, double xi, int* slots, double* N, double* dN_dxi) const override;

 private:
  Kinematics kinematics_;
};

}  // namespace grip
