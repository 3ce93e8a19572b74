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
//
// Axisymmetric (docs/algorithm.md#axisymmetric-membrane): the polyline is a meridian in the
// r-z half-plane (x = r >= 0, y = z), each element a conical frustum. Two strain increments,
// meridional d1 = ln(l / L0) and hoop d2 = ln(rm / Rm0) (rm the element's mid radius), and
// Hill's effective strain increment for normal anisotropy (the work conjugate of Hill 1979),
//   phi = A [ |d1 + d2|^m + B |d1 - d2|^m ]^(1/m),  m = M / (M - 1),
//   A = [2(1+r)]^(1/M) / 2, B = (1 + 2r)^(-1/(M-1))   (phi = c |d1| at d2 = 0),
// regularized as d_eps_bar = sqrt(phi^2 + e0^2) - e0. The element's work of the step,
// V int_0^d_eps_bar sigma_bar(eps_bar + s) ds with V = 2 pi Rm t L its volume, is the
// potential of its nodal forces (forces are totals over the circle); thickness t = V / (2 pi
// rm l) = t0 exp(-(e1 + e2)). M > 2 (m < 2) makes the Hessian of phi^2 unbounded at equal increments.
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
  // Half the square of Hill's effective strain increment, psi = phi^2 / 2, of the meridional
  // and hoop increments d = (d1, d2), with its gradient and Hessian.
  double half_square_increment(const Vec2& d, Vec2* gradient, Mat2* hessian) const;
};

class RigidPlasticMembrane final : public Body {
 public:
  // Nodes in order along the sheet; `thickness` initial; `width` out of plane (plane strain).
  // Axisymmetric: the nodes at x = r >= 0, no element on the axis; `width` unused.
  RigidPlasticMembrane(std::vector<Vec2> nodes, double thickness, HillMaterial material, double width = 1.0,
                       bool axisymmetric = false);

  int dof_count() const override { return 2 * node_count(); }
  Vector dof_length_scales() const override { return Vector::Ones(dof_count()); }
  void internal_force(const Vector& q, Vector& force, TangentSink* tangent) const override;
  int site_count() const override { return node_count(); }
  Vec2 site_reference(int site) const override { return nodes_[site]; }
  SurfacePoint surface_point(const VectorRef& q, int site, int side) const override;
  double tributary_area(int site) const override;
  double characteristic_length() const override;
  // No rigid_rotation: a membrane has no bending stiffness, so every transverse motion of a
  // flat sheet is free until tension stiffens it; solver.start handles that state.
  Vector rigid_translation(const Vec2& d) const override;
  Traits traits() const override { return {true, true, false, false}; }
  bool axisymmetric() const override { return axisymmetric_; }
  std::vector<std::vector<int>> cells() const override;
  FieldTable site_fields(const Vector& q) const override;
  FieldTable element_fields(const Vector& q) const override;
  Vector start_guess(const Vector& prescribed, const std::vector<char>& is_prescribed) const override;
  // A pressure on every element that follows the sheet (docs/algorithm.md#membrane-pressure):
  // `value` per unit current area, at load factor 1 of `load_case`, pushing each element toward
  // its left (+y for a sheet running along +x), on the current (swept) area.
  void add_pressure(double value, int load_case) { pressures_.push_back({value, load_case}); }
  bool has_follower_loads() const override { return !pressures_.empty(); }
  void follower_load(const Vector& q, const std::vector<double>& factors, Vector& force,
                     Triplets* tangent) const override;
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

  // Axisymmetric: the element's strain increments, its nodal forces (xa, ya, xb, yb) and,
  // if K is given, their derivative.
  struct FrustumState {
    double l = 0.0, rm = 0.0;        // current length and mid radius
    double d1 = 0.0, d2 = 0.0;       // meridional and hoop strain increments of the step
    double deps = 0.0, sigma = 0.0;  // regularized effective strain increment, flow stress
    double thickness = 0.0;          // current
    double tension = 0.0;            // meridional force per unit length of the circle
    Eigen::Vector4d force = Eigen::Vector4d::Zero();
  };
  FrustumState frustum_state(const VectorRef& q, int element, Eigen::Matrix4d* K) const;

 private:
  double current_thickness(const VectorRef& q, int element) const;
  struct Pressure {
    double value;
    int load_case;
  };
  std::vector<Pressure> pressures_;
  std::vector<Vec2> nodes_;
  double width_;
  HillMaterial material_;
  double c_;  // plane-strain factor
  double initial_thickness_;
  std::vector<double> initial_length_;
  bool axisymmetric_ = false;
  std::vector<double> initial_radius_, volume_;  // axisymmetric: mid radius, 2 pi Rm t L
  std::vector<Vec2> committed_x_;                // axisymmetric: node positions at the last commit
  // Committed state (end of the last converged step).
  std::vector<double> eps_bar_, thickness_, length_, radius_;
};

}  // namespace grip
