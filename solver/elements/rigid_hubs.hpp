#pragma once
// Rigid hubs of a continuum: node sets that turn as one rigid piece about a centre, each with
// three unknowns of its own, the centre's translation (x, y) and the angle theta
// (docs/algorithm.md#rigid-hubs). The hub's nodes are condensed onto them: node i at X_i sits at
// X_i + u_c + (R(theta) - I)(X_i - c), exactly on its circle with finite kinematics (the small
// rotation theta (-(Y_i - y_c), X_i - x_c) with linear kinematics). A moment on the hub is the
// generalized force on theta (a dead moment does work M theta at any angle), and its reaction
// where theta is prescribed. The hub's nodes keep their place in the node and site numbering;
// only the dofs change: the inner body's dofs off the hubs, in order, then 3 per hub.
#include <memory>
#include <string>
#include <vector>

#include "solver/model/body.hpp"

namespace grip {

struct RigidHub {
  std::string name;  // the node set's name
  std::vector<int> nodes;
  Vec2 centre = Vec2::Zero();
};

class RigidHubs final : public Body {
 public:
  // `inner`: a continuum (two dofs per node, x then y); the hubs' node sets are disjoint.
  RigidHubs(std::unique_ptr<Body> inner, std::vector<RigidHub> hubs);

  const Body& inner() const { return *inner_; }
  const std::vector<RigidHub>& hubs() const { return hubs_; }
  // The dof of hub h's component: 0 x, 1 y (its centre's translation), 2 theta.
  int hub_dof(int h, int component) const { return free_count_ + 3 * h + component; }
  // The dof that replaces the inner body's dof d (-1 for a hub node's).
  int reduced_dof(int d) const { return reduced_[d]; }
  // The inner body's dofs at the state q (the hubs' nodes on their rotation).
  Vector expand(const Vector& q) const;
  // A generalized force on the inner body's dofs as one on these (the hubs' nodes' forces
  // summed into their hub's force and moment about the centre), at the reference state.
  Vector reduce_force(const Vector& inner_force) const;

  int dof_count() const override { return free_count_ + 3 * static_cast<int>(hubs_.size()); }
  Vector dof_length_scales() const override;
  void internal_force(const Vector& q, Vector& force, TangentSink* tangent) const override;
  int site_count() const override { return inner_->site_count(); }
  int node_count() const override { return inner_->node_count(); }
  Vec2 site_reference(int site) const override { return inner_->site_reference(site); }
  int site_node(int site) const override { return inner_->site_node(site); }
  SurfacePoint surface_point(const VectorRef& q, int site, int side) const override;
  std::vector<std::array<int, 2>> surface_segments() const override { return inner_->surface_segments(); }
  std::vector<int> nodes_without_site() const override { return inner_->nodes_without_site(); }
  Vec2 node_position(const VectorRef& q, int node) const override;
  std::vector<int> add_sites(const std::vector<int>& nodes) override { return inner_->add_sites(nodes); }
  double tributary_area(int site) const override { return inner_->tributary_area(site); }
  double characteristic_length() const override { return inner_->characteristic_length(); }
  Vector rigid_translation(const Vec2& d) const override;
  Vector rigid_rotation() const override;
  Vector own_rotation_at(const Vector& q) const override;
  int dof_node(int dof) const override;
  Traits traits() const override { return inner_->traits(); }
  std::optional<ElementQuality> element_quality() const override { return inner_->element_quality(); }
  std::vector<std::vector<int>> cells() const override { return inner_->cells(); }
  FieldTable site_fields(const Vector& q) const override { return inner_->site_fields(expand(q)); }
  FieldTable element_fields(const Vector& q) const override { return inner_->element_fields(expand(q)); }
  double newton_step_fraction(const Vector& q, const Vector& dq) const override;
  std::string inadmissible(const Vector& q) const override { return inner_->inadmissible(expand(q)); }
  std::string validity_warning(const Vector& q) const override { return inner_->validity_warning(expand(q)); }
  void commit(const Vector& q) override { inner_->commit(expand(q)); }

 private:
  bool finite() const { return inner_->traits().geometric_nonlinearity; }
  // d(x_i)/d(theta) of the hub node at arm a = X_i - c, at angle theta.
  Vec2 turn_rate(const Vec2& arm, double theta) const;
  // The reduced dofs (and weights) that inner dof d moves with at the state q: itself, or its
  // hub's translation component and theta.
  struct Link {
    int dof;
    double weight;
  };
  int links(int d, const Vector& q, Link out[2]) const;

  std::unique_ptr<Body> inner_;
  std::vector<RigidHub> hubs_;
  int free_count_ = 0;
  std::vector<int> reduced_;   // inner dof -> reduced dof, -1 on a hub
  std::vector<int> inner_of_;  // reduced dof off the hubs -> inner dof
  std::vector<int> hub_of_;    // inner node -> hub, -1 off the hubs
  std::vector<Vec2> arm_;      // inner node -> X - c of its hub
};

}  // namespace grip
