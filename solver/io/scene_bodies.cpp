// Scenes of several bodies: "bodies": [{"name", ...what "body" is}] and "contacts":
// [{"slave": "BODY.SET", "master": "BODY.SET" | "OBSTACLE", "friction", "name"}].
#include <algorithm>
#include <set>
#include <unordered_map>

#include "solver/elements/continuum.hpp"
#include "solver/elements/reissner_beam.hpp"
#include "solver/elements/rigid_hubs.hpp"
#include "solver/elements/timoshenko_beam.hpp"
#include "solver/io/scene_reader.hpp"
#include "solver/model/body_set.hpp"

namespace grip::scene_io {

void read_body(Reader& r, json& body, Problem& problem, const std::string& ptr) {
  // The registry of body models: the scene's name -> its reader.
  using ModelReader = void (*)(Reader&, json&, Problem&, const std::string&);
  static const std::vector<std::pair<std::string, ModelReader>> models = {
      {"timoshenko_beam", read_timoshenko_beam},
      {"reissner_beam", read_reissner_beam},
      {"rigid_plastic_membrane", read_rigid_plastic_membrane},
      {"continuum", read_continuum},
  };
  std::vector<std::string> names;
  for (const auto& m : models) names.push_back(m.first);
  const std::string model = r.choice(body, ptr, "model", names, std::nullopt);
  for (const auto& m : models)
    if (m.first == model && r.issues.empty()) m.second(r, body, problem, ptr);
}

void read_bodies(Reader& r, json& bodies, Problem& problem) {
  if (bodies.empty()) r.error("/bodies", "needs at least one body");
  std::vector<Problem> parts;
  std::vector<std::string> names;
  std::set<std::string> named;  // names, for lookup
  for (size_t b = 0; b < bodies.size(); ++b) {
    const std::string bp = "/bodies/" + std::to_string(b);
    json& body = bodies[b];
    if (!body.is_object()) {
      r.error(bp, "is not an object");
      continue;
    }
    if (!body.contains("name")) {
      r.error(bp + "/name", "is required: contacts name the body's sets as \"BODY.SET\"");
      continue;
    }
    const json& name = body["name"];
    if (!name.is_string() || name.get<std::string>().empty() ||
        name.get<std::string>().find('.') != std::string::npos) {
      r.error(bp + "/name", show(name) + " is not a name (a non-empty string without '.')");
      continue;
    }
    if (named.count(name.get<std::string>())) r.error(bp + "/name", show(name) + " names another body already");
    if (body.value("model", "") == "rigid_plastic_membrane")
      r.error(bp + "/model",
              "a rigid_plastic_membrane has no stiffness in its flat reference state: its first step starts from a "
              "prescribed depth of one node pressed by a rigid obstacle (solver.start), whose reaction is the first "
              "contact force (docs/algorithm.md#load-stepping-and-cuts); against a deformable body that depth would be "
              "shared with the other "
              "body's compliance, which gives no starting force, so a membrane is for one-body scenes (body)");
    if (!r.issues.empty()) continue;
    Problem part;
    r.body_index = static_cast<int>(b);
    read_body(r, body, part, bp);
    if (!r.issues.empty() || !part.body) continue;
    names.push_back(name.get<std::string>());
    named.insert(names.back());
    parts.push_back(std::move(part));
  }
  if (!r.issues.empty()) return;  // every body read: parts[b] is /bodies/b
  // A section of revolution and a plane body do not meet: its forces are totals over the circle,
  // the plane body's per unit thickness (docs/algorithm.md#axisymmetric).
  for (size_t b = 1; b < parts.size(); ++b)
    if (parts[b].body->axisymmetric() != parts[0].body->axisymmetric())
      r.error("/bodies/" + std::to_string(b) + (bodies[b].contains("analysis") ? "/analysis" : ""),
              std::string("body \"") + names[b] + "\" is " + (parts[b].body->axisymmetric() ? "" : "not ") +
                  "axisymmetric and body \"" + names[0] + "\" is " + (parts[0].body->axisymmetric() ? "" : "not ") +
                  "axisymmetric: the bodies of a scene are all sections of revolution (analysis: axisymmetric) or "
                  "all plane");
  if (!r.issues.empty()) return;
  std::vector<std::unique_ptr<Body>> bodies_owned;
  for (Problem& part : parts) bodies_owned.push_back(std::move(part.body));
  auto set = std::make_unique<BodySet>(std::move(bodies_owned), names);
  problem.body = std::move(set);
  const BodySet& all = static_cast<const BodySet&>(*problem.body);
  for (int b = 0; b < all.part_count(); ++b) {
    const int offset = all.dof_offset(b), n = all.part(b).dof_count();
    for (Constraint c : parts[b].constraints) {
      c.dof += offset;
      problem.constraints.push_back(c);
    }
    for (size_t k = 0; k < parts[b].loads.size(); ++k)
      case_load(problem, static_cast<int>(k)).segment(offset, n) += parts[b].loads[k];
  }
}

namespace {

// "BODY.SET": the body's index, its sites in the set and the set's surface pieces; nullopt after
// an error. A continuum names a node set of its mesh (its contact_set's nodes in it, the
// boundary sides between them); a beam names its surface "upper" or "lower": its axis offset by
// half the depth toward +y or -y (Body::surface_point's side), through every node.
struct SetRef {
  int body = -1;
  std::vector<int> sites;                    // sites of the BodySet
  std::vector<std::array<int, 2>> segments;  // its surface pieces, body on the left of a -> b
  int side = 0;                              // a beam's surface side; 0 for a continuum
};

std::optional<SetRef> find_set(Reader& r, const BodySet& all, const std::string& text, const std::string& ptr) {
  const size_t dot = text.find('.');
  const std::string body = text.substr(0, dot), set = dot == std::string::npos ? "" : text.substr(dot + 1);
  for (int b = 0; b < all.part_count(); ++b) {
    if (all.name(b) != body) continue;
    const int first = all.site_offset(b), count = all.part(b).site_count();
    // The body that read_body built from this scene: a set names a beam's surface or a node set
    // of the continuum's mesh, so io asks for the type it built (docs/design.md).
    if (dynamic_cast<const TimoshenkoBeam*>(&all.part(b)) || dynamic_cast<const ReissnerBeam*>(&all.part(b))) {
      if (set != "upper" && set != "lower") {
        r.error(ptr, "\"" + set + "\" names no surface of the beam \"" + body +
                         "\" (surfaces: upper, lower: its axis "
                         "offset by half the depth toward +y or -y)");
        return std::nullopt;
      }
      SetRef ref{b, {}, {}, set == "upper" ? +1 : -1};
      for (int s = first; s < first + count; ++s) ref.sites.push_back(s);
      for (int s = first; s + 1 < first + count; ++s)  // the beam on the left: lower toward +x, upper toward -x
        ref.segments.push_back(ref.side < 0 ? std::array<int, 2>{s, s + 1} : std::array<int, 2>{s + 1, s});
      return ref;
    }
    const Body* part = &all.part(b);
    if (const auto* hubbed = dynamic_cast<const RigidHubs*>(part)) part = &hubbed->inner();  // same sites
    const auto* continuum = dynamic_cast<const ContinuumBody*>(part);
    if (!continuum) {
      r.error(ptr,
              "body \"" + body + "\" has no surface that pairs with another body's (continuum and beam bodies do)");
      return std::nullopt;
    }
    const auto& sets = continuum->mesh().sets;
    if (!sets.count(set)) {
      std::vector<std::string> names;
      for (const auto& [n, ids] : sets) names.push_back(n);
      r.error(ptr, "\"" + set + "\" names no node set of body \"" + body + "\" (sets: " + Reader::list(names) + ")");
      return std::nullopt;
    }
    const std::set<int> nodes(sets.at(set).begin(), sets.at(set).end());
    SetRef ref{b, {}, {}, 0};
    for (int s = 0; s < count; ++s)
      if (nodes.count(all.part(b).site_node(s))) ref.sites.push_back(first + s);
    if (ref.sites.empty()) {
      r.error(ptr, "set \"" + set + "\" shares no node with the contact_set of body \"" + body + "\"");
      return std::nullopt;
    }
    // The contact sides of its body with both ends in the set.
    const std::set<int> in_set(ref.sites.begin(), ref.sites.end());
    for (const auto& side : all.surface_segments())
      if (in_set.count(side[0]) && in_set.count(side[1])) ref.segments.push_back(side);
    return ref;
  }
  std::vector<std::string> names;
  for (int b = 0; b < all.part_count(); ++b) names.push_back(all.name(b));
  r.error(ptr, show(text) + " names no body (\"BODY.SET\", bodies: " + Reader::list(names) + ")");
  return std::nullopt;
}

}  // namespace

void read_contacts(Reader& r, json& scene, Problem& problem) {
  json* contacts = r.array(scene, "", "contacts", false);
  if (!contacts) return;
  const auto& all = static_cast<const BodySet&>(*problem.body);
  const size_t rigid = problem.obstacles.size();
  std::vector<std::vector<int>> obstacle_slaves(rigid);
  // The obstacles' and the pairs' names (a linear search per contact made reading quadratic).
  std::unordered_map<std::string, size_t> obstacle_index;
  for (size_t o = 0; o < rigid; ++o) obstacle_index.emplace(problem.obstacles[o].name, o);
  for (size_t i = 0; i < contacts->size(); ++i) {
    const std::string cp = "/contacts/" + std::to_string(i);
    json& c = (*contacts)[i];
    if (!c.is_object()) {
      r.error(cp, "is not an object");
      continue;
    }
    if (!c.contains("slave") || !c["slave"].is_string()) r.error(cp + "/slave", "is required: \"BODY.SET\"");
    if (!c.contains("master") || !c["master"].is_string())
      r.error(cp + "/master", "is required: \"BODY.SET\" or an obstacle's name");
    if (!r.issues.empty()) continue;
    const auto slave = find_set(r, all, c["slave"].get<std::string>(), cp + "/slave");
    const std::string master = c["master"].get<std::string>();
    const auto named_master = obstacle_index.find(master);
    const int obstacle = named_master != obstacle_index.end() && named_master->second < rigid
                             ? static_cast<int>(named_master->second)
                             : -1;
    if (obstacle >= 0) {
      if (c.contains("friction"))
        r.error(cp + "/friction", "is the obstacle's: give it in /obstacles/" + std::to_string(obstacle) + "/friction");
      if (slave)
        obstacle_slaves[obstacle].insert(obstacle_slaves[obstacle].end(), slave->sites.begin(), slave->sites.end());
      continue;
    }
    const auto master_set = find_set(r, all, master, cp + "/master");
    if (!slave || !master_set) continue;
    if (slave->body == master_set->body) {
      r.error(cp + "/master", "is on the slave's own body: self-contact is not supported");
      continue;
    }
    if (master_set->segments.empty()) {
      r.error(cp + "/master", "set " + show(master) + " spans no side of its body's contact surface");
      continue;
    }
    ObstacleInstance pair;
    if (!c.contains("name")) c["name"] = c["slave"].get<std::string>() + " on " + master;
    if (!c["name"].is_string()) r.error(cp + "/name", "is not a string");
    else pair.name = c["name"].get<std::string>();
    if (!pair.name.empty() && !obstacle_index.emplace(pair.name, problem.obstacles.size()).second)
      r.error(cp + "/name", show(c["name"]) + " names an obstacle or another contact already");
    pair.friction = r.number(c, cp, "friction", 0.0);
    if (pair.friction < 0) r.error(cp + "/friction", show(c["friction"]) + " is negative");
    pair.frictional = pair.friction > 0;
    pair.master = make_master_surface(all, master_set->body, master_set->segments, slave->segments, master_set->side,
                                      slave->side);
    pair.slaves = slave->sites;
    pair.slave_body = slave->body;
    problem.obstacles.push_back(std::move(pair));
  }
  // An obstacle that no contact names pairs with every body's sites (as in a one-body scene).
  for (size_t o = 0; o < rigid; ++o) {
    std::vector<int>& sites = obstacle_slaves[o];
    std::sort(sites.begin(), sites.end());
    sites.erase(std::unique(sites.begin(), sites.end()), sites.end());
    problem.obstacles[o].slaves = std::move(sites);
  }
}

}  // namespace grip::scene_io
