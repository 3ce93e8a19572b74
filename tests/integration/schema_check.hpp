#pragma once
// Validates service documents against schemas/<name>.schema.json with valijson (draft 7),
// when that schema exists; references to sibling schema files are resolved from schemas/.
#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validator.hpp>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "grip_process.hpp"

namespace grip::testing {

inline fs::path schemas_dir() { return source_dir() / "schemas"; }

namespace detail {

inline const json* fetch_schema(const std::string& uri) {
  // "event.schema.json", "./event.schema.json", "https://.../event.schema.json#..."
  std::string name = uri.substr(0, uri.find('#'));
  name = name.substr(name.find_last_of('/') + 1);
  const fs::path path = schemas_dir() / name;
  if (name.empty() || !fs::exists(path)) return nullptr;
  return new json(json::parse(read_text(path)));
}

inline void free_schema(const json* doc) { delete doc; }

}  // namespace detail

// Errors of `doc` against the named schema; nullopt when the schema file does not exist.
inline std::optional<std::vector<std::string>> schema_errors(const std::string& name, const json& doc) {
  const fs::path path = schemas_dir() / (name + ".schema.json");
  if (!fs::exists(path)) return std::nullopt;
  static std::map<std::string, std::shared_ptr<valijson::Schema>> cache;
  static std::mutex mutex;
  std::shared_ptr<valijson::Schema> schema;
  {
    std::lock_guard lock(mutex);
    auto& slot = cache[name];
    if (!slot) {
      const json schema_doc = json::parse(read_text(path));
      slot = std::make_shared<valijson::Schema>();
      valijson::SchemaParser parser;
      valijson::adapters::NlohmannJsonAdapter adapter(schema_doc);
      parser.populateSchema(adapter, *slot, detail::fetch_schema, detail::free_schema);
    }
    schema = slot;
  }
  valijson::Validator validator;
  valijson::ValidationResults results;
  valijson::adapters::NlohmannJsonAdapter target(doc);
  std::vector<std::string> errors;
  if (!validator.validate(*schema, target, &results)) {
    valijson::ValidationResults::Error error;
    while (results.popError(error)) {
      std::string where;
      for (const auto& c : error.context) where += c;
      errors.push_back(where + ": " + error.description);
    }
  }
  return errors;
}

}  // namespace grip::testing
