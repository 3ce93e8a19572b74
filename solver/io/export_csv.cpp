#include "solver/io/export_csv.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>

namespace grip {

using nlohmann::json;

namespace {

// Flattens one object into (column, value) pairs in field order.
void flatten(const json& value, const std::string& name, std::vector<std::pair<std::string, json>>& out) {
  if (value.is_object()) {
    for (auto it = value.begin(); it != value.end(); ++it)
      flatten(it.value(), name.empty() ? it.key() : name + "." + it.key(), out);
  } else if (value.is_array()) {
    static const char* xy[] = {"_x", "_y"};
    for (size_t i = 0; i < value.size(); ++i)
      flatten(value[i], name + (value.size() == 2 ? std::string(xy[i]) : "_" + std::to_string(i)), out);
  } else {
    out.emplace_back(name, value);
  }
}

std::string cell(const json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) {
    const std::string s = v.get<std::string>();
    if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
  }
  return v.dump();  // numbers round-trip, booleans as true/false
}

const json& steps_of(const json& result) {
  static const json empty = json::array();
  return result.contains("steps") && result["steps"].is_array() ? result["steps"] : empty;
}

// The body of each row of the nodes or elements table (scenes of several bodies: the result's
// bodies[] ranges); empty for one body.
std::vector<std::string> row_bodies(const json& result, const std::string& key) {
  std::vector<std::string> names;
  if (!result.contains("bodies") || (key != "nodes" && key != "elements")) return names;
  const std::string first = key == "nodes" ? "first_node" : "first_element";
  for (const json& b : result["bodies"]) {
    names.resize(b.value(first, 0), names.empty() ? "" : names.back());
    names.resize(b.value(first, 0) + b.value(key, 0), b.value("name", ""));
  }
  return names;
}

// Prefixes each item of steps[k][key] with the step number and load factor (and its body).
std::vector<json> per_step_items(const json& result, const char* key, bool with_load_factor) {
  std::vector<json> rows;
  const std::vector<std::string> bodies = row_bodies(result, key);
  for (const json& step : steps_of(result)) {
    if (!step.contains(key)) continue;
    size_t k = 0;
    for (const json& item : step[key]) {
      json row = json::object();
      row["step"] = step.value("step", 0);
      if (with_load_factor) row["load_factor"] = step.value("load_factor", 0.0);
      if (k < bodies.size()) row["body"] = bodies[k];
      ++k;
      for (auto it = item.begin(); it != item.end(); ++it) row[it.key()] = it.value();
      rows.push_back(std::move(row));
    }
  }
  return rows;
}

std::vector<json> step_rows(const json& result) {
  std::vector<json> rows;
  for (const json& step : steps_of(result)) {
    json row = json::object();
    row["step"] = step.value("step", 0);
    for (auto it = step.begin(); it != step.end(); ++it)
      if (!it.value().is_array() && !it.value().is_object() && it.key() != "step") row[it.key()] = it.value();
    if (step.contains("obstacles"))
      for (const json& o : step["obstacles"])
        row["offset." + o.value("name", std::string("obstacle"))] = o.value("offset", json::array());
    if (step.contains("reactions"))
      for (const json& r : step["reactions"])
        row["reaction.dof" + std::to_string(r.value("dof", 0))] = r.value("force", 0.0);
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace

const std::vector<std::string>& result_csv_tables() {
  static const std::vector<std::string> names = {"steps",          "nodes",         "elements",
                                                 "contact_points", "master_points", "history"};
  return names;
}

std::string result_csv(const json& result, std::string_view table) {
  if (table == "steps") return objects_csv(step_rows(result));
  if (table == "nodes") return objects_csv(per_step_items(result, "nodes", true));
  if (table == "elements") return objects_csv(per_step_items(result, "elements", true));
  if (table == "contact_points") return objects_csv(per_step_items(result, "contact_points", true));
  if (table == "master_points") return objects_csv(per_step_items(result, "master_points", true));
  if (table == "history") return objects_csv(per_step_items(result, "history", false));
  throw std::invalid_argument("unknown table '" + std::string(table) + "'");
}

std::string objects_csv(const std::vector<json>& rows) {
  // JSON objects keep their keys sorted: the identifying columns go first.
  static const std::vector<std::string> leading = {"step", "load_factor", "pass",    "m",
                                                   "body", "node",        "element", "obstacle"};
  std::vector<std::string> columns;
  std::map<std::string, size_t> index;
  std::vector<std::vector<std::pair<std::string, json>>> flat(rows.size());
  for (size_t r = 0; r < rows.size(); ++r) flatten(rows[r], "", flat[r]);
  for (const std::string& name : leading)
    for (const auto& row : flat)
      if (std::any_of(row.begin(), row.end(), [&](const auto& kv) { return kv.first == name; })) {
        index.emplace(name, columns.size());
        columns.push_back(name);
        break;
      }
  for (const auto& row : flat)
    for (const auto& [name, value] : row)
      if (index.emplace(name, columns.size()).second) columns.push_back(name);
  std::string out;
  for (size_t c = 0; c < columns.size(); ++c) out += (c ? "," : "") + cell(columns[c]);
  out += '\n';
  std::vector<std::string> line(columns.size());
  for (const auto& row : flat) {
    std::fill(line.begin(), line.end(), std::string());
    for (const auto& [name, value] : row) line[index[name]] = cell(value);
    for (size_t c = 0; c < line.size(); ++c) out += (c ? "," : "") + line[c];
    out += '\n';
  }
  return out;
}

}  // namespace grip
