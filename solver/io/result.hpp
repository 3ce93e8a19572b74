#pragma once
// Results and events as JSON (DESIGN.md vocabulary). Events are the same objects whether
// written to an NDJSON file by `grip solve --events` or streamed by the service.
#include <nlohmann/json.hpp>
#include <ostream>

#include "solver/io/scene.hpp"

namespace grip {

nlohmann::json iteration_event(const IterationEvent& ev);
nlohmann::json step_started_event(int step, double load_factor);
nlohmann::json step_finished_event(const StepRecord& rec);

// One step's fields: nodes, elements, reactions, contact points, obstacle positions.
// Fields only where the step was recorded (see SteppingParams::record_fields) and wanted.
nlohmann::json step_json(const Problem& problem, const StepRecord& rec, const OutputOptions& output = {});
// What was simulated (friction, nonlinearity, plasticity, moving obstacles, contact unknowns)
// and the work it took (factorizations, equilibrium solves).
nlohmann::json effects_json(const Scene& scene, const RunResult& run);
// The whole result: the effective scene, a summary and every step.
nlohmann::json result_json(const Scene& scene, const RunResult& run);
// The same document written as it is made (the step tables row by row, never held as JSON):
// for large meshes, where building the document took more time and memory than the solve.
void write_result(std::ostream& out, const Scene& scene, const RunResult& run);

}  // namespace grip
