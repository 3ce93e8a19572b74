#pragma once
// JSON Schema (draft 7) validation of grip's documents against the schemas in schemas/,
// which the build embeds in the library (no file is read at run time). Every error is a
// SceneIssue: the JSON pointer of the offending value ("/body/material/poisson"; "/" for
// the document itself) and a plain sentence ("0.62 is not below 0.5"). All errors are
// reported, sorted by pointer (array indices numerically), each once, up to kMaxSceneIssues.
//
// The schemas may annotate a subschema with `errorMessage` (the ajv-errors keyword, ignored
// by other validators): it replaces the generic sentence for that subschema's own failures.
#include <nlohmann/json.hpp>
#include <optional>
#include <string_view>
#include <vector>

#include "solver/io/scene.hpp"

namespace grip {

enum class SchemaName { scene, event, result, job };

// "scene", "event", "result", "job": the file is schemas/<name>.schema.json.
std::string_view schema_file_stem(SchemaName which);

// The schema as written in schemas/ (the text the build embedded).
std::string_view schema_text(SchemaName which);

// Errors of `document` against the schema; empty when it is valid. At most kMaxSceneIssues:
// collecting stops at a bound, and `more` (when given) tells whether it did. Thread-safe; the
// schemas are parsed once, on first use (std::logic_error if one was not embedded or does not
// parse).
std::vector<SceneIssue> validate_against(const nlohmann::json& document, SchemaName which, bool* more = nullptr);

// Builds the schema's validator now, as the first validate_against would: for a caller that
// does it on a thread of its own while it reads the document (grip solve: 5 ms of a refined
// Hertz scene's reading). Thread-safe; validate_against waits for a build under way.
void prepare_schema(SchemaName which);

// The `default` the schema gives the value at `pointer` of `document` (present or not), where
// the subschemas that apply to it say one; nullopt otherwise. Conditions (a body's model, a
// shape's type) are decided on `document`.
std::optional<nlohmann::json> schema_default(const nlohmann::json& document, SchemaName which,
                                             std::string_view pointer);

}  // namespace grip
