// The held real solve's forces p(q) and their stiffness (HeldContact).
#include "solver/equilibrium/equilibrium.hpp"

namespace grip {

Vector Equilibrium::held_forces(const Vector& q, const EquilibriumState& paired, const Vector& p_given,
                                TangentSink* tangent) const {
  const HeldContact& held = *held_;
  Vector p = p_given;
  LawGradient gap, zeta;
  std::vector<LawChange> dp;
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    const double kn = held.stiffness[c.eta], kt = c.xi >= 0 ? held.stiffness[c.xi] : 0.0;
    const int slip = c.xi >= 0 && kn > 0 ? held.slip[i] : 0;
    if (kn == 0.0 && kt == 0.0) continue;
    const double mu = problem_.obstacles[c.obstacle].friction;
    if (kn > 0) p[c.eta] = p_given[c.eta] + kn * (held.target[c.eta] - paired.s[c.eta]);
    if (kt > 0) p[c.xi] = p_given[c.xi] + kt * (held.target[c.xi] - paired.s[c.xi]);
    else if (slip) p[c.xi] = -slip * mu * p[c.eta];
    if (!tangent) continue;
    law_gradients(q, paired, i, kt > 0, gap, zeta);
    // s_eta = -gap and s_xi = zeta - zeta_prev: dp_eta = k_n d(gap), dp_xi = -k_t d(zeta), or on
    // the slip -+mu dp_eta.
    dp.clear();
    for (const auto& [dof, g] : gap) dp.push_back({dof, kn * g, -slip * mu * kn * g});
    for (const auto& [dof, z] : zeta) dp.push_back({dof, 0.0, -kt * z});
    add_law_tangent(paired, i, dp, *tangent);
  }
  return p;
}

}  // namespace grip
