#include "solver/io/result.hpp"

#include "solver/io/json_writer.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>

#include "solver/contact/contact_error.hpp"
#include "solver/contact/master_reading.hpp"
#include "solver/elements/rigid_hubs.hpp"
#include "solver/model/body_set.hpp"
#include "solver/problem/rigid_modes.hpp"

namespace grip {

using nlohmann::json;

json iteration_event(const IterationEvent& ev) {
  return {{"type", "iteration"},
          {"step", ev.step},
          {"pass", ev.pass},
          {"m", ev.m},
          {"trials", ev.trials},
          {"inner_iterations", ev.inner_iterations},
          {"halvings", ev.halvings},
          {"n", ev.n == 0 ? json("inf") : json(ev.n)},
          {"alpha", ev.alpha},
          {"v2", ev.v2},
          {"v_inf", ev.v_inf},
          {"open", ev.open},
          {"stick", ev.stick},
          {"slip", ev.slip},
          {"newton_iterations", ev.newton_iterations},
          {"elapsed_ms", ev.elapsed_ms}};
}

json step_started_event(int step, double load_factor) {
  return {{"type", "step_started"}, {"step", step}, {"load_factor", load_factor}};
}

json step_finished_event(const Problem& problem, const StepRecord& rec, const OutputOptions& output) {
  json j = {{"type", "step_finished"},
            {"step", rec.index},
            {"load_factor", rec.load_factor},
            {"converged", rec.converged},
            {"tau_passes", rec.passes},
            {"contact_iterations", rec.solves},
            {"newton_iterations", rec.newton_iterations},
            {"seconds", rec.seconds},
            {"stage", rec.stage},
            {"factors", rec.factors}};
  if (!rec.converged) {
    j["reason"] = rec.reason;
    j["failure"] = failure_json(rec.failure, rec.reason, rec.index);
  }
  if (!rec.warning.empty()) j["warning"] = rec.warning;
  if (!rec.notes.empty()) j["notes"] = rec.notes;
  if (!output.quantities.empty() && rec.converged) j["outputs"] = quantity_values(problem, rec, output.quantities);
  return j;
}

json failure_json(FailureKind kind, const std::string& message, int step) {
  return {{"kind", to_string(kind)}, {"message", message}, {"step", step}};
}

json job_failed_event(FailureKind kind, const std::string& reason, int step) {
  return {{"type", "job_failed"}, {"reason", reason}, {"failure", failure_json(kind, reason, step)}};
}

namespace {

// field_value without text where that is exact (Clinger's fast path): v scaled to kFieldDigits
// digits before the point and rounded, then m / 10^k (or m * 10^-k) with m and 10^k exact doubles is
// the double nearest m x 10^-k. Scaling rounds once (half a unit in the 16th digit): a fraction
// within 1e-6 of a half, or an exponent whose power of ten is inexact, takes the text way.
std::optional<double> field_value_fast(double v) {
  static constexpr double kTen[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const double a = std::fabs(v);
  const int k = kFieldDigits - 1 - static_cast<int>(std::floor(std::log10(a)));  // digits after the point
  if (k < -22 || k > 22) return std::nullopt;
  const double scaled = k >= 0 ? a * kTen[k] : a / kTen[-k];
  if (scaled < 1e6 || scaled >= 1e7) return std::nullopt;  // log10 off by one near a power of ten
  const double m = std::floor(scaled + 0.5), fraction = scaled - std::floor(scaled);
  if (std::fabs(fraction - 0.5) < 1e-6) return std::nullopt;
  const double rounded = k >= 0 ? m / kTen[k] : m * kTen[-k];
  return v < 0 ? -rounded : rounded;
}

}  // namespace

double field_value(double v) {
  if (!std::isfinite(v) || v == 0) return v;
  if (const auto fast = field_value_fast(v)) return *fast;
  char text[32];
  const char* end = std::to_chars(text, text + sizeof text, v, std::chars_format::scientific, kFieldDigits - 1).ptr;
  double rounded = v;
  std::from_chars(text, end, rounded);
  return rounded;
}

namespace {

// The scene's bodies where it has several (the BodySet that the scene reader built for
// "bodies"), null for a scene of one body: the result takes the scene's form ("bodies",
// "rigid_motions", "master_points"), so io asks for the type it built (docs/design.md).
const BodySet* body_set_of(const Body& body) { return dynamic_cast<const BodySet*>(&body); }

// Each rigid hub's angle and the moment on it about its centre (the internal forces' on its
// theta: the moment load where the hub turns freely, the reaction where its angle is held), at q.
json hubs_json(const Body& body, const Vector& q) {
  json out = json::array();
  const auto* all = body_set_of(body);
  for (int b = 0; b < std::max(1, body.part_count()); ++b) {
    const auto* hubbed = dynamic_cast<const RigidHubs*>(&body.part(b));
    if (!hubbed) continue;
    const Vector qb = q.segment(body.dof_offset(b), hubbed->dof_count());
    Vector force = Vector::Zero(qb.size());
    hubbed->internal_force(qb, force, nullptr);
    for (size_t h = 0; h < hubbed->hubs().size(); ++h) {
      const int theta = hubbed->hub_dof(static_cast<int>(h), 2);
      json hub = {{"set", hubbed->hubs()[h].name}, {"angle", qb[theta]}, {"moment", force[theta]}};
      if (all) hub["body"] = all->name(b);
      out.push_back(hub);
    }
  }
  return out;
}

json table_json(const FieldTable& t, const char* index_name) {
  json rows = json::array();
  for (size_t i = 0; i < t.rows.size(); ++i) {
    json row = {{index_name, i}};
    for (size_t c = 0; c < t.names.size(); ++c)  // NaN: a column the row's body lacks
      if (!std::isnan(t.rows[i][c])) row[t.names[c]] = field_value(t.rows[i][c]);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

namespace {

// Axisymmetric, a quadratic side's corner on the axis: 2 pi r N vanishes there, so the node
// carries no share of the area (nor of a pressure's force) and force / area says nothing. Its
// contact stress is read at the adjacent site along the surface (h / 2 away: the pressure's
// change over that distance is of order h^2 on a smooth profile).
void share_axis_stresses(const Problem& problem, std::vector<ContactPointRow>& rows) {
  const Body& body = *problem.body;
  std::map<std::pair<int, int>, size_t> row_of;  // (obstacle, site) -> row
  for (size_t i = 0; i < problem.candidates.size(); ++i)
    row_of[{problem.candidates[i].obstacle, problem.candidates[i].site}] = i;
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    if (body.tributary_area(c.site) > 0) continue;
    const Vec2 at = body.site_reference(c.site);
    double nearest = std::numeric_limits<double>::infinity();
    for (const int s : {c.site - 1, c.site + 1}) {
      const auto it = row_of.find({c.obstacle, s});
      if (it == row_of.end() || !(body.tributary_area(s) > 0)) continue;
      const double d = (body.site_reference(s) - at).norm();
      if (d >= nearest) continue;
      nearest = d;
      rows[i].sigma_n = rows[it->second].sigma_n;
      rows[i].sigma_t = rows[it->second].sigma_t;
    }
    if (!std::isfinite(nearest)) rows[i].sigma_n = rows[i].sigma_t = 0.0;  // no neighbour: none to read
  }
}

}  // namespace

// The contact points' numbers, read from the problem and the record.
std::vector<ContactPointRow> contact_point_rows(const Problem& problem, const StepRecord& rec) {
  const Body& body = *problem.body;
  const auto* all = body_set_of(body);
  std::vector<ContactPointRow> rows;
  rows.reserve(problem.candidates.size());
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    const PairedPoint& pp = rec.state.points[i];
    const double area = body.tributary_area(c.site);
    const double p_n = rec.p[c.eta], p_t = c.xi >= 0 ? rec.p[c.xi] : 0.0;
    ContactPointRow r{body.site_node(c.site),
                      problem.obstacles[c.obstacle].name,
                      to_string(contact_state(problem, i, rec.p, rec.tau)),
                      {},
                      {},
                      pp.point.x,
                      pp.projection.point,
                      pp.projection.normal,
                      p_n,
                      p_t,
                      p_n / area,
                      p_t / area,
                      pp.projection.gap,
                      c.xi >= 0 ? rec.state.s[c.xi] : 0.0};
    if (all) {  // several bodies: who touches whom
      const ObstacleInstance& o = problem.obstacles[c.obstacle];
      r.body = all->name(all->body_of_site(c.site));
      r.master = o.master ? all->name(o.master->body) : o.name;
      r.several_bodies = true;
    }
    rows.push_back(std::move(r));
  }
  share_axis_stresses(problem, rows);
  return rows;
}

json contact_points_json(const std::vector<ContactPointRow>& rows) {
  json points = json::array();
  for (const ContactPointRow& r : rows) {
    const auto f = field_value;
    json point = {{"node", r.node},
                  {"obstacle", r.obstacle},
                  {"x", f(r.x.x())},
                  {"y", f(r.x.y())},
                  {"pair", {f(r.pair.x()), f(r.pair.y())}},
                  {"normal", {f(r.normal.x()), f(r.normal.y())}},
                  {"p_n", f(r.p_n)},
                  {"p_t", f(r.p_t)},
                  {"sigma_n", f(r.sigma_n)},
                  {"sigma_t", f(r.sigma_t)},
                  {"gap", f(r.gap)},
                  {"slip", f(r.slip)},
                  {"state", r.state}};
    if (r.several_bodies) {
      point["body"] = r.body;
      point["master"] = r.master;
    }
    points.push_back(std::move(point));
  }
  return points;
}

namespace {

// contact_points_json's text, written without the document (a JSON object per point took a
// fifth of a small job's writing): keys in nlohmann's order (sorted), numbers as number() writes them.
void write_contact_points(JsonWriter& w, const std::vector<ContactPointRow>& rows) {
  const auto f = [&w](double v) { w.number(field_value(v)); };
  const auto pair = [&w, &f](const Vec2& v) {
    w.put('[');
    f(v.x());
    w.put(',');
    f(v.y());
    w.put(']');
  };
  w.put('[');
  for (size_t i = 0; i < rows.size(); ++i) {
    const ContactPointRow& r = rows[i];
    w.raw(i ? ",{" : "{");
    if (r.several_bodies) {
      w.raw("\"body\":");
      w.string(r.body);
      w.put(',');
    }
    w.raw("\"gap\":");
    f(r.gap);
    if (r.several_bodies) {
      w.raw(",\"master\":");
      w.string(r.master);
    }
    w.raw(",\"node\":");
    w.integer(r.node);
    w.raw(",\"normal\":");
    pair(r.normal);
    w.raw(",\"obstacle\":");
    w.string(r.obstacle);
    w.raw(",\"p_n\":");
    f(r.p_n);
    w.raw(",\"p_t\":");
    f(r.p_t);
    w.raw(",\"pair\":");
    pair(r.pair);
    w.raw(",\"sigma_n\":");
    f(r.sigma_n);
    w.raw(",\"sigma_t\":");
    f(r.sigma_t);
    w.raw(",\"slip\":");
    f(r.slip);
    w.raw(",\"state\":");
    w.string(r.state);
    w.raw(",\"x\":");
    f(r.x.x());
    w.raw(",\"y\":");
    f(r.x.y());
    w.put('}');
  }
  w.put(']');
}

// step_json; with `rows`, the contact points are left out of the document and put there.
json step_json(const Problem& problem, const StepRecord& rec, const OutputOptions& output,
               std::optional<std::vector<ContactPointRow>>* rows) {
  const Body& body = *problem.body;
  json j = step_finished_event(problem, rec, output);
  j.erase("type");
  j["inner_iterations"] = rec.inner_iterations;
  j["cuts"] = rec.cuts;
  if (rec.multiplier_updates) j["multiplier_updates"] = rec.multiplier_updates;
  if (rec.restarts) j["restarts"] = rec.restarts;
  // The step checks (solver/stepping/step_checks.hpp): the worst value of each over the step.
  const StepChecks& c = rec.checks;
  j["checks"] = {{"balance", c.balance},
                 {"tension", c.tension},
                 {"cone", c.cone},
                 {"penetration", c.penetration},
                 {"normal_turn", c.normal_turn},
                 {"obstacle_motion", c.obstacle_motion},
                 {"boundary_points", c.boundary_points}};
  if (rec.converged)
    j["equilibrium"] = {{"relative_residual", rec.state.relative_residual}, {"at_round_off_floor", rec.state.at_floor}};
  if (!rec.epsilon_used.empty()) j["epsilon"] = rec.epsilon_used;
  if (rec.state.q.size() && rec.bound > 0) {
    double penetration = -std::numeric_limits<double>::infinity();
    for (const PairedPoint& pp : rec.state.points) penetration = std::max(penetration, -pp.projection.gap);
    j["contact_error"] = {{"v2", rec.contact_error},
                          {"bound", rec.bound},
                          {"displacement_scale", rec.scale},
                          {"at_round_off", rec.at_round_off},
                          {"penetration", rec.state.points.empty() ? 0.0 : penetration}};
  }
  if (problem.rigid.count() && rec.converged) {
    // The rigid motion fitted to the displacement (translation of the point at the origin);
    // in a scene of several bodies, of each body with motions held by contact.
    auto motion = [](const Body& b, const Vector& q) {
      const Vector a = rigid_amplitudes(b, q);
      json m = {{"translation", {a[0], a[1]}}};
      if (a.size() > 2) m["rotation"] = a[2];
      return m;
    };
    if (const auto* all = body_set_of(body)) {
      json motions = json::array();
      for (int b = 0; b < all->part_count(); ++b) {
        if (std::find(problem.rigid.body.begin(), problem.rigid.body.end(), b) == problem.rigid.body.end()) continue;
        json m = motion(all->part(b), all->part_q(rec.state.q, b));
        m["body"] = all->name(b);
        motions.push_back(m);
      }
      j["rigid_motions"] = motions;
    } else {
      j["rigid_motion"] = motion(body, rec.state.q);
    }
  }
  if (output.wants("history")) {
    json history = json::array();
    for (const auto& ev : rec.history) {
      json h = iteration_event(ev);
      h.erase("type");
      h.erase("step");
      history.push_back(h);
    }
    j["history"] = history;
  }
  // A step whose fields were not recorded keeps only its summary.
  if (rec.state.q.size() == 0 || rec.site_fields.rows.empty()) return j;
  if (output.wants("nodes")) j["nodes"] = table_json(rec.site_fields, "node");
  if (output.wants("elements")) j["elements"] = table_json(rec.element_fields, "element");
  json obstacles = json::array();
  for (const auto& o : problem.obstacles) {
    const Vec2 off = o.offset(rec.factors);
    obstacles.push_back({{"name", o.name}, {"offset", {off.x(), off.y()}}});
  }
  j["obstacles"] = obstacles;
  if (rec.reactions.size() && output.wants("reactions")) {
    json reactions = json::array();
    for (const Constraint& c : problem.constraints)
      reactions.push_back({{"dof", c.dof}, {"force", field_value(rec.reactions[c.dof])}});
    j["reactions"] = reactions;
  }
  if (json hubs = hubs_json(body, rec.state.q); !hubs.empty()) j["hubs"] = hubs;
  if (!output.wants("contact_points")) return j;
  std::vector<ContactPointRow> points = contact_point_rows(problem, rec);
  if (rows) *rows = std::move(points);
  else j["contact_points"] = contact_points_json(points);
  if (const auto* all = body_set_of(body)) {  // each pair's field read on its master
    json readings = json::array();
    for (size_t o = 0; o < problem.obstacles.size(); ++o) {
      const ObstacleInstance& pair = problem.obstacles[o];
      if (!pair.master) continue;
      for (const MasterReading& r : master_readings(problem, rec.state.q, rec.p, rec.tau, static_cast<int>(o))) {
        const double area = body.tributary_area(r.site);
        const Vec2 x = body.surface_point(rec.state.q, r.site, 0).x;
        readings.push_back({{"node", body.site_node(r.site)},
                            {"obstacle", pair.name},
                            {"body", all->name(pair.master->body)},
                            {"x", field_value(x.x())},
                            {"y", field_value(x.y())},
                            {"p_n", field_value(r.sigma_n * area)},
                            {"p_t", field_value(r.sigma_t * area)},
                            {"sigma_n", field_value(r.sigma_n)},
                            {"sigma_t", field_value(r.sigma_t)}});
      }
    }
    j["master_points"] = readings;
  }
  return j;
}

}  // namespace

json step_json(const Problem& problem, const StepRecord& rec, const OutputOptions& output) {
  return step_json(problem, rec, output, nullptr);
}

namespace {

json counters_json(const RunResult& run) {
  long passes = 0;
  for (const auto& rec : run.steps) passes += rec.passes;
  const EquilibriumCounters& c = run.counters;
  const auto per = [](long count, long of) { return of > 0 ? static_cast<double>(count) / of : 0.0; };
  const long all = c.factorizations + c.dissected_factorizations;
  return {{"factorizations", c.factorizations},
          {"newton_factorizations", c.newton_factorizations},
          {"body_factorizations", c.body_factorizations},
          {"dissected_factorizations", c.dissected_factorizations},
          {"factorizations_per_newton_iteration", per(all, c.newton_iterations)},
          {"factorizations_per_solve", per(all, c.solves)},
          {"equilibrium_solves", c.solves},
          {"newton_iterations", c.newton_iterations},
          {"chord_solves", c.chord_solves},
          {"tau_passes", passes}};
}

}  // namespace

json effects_json(const Scene& scene, const RunResult& run) {
  json effects = effects_json(scene);
  effects["counters"] = counters_json(run);
  return effects;
}

json effects_json(const Scene& scene) {
  const Problem& problem = scene.problem;
  const Body::Traits traits = problem.body->traits();
  bool friction = false, moving = false;
  int tangential = 0;
  for (const auto& o : problem.obstacles) {
    friction |= o.frictional;
    for (const Vec2& t : o.translations) moving |= t.norm() > 0;
  }
  for (const Candidate& c : problem.candidates) tangential += c.xi >= 0;
  json effects = {{"friction", friction},
                  {"geometric_nonlinearity", traits.geometric_nonlinearity},
                  {"plasticity", traits.plasticity},
                  {"moving_obstacles", moving},
                  {"constant_tangent", traits.constant_tangent},
                  {"contact_candidates", problem.candidates.size()},
                  {"contact_unknowns", problem.component_count},
                  {"held_by_contact", problem.rigid.names},
                  {"unknowns_per_contact_point", tangential > 0 ? 2 : 1}};
  // How the free motions were held (docs/algorithm.md#bodies-held-only-by-contact), and that no
  // regularization is left.
  if (problem.rigid.count())
    effects["held_by_contact_by"] =
        scene.params.contact.method == ContactMethod::penalty
            ? "the penalty springs: the rigid amplitudes are solved with the deformation, first with springs of "
              "1e-2, 1e-4 and 1e-6 x the largest stiffness on the free motions' pins, then without them; none is "
              "left in the answer"
        : scene.params.contact.method == ContactMethod::ssn
            ? "the contact forces: the rigid amplitudes are Newton unknowns with the displacements and contact "
              "forces, the whole body's equilibrium their rows; no regularization"
            : "the contact forces: the rigid amplitudes are contact unknowns and the whole body's equilibrium "
              "their condition; no regularization";
  // Axisymmetric bodies: the conventions, and the axis nodes held by the reader.
  for (const AxisHold& hold : scene.axis_holds)
    effects["axisymmetric"].push_back(
        {{"body", hold.body},
         {"axis_nodes_held", hold.nodes},
         {"conventions",
          "x = r, y = z (the axis); loads, reactions and contact forces are totals over the full circle, tractions "
          "per unit area; szz is the hoop stress; u_r = 0 imposed on the nodes on the axis listed here"}});
  if (const auto* all = body_set_of(*problem.body)) {
    // Per body what it simulates, and per contact pair its candidates.
    json bodies = json::array(), pairs = json::array();
    for (int b = 0; b < all->part_count(); ++b) {
      const Body::Traits t = all->part(b).traits();
      json held = json::array();  // its motions held by contact, without the "BODY: " of the scene's list
      for (int k = 0; k < problem.rigid.count(); ++k)
        if (problem.rigid.body[k] == b) held.push_back(problem.rigid.names[k].substr(all->name(b).size() + 2));
      bodies.push_back({{"name", all->name(b)},
                        {"geometric_nonlinearity", t.geometric_nonlinearity},
                        {"plasticity", t.plasticity},
                        {"constant_tangent", t.constant_tangent},
                        {"dofs", all->part(b).dof_count()},
                        {"held_by_contact", held}});
    }
    for (size_t o = 0; o < problem.obstacles.size(); ++o) {
      const ObstacleInstance& pair = problem.obstacles[o];
      if (!pair.master) continue;
      int candidates = 0;
      for (const Candidate& c : problem.candidates) candidates += c.obstacle == static_cast<int>(o);
      pairs.push_back({{"name", pair.name},
                       {"slave", all->name(pair.slave_body)},
                       {"master", all->name(pair.master->body)},
                       {"friction", pair.frictional},
                       {"contact_candidates", candidates}});
    }
    effects["bodies"] = bodies;
    effects["contacts"] = pairs;
  }
  if (const auto quality = problem.body->element_quality())
    effects["element_quality"] = {{"elements", quality->elements},
                                  {"max_aspect_ratio", quality->max_aspect_ratio},
                                  {"min_angle", quality->min_angle},
                                  {"max_angle", quality->max_angle}};
  return effects;
}

namespace {

// Each body's rows of the nodes and elements tables and of mesh.cells (several bodies only).
std::optional<json> bodies_json(const Body& body) {
  const auto* all = body_set_of(body);
  if (!all) return std::nullopt;
  json bodies = json::array();
  int first_element = 0;
  for (int b = 0; b < all->part_count(); ++b) {
    const int elements = static_cast<int>(all->part(b).cells().size());
    bodies.push_back({{"name", all->name(b)},
                      {"first_node", all->node_offset(b)},
                      {"nodes", all->part(b).node_count()},
                      {"first_element", first_element},
                      {"elements", elements}});
    first_element += elements;
  }
  return bodies;
}

json summary_json(const RunResult& run) {
  json j = {{"completed", run.completed},
            {"reason", run.reason},
            {"steps", run.steps.size()},
            {"contact_iterations", run.counters.solves},
            {"newton_iterations", run.counters.newton_iterations},
            {"factorizations", run.counters.factorizations},
            {"seconds", run.seconds}};
  if (!run.completed) j["failure"] = failure_json(run.failure, run.reason, run.failure_step);
  return j;
}

// table_json's rows, written as they are made (no document of the table's size in memory),
// kRowsPerPart rows a part.
std::vector<ResultPart> table_parts(const FlatTable& t, const std::string& index_name) {
  struct Columns {
    std::vector<int> column;          // of each key in nlohmann's order (sorted); -1: the row index
    std::vector<std::string> quoted;  // "key":
  };
  std::vector<std::pair<std::string, int>> keys{{index_name, -1}};
  for (size_t c = 0; c < t.names.size(); ++c)
    if (t.names[c] != index_name) keys.emplace_back(t.names[c], static_cast<int>(c));
  std::sort(keys.begin(), keys.end());
  auto columns = std::make_shared<Columns>();
  for (const auto& [name, c] : keys) {
    columns->column.push_back(c);
    columns->quoted.push_back(json(name).dump() + ":");
  }
  std::vector<ResultPart> parts;
  for (size_t begin = 0;; begin += kRowsPerPart) {
    const size_t end = std::min(begin + kRowsPerPart, t.rows);
    parts.push_back([&t, columns, begin, end](JsonWriter& w) {
      const size_t width = t.names.size();
      if (begin == 0) w.put('[');
      for (size_t i = begin; i < end; ++i) {
        const double* row = t.values.data() + i * width;
        w.raw(i ? ",\n{" : "\n{");
        bool first = true;
        for (size_t k = 0; k < columns->column.size(); ++k) {
          const int c = columns->column[k];
          if (c >= 0 && std::isnan(row[c])) continue;  // as table_json
          if (!first) w.put(',');
          first = false;
          w.raw(columns->quoted[k]);
          if (c < 0) w.integer(static_cast<long long>(i));
          else w.number(row[c]);
        }
        w.put('}');
      }
      if (end == t.rows) w.put(']');
    });
    if (end == t.rows) return parts;
  }
}

FlatTable flat_table(const FieldTable& t) {
  FlatTable f{t.names, t.rows.size(), {}};
  f.values.reserve(t.rows.size() * t.names.size());
  for (const auto& row : t.rows) {
    if (row.size() != t.names.size()) throw std::logic_error("a field table's row is not as wide as its names");
    for (double v : row) f.values.push_back(field_value(v));  // NaN stays: a column the row's body lacks
  }
  return f;
}

// `small`'s members [from, to), each after a comma unless it is the object's first (`first`);
// whether the object is still without a member.
bool write_members(JsonWriter& w, json::const_iterator from, json::const_iterator to, bool first) {
  for (auto it = from; it != to; ++it, first = false) {
    if (!first) w.put(',');
    w.string(it.key());
    w.put(':');
    w.value(it.value());
  }
  return first;
}

using Streamed = std::vector<std::pair<std::string, std::vector<ResultPart>>>;

// The object `small` with the members `streamed` (their values written by their parts) among
// its keys, in parts: each streamed value's own, and before each of them and after the last a
// part with the small members between and the streamed key. `small` must outlive the parts.
std::vector<ResultPart> object_parts(const json& small, Streamed streamed) {
  std::sort(streamed.begin(), streamed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<ResultPart> parts;
  auto it = small.cbegin();
  for (auto& [key, value] : streamed) {
    const auto from = it;
    while (it != small.cend() && it.key() < key) ++it;
    parts.push_back([from, to = it, name = key, start = parts.empty()](JsonWriter& w) {
      if (start) w.put('{');
      if (!write_members(w, from, to, start)) w.put(',');
      w.string(name);
      w.put(':');
    });
    for (ResultPart& p : value) parts.push_back(std::move(p));
  }
  parts.push_back([from = it, to = small.cend(), start = parts.empty()](JsonWriter& w) {
    if (start) w.put('{');
    write_members(w, from, to, start);
    w.put('}');
  });
  return parts;
}

// mesh: cells, one a line, and the gmsh tags of bodies from files (as result_json's mesh.gmsh).
void write_mesh(JsonWriter& w, const std::vector<std::vector<int>>& cells, const std::vector<FileMeshTags>& files) {
  w.raw("{\"cells\":[");
  for (size_t e = 0; e < cells.size(); ++e) {
    w.raw(e ? ",\n[" : "\n[");
    for (size_t a = 0; a < cells[e].size(); ++a) {
      if (a) w.put(',');
      w.integer(cells[e][a]);
    }
    w.put(']');
  }
  w.put(']');
  if (!files.empty()) {
    json gmsh = json::array();
    for (const FileMeshTags& tags : files)
      gmsh.push_back({{"body", tags.body}, {"node_tags", tags.nodes}, {"element_tags", tags.elements}});
    w.raw(",\"gmsh\":");
    w.value(gmsh);
  }
  w.put('}');
}

}  // namespace

json result_json(const Scene& scene, const RunResult& run) {
  json steps = json::array();
  for (const auto& rec : run.steps) steps.push_back(step_json(scene.problem, rec, scene.output));
  json r = {{"scene", scene.effective},
            {"effects", effects_json(scene, run)},
            {"summary", summary_json(run)},
            {"mesh", {{"cells", scene.problem.body->cells()}}},
            {"steps", std::move(steps)}};
  if (auto bodies = bodies_json(*scene.problem.body)) r["bodies"] = std::move(*bodies);
  for (const FileMeshTags& tags : scene.file_meshes)
    r["mesh"]["gmsh"].push_back({{"body", tags.body}, {"node_tags", tags.nodes}, {"element_tags", tags.elements}});
  return r;
}

StepOutput step_output(const Problem& problem, const StepRecord& rec, const OutputOptions& output) {
  OutputOptions summary = output;
  summary.fields.erase(std::remove_if(summary.fields.begin(), summary.fields.end(),
                                      [](const std::string& f) { return f == "nodes" || f == "elements"; }),
                       summary.fields.end());
  StepOutput step;
  step.summary = step_json(problem, rec, summary, &step.contact_points);
  if (rec.state.q.size() != 0 && !rec.site_fields.rows.empty()) {  // as step_json decides
    if (output.wants("nodes")) step.nodes = flat_table(rec.site_fields);
    if (output.wants("elements")) step.elements = flat_table(rec.element_fields);
  }
  return step;
}

std::vector<ResultPart> step_parts(const StepOutput& step) {
  Streamed tables;
  if (step.nodes) tables.emplace_back("nodes", table_parts(*step.nodes, "node"));
  if (step.elements) tables.emplace_back("elements", table_parts(*step.elements, "element"));
  if (step.contact_points)
    tables.emplace_back("contact_points", std::vector<ResultPart>{[&points = *step.contact_points](JsonWriter& w) {
                          write_contact_points(w, points);
                        }});
  return object_parts(step.summary, std::move(tables));
}

void write_step(std::ostream& out, const StepOutput& step) {
  JsonWriter w(out);
  for (const ResultPart& part : step_parts(step)) part(w);
}

std::vector<ResultPart> result_head_parts(const Scene& scene) {
  return {[&scene](JsonWriter& w) {
    w.put('{');
    if (const auto bodies = bodies_json(*scene.problem.body)) {
      w.raw("\"bodies\":");
      w.value(*bodies);
      w.put(',');
    }
    w.raw("\"mesh\":");
    write_mesh(w, scene.problem.body->cells(), scene.file_meshes);
    w.raw(",\"scene\":");
    w.value(scene.effective);
    w.raw(",\"steps\":[");
  }};
}

std::vector<ResultPart> result_step_parts(const StepOutput& step, size_t k) {
  std::vector<ResultPart> parts{[k](JsonWriter& w) { w.raw(k ? ",\n" : "\n"); }};
  for (ResultPart& part : step_parts(step)) parts.push_back(std::move(part));
  return parts;
}

std::vector<ResultPart> result_tail_parts(json effects, const RunResult& run) {
  effects["counters"] = counters_json(run);
  auto tail = std::make_shared<const std::pair<json, json>>(std::move(effects), summary_json(run));
  return {[tail](JsonWriter& w) {
    w.raw("],\"effects\":");
    w.value(tail->first);
    w.raw(",\"summary\":");
    w.value(tail->second);
    w.raw("}\n");
  }};
}

void write_result(std::ostream& out, const Scene& scene, const RunResult& run) {
  JsonWriter w(out);
  for (const ResultPart& part : result_head_parts(scene)) part(w);
  for (size_t k = 0; k < run.steps.size(); ++k) {
    const StepOutput step = step_output(scene.problem, run.steps[k], scene.output);
    for (const ResultPart& part : result_step_parts(step, k)) part(w);
  }
  for (const ResultPart& part : result_tail_parts(effects_json(scene), run)) part(w);
}

}  // namespace grip
