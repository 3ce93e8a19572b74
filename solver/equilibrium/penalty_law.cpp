// The penalty law (strategy `penalty`): p(q) from the gaps and slips, and its stiffness.
#include "solver/equilibrium/equilibrium.hpp"

#include <cmath>

namespace grip {

void Equilibrium::set_penalty(std::optional<PenaltyLaw> law) {
  penalty_ = std::move(law);
  const bool free = penalty_ && problem_.rigid.count() > 0;
  if (free == pins_free_) return;
  pins_free_ = free;
  index_free_dofs();
  // Factorizations and G belong to the old free set.
  lu_.forget_pattern();
  body_lu_.forget_pattern();
  body_factorized_ = false;
  g_valid_ = false;
  surface_free_.clear();
}

Vector Equilibrium::penalty_forces(const Vector& q, const EquilibriumState& paired, TangentSink* tangent,
                                   const Vector* increment) const {
  const PenaltyLaw& law = *penalty_;
  Vector p = Vector::Zero(problem_.component_count);
  LawGradient gap, zeta;
  std::vector<LawChange> dp;
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    const PairedPoint& pp = paired.points[i];
    if (!paired.enabled[c.eta] || paired.s[c.eta] <= 0) {
      if (tangent)  // zeros keep the tangent's pattern fixed
        for (const auto& a : pp.point.jacobian)
          for (const auto& b : pp.point.jacobian) tangent->add(a.dof, b.dof, 0.0);
      continue;
    }
    p[c.eta] = -law.normal * paired.s[c.eta];
    const bool frictional = c.xi >= 0 && paired.enabled[c.xi];
    // p_eta = k_n gap; p_xi = start - k_t (zeta - zeta_prev) (stick) or -sign mu p_eta (slip).
    double stick = 0.0, slip = 0.0;  // dp_xi = stick d(zeta) + slip d(p_eta)
    if (frictional) {
      const double mu = problem_.obstacles[c.obstacle].friction;
      const double start = law.previous.size() ? law.previous[c.xi] : 0.0;
      const double trial = start - law.tangential * paired.s[c.xi];
      const double bound = mu * std::abs(p[c.eta]);
      if (std::abs(trial) <= bound || (!stick_branch_.empty() && stick_branch_[i])) {
        p[c.xi] = trial;
        stick = -law.tangential;
      } else {  // slip: the return to the cone
        const double sign = trial > 0 ? 1.0 : -1.0;
        p[c.xi] = sign * bound;
        slip = -sign * mu;
      }
    }
    if (!tangent && !increment) continue;
    law_gradients(q, paired, i, frictional, gap, zeta);
    // dp_eta = k_n d(gap), dp_xi = stick d(zeta) + slip dp_eta.
    dp.clear();
    for (const auto& [dof, g] : gap) dp.push_back({dof, law.normal * g, slip * law.normal * g});
    for (const auto& [dof, z] : zeta) dp.push_back({dof, 0.0, stick * z});
    if (increment)  // the law's linear change over the increment, from the increment itself
      for (const LawChange& d : dp) {
        p[c.eta] += d.normal * (*increment)[d.dof];
        if (frictional) p[c.xi] += d.tangential * (*increment)[d.dof];
      }
    if (tangent) add_law_tangent(paired, i, dp, *tangent);
  }
  return p;
}

void Equilibrium::law_gradients(const Vector& q, const EquilibriumState& paired, size_t i, bool with_zeta,
                                LawGradient& gap, LawGradient& zeta) const {
  // Against a rigid obstacle n . J and zeta_rate xi . J (its closest point); against a deformable
  // master also the normal's turn and the mortar weights' shift with both bodies
  // (DeformedMaster::gradients): one consistent tangent.
  const Candidate& c = problem_.candidates[i];
  const PairedPoint& pp = paired.points[i];
  gap.clear();
  zeta.clear();
  if (const auto& master = paired.masters[c.obstacle]) {
    master->gradients(problem_.body->surface_point(q, c.site, c.side), c.site, gap, zeta);
    if (!with_zeta) zeta.clear();
    return;
  }
  for (const auto& j : pp.point.jacobian) {
    gap.emplace_back(j.dof, -pp.eta.dot(j.dx));
    if (with_zeta) zeta.emplace_back(j.dof, pp.projection.zeta_rate * pp.xi.dot(j.dx));
  }
}

void Equilibrium::add_law_tangent(const EquilibriumState& paired, size_t i, const std::vector<LawChange>& dp,
                                  TangentSink& tangent) const {
  // d(T p)/dq from p's dependence on q; the residual carries it with a minus sign.
  const PairedPoint& pp = paired.points[i];
  const bool master = paired.masters[problem_.candidates[i].obstacle] != nullptr;
  for (const auto& a : pp.point.jacobian) {
    const double on_eta = a.dx.dot(pp.eta), on_xi = a.dx.dot(pp.xi);
    for (const LawChange& d : dp) {
      tangent.add(a.dof, d.dof, -(on_eta * d.normal + on_xi * d.tangential));
      if (master) tangent.add(d.dof, a.dof, 0.0);  // a tangent's pattern is symmetric
    }
  }
}

std::vector<signed char> Equilibrium::trial_signs(const EquilibriumState& paired) const {
  const PenaltyLaw& law = *penalty_;
  std::vector<signed char> signs(problem_.candidates.size(), 0);
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    if (c.xi < 0 || !paired.enabled[c.eta] || !paired.enabled[c.xi] || paired.s[c.eta] <= 0) continue;
    const double trial = (law.previous.size() ? law.previous[c.xi] : 0.0) - law.tangential * paired.s[c.xi];
    signs[i] = trial > 0 ? 1 : trial < 0 ? -1 : 0;
  }
  return signs;
}

// The law evaluated at a position carries that position's rounding, eps |x| times k (k up to
// 1e3 x the body's stiffness: ~4e-6 N a point at |x| ~ 20), a floor that Newton's residual
// cannot go below, and the load then balances the contact forces only to ~1e-6 of it. The law
// linearized at the converged iterate over one more correction dq carries only the rounding of
// dq: the same linear system that gives dq balances F + T p to the solver's precision. p then
// differs from the law at q + dq by its rounding there, and by the law's second-order change over
// dq, a correction already below Newton's tests.
EquilibriumState& Equilibrium::finish_penalty(EquilibriumState& state) {
  const Vector r = residual(state.q, state, state.p, &lu_.assemble(free_index_, free_count_));
  ++counters_.factorizations;
  ++counters_.newton_factorizations;
  const bool factorized = lu_.factorize(1e-4);
  counters_.newton_analyses = lu_.analyses();
  if (!factorized) return finish(state, penalty_forces(state.q, state, nullptr));
  Vector r_free(free_count_);
  for (int i = 0; i < r.size(); ++i)
    if (free_index_[i] >= 0) r_free[free_index_[i]] = -r[i];
  const Vector dq_free = lu_.solve(r_free);
  Vector dq = Vector::Zero(state.q.size());
  for (int i = 0; i < state.q.size(); ++i)
    if (free_index_[i] >= 0) dq[i] = dq_free[free_index_[i]];
  const Vector p = penalty_forces(state.q, state, nullptr, &dq);
  state.q += dq;
  pair(state.q, state);
  return finish(state, p);
}

}  // namespace grip
