// Newton's method for the equilibrium at given contact forces (or the penalty law's): the
// iteration, its stopping tests, the line search and the low-rank step of a constant tangent.
#include "solver/equilibrium/equilibrium.hpp"
#include "solver/equilibrium/newton_probe.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "solver/model/number_text.hpp"
#include "solver/problem/rigid_modes.hpp"

namespace grip {

NewtonIterationProbe newton_iteration_probe = nullptr;

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

// Chords (chord_converges): each correction at most this fraction of the one before, so that
// the old tangent still contracts and what remains after the last is at most that last one
// (a geometric series); begun only from a first correction within this many times the
// correction test, and at most this many corrections (each a residual and a solve).
constexpr double kChordContraction = 0.5;
constexpr double kChordStart = 10.0;
constexpr int kChordCorrections = 4;

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
  // A new load's first solve starts from the multipliers of the last converged load, off by the
  // whole increment's change: two moves there, one in later solves. One move a solve took the
  // exactly incompressible blocks and O-ring from 45-135 real solves (each increment solved
  // again after every move) to 20-60; more moves a solve, or moves to convergence, sent Newton
  // after each move of a loosely solved state into long runs and cuts (16 x 16 block: 97-184
  // real solves) (docs/algorithm.md#exact-incompressibility).
  const bool new_load = new_load_;
  EquilibriumState state = newton(q_guess, p);
  move_multipliers(state, p, new_load ? 2 : 1);
  return state;
}

void Equilibrium::continue_solve(EquilibriumState& state, const Vector& p) {
  const int before = state.newton_iterations;
  state = newton(state.q, p);
  state.newton_iterations += before;
  move_multipliers(state, p, 1);
}

void Equilibrium::continue_held(EquilibriumState& state, const Vector& p) {
  held_chords_ = true;
  continue_solve(state, p);
  held_chords_ = false;
}

void Equilibrium::move_multipliers(EquilibriumState& state, const Vector& p, int updates) {
  if (!multiplier_moves()) return;
  for (int k = 0; k < updates && state.converged && !problem_.body->update_multipliers(state.q).empty(); ++k) {
    ++counters_.multiplier_updates;
    const int before = state.newton_iterations;
    state = newton(state.q, p);
    state.newton_iterations += before;
    // Past a limit point of the body under given contact forces a move can take Newton out of
    // reach (the exactly incompressible filleted block with friction, tests/hard: steps 23-24 of
    // 30 failed after 5 cuts). From the first such failure on, this equilibrium's real solves
    // leave the pressures to load stepping's updates after the contact solve, as ssn does.
    if (!state.converged) moves_failed_ = true;
  }
}

EquilibriumState Equilibrium::newton(const Vector& q_guess, const Vector& p) {
  const CpuSpan timed(counters_.newton_cpu_s);
  EquilibriumState state;
  state.q = q_guess;
  for (const Constraint& c : problem_.constraints)
    state.q[c.dof] = c.load_case < static_cast<int>(factors_.size()) ? c.at(factors_[c.load_case]) : 0.0;
  for (const Constraint& c : extra_) state.q[c.dof] = c.value;
  const RigidModes& rigid = problem_.rigid;
  if (!pins_free_)
    for (int k = 0; k < rigid.count(); ++k) state.q[rigid.pins[k]] = rigid.scale * p[rigid.first + k];
  const double body_length = problem_.body->characteristic_length();
  constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
  // The penalty law (or the held one) adds stiffness that changes with the contact state: no
  // reuse then.
  const bool reuse = constant_tangent_ && !penalty_ && !held_;
  // A pair of bodies adds its stiffness, which moves with the pairing, on a few surface dofs:
  // kept as a low-rank correction of the constant body tangent (low_rank_step).
  const bool low_rank = reuse && has_pairs_;
  // The tangent: assembled in place into the factorization's block, or (low_rank) its contact
  // terms recorded, kept from solve to solve (no allocation once grown).
  Triplets& triplets = newton_triplets_;
  TripletSink contact_terms(triplets);
  // A changing tangent takes its geometric stiffness from the stress of the strain linearized
  // about the last iterate (MIP Newton; the first iterate's about the last converged state, an
  // equilibrium, where the guess was extrapolated from it): the linearized rotation of a
  // correction stretches a slender body's fibres, and that stretch's stress in the next tangent
  // made Newton alternate between long and short corrections
  // (docs/algorithm.md#newtons-tangent-the-linearized-stress).
  Vector base = converged_q_.size() == state.q.size() ? converged_q_ : Vector();
  const auto tangent = [&]() -> TangentSink* {
    if (reuse && !low_rank) return nullptr;
    triplets.clear();
    if (low_rank) return &contact_terms;
    TangentSink& sink = lu_.assemble(free_index_, free_count_, &length_scales_);
    if (base.size()) sink.stress_base = &base;
    return &sink;
  };
  // Where every changing tangent takes the linearized stress, each correction is taken in full
  // (within the body's own fraction): Deuflhard's test reads the trial's residual, the force of
  // the fibres a linear rotation stretches, with a tangent whose stress was linearized, as a
  // load (it cut the straight strip's first step to 1/8, where the full step converges in 4
  // iterations; later it halved corrections that the next iterate confirmed).
  const bool full_steps = !reuse && !penalty_ && !held_ && problem_.body->traits().linearized_stress;
  // Not at a new load's first solve: from the guess extrapolated to it the first chord is far
  // beyond their reach (on the strip 1e4 to 1e13 x the correction test), a force evaluation and a
  // solve thrown away.
  const bool chords = !reuse && !new_load_ && chord_ready();
  new_load_ = false;
  double last_step = 0.0, step_before = 0.0;
  std::vector<signed char> signs;  // the penalty law's trial signs at the last iterate
  // The iterates' work storage (members, sized at the first iterate of the first solve): an
  // iteration allocates nothing where the tangent is one Cholesky factorization of a pattern
  // already analysed (tests/alloc/newton_allocation_test.cpp).
  Vector& r = r_work_;
  Vector& r_step = r_step_work_;
  Vector& r_free = r_free_work_;
  Vector& dq_free = dq_free_work_;
  Vector& dq = dq_work_;
  // The solve's state (its answer, moved out) is paired before the loop: sizing its surface
  // points is the solve's one allocation that grows with the contact surface.
  pair(state.q, state);
  for (int it = 1; it <= params_.max_iterations + 1; ++it) {
    if (newton_iteration_probe) newton_iteration_probe(it, lu_.analyses() + body_lu_.analyses());
    if (it > 1) pair(state.q, state);
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
    // Where the chord test may end the solve, the tangent is assembled only if it does not; so
    // too where the last two corrections, converging quadratically, put the next one within the
    // correction test (the residual test then usually ends the solve here).
    const bool chord = it == 1 && chords;
    const bool expect_end =
        it > 2 && !reuse &&
        last_step * last_step * last_step <= params_.displacement_tolerance * step_before * step_before;
    const bool with_tangent = !chord && !expect_end;
    residual_into(state.q, state, p, with_tangent ? tangent() : nullptr, r, &force_scale, !low_rank);
    const double r_max = scaled_free_max(r);
    state.relative_residual = force_scale > 0 ? r_max / force_scale : 0.0;
    if (!std::isfinite(r_max)) {
      state.reason = "Newton produced a non-finite residual";
      state.failure = FailureKind::newton_diverged;
      return state;
    }
    const bool residual_met = r_max <= params_.residual_tolerance * force_scale;
    // The round-off floor only matters where the residual test fails (|K| costs a pass over
    // assembled entries: 6 % of the beam's time when taken at every iterate).
    bool at_floor = false;
    if (!residual_met && it > 1) {
      double k_norm = body_tangent_norm_;
      if (!reuse) k_norm = lu_.row_sum_norm();
      const double q_size = (state.q.array() * length_scales_.array()).abs().maxCoeff();
      at_floor = r_max <= params_.floor_factor * kEpsilon * (k_norm * q_size + force_scale);
    }
    if (residual_met || at_floor) {
      state.at_floor = at_floor && !residual_met;
      state.noise = state.at_floor ? last_step : 0.0;
      converged_q_ = state.q;
      if (!penalty_) newton_factor_q_ = state.q;
      if (penalty_) finish_penalty(state);
      else finish(state, held_ ? held_forces(state.q, state, p, nullptr) : p);
      return state;  // moved out (finish's reference copied every surface point's Jacobian)
    }
    if (it > params_.max_iterations) break;
    if (chord && chord_converges(state, r, p)) {
      converged_q_ = state.q;
      finish(state, held_ ? held_forces(state.q, state, p, nullptr) : p);
      return state;
    }
    if (!with_tangent) residual_into(state.q, state, p, tangent(), r, nullptr, !low_rank);
    if (!branch.empty()) {
      stick_branch_ = std::move(branch);
      residual_into(state.q, state, p, tangent(), r_step, nullptr, !low_rank);
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
      ++counters_.newton_factorizations;
      newton_factor_solve_ = -1;
      const bool factorized = lu_.factorize(1e-4);
      counters_.newton_analyses = lu_.analyses();
      if (!factorized) {
        state.reason = "singular tangent stiffness in Newton iteration " + std::to_string(it);
        state.failure = FailureKind::newton_diverged;
        return state;
      }
      // The held law's springs are in it: no compliance of the body (compliance.cpp).
      newton_factor_solve_ = held_ ? -1 : counters_.solves;
      chord_factorization_ = held_ ? -1 : lu_.factorizations();
      held_factorization_ = held_ ? lu_.factorizations() : -1;
    }
    // -r on the free dofs (negated in place: the same values as -r_free).
    r_free.resize(free_count_);
    for (int i = 0; i < r.size(); ++i)
      if (free_index_[i] >= 0) r_free[free_index_[i]] = -r_newton[i];
    if (low_rank) dq_free = low_rank_step(triplets, r_free);
    else (reuse ? body_lu_ : lu_).solve_into(r_free, dq_free);
    state.newton_iterations = it;
    ++counters_.newton_iterations;
    dq.setZero(state.q.size());
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
    step_before = last_step;
    last_step = step;
    if (step <= params_.displacement_tolerance && stick_branch_.empty()) {
      state.q += dq;
      pair(state.q, state);
      converged_q_ = state.q;
      if (!penalty_) newton_factor_q_ = state.q;
      if (penalty_) finish_penalty(state);
      else finish(state, held_ ? held_forces(state.q, state, p, nullptr) : p);
      return state;  // moved out (finish's reference copied every surface point's Jacobian)
    }
    const double a = full_steps ? problem_.body->newton_step_fraction(state.q, dq)
                                : line_search(state.q, dq, p, reuse ? body_lu_ : lu_);
    base = state.q;
    state.q += a * dq;
    stick_branch_.clear();
  }
  pair(state.q, state);
  state.failure = FailureKind::newton_diverged;
  state.reason = "Newton did not converge in " + std::to_string(params_.max_iterations) +
                 " iterations (free residual " + number_text(state.relative_residual) + " of the force scale)";
  return state;
}

void Equilibrium::free_solve_into(const FreeBlockSolver& solver, const Vector& r, Vector& x) const {
  trial_r_free_.resize(free_count_);
  for (int i = 0; i < r.size(); ++i)
    if (free_index_[i] >= 0) trial_r_free_[free_index_[i]] = r[i];
  solver.solve_into(trial_r_free_, trial_x_free_);
  x.setZero(r.size());
  for (int i = 0; i < r.size(); ++i)
    if (free_index_[i] >= 0) x[i] = trial_x_free_[free_index_[i]];
}

bool Equilibrium::chord_ready() const {
  if (held_) return held_chords_ && lu_.ok() && lu_.factorizations() == held_factorization_;
  return !penalty_ && !held_ && problem_.body->traits().linearized_stress && lu_.ok() &&
         lu_.factorizations() == chord_factorization_;
}

bool Equilibrium::chord_converges(EquilibriumState& state, const Vector& r, const Vector& p) {
  const double tolerance = params_.displacement_tolerance;
  Vector& q = trial_q_;
  Vector& dq = trial_dq_;
  q = state.q;
  const Vector* residual_at = &r;
  double last = 0.0, relative_residual = state.relative_residual;
  for (int k = 0; k < kChordCorrections; ++k) {
    if (k) {
      pair(q, trial_state_);
      double force_scale = 0.0;
      residual_into(q, trial_state_, p, nullptr, trial_r_, &force_scale);
      residual_at = &trial_r_;
      relative_residual = force_scale > 0 ? scaled_free_max(trial_r_) / force_scale : 0.0;
    }
    free_solve_into(lu_, *residual_at, dq);
    dq = -dq;
    const double size = (dq.array() * length_scales_.array()).abs().maxCoeff();
    // Too far for chords, or the tangent no longer contracts: Newton goes on from state.q.
    if (!(size <= (k ? kChordContraction * last : kChordStart * tolerance))) return false;
    q += dq;
    if (k && size <= tolerance) {
      state.q = q;
      state.relative_residual = relative_residual;  // the last residual evaluated, as Newton's
      pair(state.q, state);
      ++counters_.chord_solves;
      return true;
    }
    last = size;
  }
  return false;
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

double Equilibrium::line_search(const Vector& q, const Vector& dq, const Vector& p,
                                const FreeBlockSolver& solver) const {
  // Deuflhard's natural monotonicity test: the simplified correction K^-1 R(q + a dq), with
  // the factorization already at hand, must be shorter than (1 - a/4) |dq|. It measures the
  // distance to the solution in the tangent's metric, so a large rigid rotation with small
  // strains is a full step, where the residual norm would grow and refuse it.
  const double dq_norm = free_length_norm(dq);
  double a = problem_.body->newton_step_fraction(q, dq);
  for (int k = 0; k < params_.max_backtracks; ++k, a *= 0.5) {
    trial_q_ = q + a * dq;
    pair(trial_q_, trial_state_);
    residual_into(trial_q_, trial_state_, p, nullptr, trial_r_);
    free_solve_into(solver, trial_r_, trial_dq_);
    const double norm = free_length_norm(trial_dq_);
    if (std::isfinite(norm) && norm <= (1.0 - 0.25 * a) * dq_norm) return a;
  }
  return a;
}

bool Equilibrium::factorize_body_tangent(const Vector& q, const EquilibriumState* turning, bool indefinite) {
  if (constant_tangent_ && body_factorized_) return body_lu_.ok();
  g_turns_ = g_indefinite_ = false;
  // The turning terms, then (not positive definite with them, unless `indefinite` lets their LU
  // serve) the same pattern with zeros.
  for (const double scale : {1.0, 0.0}) {
    Vector force = Vector::Zero(q.size());
    TangentSink& sink = body_lu_.assemble(free_index_, free_count_, &length_scales_);
    problem_.body->internal_force(q, force, &sink);
    const bool turns = turning && add_turning_stiffness(*turning, sink, scale);
    ++counters_.factorizations;
    ++counters_.body_factorizations;
    body_factorized_ = true;
    // Read by Newton only for a constant tangent (a changing one has its own).
    if (constant_tangent_) body_tangent_norm_ = body_lu_.row_sum_norm();
    const bool ok = body_lu_.factorize();
    counters_.body_analyses = body_lu_.analyses();
    if (!turns || (ok && (body_lu_.symmetric() || indefinite))) {
      g_turns_ = turns;
      g_indefinite_ = turns && !body_lu_.symmetric();
      return ok;
    }
  }
  return body_lu_.ok();
}

bool Equilibrium::add_turning_stiffness(const EquilibriumState& state, TangentSink& sink, double scale) const {
  Mat2 R;
  R << 0, -1, 1, 0;
  bool any = false;
  for (size_t i = 0; i < problem_.candidates.size(); ++i) {
    const Candidate& c = problem_.candidates[i];
    const PairedPoint& pp = state.points[i];
    const double p_eta = state.p[c.eta], p_xi = c.xi >= 0 ? state.p[c.xi] : 0.0;
    // Newton's df/dx (residual()), symmetrized: C must be symmetric for the Coulomb model's
    // Cholesky factors; the friction force's part p_xi R dn/dx is not.
    const Mat2 df_dx = scale * (-p_eta * Mat2::Identity() + p_xi * R) * pp.projection.dnormal_dx;
    const Mat2 sym = 0.5 * (df_dx + df_dx.transpose());
    any = any || !sym.isZero(0.0);
    for (const auto& a : pp.point.jacobian)
      for (const auto& b : pp.point.jacobian) sink.add(a.dof, b.dof, -a.dx.dot(sym * b.dx));
  }
  return any;
}

}  // namespace grip
