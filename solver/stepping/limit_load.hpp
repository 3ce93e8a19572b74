#pragma once
// Load control past a limit load. A body that yields without hardening (Prandtl's punch, a bar
// pulled beyond 2 k) or buckles has a largest load it can carry; a load step beyond it has no
// static equilibrium, and Newton's corrections drift along the load without end. The stepping
// cuts the increment, so the last converged states creep up to the limit, where the body's
// stiffness along the load falls to nothing. This measures that stiffness on each converged
// increment that changes only applied loads, so that a step that fails there says why.
#include <string>

#include "solver/problem/problem.hpp"

namespace grip {

// A step's failure is read as the limit load where the last converged increment's stiffness
// along the load is below this fraction of the first increment's along the same load (an
// elastic bar: 1; the plane-strain perfectly plastic bar just below 2 k: under 1e-2).
constexpr double kLimitStiffnessFraction = 0.05;

class LoadPathStiffness {
 public:
  explicit LoadPathStiffness(const Problem& problem);
  // After an increment from `from` to `to` converged, moving the displacements by `dq`.
  void committed(const LoadFactors& from, const LoadFactors& to, const Vector& dq);
  // Where the failed increment from `current` to `target` raises the applied loads along the
  // last converged increments' direction and their stiffness fell below kLimitStiffnessFraction
  // of its first value: the reason, else empty.
  std::string beyond_limit(const LoadFactors& current, const LoadFactors& target) const;

 private:
  // The change of the applied loads on the free dofs; empty where the increment also moves a
  // support or an obstacle (not load control) or changes no load.
  Vector load_change(const LoadFactors& from, const LoadFactors& to) const;
  const Problem& problem_;
  std::vector<char> prescribed_;     // dof held by a support
  Vector direction_;                 // the loads' change over the current run of increments, unit
  double first_ = 0.0, last_ = 0.0;  // stiffness |df|^2 / df.dq of its first and last increment
};

}  // namespace grip
