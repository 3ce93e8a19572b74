#include "solver/stepping/limit_load.hpp"

#include <cstdio>

#include "solver/model/number_text.hpp"

namespace grip {

LoadPathStiffness::LoadPathStiffness(const Problem& problem)
    : problem_(problem), prescribed_(problem.body->dof_count(), 0) {
  for (const Constraint& c : problem.constraints) prescribed_[c.dof] = 1;
}

Vector LoadPathStiffness::load_change(const LoadFactors& from, const LoadFactors& to) const {
  bool loads = false;
  for (size_t k = 0; k < to.size(); ++k) {
    if (k < from.size() && from[k] == to[k]) continue;
    for (const Constraint& c : problem_.constraints)
      if (c.load_case == static_cast<int>(k) && c.value != 0.0) return {};
    for (const ObstacleInstance& o : problem_.obstacles)
      if (k < o.translations.size() && o.translations[k] != Vec2::Zero()) return {};
    if (k < problem_.loads.size() && problem_.loads[k].any()) loads = true;
  }
  if (!loads) return {};
  Vector df = problem_.load(to) - problem_.load(from);
  for (size_t d = 0; d < prescribed_.size(); ++d)
    if (prescribed_[d]) df[static_cast<Eigen::Index>(d)] = 0.0;
  return df;
}

void LoadPathStiffness::committed(const LoadFactors& from, const LoadFactors& to, const Vector& dq) {
  const Vector df = load_change(from, to);
  const double work = df.size() ? df.dot(dq) : 0.0;
  // Not load control, or the body gave back work along the load (a snap): the run starts anew.
  if (!(work > 0.0)) {
    direction_.resize(0);
    return;
  }
  const double size = df.norm();
  const double stiffness = size * size / work;
  const Vector unit = df / size;
  if (direction_.size() != unit.size() || direction_.dot(unit) < 0.999) {
    direction_ = unit;
    first_ = stiffness;
  }
  last_ = stiffness;
}

std::string LoadPathStiffness::beyond_limit(const LoadFactors& current, const LoadFactors& target) const {
  if (direction_.size() == 0) return {};
  const Vector df = load_change(current, target);
  if (df.size() == 0 || df.dot(direction_) < 0.999 * df.norm()) return {};
  const double fraction = last_ / first_;
  if (!(fraction < kLimitStiffnessFraction)) return {};
  std::string at;
  for (size_t k = 0; k < current.size(); ++k)
    at += (at.empty() ? "" : ", ") + (k < problem_.case_names.size() ? problem_.case_names[k] + " " : std::string()) +
          number_text(current[k]);
  char percent[32];
  std::snprintf(percent, sizeof percent, "%.2g %%", 100 * fraction);
  return "no equilibrium beyond a limit load: over the last converged increment (load factor " + at +
         ") the body's stiffness along the applied load fell to " + percent +
         " of its first increment's; no static state near it carries more load (plastic collapse or buckling), so "
         "load control cannot pass the limit: prescribe a displacement to follow the body beyond it";
}

}  // namespace grip
