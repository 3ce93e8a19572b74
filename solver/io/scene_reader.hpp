#pragma once
// Internal to solver/io: reads values out of the (mutable) effective scene, writes defaults
// in, and collects every problem with the JSON pointer of its value. Each body model's
// reader lives in its own scene_<model>.cpp.
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "solver/elements/plane_mesh.hpp"
#include "solver/io/scene.hpp"
#include "solver/obstacles/obstacle.hpp"
#include "solver/problem/problem.hpp"

namespace grip::scene_io {

using nlohmann::json;

// A key as one JSON pointer token (RFC 6901): '~' -> "~0", '/' -> "~1". Keys that the scene
// names itself (load cases, obstacles, node sets) may hold either.
inline std::string token(const std::string& key) {
  std::string t;
  for (char c : key) t += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
  return t;
}

inline std::string show(const json& j) {
  std::string s = j.dump();
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

// Reads values out of the (mutable) effective scene, writing defaults in and collecting
// every problem with its JSON pointer, up to kMaxSceneIssues: the next one ends the reading
// (SceneErrors with more()), so a scene's problems cost at most that many.
class Reader {
 public:
  std::vector<SceneIssue> issues;

  void error(const std::string& pointer, std::string detail) {
    if (issues.size() >= kMaxSceneIssues) throw SceneErrors(std::move(issues), true);
    issues.push_back({pointer.empty() ? "/" : pointer, std::move(detail)});
  }

  // obj[key] as an object or an array (created empty when absent and optional).
  json* object(json& obj, const std::string& ptr, const char* key, bool required) {
    return member(obj, ptr, key, required, json::object(), "an object");
  }
  json* array(json& obj, const std::string& ptr, const char* key, bool required) {
    return member(obj, ptr, key, required, json::array(), "an array");
  }
  json* member(json& obj, const std::string& ptr, const char* key, bool required, json empty, const char* kind) {
    const std::string p = ptr + "/" + token(key);
    if (!obj.is_object()) return nullptr;
    if (!obj.contains(key)) {
      if (required) {
        error(p, "is required");
        return nullptr;
      }
      obj[key] = std::move(empty);
      return &obj[key];
    }
    if (obj[key].type() != empty.type()) {
      error(p, show(obj[key]) + " is not " + kind);
      return nullptr;
    }
    return &obj[key];
  }

  // A finite number; `fallback` fills it in when absent (required when no fallback).
  double number(json& obj, const std::string& ptr, const char* key, std::optional<double> fallback = std::nullopt) {
    const std::string p = ptr + "/" + token(key);
    if (!obj.is_object()) return fallback.value_or(0.0);
    if (!obj.contains(key)) {
      if (!fallback) {
        error(p, "is required");
        return 0.0;
      }
      obj[key] = *fallback;
      return *fallback;
    }
    const json& v = obj[key];
    if (!v.is_number()) {
      error(p, show(v) + " is not a number");
      return fallback.value_or(0.0);
    }
    const double d = v.get<double>();
    if (!std::isfinite(d)) {
      error(p, "is not finite");
      return fallback.value_or(0.0);
    }
    return d;
  }

  double positive(json& obj, const std::string& ptr, const char* key, std::optional<double> fallback = std::nullopt) {
    const double d = number(obj, ptr, key, fallback);
    if (obj.is_object() && obj.contains(key) && obj[key].is_number() && !(d > 0))
      error(ptr + "/" + token(key), show(obj[key]) + " is not positive");
    return d;
  }

  int integer(json& obj, const std::string& ptr, const char* key, int lo, int hi,
              std::optional<int> fallback = std::nullopt) {
    const std::string p = ptr + "/" + token(key);
    if (!obj.is_object()) return fallback.value_or(lo);
    if (!obj.contains(key)) {
      if (!fallback) {
        error(p, "is required");
        return lo;
      }
      obj[key] = *fallback;
      return *fallback;
    }
    return integer_value(obj[key], p, lo, hi);
  }

  int integer_value(const json& v, const std::string& p, int lo, int hi) {
    if (!v.is_number_integer()) {
      error(p, show(v) + " is not an integer");
      return lo;
    }
    const long long i = v.get<long long>();
    if (i < lo || i > hi) {
      error(p, std::to_string(i) + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
      return lo;
    }
    return static_cast<int>(i);
  }

  std::string choice(json& obj, const std::string& ptr, const char* key, const std::vector<std::string>& options,
                     std::optional<std::string> fallback) {
    const std::string p = ptr + "/" + token(key);
    if (!obj.is_object()) return fallback.value_or(options.front());
    if (!obj.contains(key)) {
      if (!fallback) {
        error(p, "is required (one of " + list(options) + ")");
        return options.front();
      }
      obj[key] = *fallback;
      return *fallback;
    }
    const json& v = obj[key];
    if (v.is_string())
      for (const auto& o : options)
        if (v.get<std::string>() == o) return o;
    error(p, show(v) + " is not one of " + list(options));
    return fallback.value_or(options.front());
  }

  Vec2 vec2(json& obj, const std::string& ptr, const char* key, std::optional<Vec2> fallback = std::nullopt) {
    const std::string p = ptr + "/" + token(key);
    if (!obj.is_object()) return Vec2::Zero();
    if (!obj.contains(key)) {
      if (!fallback) {
        error(p, "is required ([x, y])");
        return Vec2::Zero();
      }
      obj[key] = {fallback->x(), fallback->y()};
      return *fallback;
    }
    const json& v = obj[key];
    if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number()) {
      error(p, show(v) + " is not a pair of numbers [x, y]");
      return Vec2::Zero();
    }
    const Vec2 out(v[0].get<double>(), v[1].get<double>());
    if (!out.allFinite()) error(p, "is not finite");
    return out;
  }

  // Resolves body.mesh.gmsh references (read_scene's caller; null: none can be read).
  const MeshResolver* meshes = nullptr;
  // The gmsh tags of the bodies read from files, and the index of the body being read.
  std::vector<FileMeshTags> file_meshes;
  int body_index = 0;
  std::vector<AxisHold> axis_holds;  // the axisymmetric bodies' axis nodes (scene.hpp)
  // The node sets of each body by its index (continuum bodies: their meshes' sets), which the
  // scene's outputs name.
  std::map<int, std::map<std::string, std::vector<int>>> node_sets;

  // Load cases by name, in order of first mention; "main" unless a value names another.
  std::vector<std::string> cases{"main"};

  // The load case named by obj["case"] (default "main"), registered on first mention.
  int load_case(json& obj, const std::string& ptr) {
    if (!obj.contains("case")) obj["case"] = "main";
    if (!obj["case"].is_string()) {
      error(ptr + "/case", show(obj["case"]) + " is not a string");
      return 0;
    }
    const std::string& name = obj["case"].get_ref<const std::string&>();
    const auto [it, added] = case_index_.try_emplace(name, static_cast<int>(cases.size()));
    if (added) cases.push_back(name);
    return it->second;
  }

  // The index of a registered load case; -1 for none.
  int find_case(const std::string& name) const {
    const auto it = case_index_.find(name);
    return it == case_index_.end() ? -1 : it->second;
  }

  // "\"a\", \"b\"": the first 20, then how many more (a scene may name thousands).
  static std::string list(const std::vector<std::string>& options) {
    constexpr size_t kShown = 20;
    std::string s;
    for (size_t i = 0; i < std::min(options.size(), kShown); ++i) s += (i ? ", " : "") + ("\"" + options[i] + "\"");
    if (options.size() > kShown) s += " and " + std::to_string(options.size() - kShown) + " more";
    return s;
  }

 private:
  // cases by name: a scene may name thousands (a linear search made reading quadratic).
  std::unordered_map<std::string, int> case_index_{{"main", 0}};
};

// The load vector of a case, created (zero) on first use.
inline Vector& case_load(Problem& problem, int load_case) {
  while (static_cast<int>(problem.loads.size()) <= load_case)
    problem.loads.push_back(Vector::Zero(problem.body->dof_count()));
  return problem.loads[load_case];
}

// body.supports: [{"node", "fix": [component names], "values": {name: value}, "case"}];
// `dof(node, component index)` maps to the global dof.
void read_supports(Reader& r, json& body, const std::string& ptr, int nodes, const std::vector<std::string>& components,
                   int (*dof)(int, int), Problem& problem);

// Body model readers: fill problem.body, constraints and load from the body at `ptr`
// (scene["body"], or an entry of scene["bodies"]).
void read_timoshenko_beam(Reader& r, json& body, Problem& problem, const std::string& ptr = "/body");
void read_reissner_beam(Reader& r, json& body, Problem& problem, const std::string& ptr = "/body");
void read_rigid_plastic_membrane(Reader& r, json& body, Problem& problem, const std::string& ptr = "/body");
// A continuum body's mesh from a gmsh file (scene_gmsh.cpp): the mesh, its element kind ("q4",
// "t6", ...) and the gmsh tags of its nodes and elements; nullopt after an error.
struct FileMesh {
  PlaneMesh mesh;
  std::string element;
  FileMeshTags tags;
  std::map<std::string, std::vector<int>> surfaces;  // physical surface -> the body's elements
};
std::optional<FileMesh> read_file_mesh(Reader& r, json& gmsh, const std::string& ptr);
// An obstacle's shape {"type": "gmsh_curve", "gmsh": {"file" | "id"}, "curve", "reverse"}: the
// physical curve's lines in order along it (2-node lines as segments, 3-node lines as arcs
// through their mid node), the solid on the left of gmsh's direction (or of the reverse).
std::optional<std::vector<ProfilePiece>> read_curve_pieces(Reader& r, json& shape, const std::string& ptr);

void read_continuum(Reader& r, json& body, Problem& problem, const std::string& ptr = "/body");
// One body at `ptr` by its model's reader.
void read_body(Reader& r, json& body, Problem& problem, const std::string& ptr);

// scene["bodies"]: every body read on its own, then joined into one BodySet (dofs, sites and
// load vectors at each body's offsets); a body's free rigid motions are held by contact as in
// a one-body scene (scene.cpp).
void read_bodies(Reader& r, json& bodies, Problem& problem);
// scene["contacts"]: [{slave: "BODY.SET", master: "BODY.SET" | "OBSTACLE", friction, name}]
// (after the obstacles): a pair with a body master joins problem.obstacles (no shape); one with
// an obstacle master restricts that obstacle to the slave sets that name it.
void read_contacts(Reader& r, json& scene, Problem& problem);
// scene["outputs"] (solver/io/quantities.hpp), after the bodies and obstacles: each quantity
// with its nodes, dofs or obstacle resolved. `fields_every_step`: every step's fields are
// recorded (a field output reads them).
std::vector<Quantity> read_outputs(Reader& r, json& scene, const Problem& problem, bool fields_every_step);
// The rigid motions of `body` (coefficients of translation x, y and rotation) that supports on
// the dofs `fixed` leave free.
Matrix free_motions(const Body& body, const std::vector<int>& fixed);

}  // namespace grip::scene_io
