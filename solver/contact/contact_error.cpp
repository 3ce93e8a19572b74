#include "solver/contact/contact_error.hpp"

#include <cmath>

namespace grip {
namespace {

int sign(double a) { return (a > 0) - (a < 0); }

bool at_bound(double p_xi, double tau) { return std::abs(p_xi) >= tau * (1 - kBoundTolerance); }

}  // namespace

ContactError contact_error(const Problem& problem, const Vector& p, const Vector& s, const Vector& tau,
                           const std::vector<char>& enabled) {
  ContactError e;
  e.v = Vector::Zero(problem.component_count);
  e.active.assign(problem.component_count, 0);
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    if (enabled[c.eta] && (p[c.eta] < 0 || s[c.eta] > 0)) {
      e.v[c.eta] = s[c.eta];
      e.active[c.eta] = 1;
    }
    if (c.xi < 0 || !enabled[c.xi] || tau[i] <= 0) continue;
    const double pt = p[c.xi], st = s[c.xi];
    const bool slipping = at_bound(pt, tau[i]) && sign(pt) == -sign(st) && st != 0;
    if (!slipping) {
      e.v[c.xi] = st;
      e.active[c.xi] = 1;
    }
  }
  // The equilibrium of the whole body along each free rigid motion: an equality, always active.
  for (int k = 0; k < problem.rigid.count(); ++k) {
    e.v[problem.rigid.first + k] = s[problem.rigid.first + k];
    e.active[problem.rigid.first + k] = 1;
  }
  e.norm2 = e.v.norm();
  e.norm_inf = e.v.size() ? e.v.lpNorm<Eigen::Infinity>() : 0.0;
  return e;
}

Vector project_forces(const Problem& problem, const Vector& p, const Vector& pbar, const ContactError& error,
                      const Vector& tau) {
  Vector out = p;
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    out[c.eta] = std::min(0.0, pbar[c.eta]);
    if (c.xi < 0) continue;
    if (tau[i] <= 0) out[c.xi] = 0.0;
    else if (error.active[c.xi]) out[c.xi] = std::clamp(pbar[c.xi], -tau[i], tau[i]);
    else  // slipping: stays on the bound, on its side
      out[c.xi] = sign(p[c.xi]) * tau[i];
  }
  // The rigid amplitudes have no bound (docs/algorithm.md#bodies-held-only-by-contact).
  for (int k = 0; k < problem.rigid.count(); ++k) out[problem.rigid.first + k] = pbar[problem.rigid.first + k];
  return out;
}

Vector friction_bounds(const Problem& problem, const Vector& p_star) {
  Vector tau = Vector::Zero(problem.candidates.size());
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    if (c.xi >= 0) tau[i] = problem.obstacles[c.obstacle].friction * std::abs(p_star[c.eta]);
  }
  return tau;
}

void clip_to_bounds(const Problem& problem, const Vector& tau, Vector& p) {
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    if (c.xi >= 0) p[c.xi] = std::clamp(p[c.xi], -tau[i], tau[i]);
  }
}

ContactState contact_state(const Problem& problem, size_t candidate, const Vector& p, const Vector& tau) {
  const Candidate& c = problem.candidates[candidate];
  if (p[c.eta] >= 0) return ContactState::open;
  if (c.xi < 0) return ContactState::slip;  // frictionless contact slides freely
  return at_bound(p[c.xi], tau[candidate]) ? ContactState::slip : ContactState::stick;
}

const char* to_string(ContactState state) {
  switch (state) {
    case ContactState::open:
      return "open";
    case ContactState::stick:
      return "stick";
    case ContactState::slip:
      return "slip";
  }
  return "open";
}

}  // namespace grip
