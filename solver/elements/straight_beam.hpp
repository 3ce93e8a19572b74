#pragma once
// What the plane beams share: the axis on the line y = y0 along x, nodes at strictly
// increasing abscissae with one element between consecutive nodes, three dofs per node
// (u, w, theta) and, after the nodes', three per element for the mid values. How the mid
// values are read and how the section deforms is each model's own (timoshenko_beam.hpp,
// reissner_beam.hpp).
#include <algorithm>
#include <vector>

#include "solver/model/body.hpp"

namespace grip {

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

class StraightBeam : public Body {
 public:
  // Throws std::invalid_argument unless there are two or more strictly increasing abscissae.
  StraightBeam(std::vector<double> node_x, double y0, BeamSection section);

  // Every third dof is a rotation, scaled by the beam's length.
  Vector dof_length_scales() const override;
  int site_count() const override { return node_count(); }
  Vec2 site_reference(int site) const override { return {x_[site], y0_}; }
  // The node's share of the axis' length times the section's width.
  double tributary_area(int site) const override;
  double characteristic_length() const override { return x_.back() - x_.front(); }
  int dof_node(int dof) const override { return dof / 3; }
  std::vector<std::vector<int>> cells() const override;
  FieldTable site_fields(const Vector& q) const override;
  // N, Q, M per element, from section_forces.
  FieldTable element_fields(const Vector& q) const override;

  int node_count() const override { return static_cast<int>(x_.size()); }
  int element_count() const { return node_count() - 1; }
  // Global dof of node k: component 0 = u, 1 = w, 2 = theta.
  static int node_dof(int node, int component) { return 3 * node + component; }
  // Global dof of element e's mid values, in the same component order.
  int mid_dof(int element, int component) const { return 3 * (node_count() + element) + component; }
  const BeamSection& section() const { return section_; }
  // Section forces at the element's centre.
  virtual SectionForces section_forces(const Vector& q, int element) const = 0;
  // How element e interpolates the axis' displacement (u, w) at xi in [-1, 1]: the node slots k
  // whose dofs 3k, 3k + 1 carry it, the shape values N and their derivatives dN/dxi; returns
  // how many (at most 3).
  virtual int axis_shape(int element, double xi, int* slots, double* N, double* dN_dxi) const = 0;
  // The consistent nodal forces of a dead load `per_length` [qx, qy] per unit length of the
  // undeformed axis over the abscissae [from, to], added to `load`.
  void add_line_load(const Vec2& per_length, double from, double to, Vector& load) const;

 protected:
  // Calls visit(element, xi, dx) at Gauss points (exact to degree 5) over [from, to]: dx is
  // the point's weight times the length it stands for.
  template <class Visit>
  void over_span(double from, double to, Visit visit) const {
    static const double xi[3] = {-0.7745966692414834, 0.0, 0.7745966692414834}, w[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
    for (int e = 0; e < element_count(); ++e) {
      const double a = std::max(from, x_[e]), b = std::min(to, x_[e + 1]);
      if (!(b > a)) continue;
      for (int g = 0; g < 3; ++g) {
        const double x = 0.5 * (a + b) + 0.5 * (b - a) * xi[g];
        visit(e, 2 * (x - x_[e]) / (x_[e + 1] - x_[e]) - 1, 0.5 * (b - a) * w[g]);
      }
    }
  }

  std::vector<double> x_;
  double y0_;
  BeamSection section_;
};

}  // namespace grip
