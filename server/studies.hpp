#pragma once
// Studies (docs/design.md#studies): one request that runs a scene at several mesh levels (or
// with parameters swept) as
// ordinary jobs (the same queue, store and replicas) and answers, for each of the scene's
// outputs, its value per level, the observed order of convergence, the Richardson-extrapolated
// value with each level's estimated error (server/richardson.hpp), and the cheapest level whose
// estimated error is below 10 %, 1 % and 0.1 %. The study keeps only its plan and its jobs'
// ids (Store::insert_study); its table is read from the jobs whenever it is asked for, so it
// grows as they finish, on whichever replica.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "server/job_service.hpp"

namespace grip::server {

// The most levels of one refinement study (each a job; the finest has 4^(levels - 1) times the
// coarsest's elements).
inline constexpr int kMaxStudyLevels = 6;
// The most jobs of one sweep.
inline constexpr int kMaxStudyJobs = 100;

// A job of a study: its scene and its mesh size relative to the coarsest (1). A refinement
// plan with tolerances or methods has a job per (mesh level, method, tolerance).
struct StudyLevel {
  nlohmann::json scene;
  double h = 1.0;
  nlohmann::json parameters;  // a sweep's variant: the values of its pointers
  int mesh_level = 0;         // a refinement's level, from 1 (coarsest)
  nlohmann::json tolerance;   // solver.contact.tolerance where the plan gives tolerances, else null
  nlohmann::json method;      // solver.contact.method where the plan gives methods, else null
};

// The levels of a request {"scene", "refine": {"levels": k} | {"meshes": [ref, ...]},
// "tolerances"?: [t, ...], "methods"?: [method, ...], "outputs"?},
// coarse to fine, and the outputs it studies: generated meshes (rectangle, half_disc) of every
// body with their divisions x 2^j and refine.size / 2^j (h = 2^-j); a gmsh mesh
// (body.mesh.gmsh) replaced by each reference of the list in turn (h from the node counts,
// filled in later); with tolerances or methods, every level with each method at each
// tolerance (loosest first). Throws SceneErrors whose pointers start at the request's root.
// A sweep {"scene", "sweep": [{"pointer", "values" | "range": {from, to, count}}], "mode": "grid" |
// "zip", "outputs"?}: a variant per combination (grid) or per index (zip) with each pointer's
// value set; each pointer must name a value of the scene, and the variants are at most
// kMaxStudyJobs.
// An accuracy study {"scene", "accuracy": {"output", "relative", "levels"? (3 to 6, default 6),
// "budget_seconds"?}}: the generated levels, made three first and then one at a time until the
// output's estimated error at the finest is below `relative` (Studies::advance).
struct StudyPlan {
  std::string kind = "refinement";    // or "sweep", or "accuracy"
  std::vector<std::string> pointers;  // a sweep's, in the order of each variant's parameters
  std::vector<StudyLevel> levels;
  std::vector<std::string> outputs;
  bool h_from_nodes = false;  // a list of meshes: h_j = sqrt(nodes_0 / nodes_j)
  nlohmann::json accuracy;    // an accuracy study's target: {output, relative, levels, budget_seconds?}
};
StudyPlan plan_study(const nlohmann::json& request);

// The thresholds of "the cheapest level whose estimated error is below": 10 %, 1 %, 0.1 %.
inline const std::vector<double> kStudyThresholds = {0.1, 0.01, 0.001};

// A study's table as rows, one per job, for CSV (objects_csv): level, job, status, nodes,
// seconds, h (and method, tolerance) or parameters, outputs.NAME, estimated_error.NAME.
std::vector<nlohmann::json> study_rows(const nlohmann::json& study);

class Studies {
 public:
  // An accuracy study's next level is made as soon as the level before finishes here (the
  // job service's finished hook), and again whenever the study is read: a replica lost
  // between the two leaves the study to its next reader.
  explicit Studies(JobService& jobs);
  ~Studies();
  Studies(const Studies&) = delete;
  Studies& operator=(const Studies&) = delete;
  // Checks every level's scene (as a job submission would), then submits them and stores the
  // study; its document (as study() answers). Throws SceneErrors (the plan, or a level's
  // scene: pointers under /scene), QueueFull, ShuttingDown (the levels submitted are dismissed).
  nlohmann::json submit(const nlohmann::json& request, const std::string& request_id);
  // The study's table as far as its jobs have finished; none when no study has this id.
  std::optional<nlohmann::json> study(const std::string& id);
  // Dismisses its jobs (queued and running ones stop, finished ones are removed) and removes it.
  bool remove(const std::string& id);

 private:
  // The table of a study as far as its jobs have finished.
  nlohmann::json table(const StudyRecord& rec, const nlohmann::json& plan);
  // An accuracy study whose levels are done: its answer (reached, or why not) in `doc`, or
  // the next level made (true: read the table again).
  bool advance(const StudyRecord& rec, const nlohmann::json& plan, nlohmann::json& doc);

  JobService& jobs_;
};

}  // namespace grip::server
