#include <cmath>

#include "solver/elements/reissner_beam.hpp"
#include "solver/elements/straight_beam.hpp"
#include "solver/elements/timoshenko_beam.hpp"
#include "solver/io/scene_reader.hpp"

namespace grip::scene_io {
namespace {

// A load's `follower` flag: its force turns with the section (reissner_beam only, one body).
bool follows(Reader& r, json& l, const std::string& lp, bool exact, const std::string& ptr) {
  if (!l.contains("follower")) {
    if (exact) l["follower"] = false;
    return false;
  }
  if (!l["follower"].is_boolean()) {
    r.error(lp + "/follower", show(l["follower"]) + " is not true or false");
    return false;
  }
  if (!l["follower"].get<bool>()) return false;
  if (!exact) r.error(lp + "/follower", "only a reissner_beam's loads turn with it (the von Karman beam's stay dead)");
  else if (ptr != "/body")
    r.error(lp + "/follower", "follower loads are for a one-body scene (body), not yet for a body of bodies");
  return true;
}

// A distributed load over [from, to] of the undeformed axis (default: the whole beam): dead,
// or turning and stretching with the axis (reissner_beam's follower).
void read_line_load(Reader& r, json& l, const std::string& lp, bool exact, const std::string& ptr, Problem& problem) {
  const auto& beam = static_cast<const StraightBeam&>(*problem.body);
  const double start = beam.site_reference(0).x(), end = beam.site_reference(beam.node_count() - 1).x();
  const Vec2 traction = r.vec2(l, lp, "traction");
  const double from = r.number(l, lp, "from", start), to = r.number(l, lp, "to", end);
  if (!(from >= start && from < end))
    r.error(lp + "/from",
            show(json(from)) + " is not in [" + show(json(start)) + ", " + show(json(end)) + ") along the beam");
  else if (!(to > from && to <= end))
    r.error(lp + "/to", show(json(to)) + " is not in (from, " + show(json(end)) + "] along the beam");
  const int load_case = r.load_case(l, lp);
  const bool follower = follows(r, l, lp, exact, ptr);
  if (!r.issues.empty()) return;
  if (follower) static_cast<ReissnerBeam&>(*problem.body).add_follower_traction({traction, from, to, load_case});
  else beam.add_line_load(traction, from, to, case_load(problem, load_case));
}

// The two beam models share their section, mesh, supports and loads (node dofs u, w, theta);
// the von Karman beam has its kinematics, the geometrically exact one its element.
void read_beam(Reader& r, json& body, Problem& problem, const std::string& ptr, bool exact) {
  const std::string kin = exact ? "" : r.choice(body, ptr, "kinematics", {"von_karman", "linear"}, "von_karman");
  const std::string element = exact ? r.choice(body, ptr, "element", {"b2", "b3"}, "b3") : "";
  json* mat = r.object(body, ptr, "material", true);
  json* sec = r.object(body, ptr, "section", true);
  json* mesh = r.object(body, ptr, "mesh", true);
  double E = 0, nu = 0;
  BeamSection section;
  if (mat) {
    E = r.positive(*mat, ptr + "/material", "young");
    nu = r.number(*mat, ptr + "/material", "poisson", 0.3);
    if (!(nu >= 0 && nu < 0.5)) r.error(ptr + "/material/poisson", show((*mat)["poisson"]) + " is not in [0, 0.5)");
  }
  if (sec) {
    const double width = r.positive(*sec, ptr + "/section", "width");
    const double depth = r.positive(*sec, ptr + "/section", "depth");
    const double k = r.positive(*sec, ptr + "/section", "shear_factor", 5.0 / 6.0);
    const double G = E / (2 * (1 + nu));
    section = {E * width * depth, E * width * depth * depth * depth / 12, k * G * width * depth, depth / 2, width};
  }
  std::vector<double> x;
  Vec2 origin = Vec2::Zero();
  if (mesh) {
    origin = r.vec2(*mesh, ptr + "/mesh", "origin", Vec2::Zero());
    const double length = r.positive(*mesh, ptr + "/mesh", "length");
    const int elements = r.integer(*mesh, ptr + "/mesh", "elements", 1, 100000);
    for (int i = 0; i <= elements; ++i) x.push_back(origin.x() + length * i / elements);
  }
  if (!r.issues.empty()) return;
  if (exact)
    problem.body =
        std::make_unique<ReissnerBeam>(x, origin.y(), section, element == "b2" ? BeamElement::b2 : BeamElement::b3);
  else
    problem.body = std::make_unique<TimoshenkoBeam>(x, origin.y(), section,
                                                    kin == "linear" ? Kinematics::linear : Kinematics::von_karman);
  const int nodes = problem.body->site_count();
  const Body& body_model = *problem.body;

  read_supports(r, body, ptr, nodes, {"u", "w", "theta"}, &TimoshenkoBeam::node_dof, problem);

  if (json* loads = r.array(body, ptr, "loads", false))
    for (size_t i = 0; i < loads->size(); ++i) {
      const std::string lp = ptr + "/loads/" + std::to_string(i);
      json& l = (*loads)[i];
      if (!l.is_object()) {
        r.error(lp, "is not an object");
        continue;
      }
      if (l.contains("traction")) {
        read_line_load(r, l, lp, exact, ptr, problem);
        continue;
      }
      const int node = r.integer(l, lp, "node", 0, nodes - 1);
      const Vec2 f = r.vec2(l, lp, "force", Vec2::Zero());
      const double moment = r.number(l, lp, "moment", 0.0);
      const std::string at = r.choice(l, lp, "at", {"centre", "upper", "lower"}, "centre");
      const int side = at == "upper" ? 1 : at == "lower" ? -1 : 0;
      const int load_case = r.load_case(l, lp);
      Vector& load = case_load(problem, load_case);
      load[TimoshenkoBeam::node_dof(node, 2)] += moment;
      if (follows(r, l, lp, exact, ptr)) {
        if (r.issues.empty())
          static_cast<ReissnerBeam&>(*problem.body).add_follower_load({node, f, side * section.half_depth, load_case});
        continue;
      }
      // Virtual work of the force at its point of application (a moment through the offset).
      const SurfacePoint sp = body_model.surface_point(Vector::Zero(load.size()), node, side);
      for (const auto& jac : sp.jacobian) load[jac.dof] += jac.dx.dot(f);
    }
}

}  // namespace

void read_timoshenko_beam(Reader& r, json& body, Problem& problem, const std::string& ptr) {
  read_beam(r, body, problem, ptr, false);
}

void read_reissner_beam(Reader& r, json& body, Problem& problem, const std::string& ptr) {
  read_beam(r, body, problem, ptr, true);
}

}  // namespace grip::scene_io
