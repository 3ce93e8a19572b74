#pragma once
// Results and events as JSON (docs/design.md#scenes-results-and-events). Events are the same
// objects whether written to an NDJSON file by `grip solve --events` or streamed by the service.
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "solver/io/scene.hpp"

namespace grip {

nlohmann::json iteration_event(const IterationEvent& ev);
nlohmann::json step_started_event(int step, double load_factor);
// With the scene's outputs (OutputOptions::quantities) at a converged step, as "outputs".
nlohmann::json step_finished_event(const Problem& problem, const StepRecord& rec, const OutputOptions& output);
// The failure member of a failed step, run or job: {kind, message, step}; step 0 where the
// failure is no step's (a dismissal, an invalid scene, a node or step limit).
nlohmann::json failure_json(FailureKind kind, const std::string& message, int step);
// The terminal event of a job that did not solve every step.
nlohmann::json job_failed_event(FailureKind kind, const std::string& reason, int step);

// The digits a step's fields (nodes, elements, reactions, contact and master points) are
// written with: single precision's, within 5e-7 of the value, far below any mesh's discretisation
// error; full doubles' 17 digits, which no mesh resolves, took most of a stored result's
// bytes (docs/design.md#scenes-results-and-events). Summaries, histories, events and
// the scene keep the shortest round-trip form of their doubles.
constexpr int kFieldDigits = 7;
// v rounded to kFieldDigits significant digits (written as at most that many); 0, infinities
// and NaN as they are.
double field_value(double v);

// One step's fields: nodes, elements, reactions, contact points, obstacle positions.
// Fields only where the step was recorded (see SteppingParams::record_fields) and wanted.
nlohmann::json step_json(const Problem& problem, const StepRecord& rec, const OutputOptions& output = {});
// What was simulated (friction, nonlinearity, plasticity, moving obstacles, contact unknowns)
// and the work it took (factorizations, equilibrium solves).
nlohmann::json effects_json(const Scene& scene, const RunResult& run);
// The same without the counters: what is known before the run. It reads the problem's
// description, which a solve leaves alone, so it may be made while the scene solves (the
// element quality is a pass over the mesh: 3 M instructions at Hertz a/h 20).
nlohmann::json effects_json(const Scene& scene);
// The whole result: the effective scene, a summary and every step. A JSON document, whose
// members have no order; results are written by write_result (below), never from this.
nlohmann::json result_json(const Scene& scene, const RunResult& run);
// The same document written as it is made (the step tables row by row, never held as JSON):
// for large meshes, where building the document took more time and memory than the solve.
// Its members in the order a result is written as it is solved (result_head_parts,
// result_step_parts, result_tail_parts): those known before the solve (bodies, mesh, scene),
// the steps, then those the run decides (effects, summary). The one way a result is written:
// `grip solve --out` streams the same parts, the service stores this text.
void write_result(std::ostream& out, const Scene& scene, const RunResult& run);

// A FieldTable's rows in one block (row after row), as a step's output keeps them.
struct FlatTable {
  std::vector<std::string> names;
  size_t rows = 0;
  std::vector<double> values;  // rows x names.size()
};
// One step of the result as write_result writes it, taken from the record when the step
// finishes: its small members as JSON, its tables copied. Writing it reads neither the problem
// nor the record, so `grip solve` formats each step and writes it to the file on a thread of
// its own while the next step solves (the solver itself stays single-threaded).
// A contact point of a step's "contact_points" (body and master: several bodies only).
struct ContactPointRow {
  int node = 0;
  std::string obstacle, state, body, master;
  Vec2 x, pair, normal;
  double p_n = 0, p_t = 0, sigma_n = 0, sigma_t = 0, gap = 0, slip = 0;
  bool several_bodies = false;
};
std::vector<ContactPointRow> contact_point_rows(const Problem& problem, const StepRecord& rec);
nlohmann::json contact_points_json(const std::vector<ContactPointRow>& rows);
struct StepOutput {
  nlohmann::json summary;                                      // step_json without the tables and the contact points
  std::optional<FlatTable> nodes, elements;                    // where recorded and wanted
  std::optional<std::vector<ContactPointRow>> contact_points;  // as JSON on the writer's thread
};
StepOutput step_output(const Problem& problem, const StepRecord& rec, const OutputOptions& output);
// The step's text in the result's "steps" array.
void write_step(std::ostream& out, const StepOutput& step);
// The same text in parts, each written by its own JsonWriter (on any thread, in any order):
// write_step's text is their texts one after another. A table's rows are split into parts of
// kRowsPerPart, so that two threads can share a step's formatting. The parts refer to `step`.
class JsonWriter;
using ResultPart = std::function<void(JsonWriter&)>;
constexpr size_t kRowsPerPart = 2048;
std::vector<ResultPart> step_parts(const StepOutput& step);
// write_result's text in parts, one after another: the head (`{"bodies":..,"mesh":..,"scene":..,
// "steps":[`; it reads the effective scene and the body's mesh, which a solve leaves alone, so
// it may be written while the scene solves), then each step k = 0, 1, ... (its separator and
// step_parts(step)), then the tail (`],"effects":..,"summary":..}` and a newline, from
// effects_json(scene) and the run; it holds what it writes). A run that fails at step k has
// its steps up to k and the reason in summary.
std::vector<ResultPart> result_head_parts(const Scene& scene);
std::vector<ResultPart> result_step_parts(const StepOutput& step, size_t k);
std::vector<ResultPart> result_tail_parts(nlohmann::json effects, const RunResult& run);

}  // namespace grip
