#pragma once
// Contact tractions along the contact boundary of a converged step, and the readings that the
// analytic contact benchmarks compare with their closed forms (Hertz, Cattaneo-Mindlin).
// Positions are reference positions (x of the undeformed body): the closed forms are those of
// linear elasticity, which does not tell the two apart, and a surface point's lateral
// displacement (inward, of order (1 - 2 nu) P / E) would otherwise shift every reading.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <nlohmann/json.hpp>

#include "solver/contact/contact_error.hpp"
#include "solver/elements/plane_mesh.hpp"
#include "solver/io/result.hpp"
#include "solver/stepping/load_stepping.hpp"
#include "tests/support/scenes.hpp"

namespace grip::testing {

// A half_disc mesh (its JSON object) with elements of `size` within its refinement extent of
// the pole and the fewest divisions beyond it that the generator accepts (the ring's elements
// growing at most 1.4-fold, solver/elements/half_disc_mesh.cpp): [2 (fine + coarse), fine + coarse].
inline void refine_pole(nlohmann::json& disc, double size) {
  const double extent = disc["refine"]["extent"];
  const int fine = static_cast<int>(std::lround(extent / size));
  disc["refine"]["size"] = size;
  HalfDiscSpec spec;
  spec.radius = disc["radius"];
  spec.refine = Refinement{size, extent};
  for (int coarse = 1; coarse <= 1000; ++coarse) {
    spec.ns = 2 * (fine + coarse);
    spec.nt = fine + coarse;
    try {
      half_disc_mesh(spec, ElementShape::q4);
      disc["divisions"] = {spec.ns, spec.nt};
      return;
    } catch (const std::invalid_argument&) {
    }
  }
  throw std::invalid_argument("no divisions hold the refinement");
}

// The one-body half-disc scene with elements of `size` near the pole (refine_pole).
inline nlohmann::json with_pole_elements(nlohmann::json scene, double size) {
  refine_pole(scene["body"]["mesh"]["half_disc"], size);
  return scene;
}

// Hertz's line contact of an effective scene's body (plane strain) under a load P per unit
// thickness: half-width a = sqrt(4 P R / (pi E*)), peak p0 = 2 P / (pi a); R the body's
// half-disc radius, or `radius` when given (a rigid cylinder pressed onto the body).
struct HertzContact {
  double P = 0.0, a = 0.0, p0 = 0.0;
};
inline HertzContact hertz_contact(const nlohmann::json& body, double P, double radius = 0) {
  const double E = body["material"]["young"], nu = body["material"]["poisson"];
  const double R = radius > 0 ? radius : body["mesh"]["half_disc"]["radius"].get<double>();
  const double a = std::sqrt(4 * P * R * (1 - nu * nu) / (std::numbers::pi * E));
  return {P, a, 2 * P / (std::numbers::pi * a)};
}

struct ContactNode {
  double x = 0.0;                       // reference abscissa
  double p_n = 0.0, p_t = 0.0;          // forces (p_n <= 0 presses)
  double sigma_n = 0.0, sigma_t = 0.0;  // force / tributary area
  ContactState state = ContactState::open;
};

// The candidates on `obstacle`, by increasing reference x; the stresses as the result gives them.
inline std::vector<ContactNode> contact_profile(const Problem& problem, const StepRecord& rec, int obstacle = 0) {
  const std::vector<ContactPointRow> rows = contact_point_rows(problem, rec);
  std::vector<ContactNode> nodes;
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    if (c.obstacle != obstacle) continue;
    ContactNode n;
    n.x = problem.body->site_reference(c.site).x();
    n.p_n = rec.p[c.eta];
    n.p_t = c.xi >= 0 ? rec.p[c.xi] : 0.0;
    n.sigma_n = rows[i].sigma_n;
    n.sigma_t = rows[i].sigma_t;
    n.state = contact_state(problem, i, rec.p, rec.tau);
    nodes.push_back(n);
  }
  std::sort(nodes.begin(), nodes.end(), [](const auto& a, const auto& b) { return a.x < b.x; });
  return nodes;
}

// The resultant of the contact forces on the body: of one obstacle's points, or of all (-1).
inline Vec2 contact_resultant(const Problem& problem, const StepRecord& rec, int obstacle = -1) {
  Vec2 total = Vec2::Zero();
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    if (obstacle >= 0 && c.obstacle != obstacle) continue;
    const PairedPoint& pp = rec.state.points[i];
    total += rec.p[c.eta] * pp.eta + (c.xi >= 0 ? rec.p[c.xi] : 0.0) * pp.xi;
  }
  return total;
}

// The resultant of the support reactions on the body.
inline Vec2 reaction_resultant(const Problem& problem, const StepRecord& rec) {
  return {problem.body->rigid_translation(Vec2::UnitX()).dot(rec.reactions),
          problem.body->rigid_translation(Vec2::UnitY()).dot(rec.reactions)};
}

// Where a zone of nodes (contact, or stick) ends, on each side: `inner` is the last node in
// the zone, `outer` the first node beyond it, and `edge` the zero of f^2 extrapolated linearly
// from the last two nodes in the zone, where f is the quantity that vanishes like a square
// root at the zone's end (the contact pressure at a smooth contact edge; the stick margin
// mu |p| - |q| at a stick-slip boundary). Half-widths average the two sides.
struct ZoneEnd {
  double inner = 0.0, outer = 0.0, edge = 0.0;
};
struct Zone {
  bool found = false;
  ZoneEnd left, right;
  double half_width() const { return 0.5 * (right.edge - left.edge); }
  // The longer of the two elements the zone ends in. A nodal force carries the traction over
  // half an element either side of its node, so a closed-form edge is resolved to within half
  // of it beyond the bracket: brackets(w, 0.5 * edge_element()).
  double edge_element() const { return std::max(right.outer - right.inner, left.inner - left.outer); }
  double midpoint_half_width() const { return 0.25 * ((right.inner + right.outer) - (left.inner + left.outer)); }
  // Does a zone of half-width w, centred like this one, end between the nodes on both sides
  // (within `slack`)?
  bool brackets(double w, double slack) const {
    const double centre = 0.5 * (left.edge + right.edge);
    return centre + w >= right.inner - slack && centre + w <= right.outer + slack && centre - w <= left.inner + slack &&
           centre - w >= left.outer - slack;
  }
};

template <class InZone, class Vanishing>
Zone zone_of(const std::vector<ContactNode>& nodes, InZone in_zone, Vanishing f) {
  Zone z;
  int lo = -1, hi = -1;
  for (int k = 0; k < static_cast<int>(nodes.size()); ++k)
    if (in_zone(nodes[k])) {
      if (lo < 0) lo = k;
      hi = k;
    }
  if (lo < 1 || hi + 1 >= static_cast<int>(nodes.size()) || hi - lo < 2) return z;  // needs room on both sides
  auto end = [&](int last, int prev, int beyond) {
    ZoneEnd e{nodes[last].x, nodes[beyond].x, nodes[last].x};
    const double fl = f(nodes[last]) * f(nodes[last]), fp = f(nodes[prev]) * f(nodes[prev]);
    if (fp > fl) e.edge = nodes[last].x + fl * (nodes[last].x - nodes[prev].x) / (fp - fl);
    e.edge = std::clamp(e.edge, std::min(e.inner, e.outer), std::max(e.inner, e.outer));
    return e;
  };
  z.found = true;
  z.left = end(lo, lo + 1, lo - 1);
  z.right = end(hi, hi - 1, hi + 1);
  return z;
}

// Hertz's semi-ellipse sigma_n^2 = p0^2 (1 - (x - xc)^2 / a^2), xc the centre of pressure,
// fitted by least squares (in (x - xc)^2 and sigma_n^2) to the nodes that press: its
// half-width and peak.
struct EllipseFit {
  double a = 0.0, p0 = 0.0;
};
// About a given centre (axisymmetric: the axis, x = r = 0).
inline EllipseFit fit_semi_ellipse_about(const std::vector<ContactNode>& nodes, double xc) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const auto& c : nodes) {
    if (c.p_n >= 0) continue;
    const double x = (c.x - xc) * (c.x - xc), y = c.sigma_n * c.sigma_n;
    n += 1;
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  if (n < 3) return {};
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx), intercept = (sy - slope * sx) / n;
  if (!(slope < 0 && intercept > 0)) return {};
  return {std::sqrt(-intercept / slope), std::sqrt(intercept)};
}
inline EllipseFit fit_semi_ellipse(const std::vector<ContactNode>& nodes) {
  double force = 0, moment = 0;
  for (const auto& c : nodes) {
    force += c.p_n;
    moment += c.p_n * c.x;
  }
  return fit_semi_ellipse_about(nodes, force != 0 ? moment / force : 0.0);
}

// The contact zone: nodes that press; the pressure vanishes like sqrt(a - |x|) at its edges.
inline Zone contact_zone(const std::vector<ContactNode>& nodes) {
  return zone_of(
      nodes, [](const ContactNode& n) { return n.p_n < 0; }, [](const ContactNode& n) { return n.sigma_n; });
}

// The stick zone: nodes that stick; the margin mu |sigma_n| - |sigma_t| vanishes like
// sqrt(c - |x|) at a Cattaneo-Mindlin stick-slip boundary.
inline Zone stick_zone(const std::vector<ContactNode>& nodes, double mu) {
  return zone_of(
      nodes, [](const ContactNode& n) { return n.state == ContactState::stick; },
      [mu](const ContactNode& n) { return mu * std::abs(n.sigma_n) - std::abs(n.sigma_t); });
}

// expect_every_step_sound with the Coulomb cone held only to `tau_relative` of the largest
// normal force: for a strategy stopped just below the contact tolerance (uzawa), whose tau
// passes end when p* moves less than ||v|| pins it (force_precision in strategy.cpp), which
// can be looser than the tau-pass tolerance.
inline void expect_every_step_sound_within(const Solved& s, double tau_relative) {
  EXPECT_TRUE(s.run.completed) << s.run.reason;
  InvariantTolerances tol = tolerances_of(s.scene);
  tol.tau_relative = std::max(tol.tau_relative, tau_relative);
  for (const StepRecord& rec : s.run.steps) {
    EXPECT_TRUE(step_invariants(s.scene.problem, rec, tol));
    EXPECT_TRUE(monotone_contact_error(rec));
  }
}

// The scene solved by cev and by uzawa (up to 5000 real solves a step): both converge at every
// step (uzawa's cone held to 1e-3, as above), and each step's contact forces agree to
// `relative` of the largest. uzawa stops just below the contact tolerance, which pins a force
// only to about (nodal contact stiffness) x (tolerance x length).
struct StrategyRuns {
  Solved cev, uzawa;
};
inline StrategyRuns expect_strategies_agree(const nlohmann::json& scene, double relative) {
  nlohmann::json u = scene;
  u["solver"]["contact"]["method"] = "uzawa";
  u["solver"]["contact"]["max_iterations"] = 5000;
  StrategyRuns runs{solve_scene(scene), solve_scene(u)};
  expect_every_step_sound(runs.cev);
  expect_every_step_sound_within(runs.uzawa, 1e-3);
  std::printf("real solves: cev %ld (%.3f s), uzawa %ld (%.3f s)\n", runs.cev.run.counters.solves, runs.cev.run.seconds,
              runs.uzawa.run.counters.solves, runs.uzawa.run.seconds);
  if (!runs.cev.run.completed || !runs.uzawa.run.completed) return runs;
  for (size_t k = 0; k < runs.cev.run.steps.size(); ++k) {
    const Vector& a = runs.cev.run.steps[k].p;
    const Vector& b = runs.uzawa.run.steps[k].p;
    EXPECT_LT((a - b).lpNorm<Eigen::Infinity>(), relative * a.lpNorm<Eigen::Infinity>()) << "step " << k + 1;
  }
  return runs;
}

}  // namespace grip::testing
