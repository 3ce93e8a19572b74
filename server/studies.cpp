#include "server/studies.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <set>
#include <string_view>

#include "server/richardson.hpp"
#include "server/util.hpp"
#include "solver/io/scene.hpp"
#include "solver/model/number_text.hpp"

namespace grip::server {
namespace {

using nlohmann::json;

std::string show(const json& j) {
  std::string s = j.dump();
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

// The bodies of a scene with their pointers: "body", or each of "bodies".
std::vector<std::pair<std::string, json*>> bodies_of(json& scene) {
  std::vector<std::pair<std::string, json*>> out;
  if (scene.contains("body")) out.emplace_back("/scene/body", &scene["body"]);
  else if (scene.contains("bodies") && scene["bodies"].is_array())
    for (size_t b = 0; b < scene["bodies"].size(); ++b)
      out.emplace_back("/scene/bodies/" + std::to_string(b), &scene["bodies"][b]);
  return out;
}

// Level j of a generated mesh: divisions x 2^j, refine.size / 2^j. False (with an issue) where
// the body's mesh is not generated.
bool refine_generated(json& body, const std::string& ptr, int j, std::vector<SceneIssue>& issues) {
  if (!body.is_object() || !body.contains("mesh") || !body["mesh"].is_object()) {
    issues.push_back({ptr + "/mesh", "is required: a refinement study refines a generated mesh"});
    return false;
  }
  json& mesh = body["mesh"];
  for (const char* kind : {"rectangle", "half_disc"}) {
    if (!mesh.contains(kind) || !mesh[kind].is_object()) continue;
    json& gen = mesh[kind];
    if (!gen.contains("divisions") || !gen["divisions"].is_array()) return true;  // the reader says what is wrong
    for (json& d : gen["divisions"])
      if (d.is_number_integer()) d = d.get<long long>() << j;
    if (gen.contains("refine") && gen["refine"].is_object() && gen["refine"].contains("size") &&
        gen["refine"]["size"].is_number())
      gen["refine"]["size"] = std::ldexp(gen["refine"]["size"].get<double>(), -j);
    return true;
  }
  issues.push_back({ptr + "/mesh", mesh.contains("gmsh")
                                       ? "is a mesh from a file: give its levels as refine.meshes"
                                       : "is not generated (rectangle or half_disc): a refinement "
                                         "study cannot refine it; give refine.meshes of gmsh meshes"});
  return false;
}

// The scene at generated mesh level j (from 0): every body's mesh refined. False (with an
// issue) where a body's mesh is not generated.
bool level_scene(const json& scene, int j, json& out, std::vector<SceneIssue>& issues) {
  out = scene;
  bool refined = true;
  for (auto& [ptr, body] : bodies_of(out)) refined &= refine_generated(*body, ptr, j, issues);
  return refined && issues.empty();
}

// The idempotency key of an accuracy study's level j (from 0): a level is made once, whichever
// replica reads the study first once the level before is done.
std::string level_key(const std::string& study, size_t j) { return "study/" + study + "/level/" + std::to_string(j); }

// The study whose level this idempotency key names, if it names one.
std::optional<std::string> study_of_level_key(const std::string& key) {
  constexpr std::string_view prefix = "study/", level = "/level/";
  if (key.rfind(prefix, 0) != 0) return std::nullopt;
  const size_t end = key.find(level, prefix.size());
  if (end == std::string::npos || end == prefix.size()) return std::nullopt;
  return key.substr(prefix.size(), end - prefix.size());
}

// An accuracy target {"output", "relative", "levels"?, "budget_seconds"?}, normalized with its defaults.
json plan_accuracy(const json& target, const std::vector<std::string>& names, std::vector<SceneIssue>& issues) {
  if (!target.is_object()) {
    issues.push_back({"/accuracy", "is {\"output\", \"relative\", \"levels\"?, \"budget_seconds\"?}"});
    return nullptr;
  }
  for (const auto& [key, value] : target.items())
    if (key != "output" && key != "relative" && key != "levels" && key != "budget_seconds")
      issues.push_back({"/accuracy/" + key, "is not a member of accuracy (output, relative, levels, budget_seconds)"});
  json out = {{"levels", kMaxStudyLevels}};
  if (!target.contains("output") || !target["output"].is_string() ||
      std::find(names.begin(), names.end(), target["output"].get<std::string>()) == names.end())
    issues.push_back({"/accuracy/output", (target.contains("output") ? show(target["output"]) : std::string("(none)")) +
                                              " names no output of the scene: the quantity to make accurate"});
  else out["output"] = target["output"];
  if (!target.contains("relative") || !target["relative"].is_number() || !(target["relative"].get<double>() > 0) ||
      !(target["relative"].get<double>() < 1))
    issues.push_back({"/accuracy/relative", "is required: the estimated relative error to reach, in (0, 1)"});
  else out["relative"] = target["relative"];
  if (target.contains("levels")) {
    const json& k = target["levels"];
    if (!k.is_number_integer() || k.get<long long>() < 3 || k.get<long long>() > kMaxStudyLevels)
      issues.push_back({"/accuracy/levels", show(k) + " is not an integer in [3, " + std::to_string(kMaxStudyLevels) +
                                                "]: the most mesh levels to try"});
    else out["levels"] = k;
  }
  if (target.contains("budget_seconds")) {
    const json& t = target["budget_seconds"];
    if (!t.is_number() || !(t.get<double>() > 0))
      issues.push_back({"/accuracy/budget_seconds", show(t) + " is not a time budget in seconds (> 0)"});
    else out["budget_seconds"] = t;
  }
  return out;
}

// The last converged step's outputs of a job (its step_finished events), none before.
std::optional<json> last_outputs(JobService& jobs, const std::string& id) {
  std::optional<json> last;
  std::int64_t after = 0;
  for (;;) {
    const auto events = jobs.events(id, after, 1000, "step_finished");
    for (const StoredEvent& e : events) {
      after = e.seq;
      const json ev = json::parse(e.data, nullptr, false);
      if (ev.is_object() && ev.contains("outputs") && ev["outputs"].is_object()) last = ev["outputs"];
    }
    if (events.size() < 1000) return last;
  }
}

json number_or_null(const std::optional<double>& v) { return v && std::isfinite(*v) ? json(*v) : json(nullptr); }

// The variants of a sweep: [{pointer, values | range: {from, to, count}}], as a grid (every
// combination, the last pointer fastest) or zipped (mode "zip": the k-th value of each).
void plan_sweep(const json& request, StudyPlan& plan, std::vector<SceneIssue>& issues) {
  const json& scene = request["scene"];
  const json& sweep = request["sweep"];
  plan.kind = "sweep";
  if (!sweep.is_array() || sweep.empty()) {
    issues.push_back({"/sweep", "is a non-empty list of {\"pointer\", \"values\" | \"range\"}"});
    return;
  }
  std::string mode = "grid";
  if (request.contains("mode")) {
    if (request["mode"] != "grid" && request["mode"] != "zip")
      issues.push_back({"/mode", show(request["mode"]) + " is not \"grid\" or \"zip\""});
    else mode = request["mode"];
  }
  std::vector<json::json_pointer> pointers;
  std::vector<std::vector<json>> lists;
  for (size_t i = 0; i < sweep.size(); ++i) {
    const std::string sp = "/sweep/" + std::to_string(i);
    const json& item = sweep[i];
    if (!item.is_object()) {
      issues.push_back({sp, "is not an object {\"pointer\", \"values\" | \"range\"}"});
      continue;
    }
    for (const auto& [key, value] : item.items())
      if (key != "pointer" && key != "values" && key != "range")
        issues.push_back({sp + "/" + key, "is not a member of a sweep (pointer, values, range)"});
    std::optional<json::json_pointer> pointer;
    if (!item.contains("pointer") || !item["pointer"].is_string()) {
      issues.push_back({sp + "/pointer", "is required: the JSON pointer of the scene's value to sweep"});
    } else {
      try {
        pointer = json::json_pointer(item["pointer"].get<std::string>());
      } catch (const json::exception&) {
        issues.push_back({sp + "/pointer", show(item["pointer"]) + " is not a JSON pointer (RFC 6901)"});
      }
      if (pointer && (pointer->empty() || !scene.contains(*pointer))) {
        issues.push_back({sp + "/pointer", show(item["pointer"]) + " names no value of the scene"});
        pointer.reset();
      }
    }
    std::vector<json> values;
    if (item.contains("values") == item.contains("range")) {
      issues.push_back({sp, "needs exactly one of \"values\" (a list) and \"range\" ({from, to, count})"});
    } else if (item.contains("values")) {
      if (!item["values"].is_array() || item["values"].empty())
        issues.push_back({sp + "/values", "is a non-empty list of the values to give it"});
      else values = item["values"].get<std::vector<json>>();
    } else {
      const json& r = item["range"];
      const bool ok = r.is_object() && r.contains("from") && r["from"].is_number() && r.contains("to") &&
                      r["to"].is_number() && r.contains("count") && r["count"].is_number_integer() &&
                      r["count"].get<long long>() >= 2 && r["count"].get<long long>() <= kMaxStudyJobs;
      if (!ok) {
        issues.push_back({sp + "/range", "is {\"from\", \"to\", \"count\"}: numbers and an integer count in [2, " +
                                             std::to_string(kMaxStudyJobs) + "]"});
      } else {
        const double from = r["from"], to = r["to"];
        const int count = r["count"];
        for (int k = 0; k < count; ++k) values.push_back(k + 1 == count ? to : from + (to - from) * k / (count - 1));
      }
    }
    if (pointer) pointers.push_back(*pointer);
    lists.push_back(std::move(values));
  }
  if (!issues.empty()) return;
  // The number of jobs, checked before any is made.
  double jobs = mode == "zip" ? static_cast<double>(lists[0].size()) : 1.0;
  for (size_t i = 0; i < lists.size(); ++i) {
    if (mode == "zip" && lists[i].size() != lists[0].size())
      issues.push_back({"/sweep/" + std::to_string(i), "has " + std::to_string(lists[i].size()) +
                                                           " values; zipped with /sweep/0 it needs " +
                                                           std::to_string(lists[0].size())});
    if (mode == "grid") jobs *= static_cast<double>(lists[i].size());
  }
  if (jobs > kMaxStudyJobs)
    issues.push_back({"/sweep", "makes " + number_text(jobs) + " jobs; this service runs at most " +
                                    std::to_string(kMaxStudyJobs) + " per study"});
  if (!issues.empty()) return;
  for (const auto& p : pointers) plan.pointers.push_back(p.to_string());
  std::vector<size_t> at(lists.size(), 0);
  for (size_t n = 0; n < static_cast<size_t>(jobs); ++n) {
    StudyLevel level{.scene = scene, .parameters = json::array()};
    for (size_t i = 0; i < lists.size(); ++i) {
      const json& value = lists[i][mode == "zip" ? n : at[i]];
      level.scene[pointers[i]] = value;
      level.parameters.push_back(value);
    }
    plan.levels.push_back(std::move(level));
    for (size_t i = lists.size(); mode == "grid" && i-- > 0;) {  // the odometer: the last pointer fastest
      if (++at[i] < lists[i].size()) break;
      at[i] = 0;
    }
  }
}

// A refinement plan's tolerances (numbers in (0, 1), run loosest first) and contact methods:
// every mesh level with each method at each tolerance, as solver.contact.tolerance and
// solver.contact.method of its scene.
void plan_solver_settings(const json& request, StudyPlan& plan, std::vector<SceneIssue>& issues) {
  std::vector<json> tolerances{nullptr}, methods{nullptr};
  if (request.contains("tolerances")) {
    const json& list = request["tolerances"];
    if (!list.is_array() || list.empty()) {
      issues.push_back({"/tolerances", "is a non-empty list of contact tolerances in (0, 1)"});
    } else {
      tolerances.clear();
      for (size_t i = 0; i < list.size(); ++i) {
        if (list[i].is_number() && list[i].get<double>() > 0 && list[i].get<double>() < 1)
          tolerances.push_back(list[i]);
        else issues.push_back({"/tolerances/" + std::to_string(i), show(list[i]) + " is not a number in (0, 1)"});
      }
      std::sort(tolerances.begin(), tolerances.end(), [](const json& a, const json& b) { return a > b; });
    }
  }
  if (request.contains("methods")) {
    const json& list = request["methods"];
    const std::set<std::string> known = {"cev", "uzawa", "penalty", "ssn"};
    if (!list.is_array() || list.empty()) {
      issues.push_back({"/methods", "is a non-empty list of contact methods (cev, uzawa, penalty, ssn)"});
    } else {
      methods.clear();
      for (size_t i = 0; i < list.size(); ++i) {
        if (list[i].is_string() && known.count(list[i].get<std::string>())) methods.push_back(list[i]);
        else
          issues.push_back(
              {"/methods/" + std::to_string(i), show(list[i]) + " is not a contact method (cev, uzawa, penalty, ssn)"});
      }
    }
  }
  if (!issues.empty()) return;
  const double jobs = static_cast<double>(plan.levels.size() * tolerances.size() * methods.size());
  if (jobs > kMaxStudyJobs) {
    issues.push_back({"/refine", "makes " + number_text(jobs) + " jobs (levels x methods x tolerances); this " +
                                     "service runs at most " + std::to_string(kMaxStudyJobs) + " per study"});
    return;
  }
  std::vector<StudyLevel> jobs_of_plan;
  for (size_t j = 0; j < plan.levels.size(); ++j)
    for (const json& method : methods)
      for (const json& tolerance : tolerances) {
        StudyLevel job = plan.levels[j];
        job.mesh_level = static_cast<int>(j) + 1;
        job.tolerance = tolerance;
        job.method = method;
        if (!tolerance.is_null()) job.scene["solver"]["contact"]["tolerance"] = tolerance;
        if (!method.is_null()) job.scene["solver"]["contact"]["method"] = method;
        jobs_of_plan.push_back(std::move(job));
      }
  plan.levels = std::move(jobs_of_plan);
}
}  // namespace

StudyPlan plan_study(const json& request) {
  std::vector<SceneIssue> issues;
  auto fail = [&]() { throw SceneErrors(std::move(issues)); };
  if (!request.is_object()) {
    issues.push_back({"/", "a study is a JSON object: {\"scene\", \"refine\" | \"sweep\", \"outputs\"}"});
    fail();
  }
  for (const auto& [key, value] : request.items())
    if (key != "scene" && key != "refine" && key != "tolerances" && key != "methods" && key != "sweep" &&
        key != "accuracy" && key != "mode" && key != "outputs" && key != "description")
      issues.push_back(
          {"/" + key,
           "is not a member of a study (scene, refine, tolerances, methods, sweep, accuracy, mode, outputs, "
           "description)"});
  for (const char* key : {"tolerances", "methods"})
    if (request.contains(key) && !request.contains("refine"))
      issues.push_back({std::string("/") + key, "goes with refine: each mesh level runs at each of them"});
  if (!request.contains("scene") || !request["scene"].is_object())
    issues.push_back({"/scene", "is required: the scene to study (an object, as POST /v1/jobs takes it)"});
  const bool sweeping = request.contains("sweep"), targeting = request.contains("accuracy");
  if (static_cast<int>(sweeping) + static_cast<int>(targeting) + static_cast<int>(request.contains("refine")) > 1)
    issues.push_back({sweeping ? "/sweep" : "/accuracy",
                      "goes alone: a study refines the mesh (refine), refines until an accuracy is reached "
                      "(accuracy) or sweeps parameters (sweep)"});
  else if (!sweeping && !targeting && (!request.contains("refine") || !request["refine"].is_object()))
    issues.push_back({"/refine",
                      "is required (or accuracy, or sweep): {\"levels\": k} (generated meshes) or {\"meshes\": "
                      "[...]} (gmsh)"});
  if (!issues.empty()) fail();
  const json& scene = request["scene"];

  // The outputs: the scene's, each named where it stays the same point as the mesh changes.
  std::vector<std::string> names;
  if (!scene.contains("outputs") || !scene["outputs"].is_array() || scene["outputs"].empty()) {
    issues.push_back({"/scene/outputs",
                      "a study compares the scene's outputs: name at least one quantity "
                      "(docs/design.md#quantities-of-interest)"});
  } else {
    for (size_t i = 0; i < scene["outputs"].size(); ++i) {
      const json& q = scene["outputs"][i];
      if (!q.is_object()) continue;  // the reader says what is wrong
      if (q.contains("name") && q["name"].is_string()) names.push_back(q["name"]);
      for (const char* key : {"node", "element"})
        if (q.contains(key) && !sweeping)
          issues.push_back({"/scene/outputs/" + std::to_string(i) + "/" + key,
                            std::string("an index changes with the mesh: name the point with \"at\" (a study compares "
                                        "the same quantity on every level)")});
    }
  }
  StudyPlan plan;
  if (request.contains("outputs")) {
    const json& chosen = request["outputs"];
    if (!chosen.is_array() || chosen.empty()) issues.push_back({"/outputs", "is a non-empty list of output names"});
    else
      for (size_t i = 0; i < chosen.size(); ++i) {
        if (chosen[i].is_string() && std::find(names.begin(), names.end(), chosen[i].get<std::string>()) != names.end())
          plan.outputs.push_back(chosen[i]);
        else issues.push_back({"/outputs/" + std::to_string(i), show(chosen[i]) + " names no output of the scene"});
      }
  } else {
    plan.outputs = names;
  }
  if (sweeping) {
    if (!issues.empty()) fail();
    plan_sweep(request, plan, issues);
    if (!issues.empty()) fail();
    return plan;
  }
  if (targeting) {
    plan.kind = "accuracy";
    plan.accuracy = plan_accuracy(request["accuracy"], names, issues);
    if (!issues.empty()) fail();
    for (int j = 0; j < plan.accuracy["levels"].get<int>(); ++j) {
      StudyLevel level{.h = std::ldexp(1.0, -j), .mesh_level = j + 1};
      if (!level_scene(scene, j, level.scene, issues)) fail();
      plan.levels.push_back(std::move(level));
    }
    return plan;
  }

  const json& refine = request["refine"];
  const bool by_levels = refine.contains("levels"), by_meshes = refine.contains("meshes");
  for (const auto& [key, value] : refine.items())
    if (key != "levels" && key != "meshes")
      issues.push_back({"/refine/" + key, "is not a member of refine (levels, meshes)"});
  if (by_levels == by_meshes) {
    issues.push_back({"/refine",
                      "needs exactly one of \"levels\" (generated meshes) and \"meshes\" (a list of gmsh "
                      "meshes, coarse to fine)"});
    fail();
  }
  if (by_levels) {
    const json& levels = refine["levels"];
    if (!levels.is_number_integer() || levels.get<long long>() < 2 || levels.get<long long>() > kMaxStudyLevels) {
      issues.push_back({"/refine/levels", show(levels) + " is not an integer in [2, " +
                                              std::to_string(kMaxStudyLevels) + "] (this service's limit)"});
      fail();
    }
    const int k = levels.get<int>();
    for (int j = 0; j < k; ++j) {
      StudyLevel level{.h = std::ldexp(1.0, -j)};
      if (!level_scene(scene, j, level.scene, issues)) fail();
      plan.levels.push_back(std::move(level));
    }
  } else {
    const json& meshes = refine["meshes"];
    if (!meshes.is_array() || meshes.size() < 2 || meshes.size() > static_cast<size_t>(kMaxStudyLevels))
      issues.push_back({"/refine/meshes", "is a list of 2 to " + std::to_string(kMaxStudyLevels) +
                                              " gmsh mesh references ({\"id\": ...}), coarse to fine"});
    if (!scene.contains("body") || !scene["body"].is_object() || !scene["body"].contains("mesh") ||
        !scene["body"]["mesh"].is_object() || !scene["body"]["mesh"].contains("gmsh"))
      issues.push_back({"/scene/body/mesh/gmsh", "is required with refine.meshes: each level replaces it"});
    if (!issues.empty()) fail();
    plan.h_from_nodes = true;
    for (const json& ref : meshes) {
      StudyLevel level{.scene = scene};
      level.scene["body"]["mesh"]["gmsh"] = ref;
      plan.levels.push_back(std::move(level));
    }
  }
  if (!issues.empty()) fail();
  plan_solver_settings(request, plan, issues);
  if (!issues.empty()) fail();
  return plan;
}

json Studies::submit(const json& request, const std::string& request_id) {
  StudyPlan plan = plan_study(request);
  const bool accuracy = plan.kind == "accuracy";
  // Every level's scene checked before any job is stored: a level that the reader or a job
  // limit refuses refuses the study (its pointer under /scene, the level in its sentence). An
  // accuracy study instead stops its plan before the first such level past the third.
  std::vector<SceneIssue> issues;
  std::vector<int> nodes;
  for (size_t j = 0; j < plan.levels.size(); ++j) {
    try {
      nodes.push_back(jobs_.check(plan.levels[j].scene));
    } catch (const SceneErrors& e) {
      if (accuracy && j >= 3) {
        plan.accuracy["levels"] = j;
        plan.accuracy["limited_by"] = "level " + std::to_string(j + 1) + ": " + e.issues().front().detail;
        plan.levels.resize(j);
        break;
      }
      for (const SceneIssue& issue : e.issues())
        issues.push_back({"/scene" + (issue.pointer == "/" ? "" : issue.pointer),
                          (plan.kind == "sweep" ? "variant " : "level ") + std::to_string(j + 1) + " of " +
                              std::to_string(plan.levels.size()) +
                              (plan.kind == "sweep" ? " (" + plan.levels[j].parameters.dump() + ")" : std::string()) +
                              ": " + issue.detail});
    }
    if (!issues.empty()) throw SceneErrors(std::move(issues));
  }
  if (plan.h_from_nodes)  // in 2D the element size goes as 1 / sqrt(nodes)
    for (size_t j = 0; j < plan.levels.size(); ++j)
      plan.levels[j].h = std::sqrt(static_cast<double>(nodes[0]) / std::max(1, nodes[j]));
  StudyRecord rec{new_job_id(), now_iso8601(), {}};
  // An accuracy study starts with three levels (the fewest that give an estimate); the
  // others one at a time, as each finishes (advance).
  const size_t first = accuracy ? 3 : plan.levels.size();
  std::vector<std::string> ids;
  try {
    for (size_t j = 0; j < first; ++j)
      ids.push_back(
          jobs_.submit(plan.levels[j].scene, accuracy ? std::optional(level_key(rec.id, j)) : std::nullopt, request_id)
              .job.record.id);
  } catch (...) {
    for (const std::string& id : ids) jobs_.dismiss(id);  // all levels or none
    throw;
  }
  json levels = json::array();
  for (size_t j = 0; j < (accuracy ? plan.levels.size() : ids.size()); ++j) {
    const StudyLevel& level = plan.levels[j];
    levels.push_back({{"nodes", nodes[j]}});
    if (j < ids.size()) levels.back()["job"] = ids[j];
    if (plan.kind == "sweep") {
      levels.back()["parameters"] = level.parameters;
      continue;
    }
    levels.back()["h"] = level.h;
    levels.back()["level"] = level.mesh_level;
    if (!level.method.is_null()) levels.back()["method"] = level.method;
    if (!level.tolerance.is_null()) levels.back()["tolerance"] = level.tolerance;
  }
  json document = {{"kind", plan.kind}, {"outputs", plan.outputs}, {"levels", levels}};
  if (plan.kind == "sweep") document["pointers"] = plan.pointers;
  if (accuracy) {
    document["accuracy"] = plan.accuracy;
    document["scene"] = request["scene"];
    if (plan.accuracy.contains("budget_seconds"))
      document["until"] = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count() +
                          plan.accuracy["budget_seconds"].get<double>();
  }
  rec.document = document.dump();
  try {
    jobs_.store().insert_study(rec);
  } catch (...) {
    for (const std::string& id : ids) jobs_.dismiss(id);
    throw;
  }
  spdlog::info("study {} accepted: {} levels (request {})", rec.id, ids.size(), request_id.empty() ? "-" : request_id);
  return *study(rec.id);
}

Studies::Studies(JobService& jobs) : jobs_(jobs) {
  jobs_.set_finished_hook([this](const std::string& key) {
    if (const auto id = study_of_level_key(key)) study(*id);
  });
}

Studies::~Studies() { jobs_.set_finished_hook(nullptr); }

std::optional<json> Studies::study(const std::string& id) {
  const auto rec = jobs_.store().study(id);
  if (!rec) return std::nullopt;
  const json plan = json::parse(rec->document);
  json doc = table(*rec, plan);
  if (plan["kind"] == "accuracy" && advance(*rec, plan, doc)) doc = table(*rec, plan);
  return doc;
}

bool Studies::advance(const StudyRecord& rec, const json& plan, json& doc) {
  if (doc["status"] == "accepted" || doc["status"] == "running") return false;
  const json& target = plan["accuracy"];
  const std::string name = target["output"];
  const double relative = target["relative"];
  const json& levels = doc["levels"];
  const size_t n = levels.size(), planned = plan["levels"].size();
  const json* q = nullptr;
  for (const json& quantity : doc["quantities"])
    if (quantity["name"] == name) q = &quantity;
  json answer = {{"level", levels[n - 1]["level"]}, {"job", levels[n - 1]["job"]}};
  if (doc["status"] != "successful") {
    answer["reached"] = false;
    answer["reason"] = "level " + std::to_string(n) + " did not succeed (" +
                       levels[n - 1]["status"].get<std::string>() + "): see its job";
    doc["answer"] = answer;
    return false;
  }
  const json estimate = q ? (*q)["estimated_error"][n - 1] : json(nullptr);
  answer["value"] = q ? (*q)["values"][n - 1] : json(nullptr);
  answer["estimated_error"] = estimate;
  answer["asymptotic"] = q ? (*q)["asymptotic"] : json(nullptr);
  if (estimate.is_number() && estimate.get<double>() < relative) {
    answer["reached"] = true;
    doc["answer"] = answer;
    return false;
  }
  const bool out_of_time =
      plan.contains("until") &&
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count() > plan["until"];
  if (n < planned && !out_of_time) {
    json scene;
    std::vector<SceneIssue> issues;
    level_scene(plan["scene"], static_cast<int>(n), scene, issues);  // checked when the study was made
    try {
      jobs_.submit(scene, level_key(rec.id, n));  // the same level from two replicas is one job
      return true;
    } catch (const QueueFull&) {
      doc["status"] = "running";  // the next read tries again
      doc["waiting"] = "level " + std::to_string(n + 1) + " waits for room in the queue";
      return false;
    }
  }
  std::string why = estimate.is_number()
                        ? "its estimated error at level " + std::to_string(n) + " is " +
                              number_text(estimate.get<double>()) + ", not below " + number_text(relative)
                        : "it has no estimate at level " + std::to_string(n) +
                              " (its values oscillate or stand still: no order of convergence)";
  if (out_of_time) why += "; the time budget of " + number_text(target["budget_seconds"].get<double>()) + " s is spent";
  else
    why += "; no level is left (" + std::to_string(planned) + " planned" +
           (target.contains("limited_by")
                ? ", the next over this service's limits: " + target["limited_by"].get<std::string>()
                : std::string()) +
           ")";
  answer["reached"] = false;
  answer["reason"] = name + " not accurate to " + number_text(relative) + ": " + why;
  doc["answer"] = answer;
  doc["status"] = "failed";
  return false;
}

json Studies::table(const StudyRecord& record, const json& plan) {
  json levels = json::array();
  std::vector<std::optional<json>> outputs;
  std::vector<std::optional<double>> seconds;
  std::set<std::string> states;
  for (size_t j = 0; j < plan["levels"].size(); ++j) {
    const json& l = plan["levels"][j];
    std::string job;
    if (l.contains("job")) {
      job = l["job"];
    } else if (const auto made = jobs_.store().job_by_idempotency_key(level_key(record.id, j))) {
      job = made->id;  // an accuracy study's level made as it went
    } else {
      break;
    }
    json level = {{"level", l.value("level", static_cast<int>(j) + 1)}, {"job", job}, {"nodes", l["nodes"]}};
    for (const char* key : {"h", "method", "tolerance", "parameters"})  // a refinement's job, a sweep's variant
      if (l.contains(key)) level[key] = l[key];
    const auto view = jobs_.job(job);
    std::optional<json> values;
    std::optional<double> time;
    if (!view) {
      level["status"] = "removed";
    } else {
      const JobRecord& r = view->record;
      level["status"] = to_string(r.status);
      if (r.status == JobStatus::successful) {
        values = last_outputs(jobs_, job);
        time = r.solve_seconds;
      }
      if (is_finished(r.status) && r.status != JobStatus::dismissed) level["seconds"] = r.solve_seconds;
    }
    states.insert(level["status"].get<std::string>());
    level["outputs"] = values ? *values : json(nullptr);
    levels.push_back(level);
    outputs.push_back(values);
    seconds.push_back(time);
  }
  // Each output over the levels that have it: Richardson on their sizes (a sweep: its values).
  // With tolerances or methods, the mesh levels' series is the first method's at the
  // tightest tolerance (the reference), and every job's estimated error is its distance to
  // that series' extrapolated value: the discretization and the contact solve's errors together.
  const bool sweep = plan["kind"] == "sweep";
  json reference = nullptr;
  std::vector<bool> in_reference(levels.size(), true);
  if (!sweep && !levels.empty()) {
    json tightest = nullptr;
    for (const json& l : levels)
      if (l.contains("tolerance") && (tightest.is_null() || l["tolerance"] < tightest)) tightest = l["tolerance"];
    const json method = levels[0].value("method", json(nullptr));
    for (size_t j = 0; j < levels.size(); ++j)
      in_reference[j] =
          levels[j].value("method", json(nullptr)) == method && levels[j].value("tolerance", json(nullptr)) == tightest;
    if (!tightest.is_null() || !method.is_null()) reference = {{"method", method}, {"tolerance", tightest}};
  }
  json quantities = json::array();
  for (const json& name : plan["outputs"]) {
    std::vector<double> v, h;
    json values = json::array();
    for (size_t j = 0; j < outputs.size(); ++j) {
      const bool has = outputs[j] && outputs[j]->contains(name) && (*outputs[j])[name].is_number();
      values.push_back(has ? (*outputs[j])[name] : json(nullptr));
      if (!has || !in_reference[j]) continue;
      v.push_back((*outputs[j])[name].get<double>());
      h.push_back(plan["levels"][j].value("h", 1.0));
    }
    if (sweep) {
      quantities.push_back({{"name", name}, {"values", values}});
      continue;
    }
    const Richardson r = richardson(v, h);
    json orders = json::array(), errors = json(std::vector<json>(outputs.size(), nullptr));
    for (const auto& p : r.orders) orders.push_back(number_or_null(p));
    std::vector<std::optional<double>> error(outputs.size());
    if (r.extrapolated)
      for (size_t j = 0; j < outputs.size(); ++j)
        if (values[j].is_number()) {
          error[j] = error_against(values[j].get<double>(), *r.extrapolated);
          errors[j] = number_or_null(error[j]);
        }
    // The cheapest job (level, and method and tolerance where the plan has them) under each
    // threshold.
    json cheapest = json::array();
    for (double below : kStudyThresholds) {
      json best = nullptr;
      for (size_t j = 0; j < outputs.size(); ++j) {
        const auto& t = seconds[j];
        if (!error[j] || !t || !(*error[j] < below)) continue;
        if (best.is_null() || *t < best["seconds"].get<double>()) {
          best = {{"level", levels[j]["level"]}, {"seconds", *t}, {"estimated_error", *error[j]}};
          for (const char* key : {"method", "tolerance"})
            if (levels[j].contains(key)) best[key] = levels[j][key];
        }
      }
      cheapest.push_back({{"below", below}, {"level", best}});
    }
    quantities.push_back({{"name", name},
                          {"values", values},
                          {"orders", orders},
                          {"order", number_or_null(r.order)},
                          {"order_ratio", number_or_null(r.order_ratio)},
                          {"asymptotic", r.asymptotic ? json(*r.asymptotic) : json(nullptr)},
                          {"extrapolated", number_or_null(r.extrapolated)},
                          {"estimated_error", errors},
                          {"cheapest", cheapest}});
    if (!reference.is_null()) quantities.back()["reference"] = reference;
  }
  // The study's status: running while a level is queued or runs; then successful when every
  // level is, else failed (or dismissed when its levels were).
  std::string status = "successful";
  if (states.count("accepted") || states.count("running")) status = states.count("running") ? "running" : "accepted";
  else if (states.count("dismissed") || states.count("removed")) status = "dismissed";
  else if (states.count("failed")) status = "failed";
  json links = json::array({{{"href", "/v1/studies/" + record.id}, {"rel", "self"}, {"type", "application/json"}}});
  for (const json& l : levels)
    links.push_back(
        {{"href", "/v1/jobs/" + l["job"].get<std::string>()}, {"rel", "item"}, {"type", "application/json"}});
  json doc = {{"id", record.id},  {"created", record.created}, {"kind", plan["kind"]}, {"status", status},
              {"levels", levels}, {"quantities", quantities},  {"links", links}};
  if (sweep) doc["pointers"] = plan["pointers"];
  else doc["thresholds"] = kStudyThresholds;
  if (plan.contains("accuracy")) doc["accuracy"] = plan["accuracy"];
  return doc;
}

std::vector<json> study_rows(const json& study) {
  std::vector<json> rows;
  for (size_t k = 0; k < study["levels"].size(); ++k) {
    const json& level = study["levels"][k];
    json row = {
        {"level", level["level"]}, {"job", level["job"]}, {"status", level["status"]}, {"nodes", level["nodes"]}};
    row["seconds"] = level.value("seconds", json(nullptr));
    for (const char* key : {"h", "method", "tolerance", "parameters"})
      if (level.contains(key)) row[key] = level[key];
    for (const json& q : study["quantities"]) {
      const std::string name = q["name"];
      row["outputs"][name] = q["values"][k];
      if (q.contains("estimated_error")) row["estimated_error"][name] = q["estimated_error"][k];
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

bool Studies::remove(const std::string& id) {
  const auto rec = jobs_.store().study(id);
  if (!rec) return false;
  const json plan = json::parse(rec->document);
  for (size_t j = 0; j < plan["levels"].size(); ++j) {
    const json& l = plan["levels"][j];
    if (l.contains("job")) jobs_.dismiss(l["job"].get<std::string>());
    else if (const auto made = jobs_.store().job_by_idempotency_key(level_key(id, j))) jobs_.dismiss(made->id);
  }
  return jobs_.store().remove_study(id);
}

}  // namespace grip::server
