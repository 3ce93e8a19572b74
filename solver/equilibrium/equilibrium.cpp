#include "solver/equilibrium/equilibrium.hpp"

#include <algorithm>

namespace grip {

Equilibrium::Equilibrium(const Problem& problem, NewtonParams params, std::vector<Constraint> extra)
    : problem_(problem), params_(params), extra_(std::move(extra)) {
  const int n = problem.body->dof_count();
  is_pin_.assign(n, 0);
  for (int pin : problem.rigid.pins) is_pin_[pin] = 1;
  index_free_dofs();
  length_scales_ = problem.body->dof_length_scales();
  constant_tangent_ = problem.body->traits().constant_tangent;
  for (const ObstacleInstance& o : problem.obstacles) has_pairs_ = has_pairs_ || o.master.has_value();
  turning_ = !constant_tangent_ && problem.body->traits().reference_stiffness && !has_pairs_;
  zeta_previous_.assign(problem.candidates.size(), 0.0);
}

void Equilibrium::index_free_dofs() {
  const int n = problem_.body->dof_count();
  free_index_.assign(n, 0);
  free_count_ = 0;
  for (const Constraint& c : problem_.constraints) free_index_[c.dof] = -1;
  for (const Constraint& c : extra_) free_index_[c.dof] = -1;
  if (!pins_free_)
    for (int pin : problem_.rigid.pins) free_index_[pin] = -1;
  for (int i = 0; i < n; ++i)
    if (free_index_[i] == 0) free_index_[i] = free_count_++;
  // Several bodies: each body's free rows follow one another (its dofs do), so its own tangent
  // is a diagonal block of the free block, factorized on its own (FreeBlockSolver::set_blocks).
  if (const Body& body = *problem_.body; body.part_count() > 0) {
    std::vector<int> starts;
    for (int b = 0; b <= body.part_count(); ++b) {
      const int end = body.dof_offset(b);
      starts.push_back(static_cast<int>(
          std::count_if(free_index_.begin(), free_index_.begin() + end, [](int f) { return f >= 0; })));
    }
    body_lu_.set_blocks(starts, params_.parallel);
    lu_.set_blocks(std::move(starts), params_.parallel);
  } else {
    body_lu_.set_parallel(params_.parallel);
    lu_.set_parallel(params_.parallel);
  }
}

void Equilibrium::set_step(LoadFactors factors, std::vector<double> zeta_previous) {
  factors_ = std::move(factors);
  zeta_previous_ = std::move(zeta_previous);
  new_load_ = true;
}

double Equilibrium::stiffness_scale(const Vector& q) const {
  Triplets t;
  TripletSink sink(t);
  Vector f = Vector::Zero(q.size());
  problem_.body->internal_force(q, f, &sink);
  Vector diagonal = Vector::Zero(q.size());
  for (const auto& e : t)
    if (e.row() == e.col()) diagonal[e.row()] += e.value();
  return diagonal.cwiseAbs().maxCoeff();
}

Vector Equilibrium::residual(const Vector& q, const EquilibriumState& paired, const Vector& p_given,
                             TangentSink* tangent, double* force_scale, bool body_tangent) const {
  Vector r;
  residual_into(q, paired, p_given, tangent, r, force_scale, body_tangent);
  return r;
}

void Equilibrium::residual_into(const Vector& q, const EquilibriumState& paired, const Vector& p_given,
                                TangentSink* tangent, Vector& r, double* force_scale, bool body_tangent) const {
  Vector law_p;  // a law's forces (given ones are read in place)
  if (penalty_) law_p = penalty_forces(q, paired, tangent);
  else if (held_) law_p = held_forces(q, paired, p_given, tangent);
  const Vector& p = penalty_ || held_ ? law_p : p_given;
  r.setZero(q.size());
  problem_.body->internal_force(q, r, body_tangent ? tangent : nullptr);
  // problem_.load(factors_), summed in its order into kept storage.
  Vector& external = external_work_;
  external.setZero(problem_.body->dof_count());
  for (size_t k = 0; k < problem_.loads.size() && k < factors_.size(); ++k) external += factors_[k] * problem_.loads[k];
  if (problem_.body->has_follower_loads()) {
    Triplets& follow = follow_work_;  // r = A - F(q): the follower load's derivative enters with a minus
    follow.clear();
    problem_.body->follower_load(q, factors_, external, body_tangent && tangent ? &follow : nullptr);
    for (const auto& e : follow) tangent->add(e.row(), e.col(), -e.value());
  }
  Vector& contact = contact_work_;
  contact.setZero(q.size());
  Triplets& pair_terms = pair_terms_work_;
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    const PairedPoint& pp = paired.points[i];
    const double p_eta = p[c.eta], p_xi = c.xi >= 0 ? p[c.xi] : 0.0;
    const Vec2 f = p_eta * pp.eta + p_xi * pp.xi;
    for (const auto& j : pp.point.jacobian) contact[j.dof] += j.dx.dot(f);
    if (!tangent) continue;
    // Without the body's tangent (a low-rank correction: no factorization pattern to keep), a
    // point that carries no force adds nothing.
    if (!body_tangent && p_eta == 0.0 && p_xi == 0.0) continue;
    // f = -p_eta n + p_xi rot90(n): df/dx = (-p_eta I + p_xi R) dn/dx. Emitted even when zero,
    // so that the tangent's pattern stays the same from one iterate to the next.
    Mat2 R;
    R << 0, -1, 1, 0;
    const Mat2 df_dx = (-p_eta * Mat2::Identity() + p_xi * R) * pp.projection.dnormal_dx;
    for (const auto& a : pp.point.jacobian)
      for (const auto& b : pp.point.jacobian) tangent->add(a.dof, b.dof, -a.dx.dot(df_dx * b.dx));
    // The pair's stiffness at the iterate's forces, both bodies (the penalty law's change of p
    // with the positions, the gradients of the gap and zeta, is in penalty_forces): the whole
    // consistent tangent, given forces or the law's. These terms scale with p (p / element size):
    // where a penalty law's iterates press a few points at 15-60 x the load they pass the body's
    // own stiffness and the tangent is indefinite; the penalty strategy then starts its law soft
    // (penalty.cpp) rather than leaving them out, which cost a linear rate at the answer.
    if (const auto& master = paired.masters[c.obstacle]) {
      pair_terms.clear();
      master->force_derivative(problem_.body->surface_point(q, c.site, c.side), c.site, p_eta, p_xi, pair_terms);
      for (const auto& e : pair_terms) tangent->add(e.row(), e.col(), -e.value());
    }
  }
  if (force_scale) {
    auto largest = [&](const Vector& v) { return (v.array() / length_scales_.array()).abs().maxCoeff(); };
    *force_scale = r.size() ? std::max({largest(r), largest(external), largest(contact)}) : 0.0;
  }
  r -= external + contact;
  if (pins_free_)
    for (int pin : problem_.rigid.pins) {
      r[pin] += penalty_->pin_spring * q[pin];
      if (tangent) tangent->add(pin, pin, penalty_->pin_spring);
    }
}

Vector Equilibrium::residual(const Vector& q, const Vector& p, Triplets* tangent) const {
  if (!tangent) return residual(q, evaluate(q), p, nullptr);
  TripletSink sink(*tangent);
  return residual(q, evaluate(q), p, &sink);
}

double Equilibrium::relative_residual(const Vector& q, const Vector& p) const {
  double force_scale = 0.0;
  const Vector r = residual(q, evaluate(q), p, nullptr, &force_scale);
  return force_scale > 0 ? scaled_free_max(r) / force_scale : 0.0;
}

std::optional<EquilibriumState> Equilibrium::at_rest(const Vector& q, const Vector& p) const {
  if (penalty_ || held_ || problem_.rigid.count() || !extra_.empty()) return std::nullopt;
  for (const Constraint& c : problem_.constraints)
    if (q[c.dof] != (c.load_case < static_cast<int>(factors_.size()) ? c.at(factors_[c.load_case]) : 0.0))
      return std::nullopt;
  EquilibriumState state = evaluate(q);
  double force_scale = 0.0;
  const Vector r = residual(q, state, p, nullptr, &force_scale);
  const double r_max = scaled_free_max(r);
  if (!(r_max <= params_.residual_tolerance * force_scale)) return std::nullopt;
  state.relative_residual = force_scale > 0 ? r_max / force_scale : 0.0;
  finish(state, p);
  if (!state.converged) return std::nullopt;
  return state;
}

Vector Equilibrium::applied_forces(const EquilibriumState& paired, const Vector& p) const {
  Vector f = problem_.load(factors_);
  problem_.body->follower_load(paired.q, factors_, f, nullptr);
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    const PairedPoint& pp = paired.points[i];
    const Vec2 force = p[c.eta] * pp.eta + (c.xi >= 0 ? p[c.xi] : 0.0) * pp.xi;
    for (const auto& j : pp.point.jacobian) f[j.dof] += j.dx.dot(force);
  }
  return f;
}

Vector Equilibrium::reactions(const EquilibriumState& state, const Vector& p) const {
  Vector r = residual(state.q, state, p, nullptr);
  for (int i = 0; i < r.size(); ++i)
    if (free_index_[i] >= 0) r[i] = 0.0;
  return r;  // what the supports exert on the body: A - lambda F - T p at the fixed dofs
}

std::vector<double> Equilibrium::zetas(const EquilibriumState& state) const {
  std::vector<double> z(state.points.size());
  for (size_t i = 0; i < z.size(); ++i) z[i] = state.points[i].projection.zeta;
  return z;
}

}  // namespace grip
