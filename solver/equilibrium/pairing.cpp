// The pairing: each candidate's surface point projected onto its obstacle or master at q,
// and s (the gap and the slip) from it.
#include "solver/equilibrium/equilibrium.hpp"

#include <cmath>

namespace grip {

void Equilibrium::pair(const Vector& q, EquilibriumState& state) const {
  const auto& cands = problem_.candidates;
  state.points.resize(cands.size());
  state.s.setZero(problem_.component_count);
  state.enabled.assign(problem_.component_count, 0);
  for (int k = 0; k < problem_.rigid.count(); ++k) state.enabled[problem_.rigid.first + k] = 1;
  // Deformable masters in their current configuration (mortar, segment-to-segment).
  auto& masters = state.masters;
  masters.assign(problem_.obstacles.size(), nullptr);
  for (size_t o = 0; o < masters.size(); ++o)
    if (problem_.obstacles[o].master)
      masters[o] = std::make_shared<const DeformedMaster>(*problem_.body, q, *problem_.obstacles[o].master);
  for (size_t i = 0; i < cands.size(); ++i) {
    const Candidate& c = cands[i];
    const ObstacleInstance& obstacle = problem_.obstacles[c.obstacle];
    PairedPoint& pp = state.points[i];
    problem_.body->surface_point_into(q, c.site, c.side, pp.point);
    if (const auto& master = masters[c.obstacle]) {
      // The Jacobian of the relative point x - x_m: the pair's forces act on both bodies.
      MasterPoint mp = master->project(pp.point.x, c.site);
      pp.projection = mp.projection;
      pp.point.jacobian.insert(pp.point.jacobian.end(), mp.jacobian.begin(), mp.jacobian.end());
    } else {
      const Vec2 offset = obstacle.offset(factors_);
      pp.projection = obstacle.shape->project(pp.point.x - offset);
      pp.projection.point += offset;
    }
    pp.projection.gap -= pp.point.clearance;
    pp.eta = -pp.projection.normal;
    pp.xi = pp.projection.tangent;
    state.s[c.eta] = -pp.projection.gap;
    double eta_col = 0.0, xi_col = 0.0;
    for (const auto& j : pp.point.jacobian) {
      if (free_index_[j.dof] < 0 && !is_pin_[j.dof]) continue;  // a pin moves with its amplitude
      eta_col += std::abs(j.dx.dot(pp.eta));
      xi_col += std::abs(j.dx.dot(pp.xi));
    }
    // A column of T that vanishes on the free dofs (a force on a support) is never active.
    state.enabled[c.eta] = eta_col > 1e-12;
    if (c.xi >= 0) {
      state.s[c.xi] = obstacle.master ? master_zeta_difference(*obstacle.master, pp.projection.zeta, zeta_previous_[i])
                                      : obstacle.shape->zeta_difference(pp.projection.zeta, zeta_previous_[i]);
      state.enabled[c.xi] = xi_col > 1e-12;
    }
  }
}

EquilibriumState Equilibrium::evaluate(const Vector& q) const {
  EquilibriumState state;
  state.q = q;
  pair(q, state);
  state.converged = true;
  return state;
}

}  // namespace grip
