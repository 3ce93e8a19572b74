#include "solver/stepping/step_checks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "solver/model/body_set.hpp"

namespace grip {
namespace {

// A number for a reason: 3 significant digits.
std::string num(double x) {
  std::ostringstream s;
  s.precision(3);
  s << x;
  return s.str();
}

}  // namespace

std::vector<StepChecker::BodyModes> StepChecker::body_modes(const Body& body) {
  std::vector<BodyModes> out;
  auto add = [&](const Body& part, int offset) {
    BodyModes b{{}, part.characteristic_length()};
    for (const Vec2& d : {Vec2(Vec2::UnitX()), Vec2(Vec2::UnitY())}) {
      Vector m = Vector::Zero(body.dof_count());
      m.segment(offset, part.dof_count()) = part.rigid_translation(d);
      b.modes.push_back(std::move(m));
    }
    if (const Vector r = part.rigid_rotation(); r.size()) {
      Vector m = Vector::Zero(body.dof_count());
      m.segment(offset, part.dof_count()) = r;
      b.modes.push_back(std::move(m));
    }
    out.push_back(std::move(b));
  };
  for (int b = 0; b < std::max(1, body.part_count()); ++b) add(body.part(b), body.dof_offset(b));
  return out;
}

void StepChecks::worst_of(const StepChecks& o) {
  balance = std::max(balance, o.balance);
  tension = std::max(tension, o.tension);
  cone = std::max(cone, o.cone);
  penetration = std::max(penetration, o.penetration);
  normal_turn = std::max(normal_turn, o.normal_turn);
  obstacle_motion = std::max(obstacle_motion, o.obstacle_motion);
  boundary_points = std::max(boundary_points, o.boundary_points);
}

StepCheckLimits check_limits(const Problem& problem, const ContactParams& contact) {
  StepCheckLimits l;
  // A converged state balances to Newton's residual test (newton_fraction x tolerance of the
  // forces) except on a held body's amplitude rows, which ||v|| <= tol x L bounds only in length
  // units: up to 5.7 % of the forces on the verification scenes today (a block pushed onto a
  // wall), 12-38 % on the held bodies of issue 33. 0.1 refuses the latter and keeps the former
  // until the tolerance follows the load (issue 33.2), then 1e-3 (docs/robustness.md#limits).
  l.balance = 0.1;
  // The strategies put p_n <= 0 exactly; penalty's linearized law within rounding.
  l.tension = 1e-6;
  // Coulomb's cone: to rounding where the bound moves with p_n, to the tau passes' tolerance
  // (relative to max |p_eta|) with tau passes.
  l.cone = std::max(1e-6, 10 * contact.tau_tolerance);
  // Each component of the contact error is at most tol x L at a converged step.
  l.penetration = 10 * contact.tolerance * problem.body->characteristic_length();
  return l;
}

AcceptedContact accepted_contact(const EquilibriumState& state, const Vector& p) {
  AcceptedContact a;
  a.p = p;
  for (const PairedPoint& pp : state.points) a.eta.push_back(pp.eta);
  return a;
}

StepChecker::StepChecker(const Problem& problem, const ContactParams& contact, double reach)
    : problem_(problem), penalty_(contact.method == ContactMethod::penalty),
      reach_(reach > 0 ? reach : problem.body->characteristic_length()), limits_(check_limits(problem, contact)) {
  const Body& body = *problem.body;
  const int sites = body.site_count(), obstacles = static_cast<int>(problem.obstacles.size());
  std::vector<char> paired(static_cast<size_t>(sites) * obstacles, 0);
  for (const Candidate& c : problem.candidates) paired[static_cast<size_t>(c.site) * obstacles + c.obstacle] = 1;
  for (int o = 0; o < obstacles; ++o) {
    const ObstacleInstance& obstacle = problem.obstacles[o];
    if (!obstacle.shape) continue;  // a pair of bodies: its slave set is the contact's own choice
    for (int site = 0; site < sites; ++site) {
      if (paired[static_cast<size_t>(site) * obstacles + o]) continue;
      // The side that faces the obstacle in the reference configuration (add_candidates' rule).
      const Vec2 x = body.site_reference(site);
      const int side = (obstacle.shape->project(x).point - x).y() >= 0 ? +1 : -1;
      outside_sites_.push_back({site, side, o});
    }
  }
  nodes_without_site_ = body.nodes_without_site();
  body_modes_ = body_modes(body);
  // The element size: the largest spacing of a site to its nearer neighbour in site order.
  for (int site = 0; site < sites; ++site) {
    double d = std::numeric_limits<double>::infinity();
    if (site > 0) d = std::min(d, (body.site_reference(site) - body.site_reference(site - 1)).norm());
    if (site + 1 < sites) d = std::min(d, (body.site_reference(site) - body.site_reference(site + 1)).norm());
    if (std::isfinite(d)) element_size_ = std::max(element_size_, d);
  }
  if (!(element_size_ > 0)) element_size_ = body.characteristic_length();
}

double StepChecker::increment(const LoadFactors& from, const LoadFactors& to, StepChecks& worst,
                              std::string& why) const {
  double worst_ratio = 0.0;
  for (const ObstacleInstance& o : problem_.obstacles) {
    if (!o.shape || o.translations.empty()) continue;
    const double travel = (o.offset(to) - o.offset(from)).norm();
    const double radius = o.shape->smallest_radius();
    const double bound = std::min(element_size_, radius);
    const double ratio = travel / bound;
    if (ratio > worst_ratio) worst_ratio = ratio;
    if (ratio > limits_.obstacle_motion * (1 + 1e-9) && why.empty())
      why = "the obstacle '" + o.name + "' moves by " + num(travel) + " in one increment, more than " +
            (radius < element_size_ ? "its radius of curvature " : "the body's element size ") + num(bound) +
            ": it could pass through the body";
  }
  worst.obstacle_motion = std::max(worst.obstacle_motion, worst_ratio);
  return worst_ratio / limits_.obstacle_motion;
}

std::string StepChecker::state(const Equilibrium& eq, const EquilibriumState& s, const Vector& p,
                               const AcceptedContact& before, StepChecks& worst,
                               std::vector<OutsidePoint>& outside) const {
  const Problem& pr = problem_;
  const Body& body = *pr.body;
  StepChecks c;
  std::string why;
  auto fail = [&why](std::string text) {
    if (why.empty()) why = std::move(text);
  };

  // Balance: the residual A(q) - F - T p is zero at the free dofs (to Newton's test) and the
  // reaction at a support; at a held body's pins it is the force nothing real carries.
  // The residual as Newton forms it (the body's forces, a pair's and a foundation's included).
  const Vector applied = eq.applied_forces(s, p);
  Vector residual = eq.residual(s.q, p, nullptr);
  const Vector internal_forces = residual + applied;
  // What the body carries: the loads and the contact forces each counted, not their sum (a
  // point load on a node that presses a flat is cancelled there by its contact force).
  const Vector load = pr.load(eq.factors());
  Vector carried = load.cwiseAbs() + (applied - load).cwiseAbs();
  for (const Constraint& k : pr.constraints) {
    carried[k.dof] += std::abs(residual[k.dof]);
    residual[k.dof] = 0.0;
  }
  // Where loads, contact and reactions vanish (a punch lifted off a clamped sheet), a residual
  // at the round-off of the body's own forces or of the run's force level is no imbalance.
  const double internal = internal_forces.cwiseAbs().maxCoeff();
  force_level_ = std::max(force_level_, carried.maxCoeff());
  const double floor = 1e-8 * std::max(internal, force_level_);
  // Each resultant over what the body carries: along an axis that carries nothing (a vertical
  // load), over what the other axis carries; a moment over that times the body's length. A
  // body that carries only moments (a beam rolled up by end moments) scales its forces by the
  // moment over its length.
  for (const BodyModes& b : body_modes_) {
    std::vector<double> scales;
    for (const Vector& m : b.modes) scales.push_back(m.cwiseAbs().dot(carried));
    const double moments = scales.size() > 2 ? scales[2] / b.length : 0.0;
    const double translations = std::max({scales[0], scales[1], moments});
    for (size_t k = 0; k < b.modes.size(); ++k) {
      const double scale = std::max(scales[k], k < 2 ? translations : translations * b.length);
      const double off = std::abs(b.modes[k].dot(residual));
      if (off > floor) c.balance = std::max(c.balance, scale > 0 ? off / scale : 1.0);
    }
  }
  if (c.balance > limits_.balance)
    fail("a body is out of balance by " + num(c.balance) + " of the forces it carries (limit " + num(limits_.balance) +
         ")");

  // Contact forces: no tension, the cone; candidates inside an obstacle; the normal's turn.
  double max_pn = 0.0;
  for (const Candidate& k : pr.candidates) max_pn = std::max(max_pn, std::abs(p[k.eta]));
  int worst_tension = -1, worst_cone = -1, worst_turn = -1;
  for (size_t i = 0; i < pr.candidates.size(); ++i) {
    const Candidate& k = pr.candidates[i];
    const double pn = p[k.eta], pt = k.xi >= 0 ? p[k.xi] : 0.0;
    const double mu = pr.obstacles[k.obstacle].friction;
    if (max_pn > 0 && pn > 0 && pn / max_pn > c.tension) {
      c.tension = pn / max_pn;
      worst_tension = static_cast<int>(i);
    }
    const double over = std::abs(pt) - mu * std::abs(pn);
    if (over > 0) {
      const double rel = max_pn > 0 ? over / max_pn : 1.0;
      if (rel > c.cone) {
        c.cone = rel;
        worst_cone = static_cast<int>(i);
      }
    }
    const PairedPoint& pp = s.points[i];
    // Penalty's law penetrates by design (its own measure, the result's penetration); the other
    // strategies hold every candidate's gap to the tolerance.
    if (!penalty_) c.penetration = std::max(c.penetration, -pp.projection.gap);
    const bool pressed = pn < 0 || (i < before.eta.size() && before.p.size() > k.eta && before.p[k.eta] < 0);
    if (pressed && i < before.eta.size()) {
      const double turn = std::acos(std::clamp(pp.eta.dot(before.eta[i]), -1.0, 1.0)) * 180 / std::numbers::pi;
      if (turn > c.normal_turn) {
        c.normal_turn = turn;
        worst_turn = static_cast<int>(i);
      }
    }
  }
  auto node_of = [&](int candidate) { return std::to_string(body.site_node(pr.candidates[candidate].site)); };
  if (c.tension > limits_.tension)
    fail("the contact point at node " + node_of(worst_tension) + " pulls (p_n = " + num(c.tension) +
         " of the largest pressure)");
  if (c.cone > limits_.cone)
    fail("the contact point at node " + node_of(worst_cone) +
         " lies outside Coulomb's cone (|p_t| - mu |p_n| = " + num(c.cone) + " of the largest pressure)");
  if (c.normal_turn > limits_.normal_turn)
    fail("the contact normal at node " + node_of(worst_turn) + " turned by " + num(c.normal_turn) +
         " degrees since the last accepted state: the obstacle passed through the body");

  // Every boundary point against every rigid obstacle.
  const LoadFactors& factors = eq.factors();
  for (const Pairing& k : outside_sites_) {
    const ObstacleInstance& o = pr.obstacles[k.obstacle];
    const SurfacePoint sp = body.surface_point(s.q, k.site, k.side);
    const double gap = o.shape->project(sp.x - o.offset(factors)).gap - sp.clearance;
    c.penetration = std::max(c.penetration, -gap);
    if (-gap > limits_.penetration || gap < reach_)
      outside.push_back({k.site, body.site_node(k.site), k.obstacle, gap, -gap > limits_.penetration});
  }
  for (int node : nodes_without_site_) {
    const Vec2 x = body.node_position(s.q, node);
    for (int o = 0; o < static_cast<int>(pr.obstacles.size()); ++o) {
      const ObstacleInstance& obstacle = pr.obstacles[o];
      if (!obstacle.shape) continue;
      const double gap = obstacle.shape->project(x - obstacle.offset(factors)).gap;
      c.penetration = std::max(c.penetration, -gap);
      if (-gap > limits_.penetration) outside.push_back({-1, node, o, gap, true});
    }
  }
  c.boundary_points = static_cast<int>(pr.candidates.size() + outside_sites_.size()) +
                      static_cast<int>(nodes_without_site_.size() * pr.obstacles.size());
  if (c.penetration > limits_.penetration) {
    // Where the deepest point lies among the candidates, the state is wrong; outside them the
    // caller decides (candidates grown, or the step failed with the node).
    bool among_candidates = false;
    if (!penalty_)
      for (const PairedPoint& pp : s.points) among_candidates |= -pp.projection.gap > limits_.penetration;
    if (among_candidates)
      fail("a contact point lies " + num(c.penetration) + " inside an obstacle (limit " + num(limits_.penetration) +
           ")");
  }
  worst.worst_of(c);
  return why;
}

}  // namespace grip
