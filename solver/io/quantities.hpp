#pragma once
// Quantities of interest that a scene names (`outputs`, docs/design.md#quantities-of-interest):
// numbers taken from each converged step, written in the result (steps[].outputs) and in the
// step_finished events, so that a study compares numbers, not whole fields. Forces are those on
// the body (a support's reaction, an obstacle's contact forces), in the scene's units; an
// axisymmetric body's are totals over the full circle.
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "solver/problem/problem.hpp"
#include "solver/stepping/load_stepping.hpp"

namespace grip {

enum class QuantityKind { reaction, resultant, displacement, peak_pressure, contact_width, stick_width, field };

struct Quantity {
  std::string name;
  QuantityKind kind = QuantityKind::reaction;
  // reaction, displacement: the value is the sum of weight x (reactions or q)[dof] (the weights:
  // the body's rigid translation along the component, on the named nodes' dofs).
  std::vector<std::pair<int, double>> dofs;
  // resultant, peak_pressure: the obstacle (or contact pair), -1 every one; widths: the obstacle.
  int obstacle = -1;
  int component = 0;              // resultant: 0 x, 1 y
  int element = -1, column = -1;  // field: the element and its column of the step's element fields
};

// The value of `q` at a converged step:
// - reaction, displacement: as Quantity::dofs;
// - resultant: the component of the contact forces' resultant on the body;
// - peak_pressure: the largest contact pressure -p_n / tributary area (positive, 0 without contact);
// - contact_width, stick_width: the length of the body's reference surface in contact (p_n < 0)
//   or sticking, over the candidates ordered along the obstacle; each zone ends where the square
//   of the pressure (of the stick margin mu |sigma_n| - |sigma_t|) extrapolated from its last two
//   nodes vanishes, at most at the next node (halfway to it where it cannot be extrapolated).
//   Several zones add up. 0 without contact;
// - field: the step's element field value (the step's fields are recorded: the reader asks).
double quantity_value(const Problem& problem, const StepRecord& rec, const Quantity& q);
// {name: value} of every quantity at a converged step; null for a step that did not converge.
nlohmann::json quantity_values(const Problem& problem, const StepRecord& rec, const std::vector<Quantity>& quantities);

}  // namespace grip
