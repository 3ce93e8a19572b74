// body.model "continuum": plane triangles and quadrilaterals (solver/elements/continuum.hpp).
//   "kinematics": "finite" (default) | "linear";  "analysis": "plane_strain" | "plane_stress" | "axisymmetric"
//   "element": "t3" | "t6" | "q4" | "q4_bbar" | "q8" | "q9";  "thickness" (default 1)
//   "incompressibility": "none" (default) | "f_bar" (finite kinematics, q4) | "mixed" (finite, q9 and t6) |
//     "exact" (as mixed; neo_hookean and mooney_rivlin with bulk >= 100 x shear, its penalty)
//   "material": {"young", "poisson", "law": "neo_hookean" | "saint_venant_kirchhoff" | "j2_plasticity"} |
//     {"law": "mooney_rivlin", "c10", "c01" (default 0), "bulk"}
//     j2_plasticity: "yield_stress", "hardening": {"linear": H} |
//     {"power": {"K", "n"}} | {"table": [[eps_p, sigma_y], ...]} (default perfectly plastic),
//     "kinematic_hardening": H_k (default 0),
//     "hill48": {"r"} | {"r0", "r45" (plane stress), "r90"}
//   "mesh": one of
//     {"nodes": [[x, y], ...], "elements": [[n0, n1, n2(, ...9)], ...], "sets": {name: [ids]}}
//     {"rectangle": {"origin", "size", "divisions": [nx, ny], "refine": {"towards", "size", "extent"}}}
//     {"half_disc": {"centre", "radius", "divisions": [ns (arc), nt (pole to centre)], "facing": "down" | "up",
//                    "part": "whole" | "right" (x >= centre's: a ball's section), "refine": {"size", "extent"}}}
//   "contact_set": a node set on the boundary (default "bottom" for a rectangle, "arc" for a
//     half-disc); its nodes are the contact candidates
//   "supports": [{"set" | "node", "fix": ["x", "y"], "values": {"x", "y"} | "rotation": {"about", "angle"}, "case"}]
//   "loads": [{"set" | "node", "force": [fx, fy] (on each node) | "traction": [tx, ty] (per
//     unit area of the set's boundary sides), "case"}]
//   "hubs": [{"set", "centre": [xc, yc], "angle" | "moment", "case"}]: rigid hubs on fixed centres
//     (solver/elements/rigid_hubs.hpp), turned by a prescribed angle or loaded by a moment
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "solver/elements/continuum.hpp"
#include "solver/elements/element_pairs.hpp"
#include "solver/elements/rigid_hubs.hpp"
#include "solver/io/scene_reader.hpp"
#include "solver/materials/j2_plasticity.hpp"
#include "solver/materials/mooney_rivlin.hpp"

namespace grip::scene_io {
namespace {

// The J2 law of material `mp` (law j2_plasticity); nullptr after an error.
std::shared_ptr<const PlaneMaterial> read_j2_material(Reader& r, json& mat, const std::string& mp, double young,
                                                      double poisson, const ContinuumOptions& options) {
  const size_t before = r.issues.size();
  const double yield_stress = r.positive(mat, mp, "yield_stress");
  const double kinematic = r.number(mat, mp, "kinematic_hardening", 0.0);
  IsotropicHardening h;
  if (json* hard = r.object(mat, mp, "hardening", false)) {
    const std::string hp = mp + "/hardening";
    if (hard->empty()) (*hard)["linear"] = 0.0;
    if (hard->size() != 1 || !(hard->contains("linear") || hard->contains("power") || hard->contains("table"))) {
      r.error(hp, "needs exactly one of \"linear\", \"power\" and \"table\"");
    } else if (hard->contains("linear")) {
      h.modulus = r.number(*hard, hp, "linear");
    } else if (hard->contains("power")) {
      h.kind = IsotropicHardening::Kind::power;
      if (json* pw = r.object(*hard, hp, "power", true)) {
        h.K = r.number(*pw, hp + "/power", "K");
        h.n = r.number(*pw, hp + "/power", "n");
      }
    } else if (json* table = r.array(*hard, hp, "table", true)) {
      h.kind = IsotropicHardening::Kind::table;
      for (size_t k = 0; k < table->size(); ++k) {
        const json& row = (*table)[k];
        if (!row.is_array() || row.size() != 2 || !row[0].is_number() || !row[1].is_number()) {
          r.error(hp + "/table/" + std::to_string(k), show(row) + " is not a pair [eps_p, sigma_y]");
          continue;
        }
        h.table.emplace_back(row[0].get<double>(), row[1].get<double>());
      }
    }
  }
  // Hill's 1948 anisotropy: a normal r, or r0, r45 (plane stress only) and r90.
  std::optional<Hill48> hill;
  if (json* hj = mat.contains("hill48") ? r.object(mat, mp, "hill48", true) : nullptr) {
    const std::string hp = mp + "/hill48";
    Hill48& v = hill.emplace();
    if (hj->contains("r")) {
      for (const char* key : {"r0", "r45", "r90"})
        if (hj->contains(key)) r.error(hp + "/" + key, "give either r (normal anisotropy) or r0, r45, r90");
      v.r0 = v.r45 = v.r90 = r.positive(*hj, hp, "r");
    } else if (options.analysis == PlaneAnalysis::axisymmetric) {
      r.error(hp, "axisymmetry takes a normal r only (planar anisotropy would vary round the circle)");
    } else {
      v.r0 = r.positive(*hj, hp, "r0");
      v.r90 = r.positive(*hj, hp, "r90");
      if (options.analysis == PlaneAnalysis::plane_stress) v.r45 = r.positive(*hj, hp, "r45");
      else if (hj->contains("r45"))
        r.error(hp + "/r45",
                "has no role in plane strain (the section through the thickness: the sheet-plane shear "
                "that r45 sets is zero)");
      else v.r45 = v.r0;
    }
  }
  if (r.issues.size() > before) return nullptr;
  std::string why = j2_data_issue(yield_stress, h, kinematic);
  if (why.empty() && hill) why = hill48_data_issue(*hill, options.analysis);
  if (!why.empty()) {
    const size_t colon = why.find(':');
    r.error(mp + "/" + why.substr(0, colon), why.substr(colon + 2));
    return nullptr;
  }
  return std::make_shared<J2Material>(young, poisson, yield_stress, std::move(h), kinematic, options.analysis, hill);
}

// The Mooney-Rivlin law of material `mp` (c10, c01, bulk; no young or poisson); nullptr after
// an error.
std::shared_ptr<const PlaneMaterial> read_mooney_rivlin(Reader& r, json& mat, const std::string& mp,
                                                        PlaneAnalysis analysis) {
  const size_t before = r.issues.size();
  for (const char* key : {"young", "poisson", "yield_stress", "hardening", "kinematic_hardening", "hill48"})
    if (mat.contains(key))
      r.error(mp + "/" + key, "is not a constant of law \"mooney_rivlin\": give c10, c01 and bulk");
  const double c10 = r.number(mat, mp, "c10");
  const double c01 = r.number(mat, mp, "c01", 0.0);
  const double bulk = r.positive(mat, mp, "bulk");
  if (r.issues.size() > before) return nullptr;
  if (const std::string why = mooney_rivlin_data_issue(c10, c01, bulk); !why.empty()) {
    const size_t colon = why.find(':');
    r.error(mp + "/" + why.substr(0, colon), why.substr(colon + 2));
    return nullptr;
  }
  return std::make_shared<MooneyRivlinMaterial>(c10, c01, bulk, analysis);
}

// [a, b] of integers in [lo, hi].
std::optional<std::pair<int, int>> integer_pair(Reader& r, json& obj, const std::string& ptr, const char* key, int lo,
                                                int hi) {
  const std::string p = ptr + "/" + token(key);
  if (!obj.contains(key)) {
    r.error(p, "is required ([n1, n2])");
    return std::nullopt;
  }
  const json& v = obj[key];
  if (!v.is_array() || v.size() != 2) {
    r.error(p, show(v) + " is not a pair of integers");
    return std::nullopt;
  }
  const size_t before = r.issues.size();
  const int a = r.integer_value(v[0], p + "/0", lo, hi), b = r.integer_value(v[1], p + "/1", lo, hi);
  if (r.issues.size() > before) return std::nullopt;
  return std::make_pair(a, b);
}

std::optional<Refinement> read_refinement(Reader& r, json& gen, const std::string& ptr, Vec2* towards) {
  if (!gen.contains("refine")) return std::nullopt;
  json* ref = r.object(gen, ptr, "refine", false);
  if (!ref) return std::nullopt;
  const std::string rp = ptr + "/refine";
  Refinement out;
  out.size = r.positive(*ref, rp, "size");
  out.extent = r.positive(*ref, rp, "extent");
  if (towards) *towards = r.vec2(*ref, rp, "towards");
  return out;
}

std::optional<PlaneMesh> read_explicit_mesh(Reader& r, json& mesh, const std::string& ptr) {
  PlaneMesh m;
  json* nodes = r.array(mesh, ptr, "nodes", true);
  json* elements = r.array(mesh, ptr, "elements", true);
  const size_t before = r.issues.size();
  if (nodes)
    for (size_t i = 0; i < nodes->size(); ++i) {
      const json& v = (*nodes)[i];
      if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
        r.error(ptr + "/nodes/" + std::to_string(i), show(v) + " is not a pair of numbers [x, y]");
      else m.nodes.emplace_back(v[0].get<double>(), v[1].get<double>());
    }
  if (elements)
    for (size_t e = 0; e < elements->size(); ++e) {
      const std::string ep = ptr + "/elements/" + std::to_string(e);
      const json& v = (*elements)[e];
      std::vector<int> el;
      if (!v.is_array()) r.error(ep, show(v) + " is not an array of node ids");
      else
        for (size_t a = 0; a < v.size(); ++a)
          el.push_back(r.integer_value(v[a], ep + "/" + std::to_string(a), 0, 1 << 30));
      m.elements.push_back(el);
    }
  if (json* sets = r.object(mesh, ptr, "sets", false))
    for (auto& [name, v] : sets->items()) {
      const std::string sp = ptr + "/sets/" + token(name);
      std::vector<int> ids;
      if (!v.is_array()) r.error(sp, show(v) + " is not an array of node ids");
      else
        for (size_t k = 0; k < v.size(); ++k)
          ids.push_back(r.integer_value(v[k], sp + "/" + std::to_string(k), 0,
                                        std::max(0, static_cast<int>(m.nodes.size()) - 1)));
      m.sets[name] = ids;
    }
  if (r.issues.size() > before) return std::nullopt;
  if (m.elements.empty()) {
    r.error(ptr + "/elements", "needs at least one element");
    return std::nullopt;
  }
  return m;  // checked by the body's constructor (report_mesh_issues)
}

std::optional<PlaneMesh> read_generated_mesh(Reader& r, json& mesh, const std::string& ptr, ElementShape shape,
                                             const std::string& kind) {
  const std::string gp = ptr + "/" + kind;
  json* gen = r.object(mesh, ptr, kind.c_str(), true);
  if (!gen) return std::nullopt;
  const size_t before = r.issues.size();
  PlaneMesh m;
  try {
    if (kind == "rectangle") {
      RectangleSpec spec;
      spec.origin = r.vec2(*gen, gp, "origin", Vec2::Zero());
      spec.size = r.vec2(*gen, gp, "size");
      if (!(spec.size.x() > 0 && spec.size.y() > 0)) r.error(gp + "/size", "needs a positive width and height");
      const auto div = integer_pair(r, *gen, gp, "divisions", 1, 2000);
      spec.refine = read_refinement(r, *gen, gp, &spec.towards);
      if (r.issues.size() > before || !div) return std::nullopt;
      spec.nx = div->first;
      spec.ny = div->second;
      m = rectangle_mesh(spec, shape);
    } else {
      HalfDiscSpec spec;
      spec.centre = r.vec2(*gen, gp, "centre", Vec2::Zero());
      spec.radius = r.positive(*gen, gp, "radius");
      const auto div = integer_pair(r, *gen, gp, "divisions", 1, 2000);
      if (div && (div->first % 2 || div->first < 4))
        r.error(gp + "/divisions/0",
                "must be an even integer from 4: a node sits at the pole, and the arc has a block at each end");
      if (div && div->second < 2) r.error(gp + "/divisions/1", "must be at least 2: a pole block and a ring round it");
      spec.facing_up = r.choice(*gen, gp, "facing", {"down", "up"}, "down") == "up";
      spec.right_half = r.choice(*gen, gp, "part", {"whole", "right"}, "whole") == "right";
      spec.refine = read_refinement(r, *gen, gp, nullptr);
      if (r.issues.size() > before || !div) return std::nullopt;
      spec.ns = div->first;
      spec.nt = div->second;
      m = half_disc_mesh(spec, shape);
    }
  } catch (const std::invalid_argument& e) {
    r.error(gp + "/divisions", e.what());
    return std::nullopt;
  }
  return m;  // checked by the body's constructor (report_mesh_issues)
}

// The issues check_mesh found (through the body's constructor), each at its JSON pointer: an
// explicit mesh's elements and nodes, or the generator's object (`kind`) with its first.
void report_mesh_issues(Reader& r, const std::vector<MeshIssue>& issues, const std::string& ptr,
                        const std::string& kind, const FileMeshTags* tags) {
  if (kind == "gmsh") {  // name the element and node by their gmsh tags
    for (const MeshIssue& issue : issues)
      r.error(ptr + "/gmsh",
              issue.element >= 0
                  ? "element tag " + std::to_string(tags->elements.at(issue.element)) + " " + issue.detail
                  : "node tag " + std::to_string(tags->nodes.at(issue.node)) + " " + issue.detail);
    return;
  }
  if (kind != "nodes") {
    r.error(ptr + "/" + kind, "generated element " + std::to_string(issues.at(0).element) + " " + issues[0].detail +
                                  ": soften the refinement or change the divisions");
    return;
  }
  for (const MeshIssue& issue : issues)
    r.error(issue.element >= 0 ? ptr + "/elements/" + std::to_string(issue.element)
                               : ptr + "/nodes/" + std::to_string(issue.node),
            (issue.element >= 0 ? "element " + std::to_string(issue.element) : "node " + std::to_string(issue.node)) +
                " " + issue.detail);
}

// The nodes named by {"set": name} or {"node": id}; nullopt after an error.
std::optional<std::vector<int>> read_target(Reader& r, json& obj, const std::string& ptr, const PlaneMesh& mesh) {
  const bool by_set = obj.contains("set"), by_node = obj.contains("node");
  if (by_set == by_node) {
    r.error(ptr, "needs exactly one of \"set\" (a node set's name) and \"node\" (a node id)");
    return std::nullopt;
  }
  if (by_node) {
    const size_t before = r.issues.size();
    const int node = r.integer(obj, ptr, "node", 0, static_cast<int>(mesh.nodes.size()) - 1);
    if (r.issues.size() > before) return std::nullopt;
    return std::vector<int>{node};
  }
  const json& name = obj["set"];
  std::vector<std::string> names;
  for (const auto& [n, ids] : mesh.sets) names.push_back(n);
  if (!name.is_string() || !mesh.sets.count(name.get<std::string>())) {
    r.error(ptr + "/set", show(name) + " names no node set (sets: " + Reader::list(names) + ")");
    return std::nullopt;
  }
  return mesh.sets.at(name.get<std::string>());
}

// read(entry, pointer) for each entry of the optional array body[key]; entries that are not
// objects are errors.
template <class Read>
void for_each_object(Reader& r, json& body, const std::string& ptr, const char* key, Read read) {
  json* entries = r.array(body, ptr, key, false);
  if (!entries) return;
  for (size_t i = 0; i < entries->size(); ++i) {
    const std::string p = ptr + "/" + token(key) + "/" + std::to_string(i);
    if ((*entries)[i].is_object()) read((*entries)[i], p);
    else r.error(p, "is not an object");
  }
}

void read_continuum_supports(Reader& r, json& body, const std::string& ptr, const PlaneMesh& mesh, bool finite,
                             Problem& problem) {
  // Per dof: the support that fixes it (an index of `pointers`, -1 for none) and its value.
  std::vector<int> fixed_by(2 * mesh.nodes.size(), -1);
  std::vector<double> fixed_value(fixed_by.size(), 0.0);
  std::vector<std::string> pointers;
  for_each_object(r, body, ptr, "supports", [&](json& s, const std::string& sp) {
    const auto nodes = read_target(r, s, sp, mesh);
    const int load_case = r.load_case(s, sp);
    if (s.contains("fix") == s.contains("rotation")) {
      r.error(sp, "needs exactly one of \"fix\" (components, with values) and \"rotation\" (a rigid rotation)");
      return;
    }
    // axis >= 0: a finite rotation of the node at `arm` (Constraint::at), value its angle.
    const auto hold = [&](int dof, double value, const std::string& at, const std::string& what, int axis = -1,
                          const Vec2& arm = Vec2::Zero()) {
      if (fixed_by[dof] >= 0) {
        // The same zero support twice (a corner in two sets) is harmless; two prescribed
        // values of one dof are ambiguous.
        if (value != 0.0 || fixed_value[dof] != 0.0)
          r.error(at, "prescribes " + what + ", which " + pointers[fixed_by[dof]] +
                          " fixes already: give each dof one support");
        return;
      }
      fixed_by[dof] = static_cast<int>(pointers.size()) - 1;
      fixed_value[dof] = value;
      problem.constraints.push_back({dof, value, load_case, axis, arm});
    };
    if (json* rotation = s.contains("rotation") ? r.object(s, sp, "rotation", true) : nullptr) {
      // A rigid rotation: with finite kinematics the exact one, u = (R(t angle) - I)(X - c) at
      // factor t; with linear kinematics the small one, u = t angle (-(y - yc), x - xc).
      const std::string rp = sp + "/rotation";
      const Vec2 about = r.vec2(*rotation, rp, "about");
      const double angle = r.number(*rotation, rp, "angle");
      if (s.contains("values")) r.error(sp + "/values", "goes with \"fix\"; a rotation sets both components");
      if (!nodes) return;
      pointers.push_back(sp);
      for (int node : *nodes) {
        const Vec2 d = mesh.nodes[node] - about;
        const std::string what = "x and y of node " + std::to_string(node);
        if (finite) {
          const double a = d.isZero() ? 0.0 : angle;  // the centre stays put
          hold(ContinuumBody::node_dof(node, 0), a, rp, what, 0, d);
          hold(ContinuumBody::node_dof(node, 1), a, rp, what, 1, d);
        } else {
          hold(ContinuumBody::node_dof(node, 0), -angle * d.y(), rp, what);
          hold(ContinuumBody::node_dof(node, 1), angle * d.x(), rp, what);
        }
      }
      return;
    }
    json* fix = r.array(s, sp, "fix", true);
    json* values = r.object(s, sp, "values", false);
    if (!fix || !nodes) return;
    pointers.push_back(sp);
    if (fix->empty()) r.error(sp + "/fix", "names no component (\"x\", \"y\")");
    for (size_t c = 0; c < fix->size(); ++c) {
      const json& comp = (*fix)[c];
      if (!(comp == "x" || comp == "y")) {
        r.error(sp + "/fix/" + std::to_string(c), show(comp) + " is not one of \"x\", \"y\"");
        continue;
      }
      const std::string name = comp.get<std::string>();
      const double value = values && values->contains(name) ? r.number(*values, sp + "/values", name.c_str()) : 0.0;
      for (int node : *nodes)
        hold(ContinuumBody::node_dof(node, name == "x" ? 0 : 1), value, sp + "/fix/" + std::to_string(c),
             name + " of node " + std::to_string(node));
    }
    if (values)
      for (const auto& [name, v] : values->items()) {
        bool listed = false;
        for (const auto& comp : *fix) listed |= comp == name;
        if (!listed) r.error(sp + "/values/" + token(name), "is given but \"" + name + "\" is not in fix");
      }
  });
}

// Axisymmetric: u_r = 0 on the axis (a node there lies on every meridian plane), imposed on the
// nodes whose x is not held already, and listed for the result's effects.
void hold_axis(const PlaneMesh& mesh, Reader& r, Problem& problem) {
  std::vector<char> fixed(2 * mesh.nodes.size(), 0);
  for (const Constraint& c : problem.constraints) fixed[c.dof] = 1;
  AxisHold hold{r.body_index, {}};
  for (int node : axis_nodes(mesh))
    if (!fixed[ContinuumBody::node_dof(node, 0)]) {
      problem.constraints.push_back({ContinuumBody::node_dof(node, 0), 0.0, 0});
      hold.nodes.push_back(node);
    }
  r.axis_holds.push_back(std::move(hold));
}

void read_continuum_loads(Reader& r, json& body, const std::string& ptr, const PlaneMesh& mesh, ElementShape shape,
                          Problem& problem, double thickness, bool axisymmetric) {
  for_each_object(r, body, ptr, "loads", [&](json& l, const std::string& lp) {
    const auto nodes = read_target(r, l, lp, mesh);
    const int load_case = r.load_case(l, lp);
    const bool force = l.contains("force"), traction = l.contains("traction");
    if (force == traction) {
      r.error(lp, "needs exactly one of \"force\" (on each node) and \"traction\" (per unit area)");
      return;
    }
    const Vec2 f = r.vec2(l, lp, force ? "force" : "traction");
    if (!nodes) return;
    Vector& load = case_load(problem, load_case);
    if (force) {
      for (int node : *nodes) load.segment<2>(2 * node) += f;
      return;
    }
    if (!l.contains("set")) {
      r.error(lp + "/traction", "acts on the boundary sides of a set: give \"set\", not \"node\"");
      return;
    }
    try {
      const BoundaryPart part = boundary_part(mesh, shape, *nodes);
      // A traction is per unit area: each node takes f times its share of the side's area
      // (axisymmetric: the revolved area, so that the force is the total over the circle).
      for (size_t k = 0; k < part.nodes.size(); ++k)
        load.segment<2>(2 * part.nodes[k]) += (axisymmetric ? part.revolved_areas[k] : part.lengths[k] * thickness) * f;
    } catch (const std::invalid_argument& e) {
      r.error(lp + "/set", e.what());
    }
  });
}

// body.hubs: each a node set turned rigidly about its centre, which stays put, by a prescribed
// angle or loaded by a moment (neither: free to turn, no moment); the hubs' nodes leave the
// body's dofs for three per hub (RigidHubs), so the constraints and loads read so far are
// carried over. The hub dofs' supports and loads: x and y of the centre at zero, theta at
// the angle (exact at any angle: theta is the angle), or a moment on theta.
void read_hubs(Reader& r, json& body, const std::string& ptr, const PlaneMesh& mesh, Problem& problem) {
  struct Drive {
    double angle = 0.0, moment = 0.0;
    bool turned = false;
    int load_case = 0;
  };
  std::vector<RigidHub> hubs;
  std::vector<Drive> drives;
  std::vector<int> hub_of(mesh.nodes.size(), -1);
  std::vector<std::string> pointers;
  for_each_object(r, body, ptr, "hubs", [&](json& h, const std::string& hp) {
    if (!h.contains("set")) {
      r.error(hp + "/set", "is required: the node set that turns as the hub");
      return;
    }
    const auto nodes = read_target(r, h, hp, mesh);
    const Vec2 centre = r.vec2(h, hp, "centre");
    Drive d;
    d.load_case = r.load_case(h, hp);
    if (h.contains("angle") && h.contains("moment"))
      r.error(hp, "needs at most one of \"angle\" (a prescribed turn) and \"moment\" (a moment load; the angle free)");
    d.turned = h.contains("angle");
    if (d.turned) d.angle = r.number(h, hp, "angle");
    if (h.contains("moment")) d.moment = r.number(h, hp, "moment");
    if (!nodes) return;
    for (int node : *nodes)
      if (hub_of[node] >= 0) {
        r.error(hp + "/set", "node " + std::to_string(node) + " is in hub " + pointers[hub_of[node]] + " already");
        return;
      }
    for (int node : *nodes) hub_of[node] = static_cast<int>(hubs.size());
    pointers.push_back(hp);
    hubs.push_back({h["set"].get<std::string>(), *nodes, centre});
    drives.push_back(d);
  });
  if (hubs.empty() || !r.issues.empty()) return;
  if (problem.body->axisymmetric()) {
    r.error(ptr + "/hubs", "turn in the plane: a section of a body of revolution has no hub to turn");
    return;
  }
  for (const Constraint& c : problem.constraints)
    if (hub_of[c.dof / 2] >= 0) {
      r.error(ptr + "/supports", "hold node " + std::to_string(c.dof / 2) + ", which hub " +
                                     pointers[hub_of[c.dof / 2]] + " turns: hold the hub (its angle) instead");
      return;
    }
  auto hubbed = std::make_unique<RigidHubs>(std::move(problem.body), std::move(hubs));
  for (Constraint& c : problem.constraints) c.dof = hubbed->reduced_dof(c.dof);
  for (Vector& load : problem.loads) load = hubbed->reduce_force(load);
  for (size_t h = 0; h < drives.size(); ++h) {
    const int k = static_cast<int>(h);
    problem.constraints.push_back({hubbed->hub_dof(k, 0), 0.0, 0});
    problem.constraints.push_back({hubbed->hub_dof(k, 1), 0.0, 0});
    if (drives[h].turned) problem.constraints.push_back({hubbed->hub_dof(k, 2), drives[h].angle, drives[h].load_case});
  }
  problem.body = std::move(hubbed);
  for (size_t h = 0; h < drives.size(); ++h)
    if (drives[h].moment != 0.0) {
      const int theta = static_cast<const RigidHubs&>(*problem.body).hub_dof(static_cast<int>(h), 2);
      case_load(problem, drives[h].load_case)[theta] += drives[h].moment;
    }
}

}  // namespace

void read_continuum(Reader& r, json& body, Problem& problem, const std::string& ptr) {
  // A mesh from a file says its element kind: read it first (scene_gmsh.cpp).
  std::optional<FileMesh> file;
  if (body.is_object() && body.contains("mesh") && body["mesh"].is_object() && body["mesh"].contains("gmsh")) {
    if (json* gmsh = r.object(body["mesh"], ptr + "/mesh", "gmsh", true))
      file = read_file_mesh(r, *gmsh, ptr + "/mesh/gmsh");
    if (!file) return;
    if (!body.contains("element")) body["element"] = file->element;
    else if (body["element"] != file->element)
      r.error(ptr + "/element", show(body["element"]) + " differs from the mesh file's elements, " + file->element +
                                    ": leave \"element\" out for a mesh from a file");
  }
  const std::string kin = r.choice(body, ptr, "kinematics", {"finite", "linear"}, "finite");
  const std::string analysis =
      r.choice(body, ptr, "analysis", {"plane_strain", "plane_stress", "axisymmetric"}, "plane_strain");
  const std::string element = r.choice(body, ptr, "element", {"t3", "t6", "q4", "q4_bbar", "q8", "q9"}, "q4");
  ContinuumOptions options;
  options.kinematics = kin == "linear" ? ContinuumKinematics::linear : ContinuumKinematics::finite;
  options.analysis = analysis == "plane_stress"   ? PlaneAnalysis::plane_stress
                     : analysis == "axisymmetric" ? PlaneAnalysis::axisymmetric
                                                  : PlaneAnalysis::plane_strain;
  for (ContinuumElement e : {ContinuumElement::t3, ContinuumElement::t6, ContinuumElement::q4,
                             ContinuumElement::q4_bbar, ContinuumElement::q8, ContinuumElement::q9})
    if (element == element_name(e)) options.element = e;
  options.thickness = r.positive(body, ptr, "thickness", 1.0);
  const std::string incompressibility =
      r.choice(body, ptr, "incompressibility", {"none", "f_bar", "mixed", "exact"}, "none");
  options.incompressibility = incompressibility == "f_bar"   ? Incompressibility::f_bar
                              : incompressibility == "mixed" ? Incompressibility::mixed
                              : incompressibility == "exact" ? Incompressibility::exact
                                                             : Incompressibility::none;
  if (const std::string why = incompressibility_issue(options); !why.empty()) r.error(ptr + "/incompressibility", why);
  if (options.element == ContinuumElement::q4_bbar) {
    if (options.kinematics == ContinuumKinematics::finite)
      r.error(ptr + "/element",
              "\"q4_bbar\" (mean dilatation) is implemented for linear kinematics; "
              "for finite strain near incompressibility use \"q9\"");
    if (options.analysis == PlaneAnalysis::plane_stress)
      r.error(ptr + "/element", "\"q4_bbar\" is for plane strain: plane stress does not lock, use \"q4\"");
    if (options.analysis == PlaneAnalysis::axisymmetric)
      r.error(ptr + "/element", "\"q4_bbar\" is for plane strain: in axisymmetry use t3, t6, q4, q8 or q9");
  }
  const ElementShape shape = element_shape(options.element);

  const auto read_law = [&](json& mat, const std::string& mp) -> std::shared_ptr<const PlaneMaterial> {
    const std::string law = r.choice(
        mat, mp, "law", {"neo_hookean", "saint_venant_kirchhoff", "j2_plasticity", "mooney_rivlin"}, "neo_hookean");
    if (law == "mooney_rivlin") return read_mooney_rivlin(r, mat, mp, options.analysis);
    for (const char* key : {"c10", "c01", "bulk"})
      if (mat.contains(key))
        r.error(mp + "/" + key, "belongs to law \"mooney_rivlin\" (this law takes young and poisson)");
    const double young = r.positive(mat, mp, "young");
    const double poisson = r.number(mat, mp, "poisson", 0.3);
    if (!(poisson > -1 && poisson < 0.5)) r.error(mp + "/poisson", show(mat["poisson"]) + " is not in (-1, 0.5)");
    if (law == "j2_plasticity") return read_j2_material(r, mat, mp, young, poisson, options);
    for (const char* key : {"yield_stress", "hardening", "kinematic_hardening", "hill48"})
      if (mat.contains(key)) r.error(mp + "/" + key, "belongs to law \"j2_plasticity\" (this law is elastic)");
    if (law == "neo_hookean") return std::make_shared<NeoHookeMaterial>(young, poisson, options.analysis);
    return std::make_shared<HookeMaterial>(young, poisson, options.analysis);
  };
  // The exact form refuses the laws it cannot hold and a bulk modulus too low for its penalty.
  const auto read_material = [&](json& mat, const std::string& mp) -> std::shared_ptr<const PlaneMaterial> {
    const size_t before = r.issues.size();
    std::shared_ptr<const PlaneMaterial> law = read_law(mat, mp);
    if (law && r.issues.size() == before && options.incompressibility == Incompressibility::exact)
      if (const std::string why = exact_law_issue(*law); !why.empty()) {
        const size_t colon = why.find(':');
        r.error(mp + "/" + why.substr(0, colon), why.substr(colon + 2));
        return nullptr;
      }
    return law;
  };
  // `material` for every element, or `materials` by physical surface (a mesh file).
  std::vector<std::shared_ptr<const PlaneMaterial>> materials;
  std::map<std::string, std::shared_ptr<const PlaneMaterial>> by_surface;
  if (body.contains("materials")) {
    if (!file) r.error(ptr + "/materials", "name the physical surfaces of a mesh file: give \"material\" here");
    else if (json* mats = r.object(body, ptr, "materials", true))
      for (auto& [name, mat] : mats->items()) {
        const std::string mp = ptr + "/materials/" + token(name);
        if (!file->surfaces.count(name)) {
          std::vector<std::string> names;
          for (const auto& [n, elements] : file->surfaces) names.push_back(n);
          r.error(mp, "\"" + name + "\" names no physical surface of the body (surfaces: " + Reader::list(names) + ")");
        } else if (!mat.is_object()) {
          r.error(mp, "is not an object");
        } else {
          by_surface[name] = read_material(mat, mp);
        }
      }
  }
  if (body.contains("material") || by_surface.empty())
    if (json* mat = r.object(body, ptr, "material", true)) materials.push_back(read_material(*mat, ptr + "/material"));

  // docs/algorithm.md#element-formulation-pairs: a pair that locks is refused with its reason.
  if (r.issues.empty()) {
    std::vector<const PlaneMaterial*> laws;
    for (const auto& m : materials) laws.push_back(m.get());
    for (const auto& [name, m] : by_surface) laws.push_back(m.get());
    for (const PlaneMaterial* law : laws)
      if (const std::string why = law ? element_pair_issue(options, *law) : ""; !why.empty()) {
        r.error(ptr + "/element", why);
        break;
      }
  }
  std::optional<PlaneMesh> mesh;
  std::string kind, default_contact;  // kind: "nodes", "rectangle" or "half_disc"
  const std::string mp = ptr + "/mesh";
  if (json* m = r.object(body, ptr, "mesh", true)) {
    std::vector<std::string> kinds;
    for (const char* k : {"nodes", "rectangle", "half_disc", "gmsh"})
      if (m->contains(k)) kinds.push_back(k);
    if (kinds.size() != 1) {
      r.error(mp, "needs exactly one of \"nodes\" (with \"elements\"), \"rectangle\", \"half_disc\" and \"gmsh\"");
    } else if ((kind = kinds[0]) == "gmsh") {
      if (m->contains("sets")) r.error(mp + "/sets", "come from the mesh file's physical curves and points");
      if (file) mesh = std::move(file->mesh);
    } else if (kind == "nodes") {
      mesh = read_explicit_mesh(r, *m, mp);
    } else {
      if (m->contains("sets")) r.error(mp + "/sets", "are generated for a " + kind);
      mesh = read_generated_mesh(r, *m, mp, shape, kind);
      default_contact = kind == "rectangle" ? "bottom" : "arc";
    }
  }
  if (!mesh || !r.issues.empty()) return;
  if (options.analysis == PlaneAnalysis::axisymmetric)
    if (const std::vector<int> off = nodes_off_half_plane(*mesh); !off.empty()) {
      r.error(mp, "axisymmetric: the section lies in the half-plane r = x >= 0; nodes at x < 0: " + id_list(off));
      return;
    }

  if (!body.contains("contact_set")) {
    if (default_contact.empty()) {
      r.error(ptr + "/contact_set", "is required: the name of the node set whose nodes can touch an obstacle");
      return;
    }
    body["contact_set"] = default_contact;
  }
  const json& cs = body["contact_set"];
  std::vector<std::string> names;
  for (const auto& [n, ids] : mesh->sets) names.push_back(n);
  if (!cs.is_string() || !mesh->sets.count(cs.get<std::string>())) {
    r.error(ptr + "/contact_set", show(cs) + " names no node set (sets: " + Reader::list(names) + ")");
    return;
  }
  const std::vector<int> contact_set = mesh->sets.at(cs.get<std::string>());
  if (!by_surface.empty()) {  // per element: its surface's material, else `material`
    std::vector<std::shared_ptr<const PlaneMaterial>> per_element(mesh->elements.size(),
                                                                  materials.empty() ? nullptr : materials[0]);
    for (const auto& [name, material] : by_surface)
      for (int e : file->surfaces.at(name)) per_element[e] = material;
    for (size_t e = 0; e < per_element.size(); ++e)
      if (!per_element[e]) {
        r.error(ptr + "/materials", "element tag " + std::to_string(file->tags.elements[e]) +
                                        " lies in none of these surfaces: name its surface, or give \"material\" "
                                        "for the rest");
        return;
      }
    materials = std::move(per_element);
  }
  std::unique_ptr<ContinuumBody> continuum;
  try {
    continuum = std::make_unique<ContinuumBody>(std::move(*mesh), contact_set, std::move(materials), options);
  } catch (const InvalidMesh& e) {
    report_mesh_issues(r, e.issues, mp, kind, file ? &file->tags : nullptr);
    return;
  } catch (const std::invalid_argument& e) {
    r.error(ptr + "/contact_set", e.what());
    return;
  }
  const PlaneMesh& checked = continuum->mesh();
  problem.body = std::move(continuum);
  r.node_sets[r.body_index] = checked.sets;
  if (file) {
    file->tags.body = r.body_index;
    r.file_meshes.push_back(std::move(file->tags));
  }

  read_continuum_supports(r, body, ptr, checked, options.kinematics == ContinuumKinematics::finite, problem);
  read_continuum_loads(r, body, ptr, checked, shape, problem, options.thickness,
                       options.analysis == PlaneAnalysis::axisymmetric);
  if (!r.issues.empty()) return;
  if (options.analysis == PlaneAnalysis::axisymmetric) hold_axis(checked, r, problem);
  // docs/algorithm.md#bodies-held-only-by-contact: contact holds the free rigid motions of one
  // connected body (scene.cpp); a mesh of several parts must have each part held by its supports.
  // A hub holds its nodes.
  std::vector<char> fixed(problem.body->dof_count(), 0);
  for (const Constraint& c : problem.constraints) fixed[c.dof] = 1;
  if (const json* hubs = body.contains("hubs") ? &body["hubs"] : nullptr; hubs && hubs->is_array())
    for (const json& h : *hubs)
      if (h.is_object() && h.contains("set") && h["set"].is_string() && checked.sets.count(h["set"].get<std::string>()))
        for (int node : checked.sets.at(h["set"].get<std::string>())) fixed[2 * node] = fixed[2 * node + 1] = 1;
  const std::string free = free_rigid_motion(checked, fixed);
  if (free.rfind("the part containing", 0) == 0)
    r.error(ptr + "/supports",
            "leave " + free +
                ": contact holds the free rigid motions of a connected body only; add supports to each part, "
                "or prescribe the displacement of a boundary set");
  read_hubs(r, body, ptr, checked, problem);
}

}  // namespace grip::scene_io
