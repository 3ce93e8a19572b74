#pragma once
// Rigid-plastic membrane in plane strain (paper Appendix A, after Germain, Chung & Wagoner),
// solved in incremental form (eq. 1): two-node elements; unknowns are the nodal displacements
// from the initial configuration, and each step's increment is measured from the state
// committed at the end of the previous step.
//
// Hill's 1979 yield with r and M; hardening sigma_bar = H (eps_bar + a0)^n. In plane strain
// (d2 = 0) the effective strain increment (docs/algorithm.md#reading-the-paper) is c |d1| with
//   c = 0.5 [2(1+r)]^(1/M) [1 + (1+2r)^(-1/(M-1))]^((M-1)/M)   (2/sqrt(3) for r = 1, M = 2),
// d1 = ln(l / L0) the logarithmic stretch increment of the element. An element with d1 = 0 has
// an indeterminate stress, so d1 enters through the smooth regularization of section 9,
//   d_eps_bar = sqrt(c^2 d1^2 + e0^2) - e0,
// with e0 = `regularization` (default 1e-5): an element straining by much less than e0 per
// step behaves as (stiff) elastic instead of rigid. Tension per unit width:
//   T = sigma_bar(eps_bar + d_eps_bar) * V * d(d_eps_bar)/dl,  V = t L (constant volume).
// Thickness follows volume constancy, t = V / l. Contact points are the mid-surface nodes
// with a clearance of half the current thickness toward the obstacle (frozen in T), and the
// contact force acts on the node (virtual work at the node: the friction force is not scaled
// by R / (R + t/2)).
#include <vector>

#include "solver/model/body.hpp"

namespace grip {

struct HillMaterial {
  double r = 1.0;                // normal anisotropy
  double M = 2.0;                // yield-surface exponent, > 1
  double H = 0.0;                // hardening coefficient (stress)
  double a0 = 1e-4;              // pre-strain
  double n = 0.2;                // hardening exponent
  double regularization = 1e-5;  // e0: strain-increment scale of the smooth cut-off
  // The plane-strain factor c of d_eps_bar = c |d1|.
  double plane_strain_factor() const;
  double flow_stress(double eps_bar) const;
  double hardening_slope(double eps_bar) const;
};

class RigidPlasticMembrane final : public Body {
 public:
  // Nodes in order along the sheet; `thickness` initial; `width` out of plane.
  RigidPlasticMembrane(std::vector<Vec2> nodes, double thickness, HillMaterial material, double width = 1.0);

  int dof_count() const override { return 2 * node_count(); }
  Vector dof_length_scales() const override { return Vector::Ones(dof_count()); }
  void internal_force(const Vector& q, Vector& force, Triplets* tangent) const override;
  int site_count() const override { return node_count(); }
  Vec2 site_reference(int site) const override { return nodes_[site]; }
  SurfacePoint surface_point(const VectorRef& q, int site, int side) const override;
  double tributary_area(int site) const override;
  double characteristic_length() const override;
  // No rigid_rotation: a membrane has no bending stiffness, so every transverse motion of a
  // flat sheet is free until tension stiffens it; solver.start handles that state.
  Vector rigid_translation(const Vec2& d) const override;
  Traits traits() const override { return {true, true, false}; }
  std::vector<std::vector<int>> cells() const override;
  FieldTable site_fields(const Vector& q) const override;
  FieldTable element_fields(const Vector& q) const override;
  Vector start_guess(const Vector& prescribed, const std::vector<char>& is_prescribed) const override;
  double newton_step_fraction(const Vector& q, const Vector& dq) const override;
  std::string inadmissible(const Vector& q) const override;
  void commit(const Vector& q) override;

  int node_count() const { return static_cast<int>(nodes_.size()); }
  int element_count() const { return node_count() - 1; }
  static int node_dof(int node, int component) { return 2 * node + component; }

  // The element's kinematics and stress at state q, from the committed state.
  struct ElementState {
    Vec2 e;                // unit vector node a -> node b
    double l = 0.0;        // current length
    double d1 = 0.0;       // logarithmic stretch increment of the step
    double deps = 0.0;     // regularized effective strain increment
    double sigma = 0.0;    // flow stress at eps_bar + deps
    double tension = 0.0;  // per unit width
    double dtension_dl = 0.0;
    double thickness = 0.0;  // current
  };
  ElementState element_state(const Vector& q, int element) const;

 private:
  std::vector<Vec2> nodes_;
  double width_;
  HillMaterial material_;
  double c_;  // plane-strain factor
  double initial_thickness_;
  std::vector<double> initial_length_;
  // Committed state (end of the last converged step).
  std::vector<double> eps_bar_, thickness_, length_;
};

}  // namespace grip
