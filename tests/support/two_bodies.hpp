#pragma once
// Readings of scenes of several bodies (BodySet): the contact forces on every dof, each
// body's share of forces, and the contact pressure read on the master side of a pair.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "solver/contact/master_reading.hpp"
#include "solver/model/body_set.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/scenes.hpp"

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

// The shipped two cylinders with elements of `size` near both poles (refine_pole).
inline nlohmann::json cylinders_with_pole_elements(double size) {
  nlohmann::json j = example_scene("two-cylinders");
  for (auto& b : j["bodies"]) refine_pole(b["mesh"]["half_disc"], size);
  return j;
}

// Hertz between two elastic half-discs of the scene (1/R = 1/R1 + 1/R2, 1/E* = sum of
// (1 - nu^2)/E) at load P per unit thickness.
inline HertzContact combined_hertz(const nlohmann::json& scene, double P) {
  double inverse_R = 0, inverse_E = 0;
  for (const nlohmann::json& b : scene["bodies"]) {
    const double E = b["material"]["young"], nu = b["material"]["poisson"];
    inverse_R += 1 / b["mesh"]["half_disc"]["radius"].get<double>();
    inverse_E += (1 - nu * nu) / E;
  }
  const double a = std::sqrt(4 * P / inverse_R * inverse_E / std::numbers::pi);
  return {P, a, 2 * P / (std::numbers::pi * a)};
}

// The forces of every pair cancel over the two bodies, and each body is in equilibrium with
// its own reactions.
inline void expect_pairs_balanced(const Solved& s, const StepRecord& rec) {
  const Problem& problem = s.scene.problem;
  const Vector f = contact_forces(problem, rec);
  double scale = 0.0;
  for (size_t i = 0; i < problem.candidates.size(); ++i) scale += std::abs(rec.p[problem.candidates[i].eta]);
  Vec2 total = Vec2::Zero();
  for (int b = 0; b < body_set(problem).part_count(); ++b) {
    const Vec2 on_body = body_resultant(problem, b, f);
    total += on_body;
    const Vec2 reaction =
        body_resultant(problem, b, rec.reactions) + body_resultant(problem, b, problem.load(rec.factors));
    EXPECT_LT((on_body + reaction).norm(), 1e-7 * scale) << "body " << b << " step " << rec.index;
  }
  EXPECT_LT(total.norm(), 1e-12 * scale) << "step " << rec.index;
}

// The contact stresses on the master body of the pair on `obstacle`, read from the slave's
// traction field (master_readings, the result's master_points). Positions are the master's
// reference x; p_n is the stress times the master's tributary length.
inline std::vector<ContactNode> master_field_profile(const Problem& problem, const StepRecord& rec, int obstacle) {
  std::vector<ContactNode> nodes;
  for (const MasterReading& r : master_readings(problem, rec.state.q, rec.p, rec.tau, obstacle)) {
    ContactNode n;
    n.x = problem.body->site_reference(r.site).x();
    n.sigma_n = r.sigma_n;
    n.sigma_t = r.sigma_t;
    const double area = problem.body->tributary_area(r.site);
    n.p_n = n.sigma_n * area;
    n.p_t = n.sigma_t * area;
    n.state = n.p_n < 0 ? ContactState::slip : ContactState::open;
    nodes.push_back(n);
  }
  std::sort(nodes.begin(), nodes.end(), [](const auto& a, const auto& c) { return a.x < c.x; });
  return nodes;
}

struct CylinderReading {
  HertzContact closed;
  EllipseFit slave, master, master_nodal;  // master: the slave's field read at the master's sites
};

inline CylinderReading read_cylinders(const Solved& s, const StepRecord& rec) {
  const nlohmann::json& scene = s.scene.effective;
  const double P =
      -body_resultant(s.scene.problem, 0, rec.reactions).y() / scene["bodies"][0]["thickness"].get<double>();
  CylinderReading r{combined_hertz(scene, P), fit_semi_ellipse(contact_profile(s.scene.problem, rec)), {}};
  const int master = scene["contacts"][0]["master"].get<std::string>().rfind("lower", 0) == 0 ? 1 : 0;
  const nlohmann::json& disc = scene["bodies"][master]["mesh"]["half_disc"];
  const Vec2 centre(disc["centre"][0].get<double>(), disc["centre"][1].get<double>());
  r.master_nodal = fit_semi_ellipse(
      master_profile(s.scene.problem, rec, master, [&](const Vec2& x) { return Vec2((x - centre).normalized()); }));
  r.master = fit_semi_ellipse(master_field_profile(s.scene.problem, rec, 0));
  std::printf(
      "step %d: P %.2f N/mm, a %.4f mm (slave %+.2f %%, master %+.2f %%, master nodal forces %+.2f %%), "
      "p0 %.1f MPa (slave %+.2f %%, master %+.2f %%, master nodal forces %+.2f %%)\n",
      rec.index, P, r.closed.a, 100 * (r.slave.a / r.closed.a - 1), 100 * (r.master.a / r.closed.a - 1),
      100 * (r.master_nodal.a / r.closed.a - 1), r.closed.p0, 100 * (r.slave.p0 / r.closed.p0 - 1),
      100 * (r.master.p0 / r.closed.p0 - 1), 100 * (r.master_nodal.p0 / r.closed.p0 - 1));
  return r;
}

}  // namespace grip::testing
