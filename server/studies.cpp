#include "server/studies.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "server/richardson.hpp"
#include "server/util.hpp"
#include "solver/io/scene.hpp"

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

}  // namespace

StudyPlan plan_study(const json& request) {
  std::vector<SceneIssue> issues;
  auto fail = [&]() { throw SceneErrors(std::move(issues)); };
  if (!request.is_object()) {
    issues.push_back({"/", "a study is a JSON object: {\"scene\", \"refine\", \"outputs\"}"});
    fail();
  }
  for (const auto& [key, value] : request.items())
    if (key != "scene" && key != "refine" && key != "outputs" && key != "description")
      issues.push_back({"/" + key, "is not a member of a study (scene, refine, outputs, description)"});
  if (!request.contains("scene") || !request["scene"].is_object())
    issues.push_back({"/scene", "is required: the scene to study (an object, as POST /v1/jobs takes it)"});
  if (!request.contains("refine") || !request["refine"].is_object())
    issues.push_back({"/refine", "is required: {\"levels\": k} (generated meshes) or {\"meshes\": [...]} (gmsh)"});
  if (!issues.empty()) fail();
  const json& scene = request["scene"];
  const json& refine = request["refine"];

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
        if (q.contains(key))
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
      StudyLevel level{scene, std::ldexp(1.0, -j)};
      bool refined = true;
      for (auto& [ptr, body] : bodies_of(level.scene)) refined &= refine_generated(*body, ptr, j, issues);
      if (!refined || !issues.empty()) fail();
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
      StudyLevel level{scene, 1.0};
      level.scene["body"]["mesh"]["gmsh"] = ref;
      plan.levels.push_back(std::move(level));
    }
  }
  if (!issues.empty()) fail();
  return plan;
}

json Studies::submit(const json& request, const std::string& request_id) {
  StudyPlan plan = plan_study(request);
  // Every level's scene checked before any job is stored: a level that the reader or a job
  // limit refuses refuses the study (its pointer under /scene, the level in its sentence).
  std::vector<SceneIssue> issues;
  std::vector<int> nodes;
  for (size_t j = 0; j < plan.levels.size(); ++j) {
    try {
      nodes.push_back(jobs_.check(plan.levels[j].scene));
    } catch (const SceneErrors& e) {
      for (const SceneIssue& issue : e.issues())
        issues.push_back(
            {"/scene" + (issue.pointer == "/" ? "" : issue.pointer),
             "level " + std::to_string(j + 1) + " of " + std::to_string(plan.levels.size()) + ": " + issue.detail});
    }
    if (!issues.empty()) throw SceneErrors(std::move(issues));
  }
  if (plan.h_from_nodes)  // in 2D the element size goes as 1 / sqrt(nodes)
    for (size_t j = 0; j < plan.levels.size(); ++j)
      plan.levels[j].h = std::sqrt(static_cast<double>(nodes[0]) / std::max(1, nodes[j]));
  std::vector<std::string> ids;
  try {
    for (const StudyLevel& level : plan.levels)
      ids.push_back(jobs_.submit(level.scene, std::nullopt, request_id).job.record.id);
  } catch (...) {
    for (const std::string& id : ids) jobs_.dismiss(id);  // all levels or none
    throw;
  }
  StudyRecord rec{new_job_id(), now_iso8601(), {}};
  json levels = json::array();
  for (size_t j = 0; j < ids.size(); ++j)
    levels.push_back({{"job", ids[j]}, {"h", plan.levels[j].h}, {"nodes", nodes[j]}});
  rec.document = json{{"kind", "refinement"}, {"outputs", plan.outputs}, {"levels", levels}}.dump();
  try {
    jobs_.store().insert_study(rec);
  } catch (...) {
    for (const std::string& id : ids) jobs_.dismiss(id);
    throw;
  }
  spdlog::info("study {} accepted: {} levels (request {})", rec.id, ids.size(), request_id.empty() ? "-" : request_id);
  return *study(rec.id);
}

std::optional<json> Studies::study(const std::string& id) {
  const auto rec = jobs_.store().study(id);
  if (!rec) return std::nullopt;
  const json plan = json::parse(rec->document);
  json levels = json::array();
  std::vector<std::optional<json>> outputs;
  std::vector<std::optional<double>> seconds;
  std::set<std::string> states;
  for (size_t j = 0; j < plan["levels"].size(); ++j) {
    const json& l = plan["levels"][j];
    const std::string job = l["job"];
    json level = {{"level", j + 1}, {"job", job}, {"h", l["h"]}, {"nodes", l["nodes"]}};
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
  // Each output over the levels that have it: Richardson on their sizes.
  json quantities = json::array();
  for (const json& name : plan["outputs"]) {
    std::vector<double> v, h;
    std::vector<size_t> at;  // the level of each value
    json values = json::array();
    for (size_t j = 0; j < outputs.size(); ++j) {
      const bool has = outputs[j] && outputs[j]->contains(name) && (*outputs[j])[name].is_number();
      values.push_back(has ? (*outputs[j])[name] : json(nullptr));
      if (!has) continue;
      v.push_back((*outputs[j])[name].get<double>());
      h.push_back(plan["levels"][j]["h"].get<double>());
      at.push_back(j);
    }
    const Richardson r = richardson(v, h);
    json orders = json::array(), errors = json(std::vector<json>(outputs.size(), nullptr));
    for (const auto& p : r.orders) orders.push_back(number_or_null(p));
    for (size_t k = 0; k < at.size(); ++k) errors[at[k]] = number_or_null(r.estimated_error[k]);
    json cheapest = json::array();
    for (double below : kStudyThresholds) {
      json best = nullptr;
      for (size_t k = 0; k < at.size(); ++k) {
        const auto& e = r.estimated_error[k];
        const auto& t = seconds[at[k]];
        if (!e || !t || !(*e < below)) continue;
        if (best.is_null() || *t < best["seconds"].get<double>())
          best = {{"level", at[k] + 1}, {"seconds", *t}, {"estimated_error", *e}};
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
  }
  // The study's status: running while a level is queued or runs; then successful when every
  // level is, else failed (or dismissed when its levels were).
  std::string status = "successful";
  if (states.count("accepted") || states.count("running")) status = states.count("running") ? "running" : "accepted";
  else if (states.count("dismissed") || states.count("removed")) status = "dismissed";
  else if (states.count("failed")) status = "failed";
  json links = json::array({{{"href", "/v1/studies/" + rec->id}, {"rel", "self"}, {"type", "application/json"}}});
  for (const json& l : levels)
    links.push_back(
        {{"href", "/v1/jobs/" + l["job"].get<std::string>()}, {"rel", "item"}, {"type", "application/json"}});
  return json{{"id", rec->id},    {"created", rec->created},  {"kind", plan["kind"]},           {"status", status},
              {"levels", levels}, {"quantities", quantities}, {"thresholds", kStudyThresholds}, {"links", links}};
}

bool Studies::remove(const std::string& id) {
  const auto rec = jobs_.store().study(id);
  if (!rec) return false;
  const json plan = json::parse(rec->document);
  for (const json& l : plan["levels"]) jobs_.dismiss(l["job"].get<std::string>());
  return jobs_.store().remove_study(id);
}

}  // namespace grip::server
