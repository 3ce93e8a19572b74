#include "server/studies.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <set>

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
    StudyLevel level{scene, 1.0, json::array()};
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

}  // namespace

StudyPlan plan_study(const json& request) {
  std::vector<SceneIssue> issues;
  auto fail = [&]() { throw SceneErrors(std::move(issues)); };
  if (!request.is_object()) {
    issues.push_back({"/", "a study is a JSON object: {\"scene\", \"refine\" | \"sweep\", \"outputs\"}"});
    fail();
  }
  for (const auto& [key, value] : request.items())
    if (key != "scene" && key != "refine" && key != "sweep" && key != "mode" && key != "outputs" &&
        key != "description")
      issues.push_back({"/" + key, "is not a member of a study (scene, refine, sweep, mode, outputs, description)"});
  if (!request.contains("scene") || !request["scene"].is_object())
    issues.push_back({"/scene", "is required: the scene to study (an object, as POST /v1/jobs takes it)"});
  const bool sweeping = request.contains("sweep");
  if (sweeping && request.contains("refine"))
    issues.push_back({"/sweep", "goes without refine: a study either refines the mesh or sweeps parameters"});
  else if (!sweeping && (!request.contains("refine") || !request["refine"].is_object()))
    issues.push_back(
        {"/refine", "is required (or sweep): {\"levels\": k} (generated meshes) or {\"meshes\": [...]} (gmsh)"});
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
      StudyLevel level{scene, std::ldexp(1.0, -j), nullptr};
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
      StudyLevel level{scene, 1.0, nullptr};
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
  for (size_t j = 0; j < ids.size(); ++j) {
    levels.push_back({{"job", ids[j]}, {"nodes", nodes[j]}});
    if (plan.kind == "sweep") levels.back()["parameters"] = plan.levels[j].parameters;
    else levels.back()["h"] = plan.levels[j].h;
  }
  json document = {{"kind", plan.kind}, {"outputs", plan.outputs}, {"levels", levels}};
  if (plan.kind == "sweep") document["pointers"] = plan.pointers;
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
    json level = {{"level", j + 1}, {"job", job}, {"nodes", l["nodes"]}};
    for (const char* key : {"h", "parameters"})  // a refinement's level, a sweep's variant
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
  const bool sweep = plan["kind"] == "sweep";
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
      h.push_back(plan["levels"][j].value("h", 1.0));
      at.push_back(j);
    }
    if (sweep) {
      quantities.push_back({{"name", name}, {"values", values}});
      continue;
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
  json doc = {{"id", rec->id},    {"created", rec->created},  {"kind", plan["kind"]}, {"status", status},
              {"levels", levels}, {"quantities", quantities}, {"links", links}};
  if (sweep) doc["pointers"] = plan["pointers"];
  else doc["thresholds"] = kStudyThresholds;
  return doc;
}

std::vector<json> study_rows(const json& study) {
  std::vector<json> rows;
  for (size_t k = 0; k < study["levels"].size(); ++k) {
    const json& level = study["levels"][k];
    json row = {
        {"level", level["level"]}, {"job", level["job"]}, {"status", level["status"]}, {"nodes", level["nodes"]}};
    row["seconds"] = level.value("seconds", json(nullptr));
    for (const char* key : {"h", "parameters"})
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
  for (const json& l : plan["levels"]) jobs_.dismiss(l["job"].get<std::string>());
  return jobs_.store().remove_study(id);
}

}  // namespace grip::server
