#pragma once
// Readings of scenes of several bodies (BodySet): the contact forces on every dof, each
// body's share of forces, and the contact pressure read on the master side of a pair.
#include <algorithm>
#include <cmath>
#include <vector>

#include "solver/core/body_set.hpp"
#include "tests/support/contact_profile.hpp"

namespace grip::testing {

inline const BodySet& body_set(const Problem& problem) { return dynamic_cast<const BodySet&>(*problem.body); }

// T p on every dof: the contact forces on both bodies of every pair.
inline Vector contact_forces(const Problem& problem, const StepRecord& rec) {
  Vector f = Vector::Zero(problem.body->dof_count());
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    const PairedPoint& pp = rec.state.points[i];
    const Vec2 force = rec.p[c.eta] * pp.eta + (c.xi >= 0 ? rec.p[c.xi] : 0.0) * pp.xi;
    for (const auto& j : pp.point.jacobian) f[j.dof] += j.dx.dot(force);
  }
  return f;
}

// The resultant of a generalized force on body b (a rigid translation of b alone).
inline Vec2 body_resultant(const Problem& problem, int b, const Vector& force) {
  const BodySet& all = body_set(problem);
  const int o = all.dof_offset(b), n = all.part(b).dof_count();
  const Vector fb = force.segment(o, n);
  return {all.part(b).rigid_translation(Vec2::UnitX()).dot(fb), all.part(b).rigid_translation(Vec2::UnitY()).dot(fb)};
}

// The contact pressure on the master body b of a pair, per master site: the force T p puts on
// the site along the master's outward normal `outward(reference position)`, over the site's
// tributary area; p_t the rest of the force, along rot90(outward). Positions are reference x.
template <class Outward>
std::vector<ContactNode> master_profile(const Problem& problem, const StepRecord& rec, int b, Outward outward) {
  const BodySet& all = body_set(problem);
  const Vector f = contact_forces(problem, rec);
  std::vector<ContactNode> nodes;
  const Body& master = all.part(b);
  const Vector q0 = Vector::Zero(master.dof_count());
  for (int s = 0; s < master.site_count(); ++s) {
    const SurfacePoint sp = master.surface_point(q0, s, 0);
    Vec2 force = Vec2::Zero();
    for (const auto& j : sp.jacobian) force += f[all.dof_offset(b) + j.dof] * j.dx;
    const Vec2 n_out = outward(master.site_reference(s));
    ContactNode n;
    n.x = master.site_reference(s).x();
    n.p_n = force.dot(n_out);
    n.p_t = force.dot(rot90(n_out));
    n.sigma_n = n.p_n / master.tributary_area(s);
    n.sigma_t = n.p_t / master.tributary_area(s);
    n.state = n.p_n < 0 ? ContactState::slip : ContactState::open;
    nodes.push_back(n);
  }
  // A slave point a hair from a master site still hands a share to the segment's other end
  // (t of 1e-5, matching meshes): below 1e-3 of the peak that is no contact edge to fit.
  double peak = 0.0;
  for (const auto& n : nodes) peak = std::max(peak, -n.p_n);
  for (auto& n : nodes)
    if (-n.p_n < 1e-3 * peak) n.state = ContactState::open, n.p_n = n.sigma_n = 0.0;
  std::sort(nodes.begin(), nodes.end(), [](const auto& a, const auto& c) { return a.x < c.x; });
  return nodes;
}

}  // namespace grip::testing
