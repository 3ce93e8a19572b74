// libFuzzer target: the input bytes are a scene document, read the way `POST /v1/jobs`
// (server/http_server.cpp, server/job_service.cpp) and `grip solve` read one: a bound on
// nesting, then json::parse (either failing is the service's 400), then read_scene (schema stage, then the checked
// reader and problem building; SceneErrors is the 422). Nothing is solved.
// Any other exception, a crash, a leak or a UBSan report is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <string_view>

#include <nlohmann/json.hpp>

#include "solver/io/json_depth.hpp"
#include "solver/io/scene.hpp"

namespace {

// A rejection must say where: at least one issue, each with a well-formed JSON pointer.
void check_issues(const grip::SceneErrors& e) {
  if (e.issues().empty()) {
    std::cerr << "SceneErrors without issues\n";
    std::abort();
  }
  for (const grip::SceneIssue& issue : e.issues()) {
    bool ok = !issue.pointer.empty() && issue.pointer.front() == '/' && !issue.detail.empty();
    if (ok) {
      try {
        nlohmann::json::json_pointer p(issue.pointer);  // rejects a bad '~' escape
      } catch (const nlohmann::json::exception&) {
        ok = false;
      }
    }
    if (!ok) {
      std::cerr << "issue without a valid JSON pointer: '" << issue.pointer << "': " << issue.detail << "\n";
      std::abort();
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (grip::nested_deeper_than(text, grip::kMaxJsonDepth)) return 0;  // 400 malformed-json
  nlohmann::json scene;
  try {
    scene = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception&) {
    return 0;  // 400 malformed-json (parse_error, or out_of_range.406 for 1e400)
  }
  (void)scene.dump();  // JobService::submit keys idempotency on the canonical dump
  try {
    const grip::Scene s = grip::read_scene(scene);
    // JobService::submit counts nodes and steps of an accepted scene.
    if (!s.problem.body || s.steps.empty()) {
      std::cerr << "accepted scene without a body or without load steps\n";
      std::abort();
    }
    (void)s.problem.body->site_count();
  } catch (const grip::SceneErrors& e) {
    check_issues(e);
  }
  return 0;
}
