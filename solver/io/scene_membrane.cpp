#include "solver/elements/continuum.hpp"  // id_list
#include "solver/elements/rigid_plastic_membrane.hpp"
#include "solver/io/scene_reader.hpp"

namespace grip::scene_io {

// body: {"model": "rigid_plastic_membrane", "material": {r, M, H, a0, n, regularization},
//        "thickness", "width", "analysis": "plane_strain" | "axisymmetric", "mesh": {"origin", "length", "elements"} | {"nodes": [[x, y]...]},
//        "supports": [{"node", "fix": ["x", "y"]}], "loads": [{"node", "force", "case"} | {"pressure", "case"}]}
void read_rigid_plastic_membrane(Reader& r, json& body, Problem& problem, const std::string& ptr) {
  json* mat = r.object(body, ptr, "material", true);
  json* mesh = r.object(body, ptr, "mesh", true);
  HillMaterial m;
  if (mat) {
    const std::string mp = ptr + "/material";
    m.r = r.positive(*mat, mp, "r", 1.0);
    m.M = r.number(*mat, mp, "M", 2.0);
    if (!(m.M > 1)) r.error(mp + "/M", show((*mat)["M"]) + " is not above 1");
    m.H = r.positive(*mat, mp, "H");
    m.a0 = r.positive(*mat, mp, "a0", 1e-4);
    m.n = r.number(*mat, mp, "n");
    if (!(m.n >= 0 && m.n < 1)) r.error(mp + "/n", show((*mat)["n"]) + " is not in [0, 1)");
    m.regularization = r.positive(*mat, mp, "regularization", 1e-5);
  }
  const double thickness = r.positive(body, ptr, "thickness");
  const bool axisymmetric =
      r.choice(body, ptr, "analysis", {"plane_strain", "axisymmetric"}, "plane_strain") == "axisymmetric";
  if (axisymmetric && body.contains("width"))
    r.error(ptr + "/width", "is not used in axisymmetry (forces are totals over the circle): leave it out");
  const double width = axisymmetric ? 1.0 : r.positive(body, ptr, "width", 1.0);
  std::vector<Vec2> nodes;
  if (mesh) {
    const std::string mp = ptr + "/mesh";
    if (mesh->contains("nodes")) {
      json* list = r.array(*mesh, mp, "nodes", true);
      if (list && list->size() < 2) r.error(mp + "/nodes", "needs at least two nodes");
      if (list)
        for (size_t i = 0; i < list->size(); ++i) {
          const std::string key = std::to_string(i);
          json wrap = {{key, (*list)[i]}};
          nodes.push_back(r.vec2(wrap, mp + "/nodes", key.c_str()));
        }
      for (size_t i = 1; i < nodes.size(); ++i)
        if ((nodes[i] - nodes[i - 1]).norm() == 0)
          r.error(mp + "/nodes/" + std::to_string(i), "repeats the previous node (a zero-length element)");
    } else {
      const Vec2 origin = r.vec2(*mesh, mp, "origin", Vec2::Zero());
      const double length = r.positive(*mesh, mp, "length");
      const int elements = r.integer(*mesh, mp, "elements", 1, 100000);
      for (int i = 0; i <= elements; ++i) nodes.push_back(origin + Vec2(length * i / elements, 0));
    }
  }
  if (axisymmetric) {
    std::vector<int> off;
    for (size_t i = 0; i < nodes.size(); ++i)
      if (!(nodes[i].x() >= 0)) off.push_back(static_cast<int>(i));
    if (!off.empty())
      r.error(ptr + "/mesh",
              "axisymmetric: the meridian lies in the half-plane r = x >= 0; nodes at x < 0: " + id_list(off));
    for (size_t i = 1; i < nodes.size(); ++i)
      if (nodes[i].x() == 0 && nodes[i - 1].x() == 0)
        r.error(ptr + "/mesh", "axisymmetric: element " + std::to_string(i - 1) + " lies on the axis");
  }
  if (!r.issues.empty()) return;
  problem.body = std::make_unique<RigidPlasticMembrane>(nodes, thickness, m, width, axisymmetric);
  const int count = static_cast<int>(nodes.size());
  read_supports(r, body, ptr, count, {"x", "y"}, &RigidPlasticMembrane::node_dof, problem);
  if (axisymmetric) {  // u_r = 0 on the axis, as for the continuum (docs/algorithm.md#axisymmetric)
    std::vector<char> fixed(2 * nodes.size(), 0);
    for (const Constraint& c : problem.constraints) fixed[c.dof] = 1;
    AxisHold hold{r.body_index, {}};
    for (int k = 0; k < count; ++k)
      if (nodes[k].x() == 0 && !fixed[RigidPlasticMembrane::node_dof(k, 0)]) {
        problem.constraints.push_back({RigidPlasticMembrane::node_dof(k, 0), 0.0, 0});
        hold.nodes.push_back(k);
      }
    r.axis_holds.push_back(std::move(hold));
  }
  if (json* loads = r.array(body, ptr, "loads", false))
    for (size_t i = 0; i < loads->size(); ++i) {
      const std::string lp = ptr + "/loads/" + std::to_string(i);
      json& l = (*loads)[i];
      if (!l.is_object()) {
        r.error(lp, "is not an object");
        continue;
      }
      if (l.contains("pressure")) {  // on every element, following the sheet
        const double p = r.number(l, lp, "pressure");
        const int load_case = r.load_case(l, lp);
        case_load(problem, load_case);
        if (l.contains("node") || l.contains("force"))
          r.error(lp, "a pressure acts on every element, following the sheet: give no \"node\" or \"force\" with it");
        if (ptr != "/body") r.error(lp + "/pressure", "a pressure follows the sheet: for a one-body scene (body) only");
        if (r.issues.empty()) static_cast<RigidPlasticMembrane&>(*problem.body).add_pressure(p, load_case);
        continue;
      }
      const int node = r.integer(l, lp, "node", 0, count - 1);
      const Vec2 f = r.vec2(l, lp, "force", Vec2::Zero());
      Vector& load = case_load(problem, r.load_case(l, lp));
      load.segment<2>(RigidPlasticMembrane::node_dof(node, 0)) += f;
    }
}

}  // namespace grip::scene_io
