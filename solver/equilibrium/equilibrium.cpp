#include "solver/equilibrium/equilibrium.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <tuple>

#include "solver/model/body_set.hpp"
#include "solver/equilibrium/rigid_equilibrium.hpp"

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
  if (const auto* set = dynamic_cast<const BodySet*>(problem_.body.get())) {
    std::vector<int> starts;
    for (int b = 0; b <= set->count(); ++b) {
      const int end = set->dof_offset(b);
      starts.push_back(static_cast<int>(
          std::count_if(free_index_.begin(), free_index_.begin() + end, [](int f) { return f >= 0; })));
    }
    body_lu_.set_blocks(starts, params_.parallel);
    lu_.set_blocks(std::move(starts), params_.parallel);
  }
}

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

void Equilibrium::set_step(LoadFactors factors, std::vector<double> zeta_previous) {
  factors_ = std::move(factors);
  zeta_previous_ = std::move(zeta_previous);
}

void Equilibrium::pair(const Vector& q, EquilibriumState& state) const {
  const auto& cands = problem_.candidates;
  state.points.resize(cands.size());
  state.s = Vector::Zero(problem_.component_count);
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
    pp.point = problem_.body->surface_point(q, c.site, c.side);
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
      state.s[c.xi] = obstacle.master ? pp.projection.zeta - zeta_previous_[i]
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

Vector Equilibrium::penalty_forces(const Vector& q, const EquilibriumState& paired, Triplets* tangent,
                                   const Vector* increment) const {
  const PenaltyLaw& law = *penalty_;
  Vector p = Vector::Zero(problem_.component_count);
  std::vector<std::pair<int, double>> gap, zeta;  // d(gap)/dq, d(zeta)/dq: (dof, derivative)
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    const PairedPoint& pp = paired.points[i];
    if (!paired.enabled[c.eta] || paired.s[c.eta] <= 0) {
      if (tangent)  // zeros keep the tangent's pattern fixed
        for (const auto& a : pp.point.jacobian)
          for (const auto& b : pp.point.jacobian) tangent->emplace_back(a.dof, b.dof, 0.0);
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
    // The gradients of the gap and of zeta: against a rigid obstacle n . J and zeta_rate xi . J
    // (its closest point); against a deformable master also the normal's turn and the mortar
    // weights' shift with both bodies (DeformedMaster::gradients): one consistent tangent.
    gap.clear();
    zeta.clear();
    const auto& master = paired.masters[c.obstacle];
    if (master) {
      master->gradients(problem_.body->surface_point(q, c.site, c.side), c.site, gap, zeta);
    } else {
      for (const auto& j : pp.point.jacobian) {
        gap.emplace_back(j.dof, -pp.eta.dot(j.dx));
        if (frictional) zeta.emplace_back(j.dof, pp.projection.zeta_rate * pp.xi.dot(j.dx));
      }
    }
    // dp_eta = k_n d(gap), dp_xi = stick d(zeta) + slip dp_eta, as (dof, dp_eta, dp_xi).
    std::vector<std::tuple<int, double, double>> dp;
    for (const auto& [dof, g] : gap) dp.emplace_back(dof, law.normal * g, slip * law.normal * g);
    if (frictional)
      for (const auto& [dof, z] : zeta) dp.emplace_back(dof, 0.0, stick * z);
    if (increment)  // the law's linear change over the increment, from the increment itself
      for (const auto& [dof, dpn, dpt] : dp) {
        p[c.eta] += dpn * (*increment)[dof];
        if (frictional) p[c.xi] += dpt * (*increment)[dof];
      }
    if (!tangent) continue;
    // d(T p)/dq from p's dependence on q; the residual carries it with a minus sign.
    for (const auto& a : pp.point.jacobian) {
      const double on_eta = a.dx.dot(pp.eta), on_xi = a.dx.dot(pp.xi);
      for (const auto& [dof, dpn, dpt] : dp) {
        tangent->emplace_back(a.dof, dof, -(on_eta * dpn + on_xi * dpt));
        if (master) tangent->emplace_back(dof, a.dof, 0.0);  // a tangent's pattern is symmetric
      }
    }
  }
  return p;
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

double Equilibrium::stiffness_scale(const Vector& q) const {
  Triplets t;
  Vector f = Vector::Zero(q.size());
  problem_.body->internal_force(q, f, &t);
  Vector diagonal = Vector::Zero(q.size());
  for (const auto& e : t)
    if (e.row() == e.col()) diagonal[e.row()] += e.value();
  return diagonal.cwiseAbs().maxCoeff();
}

Vector Equilibrium::residual(const Vector& q, const EquilibriumState& paired, const Vector& p_given,
                             Triplets* tangent, double* force_scale, bool body_tangent) const {
  const Vector p = penalty_ ? penalty_forces(q, paired, tangent) : p_given;
  Vector r = Vector::Zero(q.size());
  problem_.body->internal_force(q, r, body_tangent ? tangent : nullptr);
  const Vector external = problem_.load(factors_);
  Vector contact = Vector::Zero(q.size());
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
      for (const auto& b : pp.point.jacobian)
        tangent->emplace_back(a.dof, b.dof, -a.dx.dot(df_dx * b.dx));
    // The pair's stiffness at the iterate's forces, both bodies (the penalty law's change of p
    // with the positions, the gradients of the gap and zeta, is in penalty_forces): the whole
    // consistent tangent, given forces or the law's. These terms scale with p (p / element size):
    // where a penalty law's iterates press a few points at 15-60 x the load they pass the body's
    // own stiffness and the tangent is indefinite; the penalty strategy then starts its law soft
    // (penalty.cpp) rather than leaving them out, which cost a linear rate at the answer.
    if (const auto& master = paired.masters[c.obstacle]) {
      const size_t first = tangent->size();
      master->force_derivative(problem_.body->surface_point(q, c.site, c.side), c.site, p_eta, p_xi, *tangent);
      for (size_t k = first; k < tangent->size(); ++k)
        (*tangent)[k] = {(*tangent)[k].row(), (*tangent)[k].col(), -(*tangent)[k].value()};
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
      if (tangent) tangent->emplace_back(pin, pin, penalty_->pin_spring);
    }
  return r;
}

Vector Equilibrium::residual(const Vector& q, const Vector& p, Triplets* tangent) const {
  return residual(q, evaluate(q), p, tangent);
}


// The largest residual over the free dofs in force units: a rotation's (moment) residual is
// divided by its dof's length scale, so that the stopping test does not depend on the unit of
// length (the iteration counts of a scene stay the same when its lengths are rescaled).
double Equilibrium::scaled_free_max(const Vector& r) const {
  double largest = 0.0;
  for (int i = 0; i < r.size(); ++i)
    if (free_index_[i] >= 0) largest = std::max(largest, std::abs(r[i] / length_scales_[i]));
  return largest;
}

// The Euclidean norm of a displacement change over the free dofs in length units (rotations
// times their dof's length scale): the line search's measure, independent of the length unit.
double Equilibrium::free_length_norm(const Vector& dq) const {
  double norm = 0.0;
  for (int i = 0; i < dq.size(); ++i)
    if (free_index_[i] >= 0) norm += (dq[i] * length_scales_[i]) * (dq[i] * length_scales_[i]);
  return std::sqrt(norm);
}

namespace {

// |K|_inf over the free block in force / length units (moments over the length scale of
// their dof, rotations times it), from the tangent's triplets.
double free_row_sum_norm(const Triplets& triplets, const std::vector<int>& free_index, int free_count,
                         const Vector& length_scales) {
  Vector rows = Vector::Zero(free_count);
  for (const auto& t : triplets)
    if (free_index[t.row()] >= 0 && free_index[t.col()] >= 0)
      rows[free_index[t.row()]] += std::abs(t.value()) / (length_scales[t.row()] * length_scales[t.col()]);
  return free_count ? rows.maxCoeff() : 0.0;
}

// y solving (I + B) y = c by GMRES (Arnoldi with modified Gram-Schmidt, Givens rotations, no
// restart), `apply` giving B v: stops where the residual is below `tolerance` |c|, or after
// `most` iterations (then the least-residual iterate of that space).
Vector gmres(const std::function<Vector(const Vector&)>& apply, const Vector& c, double tolerance, int most) {
  const int m = static_cast<int>(c.size());
  const double c_norm = c.norm();
  if (c_norm == 0.0 || m == 0) return Vector::Zero(m);
  most = std::min(most, m);
  Matrix V(m, most + 1), H = Matrix::Zero(most + 1, most);
  Vector cs(most), sn(most), g = Vector::Zero(most + 1);
  V.col(0) = c / c_norm;
  g[0] = c_norm;
  int k = 0;
  while (k < most) {
    Vector w = V.col(k) + apply(V.col(k));
    for (int i = 0; i <= k; ++i) {
      H(i, k) = V.col(i).dot(w);
      w -= H(i, k) * V.col(i);
    }
    const double next = w.norm();  // zero: the space is invariant, the iterate exact
    H(k + 1, k) = next;
    if (next > 0.0) V.col(k + 1) = w / next;
    for (int i = 0; i < k; ++i) {
      const double a = H(i, k), b = H(i + 1, k);
      H(i, k) = cs[i] * a + sn[i] * b;
      H(i + 1, k) = -sn[i] * a + cs[i] * b;
    }
    const double r = std::hypot(H(k, k), H(k + 1, k));
    cs[k] = r > 0.0 ? H(k, k) / r : 1.0;
    sn[k] = r > 0.0 ? H(k + 1, k) / r : 0.0;
    H(k, k) = r;
    H(k + 1, k) = 0.0;
    g[k + 1] = -sn[k] * g[k];
    g[k] *= cs[k];
    ++k;
    if (std::abs(g[k]) <= tolerance * c_norm || next == 0.0) break;
  }
  const Vector z = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
  return V.leftCols(k) * z;
}

}  // namespace

// Newton's step for the constant body tangent K plus the pair's stiffness A (the `contact`
// triplets, on the m free dofs P where A is not zero: the pressing points' and their master
// segments'): (K + P A P^T) dq = b with dq = z + K^-1 P y, z = K^-1 b, and y solving
// (I + A G) y = -A P^T z, G = P^T K^-1 P, by GMRES with one body solve per product G v, or
// with the compliance's G where it has these rows (A is
// small beside K near an answer: 5-6 iterations to 1e-15 at 1501 slave points; the same forces
// to every printed digit as the Woodbury form). Nothing of size m^2: a dense G and the LU of
// I + G A (the Woodbury form) cost 5100^2 doubles and two m^3 products per Newton iteration at
// 1501 slave points (250 s, 1.2 GB).
Vector Equilibrium::low_rank_step(const Triplets& contact, const Vector& rhs) const {
  const Vector z = body_lu_.solve(rhs);
  std::vector<int> slot(free_count_, -1);  // free index -> row of A
  std::vector<int> rows;
  Triplets a_local;
  for (const auto& t : contact) {
    const int i = free_index_[t.row()], j = free_index_[t.col()];
    if (i < 0 || j < 0 || t.value() == 0.0) continue;
    for (int f : {i, j})
      if (slot[f] < 0) {
        slot[f] = static_cast<int>(rows.size());
        rows.push_back(f);
      }
    a_local.emplace_back(slot[i], slot[j], t.value());
  }
  const int m = static_cast<int>(rows.size());
  if (m == 0) return z;
  Eigen::SparseMatrix<double> A(m, m);
  A.setFromTriplets(a_local.begin(), a_local.end());
  Vector zs(m);
  for (int k = 0; k < m; ++k) zs[k] = z[rows[k]];
  Vector spread = Vector::Zero(free_count_);
  auto scatter = [&](const Vector& v) {  // P v on the free dofs
    for (int k = 0; k < m; ++k) spread[rows[k]] = v[k];
    return spread;
  };
  // G v from the compliance's G where it covers every row (the same constant K; its dense form
  // is formed for small contact zones anyway): m^2 a product instead of a body solve (the
  // refined two cylinders: 2.5e9 -> 3.5e9 instructions with the solves).
  const bool from_g = g_valid_ && std::all_of(rows.begin(), rows.end(), [&](int f) {
    return f < static_cast<int>(surface_row_.size()) && surface_row_[f] >= 0;
  });
  Matrix g;
  if (from_g) {
    g.resize(m, m);
    for (int b = 0; b < m; ++b)
      for (int a = 0; a < m; ++a) g(a, b) = g_(surface_row_[rows[a]], surface_row_[rows[b]]);
  }
  const Vector y = gmres(
      [&](const Vector& v) {
        if (from_g) return Vector(A * (g * v));
        const Vector x = body_lu_.solve(scatter(v));
        Vector gv(m);
        for (int k = 0; k < m; ++k) gv[k] = x[rows[k]];
        return Vector(A * gv);
      },
      Vector(-(A * zs)), kLowRankTolerance, kLowRankIterations);
  return z + body_lu_.solve(scatter(y));
}

EquilibriumState Equilibrium::solve(const Vector& q_guess, const Vector& p) {
  ++counters_.solves;
  return newton(q_guess, p);
}

void Equilibrium::continue_solve(EquilibriumState& state, const Vector& p) {
  const int before = state.newton_iterations;
  state = newton(state.q, p);
  state.newton_iterations += before;
}

EquilibriumState Equilibrium::newton(const Vector& q_guess, const Vector& p) {
  EquilibriumState state;
  state.q = q_guess;
  for (const Constraint& c : problem_.constraints)
    state.q[c.dof] = c.load_case < static_cast<int>(factors_.size()) ? factors_[c.load_case] * c.value : 0.0;
  for (const Constraint& c : extra_) state.q[c.dof] = c.value;
  const RigidModes& rigid = problem_.rigid;
  if (!pins_free_)
    for (int k = 0; k < rigid.count(); ++k) state.q[rigid.pins[k]] = rigid.scale * p[rigid.first + k];
  const double body_length = problem_.body->characteristic_length();
  constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
  // The penalty law adds stiffness that changes with the contact state: no reuse then.
  const bool reuse = constant_tangent_ && !penalty_;
  // A pair of bodies adds its stiffness, which moves with the pairing, on a few surface dofs:
  // kept as a low-rank correction of the constant body tangent (low_rank_step).
  const bool low_rank = reuse && has_pairs_;
  Triplets triplets;
  double last_step = 0.0;
  std::vector<signed char> signs;  // the penalty law's trial signs at the last iterate
  for (int it = 1; it <= params_.max_iterations + 1; ++it) {
    pair(state.q, state);
    triplets.clear();
    // A penalty point whose trial tangential force changed sign since the last iterate has
    // crossed the cone's interior, its stick band (width 2 mu |p_eta| / k_t, a few 1e-6 of the
    // body when k_t is 1e3 x its stiffness): Newton from either slip branch predicts the other
    // one (no tangential stiffness there), so it cycles between them. The step is taken on the
    // stick branch instead (trial force and spring), which puts such a point in its band; the
    // stopping tests always use the law itself.
    std::vector<char> branch;
    stick_branch_.clear();
    if (penalty_) {
      std::vector<signed char> now = trial_signs(state);
      for (size_t i = 0; i < signs.size(); ++i)
        if (now[i] * signs[i] < 0) {
          branch.resize(now.size(), 0);
          branch[i] = 1;
        }
      signs = std::move(now);
    }
    double force_scale = 0.0;
    // low_rank: the contact terms only (the body's are in its kept factorization).
    const Vector r = residual(state.q, state, p, reuse && !low_rank ? nullptr : &triplets, &force_scale, !low_rank);
    const double r_max = scaled_free_max(r);
    state.relative_residual = force_scale > 0 ? r_max / force_scale : 0.0;
    if (!std::isfinite(r_max)) {
      state.reason = "Newton produced a non-finite residual";
      state.failure = FailureKind::newton_diverged;
      return state;
    }
    const bool residual_met = r_max <= params_.residual_tolerance * force_scale;
    // The round-off floor only matters where the residual test fails (|K| costs a pass over
    // the triplets: 6 % of the beam's time when taken at every iterate).
    bool at_floor = false;
    if (!residual_met && it > 1) {
      double k_norm = body_tangent_norm_;
      if (!reuse) k_norm = free_row_sum_norm(triplets, free_index_, free_count_, length_scales_);
      const double q_size = (state.q.array() * length_scales_.array()).abs().maxCoeff();
      at_floor = r_max <= params_.floor_factor * kEpsilon * (k_norm * q_size + force_scale);
    }
    if (residual_met || at_floor) {
      state.at_floor = at_floor && !residual_met;
      state.noise = state.at_floor ? last_step : 0.0;
      return penalty_ ? finish_penalty(state) : finish(state, p);
    }
    if (it > params_.max_iterations) break;
    Vector r_step;
    if (!branch.empty()) {
      stick_branch_ = std::move(branch);
      triplets.clear();
      r_step = residual(state.q, state, p, reuse && !low_rank ? nullptr : &triplets, nullptr, !low_rank);
    }
    const Vector& r_newton = stick_branch_.empty() ? r : r_step;
    if (reuse) {
      if (!factorize_body_tangent(state.q)) {
        state.reason = "singular stiffness: the supports do not hold the body";
        state.failure = FailureKind::newton_diverged;
        return state;
      }
    } else {
      ++counters_.factorizations;
      if (!lu_.factorize(triplets, free_index_, free_count_, 1e-4)) {
        state.reason = "singular tangent stiffness in Newton iteration " + std::to_string(it);
        state.failure = FailureKind::newton_diverged;
        return state;
      }
    }
    Vector r_free(free_count_);
    for (int i = 0; i < r.size(); ++i)
      if (free_index_[i] >= 0) r_free[free_index_[i]] = r_newton[i];
    const Vector dq_free = low_rank ? low_rank_step(triplets, Vector(-r_free))
                           : reuse  ? body_lu_.solve(Vector(-r_free))
                                    : lu_.solve(Vector(-r_free));
    state.newton_iterations = it;
    ++counters_.newton_iterations;
    Vector dq = Vector::Zero(state.q.size());
    for (int i = 0; i < state.q.size(); ++i)
      if (free_index_[i] >= 0) dq[i] = dq_free[free_index_[i]];
    const double step = (dq.array() * length_scales_.array()).abs().maxCoeff();
    if (!std::isfinite(step)) {
      state.reason = "Newton produced a non-finite displacement";
      state.failure = FailureKind::newton_diverged;
      return state;
    }
    if (step > params_.divergence_lengths * body_length) {
      state.reason = "Newton diverged (correction of " + number_text(step) + " length units)";
      state.failure = FailureKind::newton_diverged;
      return state;
    }
    last_step = step;
    if (step <= params_.displacement_tolerance && stick_branch_.empty()) {
      state.q += dq;
      pair(state.q, state);
      return penalty_ ? finish_penalty(state) : finish(state, p);
    }
    state.q += line_search(state.q, dq, p, reuse ? body_lu_ : lu_) * dq;
    stick_branch_.clear();
  }
  pair(state.q, state);
  state.failure = FailureKind::newton_diverged;
  state.reason = "Newton did not converge in " + std::to_string(params_.max_iterations) +
                 " iterations (free residual " + number_text(state.relative_residual) +
                 " of the force scale)";
  return state;
}

// The law evaluated at a position carries that position's rounding, eps |x| times k (k up to
// 1e3 x the body's stiffness: ~4e-6 N a point at |x| ~ 20), a floor that Newton's residual
// cannot go below, and the load then balances the contact forces only to ~1e-6 of it. The law
// linearized at the converged iterate over one more correction dq carries only the rounding of
// dq: the same linear system that gives dq balances F + T p to the solver's precision. p then
// differs from the law at q + dq by its rounding there, and by the law's second-order change over
// dq, a correction already below Newton's tests.
EquilibriumState& Equilibrium::finish_penalty(EquilibriumState& state) {
  Triplets tangent;
  const Vector r = residual(state.q, state, state.p, &tangent);
  ++counters_.factorizations;
  if (!lu_.factorize(tangent, free_index_, free_count_, 1e-4)) return finish(state, penalty_forces(state.q, state, nullptr));
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

EquilibriumState& Equilibrium::finish(EquilibriumState& state, const Vector& p) const {
  state.reason = problem_.body->inadmissible(state.q);
  state.converged = state.reason.empty();
  state.failure = state.converged ? FailureKind::none : FailureKind::invalid_state;
  state.p = p;
  const RigidModes& rigid = problem_.rigid;
  if (pins_free_)  // the amplitudes were solved for: they are the pins' displacements
    for (int k = 0; k < rigid.count(); ++k) state.p[rigid.first + k] = state.q[rigid.pins[k]] / rigid.scale;
  if (rigid.count()) {
    const Vector applied = applied_forces(state, state.p);
    const Matrix modes = rigid_modes_at(problem_, state.q);
    for (int k = 0; k < rigid.count(); ++k) state.s[rigid.first + k] = rigid.scale * modes.col(k).dot(applied);
  }
  return state;
}

Vector Equilibrium::applied_forces(const EquilibriumState& paired, const Vector& p) const {
  Vector f = problem_.load(factors_);
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    const PairedPoint& pp = paired.points[i];
    const Vec2 force = p[c.eta] * pp.eta + (c.xi >= 0 ? p[c.xi] : 0.0) * pp.xi;
    for (const auto& j : pp.point.jacobian) f[j.dof] += j.dx.dot(force);
  }
  return f;
}

double Equilibrium::line_search(const Vector& q, const Vector& dq, const Vector& p,
                                const FreeBlockSolver& solver) const {
  // Deuflhard's natural monotonicity test: the simplified correction K^-1 R(q + a dq), with
  // the factorization already at hand, must be shorter than (1 - a/4) |dq|. It measures the
  // distance to the solution in the tangent's metric, so a large rigid rotation with small
  // strains is a full step, where the residual norm would grow and refuse it.
  const double dq_norm = free_length_norm(dq);
  double a = problem_.body->newton_step_fraction(q, dq);
  for (int k = 0; k < params_.max_backtracks; ++k, a *= 0.5) {
    const Vector qa = q + a * dq;
    EquilibriumState paired;
    pair(qa, paired);
    const Vector r = residual(qa, paired, p, nullptr);
    Vector r_free(free_count_);
    for (int i = 0; i < r.size(); ++i)
      if (free_index_[i] >= 0) r_free[free_index_[i]] = r[i];
    const Vector simplified = solver.solve(r_free);
    Vector full = Vector::Zero(q.size());
    for (int i = 0; i < q.size(); ++i)
      if (free_index_[i] >= 0) full[i] = simplified[free_index_[i]];
    const double norm = free_length_norm(full);
    if (std::isfinite(norm) && norm <= (1.0 - 0.25 * a) * dq_norm) return a;
  }
  return a;
}

Matrix Compliance::sub(const std::vector<int>& components) const {
  Matrix B(components.size(), components.size());
  for (size_t a = 0; a < components.size(); ++a)
    for (size_t b = 0; b < components.size(); ++b) B(a, b) = (*this)(components[a], components[b]);
  return B;
}

bool Equilibrium::factorize_body_tangent(const Vector& q) {
  if (constant_tangent_ && body_factorized_) return body_lu_.ok();
  Triplets triplets;
  Vector force = Vector::Zero(q.size());
  problem_.body->internal_force(q, force, &triplets);
  ++counters_.factorizations;
  body_factorized_ = true;
  // Read by Newton only for a constant tangent (a changing one has its own triplets).
  if (constant_tangent_) body_tangent_norm_ = free_row_sum_norm(triplets, free_index_, free_count_, length_scales_);
  return body_lu_.factorize(triplets, free_index_, free_count_);
}

void Equilibrium::extend_surface_compliance(const std::vector<int>& added) {
  const int m0 = static_cast<int>(surface_free_.size());
  for (int f : added) {
    surface_row_[f] = static_cast<int>(surface_free_.size());
    surface_free_.push_back(f);
  }
  const int m = static_cast<int>(surface_free_.size());
  counters_.compliance_columns += m - m0;
  if (m0 == 0 && body_lu_.inverse_block(surface_free_, g_)) return;  // a new G: sparse solves
  g_.conservativeResize(m, m);
  // Unit right-hand sides in blocks: the work storage stays (free dofs) x kBlock.
  constexpr int kBlock = 64;
  Matrix rhs;
  for (int start = m0; start < m; start += kBlock) {
    const int cols = std::min(kBlock, m - start);
    rhs.setZero(free_count_, cols);
    for (int c = 0; c < cols; ++c) rhs(surface_free_[start + c], c) = 1.0;
    const Matrix x = body_lu_.solve(rhs);
    for (int c = 0; c < cols; ++c)
      for (int r = 0; r < m; ++r) {
        g_(r, start + c) = x(surface_free_[r], c);
        if (r < m0) g_(start + c, r) = g_(r, start + c);
      }
  }
  const Matrix added_block = g_.bottomRightCorner(m - m0, m - m0);
  g_.bottomRightCorner(m - m0, m - m0) = 0.5 * (added_block + added_block.transpose());
}

namespace {

bool same_sparse(const Eigen::SparseMatrix<double>& a, const Eigen::SparseMatrix<double>& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && a.nonZeros() == b.nonZeros() &&
         std::equal(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1, b.outerIndexPtr()) &&
         std::equal(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros(), b.innerIndexPtr()) &&
         std::equal(a.valuePtr(), a.valuePtr() + a.nonZeros(), b.valuePtr());
}

// T on the given components (columns at `position`), one row per free dof as `row` numbers it.
template <class Row>
Eigen::SparseMatrix<double> contact_map(const Problem& problem, const EquilibriumState& state,
                                        const std::vector<int>& position, const std::vector<int>& free_index,
                                        int rows, int cols, Row row) {
  Triplets ts;
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    const PairedPoint& pp = state.points[i];
    const int eta = position[c.eta], xi = c.xi >= 0 ? position[c.xi] : -1;
    if (eta < 0 && xi < 0) continue;
    for (const auto& j : pp.point.jacobian) {
      const int f = free_index[j.dof];
      if (f < 0) continue;
      if (eta >= 0) ts.emplace_back(row(f), eta, j.dx.dot(pp.eta));
      if (xi >= 0) ts.emplace_back(row(f), xi, j.dx.dot(pp.xi));
    }
  }
  Eigen::SparseMatrix<double> t(rows, cols);
  t.setFromTriplets(ts.begin(), ts.end());
  return t;
}

}  // namespace

const Compliance& Equilibrium::compliance(const EquilibriumState& state, const std::vector<int>& components,
                                          int sparse_from) {
  const int k = static_cast<int>(components.size());
  bool tangent_ok = false;
  if (k > 0) {
    tangent_ok = compliance_tangent(state);
    // The border of a body held by contact stays dense (its block is indefinite).
    if (tangent_ok && k >= sparse_from && problem_.rigid.count() == 0 && body_lu_.symmetric())
      return sparse_compliance(state, components);
  }
  std::vector<int> position(problem_.component_count, -1);
  for (int a = 0; a < k; ++a) position[components[a]] = a;
  const bool same_components = position == c_.position;
  c_.position = std::move(position);
  auto empty = [&]() -> const Compliance& {
    c_.block.setZero(k, k);
    c_.factor.reset();
    t_surface_.resize(0, k);
    c_version_ = -1;
    return c_;
  };
  if (components.empty() || !tangent_ok) return empty();
  // The surface dofs of these components that G does not cover yet join it.
  std::vector<int> added;
  std::vector<char> adding(free_count_, 0);
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    if (c_.position[c.eta] < 0 && (c.xi < 0 || c_.position[c.xi] < 0)) continue;
    for (const auto& j : state.points[i].point.jacobian) {
      const int f = free_index_[j.dof];
      if (f >= 0 && surface_row_[f] < 0 && !adding[f]) {
        adding[f] = 1;
        added.push_back(f);
      }
    }
  }
  if (!added.empty()) {
    extend_surface_compliance(added);
    ++g_version_;
  }
  Eigen::SparseMatrix<double> t_surface = contact_map(problem_, state, c_.position, free_index_, g_.rows(), k,
                                                      [&](int f) { return surface_row_[f]; });
  // The same G, components and T_s (a constant tangent, a pairing that did not move): the same
  // C, and the inner solver keeps its factorizations.
  if (same_components && c_version_ == g_version_ && same_sparse(t_surface, t_surface_)) return c_;
  t_surface_ = std::move(t_surface);
  c_version_ = g_version_;
  c_.factor.reset();
  // C = T_s^T G T_s column by column: G t_b from the few non-zeros of t_b (a point's dofs),
  // then its products with the columns a >= b of T_s, mirrored (C symmetric by construction).
  // Eigen's blocked dense-sparse products cost ~2x more here (allocations, zeroed temporaries).
  using Column = Eigen::SparseMatrix<double>::InnerIterator;
  c_.block.resize(k, k);
  Vector gt(g_.rows());
  for (int b = 0; b < k; ++b) {
    gt.setZero();
    for (Column t(t_surface_, b); t; ++t) gt.noalias() += t.value() * g_.col(t.row());
    for (int a = b; a < k; ++a) {
      double sum = 0.0;
      for (Column t(t_surface_, a); t; ++t) sum += t.value() * gt[t.row()];
      c_.block(a, b) = c_.block(b, a) = sum;
    }
  }
  add_rigid_border(state);
  return c_;
}

bool Equilibrium::compliance_tangent(const EquilibriumState& state) {
  if (!constant_tangent_ && !compliance_reuse_) g_valid_ = false;
  compliance_reused_ = g_valid_ && !constant_tangent_;
  if (g_valid_) return body_lu_.ok();
  // A new G: from the tangent at this state.
  surface_free_.clear();
  surface_row_.assign(free_count_, -1);
  g_.resize(0, 0);
  if (!factorize_body_tangent(state.q)) return false;
  ++counters_.compliance_forms;
  ++g_version_;
  ++tangent_version_;
  g_valid_ = true;
  return true;
}

const Compliance& Equilibrium::sparse_compliance(const EquilibriumState& state,
                                                 const std::vector<int>& components) {
  const int k = static_cast<int>(components.size());
  std::vector<int> position(problem_.component_count, -1);
  for (int a = 0; a < k; ++a) position[components[a]] = a;
  const bool same_components = position == sparse_.position;
  sparse_.position = std::move(position);
  Eigen::SparseMatrix<double> t =
      contact_map(problem_, state, sparse_.position, free_index_, free_count_, k, [](int f) { return f; });
  // The same tangent, components and T (a constant tangent, a pairing that did not move): the
  // same C, and the inner solver keeps its factorizations.
  if (same_components && sparse_.body && sparse_version_ == tangent_version_ && same_sparse(t, sparse_.t))
    return sparse_;
  sparse_.t = std::move(t);
  sparse_.normal_of.assign(k, -1);
  for (const Candidate& c : problem_.candidates)
    if (c.xi >= 0 && sparse_.position[c.xi] >= 0) sparse_.normal_of[sparse_.position[c.xi]] = sparse_.position[c.eta];
  sparse_.body = &body_lu_;
  sparse_.saddle.reset();
  sparse_version_ = tangent_version_;
  sparse_.diagonal_entries = body_lu_.quadratic_forms(sparse_.t);
  return sparse_;
}

Vector Compliance::apply(const Vector& z) const {
  if (!sparse()) return block * z;
  const Vector force = t * z;
  return t.transpose() * body->solve(force);
}

// The border G = T^T R of the compliance (docs/algorithm.md#bodies-held-only-by-contact), times the
// amplitudes' scale: the rigid motion moves every contact point with it, and the amplitudes' s, the
// whole body's equilibrium, changes with p by G^T. R at the state (rigid_modes_at): for a deformed
// body free to rotate with finite kinematics, about its current shape, where K R = 0 holds only up
// to terms in its stresses (K R is the load's own turn); the model is then approximate there and
// the real solves decide, as for any changing tangent.
void Equilibrium::add_rigid_border(const EquilibriumState& state) {
  const RigidModes& rigid = problem_.rigid;
  c_.bordered = false;
  if (rigid.count() == 0) return;
  const Matrix modes = rigid_modes_at(problem_, state.q);
  for (int k = 0; k < rigid.count(); ++k) {
    const int col = c_.position[rigid.first + k];
    if (col < 0) continue;
    c_.bordered = true;
    for (size_t i = 0; i < problem_.candidates.size(); ++i) {
      const Candidate& c = problem_.candidates[i];
      const PairedPoint& pp = state.points[i];
      const int eta = c_.position[c.eta], xi = c.xi >= 0 ? c_.position[c.xi] : -1;
      double g_eta = 0.0, g_xi = 0.0;
      for (const auto& j : pp.point.jacobian) {
        g_eta += j.dx.dot(pp.eta) * modes(j.dof, k);
        g_xi += j.dx.dot(pp.xi) * modes(j.dof, k);
      }
      if (eta >= 0) c_.block(eta, col) = c_.block(col, eta) = rigid.scale * g_eta;
      if (xi >= 0) c_.block(xi, col) = c_.block(col, xi) = rigid.scale * g_xi;
    }
  }
}

Vector Equilibrium::predicted_change(const Compliance& C, const Vector& dp) const {
  Vector du = Vector::Zero(free_index_.size());
  if (C.sparse()) {  // T on the free dofs; no rigid amplitudes
    Vector dp_block = Vector::Zero(C.size());
    for (size_t j = 0; j < C.position.size(); ++j)
      if (C.position[j] >= 0) dp_block[C.position[j]] = dp[j];
    const Vector du_free = C.body->solve(Vector(C.t * dp_block));
    for (size_t i = 0; i < free_index_.size(); ++i)
      if (free_index_[i] >= 0) du[i] = du_free[free_index_[i]];
    return du;
  }
  if (C.block.rows() == 0 || t_surface_.cols() != C.block.rows() || !body_lu_.ok()) return du;
  Vector dp_block = Vector::Zero(C.block.rows());
  for (size_t j = 0; j < C.position.size(); ++j)
    if (C.position[j] >= 0) dp_block[C.position[j]] = dp[j];
  const Vector force_surface = t_surface_ * dp_block;
  Vector force = Vector::Zero(free_count_);
  for (size_t r = 0; r < surface_free_.size(); ++r) force[surface_free_[r]] = force_surface[r];
  const Vector du_free = body_lu_.solve(force);
  for (size_t i = 0; i < free_index_.size(); ++i)
    if (free_index_[i] >= 0) du[i] = du_free[free_index_[i]];
  const RigidModes& rigid = problem_.rigid;
  for (int k = 0; k < rigid.count(); ++k) du += rigid.scale * dp[rigid.first + k] * rigid.modes.col(k);
  return du;
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
