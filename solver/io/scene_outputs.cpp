// scene["outputs"]: the quantities of interest (solver/io/quantities.hpp).
//   [{"name", "kind": "reaction" | "resultant" | "displacement" | "peak_pressure" | "contact_width" |
//     "stick_width" | "field", and by kind:
//     reaction: "set" | "node" | "at", "component": "x" | "y";
//     displacement: "node" | "at", "component": "x" | "y";
//     resultant, peak_pressure: "obstacle" (optional: every obstacle), resultant's "component";
//     contact_width, stick_width: "obstacle" (optional where the scene has one);
//     field: "element" | "at", "component": an element field's name}]
// "set" names a node set ("BODY.SET" in a scene of several bodies), "node" a node by its row of
// the result's nodes table, "at" the node (field: the element) nearest a reference position.
#include <limits>
#include <set>

#include "solver/io/scene_reader.hpp"

namespace grip::scene_io {
namespace {

constexpr size_t kMaxOutputs = 100;

const std::vector<std::string> kKinds = {"reaction",      "resultant",   "displacement", "peak_pressure",
                                         "contact_width", "stick_width", "field"};

// The keys each kind takes besides name and kind.
const std::map<std::string, std::vector<std::string>> kKeys = {{"reaction", {"set", "node", "at", "component"}},
                                                               {"displacement", {"node", "at", "component"}},
                                                               {"resultant", {"obstacle", "component"}},
                                                               {"peak_pressure", {"obstacle"}},
                                                               {"contact_width", {"obstacle"}},
                                                               {"stick_width", {"obstacle"}},
                                                               {"field", {"element", "at", "component"}}};

int parts_of(const Body& body) { return std::max(1, body.part_count()); }

// The first global node of each part (the rows of the result's nodes table).
std::vector<int> node_offsets(const Body& body) {
  std::vector<int> first{0};
  for (int b = 0; b < parts_of(body); ++b) first.push_back(first.back() + body.part(b).node_count());
  return first;
}

// The weights of a component (0: x, 1: y) on the dofs of the given global nodes.
std::vector<std::pair<int, double>> node_dofs(const Body& body, const std::set<int>& nodes, int component) {
  std::vector<std::pair<int, double>> dofs;
  const std::vector<int> first = node_offsets(body);
  for (int b = 0; b < parts_of(body); ++b) {
    const Body& part = body.part(b);
    const Vector t = part.rigid_translation(component == 0 ? Vec2::UnitX() : Vec2::UnitY());
    for (int d = 0; d < part.dof_count(); ++d)
      if (t[d] != 0 && nodes.count(first[b] + part.dof_node(d))) dofs.emplace_back(body.dof_offset(b) + d, t[d]);
  }
  return dofs;
}

// Reference positions of every node (the x, y columns of the fields at rest).
std::vector<Vec2> node_positions(const Body& body) {
  const FieldTable t = body.site_fields(Vector::Zero(body.dof_count()));
  const auto col = [&](const char* name) {
    return static_cast<size_t>(std::find(t.names.begin(), t.names.end(), name) - t.names.begin());
  };
  const size_t x = col("x"), y = col("y");
  std::vector<Vec2> out;
  for (const auto& row : t.rows) out.emplace_back(x < row.size() ? row[x] : 0.0, y < row.size() ? row[y] : 0.0);
  return out;
}

int nearest(const std::vector<Vec2>& points, const Vec2& at) {
  int best = 0;
  double d = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < points.size(); ++k)
    if ((points[k] - at).squaredNorm() < d) {
      d = (points[k] - at).squaredNorm();
      best = static_cast<int>(k);
    }
  return best;
}

// The global nodes of a set: "SET" in a scene of one body, "BODY.SET" in one of several.
std::optional<std::set<int>> set_nodes(Reader& r, const json& scene, const Body& body, const json& name,
                                       const std::string& ptr) {
  if (!name.is_string()) {
    r.error(ptr, show(name) + " is not a string");
    return std::nullopt;
  }
  const std::string text = name.get<std::string>();
  int b = 0;
  std::string set = text;
  if (scene.contains("bodies")) {
    const size_t dot = text.find('.');
    std::vector<std::string> names;
    b = -1;
    for (size_t k = 0; k < scene["bodies"].size(); ++k) {
      const json& named = scene["bodies"][k];
      names.push_back(named.is_object() && named.contains("name") && named["name"].is_string()
                          ? named["name"].get<std::string>()
                          : "");
      if (dot != std::string::npos && names.back() == text.substr(0, dot)) b = static_cast<int>(k);
    }
    if (b < 0) {
      r.error(ptr, show(name) + " names no body (\"BODY.SET\", bodies: " + Reader::list(names) + ")");
      return std::nullopt;
    }
    set = text.substr(dot + 1);
  }
  const auto sets = r.node_sets.find(b);
  std::vector<std::string> names;
  if (sets != r.node_sets.end())
    for (const auto& [n, ids] : sets->second) names.push_back(n);
  if (sets == r.node_sets.end() || !sets->second.count(set)) {
    r.error(ptr, "\"" + set + "\" names no node set (sets: " + (names.empty() ? "none" : Reader::list(names)) + ")");
    return std::nullopt;
  }
  const int first = node_offsets(body)[b];
  std::set<int> nodes;
  for (int n : sets->second.at(set)) nodes.insert(first + n);
  return nodes;
}

// The obstacle (or contact pair) named by q["obstacle"]; -1 when absent.
int obstacle_of(Reader& r, json& q, const std::string& ptr, const Problem& problem) {
  if (!q.contains("obstacle")) return -1;
  std::vector<std::string> names;
  for (size_t o = 0; o < problem.obstacles.size(); ++o) {
    names.push_back(problem.obstacles[o].name);
    if (q["obstacle"].is_string() && q["obstacle"].get<std::string>() == names.back()) return static_cast<int>(o);
  }
  r.error(ptr + "/obstacle",
          show(q["obstacle"]) + " names no obstacle or contact (names: " + Reader::list(names) + ")");
  return -1;
}

}  // namespace

std::vector<Quantity> read_outputs(Reader& r, json& scene, const Problem& problem, bool fields_every_step) {
  std::vector<Quantity> out;
  if (!scene.contains("outputs")) return out;
  json* outputs = r.array(scene, "", "outputs", false);
  if (!outputs || !problem.body) return out;
  if (outputs->size() > kMaxOutputs)
    r.error("/outputs", "has " + std::to_string(outputs->size()) + " entries; at most " + std::to_string(kMaxOutputs));
  const Body& body = *problem.body;
  std::vector<Vec2> positions;  // of the nodes, read once where "at" asks
  std::set<std::string> names;
  for (size_t i = 0; i < outputs->size() && i < kMaxOutputs; ++i) {
    const std::string ptr = "/outputs/" + std::to_string(i);
    json& q = (*outputs)[i];
    if (!q.is_object()) {
      r.error(ptr, "is not an object");
      continue;
    }
    const size_t before = r.issues.size();
    Quantity quantity;
    if (!q.contains("name") || !q["name"].is_string() || q["name"].get<std::string>().empty())
      r.error(ptr + "/name", "is required: a non-empty string that names the quantity in the results");
    else if (!names.insert(q["name"].get<std::string>()).second)
      r.error(ptr + "/name", show(q["name"]) + " names another output already");
    else quantity.name = q["name"].get<std::string>();
    const std::string kind = r.choice(q, ptr, "kind", kKinds, std::nullopt);
    if (r.issues.size() > before) continue;
    quantity.kind = static_cast<QuantityKind>(std::find(kKinds.begin(), kKinds.end(), kind) - kKinds.begin());
    const std::vector<std::string>& keys = kKeys.at(kind);
    for (const auto& [key, value] : q.items())
      if (key != "name" && key != "kind" && std::find(keys.begin(), keys.end(), key) == keys.end())
        r.error(ptr + "/" + token(key), "is not used by kind \"" + kind + "\" (it takes " + Reader::list(keys) + ")");
    if (r.issues.size() > before) continue;

    // Where: the nodes (reaction, displacement) or the element (field).
    const bool takes_nodes = kind == "reaction" || kind == "displacement" || kind == "field";
    std::set<int> nodes;
    if (takes_nodes) {
      std::vector<std::string> given;
      for (const char* key : {"set", "node", "element", "at"})
        if (q.contains(key)) given.push_back(key);
      std::vector<std::string> allowed;
      for (const char* key : {"set", "node", "element", "at"})
        if (std::find(keys.begin(), keys.end(), key) != keys.end()) allowed.push_back(key);
      if (given.size() != 1) {
        r.error(ptr, "needs exactly one of " + Reader::list(allowed));
        continue;
      }
      const std::string& where = given[0];
      if (where == "set") {
        if (auto s = set_nodes(r, scene, body, q["set"], ptr + "/set")) nodes = std::move(*s);
      } else if (where == "node") {
        nodes.insert(r.integer(q, ptr, "node", 0, body.node_count() - 1));
      } else if (where == "element") {
        quantity.element = r.integer(q, ptr, "element", 0, static_cast<int>(body.cells().size()) - 1);
      } else {
        const Vec2 at = r.vec2(q, ptr, "at");
        if (positions.empty()) positions = node_positions(body);
        if (kind != "field") {
          nodes.insert(nearest(positions, at));
        } else {  // the element whose corners' mean is nearest
          std::vector<Vec2> centres;
          for (const auto& cell : body.cells()) {
            Vec2 c = Vec2::Zero();
            for (int n : cell) c += positions[n] / static_cast<double>(cell.size());
            centres.push_back(c);
          }
          quantity.element = nearest(centres, at);
        }
      }
    }
    if (kind == "reaction" || kind == "displacement" || kind == "resultant") {
      quantity.component = r.choice(q, ptr, "component", {"x", "y"}, std::nullopt) == "x" ? 0 : 1;
      if (kind != "resultant") quantity.dofs = node_dofs(body, nodes, quantity.component);
    }
    if (kind == "field") {
      if (!fields_every_step)
        r.error(ptr + "/kind",
                "a field output reads each step's element fields: record every step (output.steps \"all\")");
      if (!q.contains("component") || !q["component"].is_string()) {
        r.error(ptr + "/component", "is required: the name of an element field");
      } else {
        const std::vector<std::string> fields = body.element_fields(Vector::Zero(body.dof_count())).names;
        const auto it = std::find(fields.begin(), fields.end(), q["component"].get<std::string>());
        if (it == fields.end())
          r.error(ptr + "/component", show(q["component"]) +
                                          " is no element field of this body (fields: " + Reader::list(fields) +
                                          "); a plastic strain is one only where the material has plasticity");
        quantity.column = static_cast<int>(it - fields.begin());
      }
    }
    if (kind == "resultant" || kind == "peak_pressure" || kind == "contact_width" || kind == "stick_width") {
      quantity.obstacle = obstacle_of(r, q, ptr, problem);
      const bool width = kind == "contact_width" || kind == "stick_width";
      if (width && !q.contains("obstacle")) {
        if (problem.obstacles.size() == 1) quantity.obstacle = 0;
        else
          r.error(ptr + "/obstacle", "is required: the scene has " + std::to_string(problem.obstacles.size()) +
                                         " obstacles and contacts, and a width is measured along one");
      }
      if (kind == "stick_width" && quantity.obstacle >= 0 && !problem.obstacles[quantity.obstacle].frictional)
        r.error(ptr + (q.contains("obstacle") ? "/obstacle" : "/kind"),
                "\"" + problem.obstacles[quantity.obstacle].name + "\" has no friction: no point sticks on it");
    }
    if (r.issues.size() == before) out.push_back(std::move(quantity));
  }
  return out;
}

}  // namespace grip::scene_io
