#pragma once
// CSV tables of a result document (the JSON of result_json), for spreadsheets. Generic over
// body models: the columns are the fields the result holds, in order of first appearance;
// every table is in long form with the step (and load factor) first, so one file holds all
// steps.
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace grip {

// Tables result_csv writes:
//   steps           one row per step: load factor, convergence, counters, obstacle offsets,
//                   reactions
//   nodes           one row per step and node (site): deformed position, displacements, ...
//                   (with several bodies, each row names its body: the result's bodies[])
//   elements        one row per step and element: stresses or section forces
//   contact_points  one row per step and contact candidate: p_n, p_t, sigma_n, gap, state, ...
//   history         one row per step and contact iteration: the contact error history
const std::vector<std::string>& result_csv_tables();

// Throws std::invalid_argument for a table not in result_csv_tables().
std::string result_csv(const nlohmann::json& result, std::string_view table);

// Objects as CSV rows. Columns: step, load_factor, pass, m, body, node, element, obstacle where
// present, then the others in order of first appearance. Scalars are columns; an array of
// two numbers becomes name_x, name_y, a longer one name_0, name_1, ...; nested objects become
// name.key. Missing values are empty.
std::string objects_csv(const std::vector<nlohmann::json>& rows);

}  // namespace grip
