#include "solver/io/scene.hpp"

#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>

#include "solver/elements/timoshenko_beam.hpp"

namespace grip {
namespace {

using nlohmann::json;

std::string join(const std::vector<SceneIssue>& issues) {
  std::ostringstream os;
  for (size_t i = 0; i < issues.size(); ++i)
    os << (i ? "\n" : "") << issues[i].pointer << ": " << issues[i].detail;
  return os.str();
}

std::string show(const json& j) {
  std::string s = j.dump();
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

// Reads values out of the (mutable) effective scene, writing defaults in and collecting
// every problem with its JSON pointer.
class Reader {
 public:
  std::vector<SceneIssue> issues;

  void error(const std::string& pointer, std::string detail) {
    issues.push_back({pointer.empty() ? "/" : pointer, std::move(detail)});
  }

  // obj[key] as an object (created empty when absent and optional).
  json* object(json& obj, const std::string& ptr, const char* key, bool required) {
    const std::string p = ptr + "/" + key;
    if (!obj.is_object()) return nullptr;
    if (!obj.contains(key)) {
      if (required) {
        error(p, "is required");
        return nullptr;
      }
      obj[key] = json::object();
    }
    if (!obj[key].is_object()) {
      error(p, show(obj[key]) + " is not an object");
      return nullptr;
    }
    return &obj[key];
  }

  json* array(json& obj, const std::string& ptr, const char* key, bool required) {
    const std::string p = ptr + "/" + key;
    if (!obj.is_object()) return nullptr;
    if (!obj.contains(key)) {
      if (required) {
        error(p, "is required");
        return nullptr;
      }
      obj[key] = json::array();
    }
    if (!obj[key].is_array()) {
      error(p, show(obj[key]) + " is not an array");
      return nullptr;
    }
    return &obj[key];
  }

  // A finite number; `fallback` fills it in when absent (required when no fallback).
  double number(json& obj, const std::string& ptr, const char* key,
                std::optional<double> fallback = std::nullopt) {
    const std::string p = ptr + "/" + key;
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

  double positive(json& obj, const std::string& ptr, const char* key,
                  std::optional<double> fallback = std::nullopt) {
    const double d = number(obj, ptr, key, fallback);
    if (obj.is_object() && obj.contains(key) && obj[key].is_number() && !(d > 0))
      error(ptr + "/" + key, show(obj[key]) + " is not positive");
    return d;
  }

  int integer(json& obj, const std::string& ptr, const char* key, int lo, int hi,
              std::optional<int> fallback = std::nullopt) {
    const std::string p = ptr + "/" + key;
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

  std::string choice(json& obj, const std::string& ptr, const char* key,
                     const std::vector<std::string>& options, std::optional<std::string> fallback) {
    const std::string p = ptr + "/" + key;
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

  Vec2 vec2(json& obj, const std::string& ptr, const char* key,
            std::optional<Vec2> fallback = std::nullopt) {
    const std::string p = ptr + "/" + key;
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

  static std::string list(const std::vector<std::string>& options) {
    std::string s;
    for (size_t i = 0; i < options.size(); ++i) s += (i ? ", " : "") + ("\"" + options[i] + "\"");
    return s;
  }
};

// ---- obstacles

ProfilePiece read_piece(Reader& r, json& j, const std::string& ptr) {
  const std::string type = r.choice(j, ptr, "type", {"segment", "arc"}, std::nullopt);
  if (type == "segment") return SegmentPiece{r.vec2(j, ptr, "from"), r.vec2(j, ptr, "to")};
  const double deg = std::numbers::pi / 180;
  return ArcPiece{r.vec2(j, ptr, "centre"), r.positive(j, ptr, "radius"),
                  r.number(j, ptr, "start_angle") * deg, r.number(j, ptr, "end_angle") * deg};
}

std::unique_ptr<Obstacle> read_shape(Reader& r, json& j, const std::string& ptr) {
  const std::string type =
      r.choice(j, ptr, "type", {"circle", "segment", "arc", "profile"}, std::nullopt);
  const size_t before = r.issues.size();
  std::vector<ProfilePiece> pieces;
  if (type == "circle") {
    const Vec2 c = r.vec2(j, ptr, "centre");
    const double radius = r.positive(j, ptr, "radius");
    if (r.issues.size() > before) return nullptr;
    return make_circle(c, radius);
  }
  if (type == "profile") {
    json* arr = r.array(j, ptr, "pieces", true);
    if (arr && arr->empty()) r.error(ptr + "/pieces", "needs at least one piece");
    if (arr)
      for (size_t i = 0; i < arr->size(); ++i) {
        const std::string pp = ptr + "/pieces/" + std::to_string(i);
        if (!(*arr)[i].is_object()) {
          r.error(pp, "is not an object");
          continue;
        }
        pieces.push_back(read_piece(r, (*arr)[i], pp));
      }
  } else {
    pieces.push_back(read_piece(r, j, ptr));
  }
  if (r.issues.size() > before) return nullptr;
  try {
    return make_profile(std::move(pieces));
  } catch (const std::invalid_argument& e) {
    r.error(ptr, e.what());
    return nullptr;
  }
}

// ---- the beam

int beam_component(const std::string& name) { return name == "u" ? 0 : name == "w" ? 1 : 2; }

void read_beam(Reader& r, json& body, Problem& problem) {
  const std::string ptr = "/body";
  const std::string kin = r.choice(body, ptr, "kinematics", {"von_karman", "linear"}, "von_karman");
  json* mat = r.object(body, ptr, "material", true);
  json* sec = r.object(body, ptr, "section", true);
  json* mesh = r.object(body, ptr, "mesh", true);
  double E = 0, nu = 0;
  BeamSection section;
  if (mat) {
    E = r.positive(*mat, ptr + "/material", "young");
    nu = r.number(*mat, ptr + "/material", "poisson", 0.3);
    if (!(nu >= 0 && nu < 0.5))
      r.error(ptr + "/material/poisson", show((*mat)["poisson"]) + " is not in [0, 0.5)");
  }
  if (sec) {
    const double width = r.positive(*sec, ptr + "/section", "width");
    const double depth = r.positive(*sec, ptr + "/section", "depth");
    const double k = r.positive(*sec, ptr + "/section", "shear_factor", 5.0 / 6.0);
    const double G = E / (2 * (1 + nu));
    section = {E * width * depth, E * width * depth * depth * depth / 12, k * G * width * depth,
               depth / 2, width};
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
  auto beam = std::make_unique<TimoshenkoBeam>(
      x, origin.y(), section, kin == "linear" ? Kinematics::linear : Kinematics::von_karman);
  const int nodes = beam->node_count();
  problem.load = Vector::Zero(beam->dof_count());

  if (json* sup = r.array(body, ptr, "supports", false))
    for (size_t i = 0; i < sup->size(); ++i) {
      const std::string sp = ptr + "/supports/" + std::to_string(i);
      json& s = (*sup)[i];
      if (!s.is_object()) {
        r.error(sp, "is not an object");
        continue;
      }
      const int node = r.integer(s, sp, "node", 0, nodes - 1);
      json* fix = r.array(s, sp, "fix", true);
      json* values = r.object(s, sp, "values", false);
      if (!fix) continue;
      for (size_t c = 0; c < fix->size(); ++c) {
        const json& comp = (*fix)[c];
        if (!(comp == "u" || comp == "w" || comp == "theta")) {
          r.error(sp + "/fix/" + std::to_string(c), show(comp) + " is not one of \"u\", \"w\", \"theta\"");
          continue;
        }
        const std::string name = comp.get<std::string>();
        double value = 0.0;
        if (values && values->contains(name)) value = r.number(*values, sp + "/values", name.c_str());
        problem.constraints.push_back({TimoshenkoBeam::node_dof(node, beam_component(name)), value});
      }
      if (values)
        for (const auto& [name, v] : values->items()) {
          bool fixed = false;
          for (const auto& comp : *fix) fixed |= comp == name;
          if (!fixed) r.error(sp + "/values/" + name, "is given but \"" + name + "\" is not in fix");
        }
    }

  if (json* loads = r.array(body, ptr, "loads", false))
    for (size_t i = 0; i < loads->size(); ++i) {
      const std::string lp = ptr + "/loads/" + std::to_string(i);
      json& l = (*loads)[i];
      if (!l.is_object()) {
        r.error(lp, "is not an object");
        continue;
      }
      const int node = r.integer(l, lp, "node", 0, nodes - 1);
      const Vec2 f = r.vec2(l, lp, "force", Vec2::Zero());
      const double moment = r.number(l, lp, "moment", 0.0);
      const std::string at = r.choice(l, lp, "at", {"centre", "upper", "lower"}, "centre");
      const int side = at == "upper" ? 1 : at == "lower" ? -1 : 0;
      // Virtual work of the force at its point of application (a moment through the offset).
      const SurfacePoint sp = beam->surface_point(Vector::Zero(beam->dof_count()), node, side);
      for (const auto& jac : sp.jacobian) problem.load[jac.dof] += jac.dx.dot(f);
      problem.load[TimoshenkoBeam::node_dof(node, 2)] += moment;
    }
  problem.body = std::move(beam);
}

// ---- solver parameters

void read_solver(Reader& r, json& scene, SteppingParams& params) {
  json* solver = r.object(scene, "", "solver", false);
  if (!solver) return;
  const std::string sp = "/solver";
  json* contact = r.object(*solver, sp, "contact", false);
  ContactParams& c = params.contact;
  if (contact) {
    const std::string cp = sp + "/contact";
    const std::string method = r.choice(*contact, cp, "method", {"cev", "uzawa"}, "cev");
    c.method = method == "uzawa" ? ContactMethod::uzawa : ContactMethod::cev;
    c.tolerance = r.positive(*contact, cp, "tolerance", c.tolerance);
    if (c.tolerance >= 1) r.error(cp + "/tolerance", "is a relative tolerance and must be below 1");
    const std::string loop = r.choice(*contact, cp, "loop", {"inner", "paper"}, "inner");
    c.loop = loop == "paper" ? ContactLoop::paper : ContactLoop::inner;
    c.max_iterations = r.integer(*contact, cp, "max_iterations", 1, 1000000, c.max_iterations);
    c.max_tau_passes = r.integer(*contact, cp, "max_tau_passes", 1, 1000, c.max_tau_passes);
    c.tau_tolerance = r.positive(*contact, cp, "tau_tolerance", c.tau_tolerance);
    c.uzawa_alpha = r.positive(*contact, cp, "uzawa_alpha", c.uzawa_alpha);
    if (json* acc = r.object(*contact, cp, "acceleration", false)) {
      const std::string ap = cp + "/acceleration";
      if (!acc->contains("n")) (*acc)["n"] = "inf";
      const json& n = (*acc)["n"];
      if (n.is_string() && n == "inf")
        c.acceleration = kAccelerationInfinity;
      else if (n.is_string() && n == "auto")
        c.acceleration = kAccelerationAuto;
      else if (n.is_number_integer())
        c.acceleration = r.integer_value(n, ap + "/n", 1, 64);
      else
        r.error(ap + "/n", show(n) + " is not \"inf\", \"auto\" or an integer from 1 to 64");
      const std::string eps = r.choice(*acc, ap, "epsilon", {"exact", "warmup"}, "exact");
      c.epsilon = eps == "warmup" ? EpsilonSource::warmup : EpsilonSource::exact;
    }
  }
  if (json* newton = r.object(*solver, sp, "newton", false))
    params.newton.max_iterations = r.integer(*newton, sp + "/newton", "max_iterations", 1, 1000, params.newton.max_iterations);
  params.max_cuts = r.integer(*solver, sp, "max_cuts", 0, 30, params.max_cuts);
}

std::vector<double> read_steps(Reader& r, json& scene) {
  if (!scene.contains("steps")) scene["steps"] = 1;
  const json& s = scene["steps"];
  std::vector<double> factors;
  if (s.is_number_integer()) {
    const int n = r.integer_value(s, "/steps", 1, 100000);
    for (int k = 1; k <= n; ++k) factors.push_back(static_cast<double>(k) / n);
  } else if (s.is_array()) {
    if (s.empty() || s.size() > 100000) r.error("/steps", "needs 1 to 100000 load factors");
    for (size_t i = 0; i < s.size(); ++i) {
      if (!s[i].is_number() || !std::isfinite(s[i].get<double>()))
        r.error("/steps/" + std::to_string(i), show(s[i]) + " is not a finite number");
      else
        factors.push_back(s[i].get<double>());
    }
  } else {
    r.error("/steps", show(s) + " is neither a step count nor a list of load factors");
  }
  return factors;
}

}  // namespace

SceneErrors::SceneErrors(std::vector<SceneIssue> issues)
    : std::runtime_error(join(issues)), issues_(std::move(issues)) {}

Scene read_scene(const nlohmann::json& input) {
  Reader r;
  Scene scene;
  scene.effective = input;
  json& e = scene.effective;
  if (!e.is_object()) throw SceneErrors(std::vector<SceneIssue>{{"/", "a scene is a JSON object"}});
  if (json* body = r.object(e, "", "body", true)) {
    const std::string model = r.choice(*body, "/body", "model", {"timoshenko_beam"}, std::nullopt);
    if (model == "timoshenko_beam") read_beam(r, *body, scene.problem);
  }
  if (json* obs = r.array(e, "", "obstacles", true)) {
    if (obs->empty()) r.error("/obstacles", "needs at least one obstacle");
    for (size_t i = 0; i < obs->size(); ++i) {
      const std::string op = "/obstacles/" + std::to_string(i);
      json& o = (*obs)[i];
      if (!o.is_object()) {
        r.error(op, "is not an object");
        continue;
      }
      ObstacleInstance inst;
      if (!o.contains("name")) o["name"] = "obstacle" + std::to_string(i);
      if (!o["name"].is_string()) r.error(op + "/name", "is not a string");
      else inst.name = o["name"].get<std::string>();
      if (json* shape = r.object(o, op, "shape", true)) inst.shape = read_shape(r, *shape, op + "/shape");
      inst.friction = r.number(o, op, "friction", 0.0);
      if (inst.friction < 0) r.error(op + "/friction", show(o["friction"]) + " is negative");
      if (json* motion = r.object(o, op, "motion", false))
        inst.translation = r.vec2(*motion, op + "/motion", "translation", Vec2::Zero());
      scene.problem.obstacles.push_back(std::move(inst));
    }
  }
  scene.load_factors = read_steps(r, e);
  read_solver(r, e, scene.params);
  if (!r.issues.empty()) throw SceneErrors(std::move(r.issues));
  add_candidates(scene.problem);
  return scene;
}

Scene read_scene_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw SceneErrors(std::vector<SceneIssue>{{"/", "cannot open " + path}});
  json j;
  try {
    in >> j;
  } catch (const json::parse_error& e) {
    throw SceneErrors(std::vector<SceneIssue>{{"/", std::string("malformed JSON: ") + e.what()}});
  }
  return read_scene(j);
}

}  // namespace grip
