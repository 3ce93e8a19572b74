#include "solver/elements/rigid_hubs.hpp"

#include <cmath>
#include <stdexcept>

namespace grip {

namespace {

Vec2 turned(const Vec2& a, double c, double s) { return Vec2(c * a.x() - s * a.y(), s * a.x() + c * a.y()); }

}  // namespace

RigidHubs::RigidHubs(std::unique_ptr<Body> inner, std::vector<RigidHub> hubs)
    : inner_(std::move(inner)), hubs_(std::move(hubs)) {
  const int n = inner_->node_count();
  if (inner_->dof_count() != 2 * n) throw std::invalid_argument("rigid hubs need two dofs a node");
  const Vector rot = inner_->rigid_rotation();  // (-Y, X) at each node: the reference positions
  hub_of_.assign(n, -1);
  arm_.assign(n, Vec2::Zero());
  for (size_t h = 0; h < hubs_.size(); ++h)
    for (int node : hubs_[h].nodes) {
      if (hub_of_[node] >= 0) throw std::invalid_argument("node " + std::to_string(node) + " is in two hubs");
      hub_of_[node] = static_cast<int>(h);
      arm_[node] = Vec2(rot[2 * node + 1], -rot[2 * node]) - hubs_[h].centre;
    }
  reduced_.assign(2 * n, -1);
  for (int d = 0; d < 2 * n; ++d)
    if (hub_of_[d / 2] < 0) {
      reduced_[d] = free_count_++;
      inner_of_.push_back(d);
    }
}

Vec2 RigidHubs::turn_rate(const Vec2& arm, double theta) const {
  if (!finite()) return Vec2(-arm.y(), arm.x());
  return turned(Vec2(-arm.y(), arm.x()), std::cos(theta), std::sin(theta));
}

Vector RigidHubs::expand(const Vector& q) const {
  Vector full(inner_->dof_count());
  for (int d = 0; d < full.size(); ++d)
    if (reduced_[d] >= 0) full[d] = q[reduced_[d]];
  for (int node = 0; node < static_cast<int>(hub_of_.size()); ++node) {
    const int h = hub_of_[node];
    if (h < 0) continue;
    const double theta = q[hub_dof(h, 2)];
    const Vec2 a = arm_[node];
    const Vec2 spin =
        finite() ? Vec2(turned(a, std::cos(theta), std::sin(theta)) - a) : Vec2(theta * Vec2(-a.y(), a.x()));
    full.segment<2>(2 * node) = Vec2(q[hub_dof(h, 0)], q[hub_dof(h, 1)]) + spin;
  }
  return full;
}

int RigidHubs::links(int d, const Vector& q, Link out[2]) const {
  if (reduced_[d] >= 0) {
    out[0] = {reduced_[d], 1.0};
    return 1;
  }
  const int node = d / 2, component = d % 2, h = hub_of_[node];
  const double theta = q.size() ? q[hub_dof(h, 2)] : 0.0;
  out[0] = {hub_dof(h, component), 1.0};
  out[1] = {hub_dof(h, 2), turn_rate(arm_[node], theta)[component]};
  return 2;
}

Vector RigidHubs::reduce_force(const Vector& inner_force) const {
  Vector f = Vector::Zero(dof_count());
  Link l[2];
  for (int d = 0; d < inner_force.size(); ++d)
    for (int k = 0, m = links(d, Vector(), l); k < m; ++k) f[l[k].dof] += l[k].weight * inner_force[d];
  return f;
}

void RigidHubs::internal_force(const Vector& q, Vector& force, TangentSink* tangent) const {
  const Vector full = expand(q);
  Vector f = Vector::Zero(full.size());
  Triplets inner_tangent;  // mapped through the links below, entry by entry
  TripletSink inner_sink(inner_tangent);
  const Vector base = tangent && tangent->stress_base ? expand(*tangent->stress_base) : Vector();
  if (base.size()) inner_sink.stress_base = &base;
  inner_->internal_force(full, f, tangent ? &inner_sink : nullptr);
  Link l[2];
  for (int d = 0; d < f.size(); ++d)
    for (int k = 0, m = links(d, q, l); k < m; ++k) force[l[k].dof] += l[k].weight * f[d];
  if (!tangent) return;
  // P^T K P, P the links at q; every product emitted (the pattern repeats from one call to the
  // next, which the free-block solver relies on).
  Link a[2], b[2];
  for (const auto& t : inner_tangent) {
    const int ma = links(t.row(), q, a), mb = links(t.col(), q, b);
    for (int i = 0; i < ma; ++i)
      for (int j = 0; j < mb; ++j) tangent->add(a[i].dof, b[j].dof, a[i].weight * b[j].weight * t.value());
  }
  // The turn's own curvature with finite kinematics: d2x_i/dtheta2 = -R(theta) a_i, so the
  // hub's force does work at second order: sum_i f_i . (-R(theta) a_i) on (theta, theta).
  for (size_t h = 0; h < hubs_.size(); ++h) {
    const double theta = q[hub_dof(static_cast<int>(h), 2)];
    double curvature = 0.0;
    if (finite())
      for (int node : hubs_[h].nodes)
        curvature -= f.segment<2>(2 * node).dot(turned(arm_[node], std::cos(theta), std::sin(theta)));
    const int t = hub_dof(static_cast<int>(h), 2);
    tangent->add(t, t, curvature);
  }
}

SurfacePoint RigidHubs::surface_point(const VectorRef& q, int site, int side) const {
  const Vector qv = q;
  SurfacePoint p = inner_->surface_point(expand(qv), site, side);
  std::vector<PointJacobianEntry> jacobian;
  Link l[2];
  for (const auto& j : p.jacobian)
    for (int k = 0, m = links(j.dof, qv, l); k < m; ++k) jacobian.push_back({l[k].dof, l[k].weight * j.dx});
  p.jacobian = std::move(jacobian);
  return p;
}

Vec2 RigidHubs::node_position(const VectorRef& q, int node) const {
  return inner_->node_position(expand(Vector(q)), node);
}

Vector RigidHubs::dof_length_scales() const {
  const Vector inner = inner_->dof_length_scales();
  Vector s = Vector::Ones(dof_count());
  for (int d = 0; d < inner.size(); ++d)
    if (reduced_[d] >= 0) s[reduced_[d]] = inner[d];
  for (int node = 0; node < static_cast<int>(hub_of_.size()); ++node)
    if (hub_of_[node] >= 0) {
      const int t = hub_dof(hub_of_[node], 2);
      s[t] = std::max(s[t], arm_[node].norm());  // a radian moves the farthest node by its arm
    }
  return s;
}

Vector RigidHubs::rigid_translation(const Vec2& d) const {
  Vector t = Vector::Zero(dof_count());
  const Vector inner = inner_->rigid_translation(d);
  for (int k = 0; k < inner.size(); ++k)
    if (reduced_[k] >= 0) t[reduced_[k]] = inner[k];
  for (size_t h = 0; h < hubs_.size(); ++h) t.segment<2>(hub_dof(static_cast<int>(h), 0)) = d;
  return t;
}

Vector RigidHubs::rigid_rotation() const {
  const Vector inner = inner_->rigid_rotation();
  if (inner.size() == 0) return {};
  Vector r = Vector::Zero(dof_count());
  for (int k = 0; k < inner.size(); ++k)
    if (reduced_[k] >= 0) r[reduced_[k]] = inner[k];
  for (size_t h = 0; h < hubs_.size(); ++h) {
    const Vec2 c = hubs_[h].centre;
    const int x = hub_dof(static_cast<int>(h), 0);
    r.segment<3>(x) = Eigen::Vector3d(-c.y(), c.x(), 1.0);
  }
  return r;
}

// The rotation by one radian about the origin at q: every node off the hubs about its current
// position, each hub's centre about its current position, and each hub's angle by one radian.
// The hubs' nodes then turn about the origin with the rest, so the internal forces do no work
// along it (solver/problem/rigid_modes.cpp).
Vector RigidHubs::own_rotation_at(const Vector& q) const {
  if (!finite()) return rigid_rotation();
  Vector r = rigid_rotation();
  const Vector full = expand(q);
  for (int node = 0; node < static_cast<int>(hub_of_.size()); ++node)
    if (hub_of_[node] < 0) {
      r[reduced_[2 * node]] -= full[2 * node + 1];
      r[reduced_[2 * node + 1]] += full[2 * node];
    }
  for (size_t h = 0; h < hubs_.size(); ++h) {
    const int x = hub_dof(static_cast<int>(h), 0);
    r[x] -= q[x + 1];
    r[x + 1] += q[x];
  }
  return r;
}

int RigidHubs::dof_node(int dof) const {
  if (dof >= free_count_) return hubs_[(dof - free_count_) / 3].nodes.front();
  return inner_->dof_node(inner_of_[dof]);
}

double RigidHubs::newton_step_fraction(const Vector& q, const Vector& dq) const {
  const Vector full = expand(q);
  return inner_->newton_step_fraction(full, expand(Vector(q + dq)) - full);
}

}  // namespace grip
