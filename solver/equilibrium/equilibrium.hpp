#pragma once
// SOLVE(U, p) (docs/algorithm.md#equilibrium-for-given-contact-forces): equilibrium of eq. 1-2 for given contact forces p,
// by Newton's method with the pairing, T(u) and the stiffness of the follower contact load
// d(T(u) p)/du re-evaluated at every iterate. Also the contact compliance C = T^T K^-1 T.
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solver/equilibrium/compliance.hpp"
#include "solver/equilibrium/equilibrium_state.hpp"
#include "solver/equilibrium/free_block_solver.hpp"
#include "solver/equilibrium/held_contact.hpp"
#include "solver/equilibrium/newton_params.hpp"
#include "solver/equilibrium/penalty_law.hpp"
#include "solver/model/parallel.hpp"
#include "solver/problem/problem.hpp"

namespace grip {

// Implemented in equilibrium.cpp (set-up, residual, reactions), pairing.cpp, newton.cpp,
// compliance.cpp and penalty_law.cpp.
class Equilibrium {
 public:
  // `extra` prescribes further dofs at absolute values (the start-up solve).
  Equilibrium(const Problem& problem, NewtonParams params, std::vector<Constraint> extra = {});

  // Sets the load factor (loads, prescribed dofs, obstacle positions) and the surface
  // coordinates zeta of the last converged step that the slips s_xi are measured from.
  void set_step(LoadFactors factors, std::vector<double> zeta_previous);
  const LoadFactors& factors() const { return factors_; }

  // A real solve: Newton under the given contact forces p. Where the body holds a constraint by
  // multipliers (exact incompressibility), it moves them once at the answer and Newton goes on
  // (move_multipliers): the contact loop's iterations are also the multipliers' Uzawa iterations.
  EquilibriumState solve(const Vector& q_guess, const Vector& p);
  // Off: real solves leave the multipliers as they are (ssn, whose own Newton iterations hold
  // them; load stepping then updates them after the contact solve).
  void set_multiplier_moves(bool on) { multiplier_moves_ = on; }
  bool multiplier_moves() const { return multiplier_moves_ && !moves_failed_; }
  // Newton continued from a converged state at the current tests (tightened since): the same
  // real solve finished more precisely, not counted as another.
  void continue_solve(EquilibriumState& state, const Vector& p);
  // continue_solve after a move of the held law's base forces: chords from the held trial's
  // last factorization first.
  void continue_held(EquilibriumState& state, const Vector& p);
  // With a penalty law set, solve() ignores its p and finds p(q) from the law.
  // A body held by contact then has its pins free (PenaltyLaw::pin_spring).
  void set_penalty(std::optional<PenaltyLaw> law);
  // With a held law set, solve(q, p) carries p + k (target - s(q)) at the held components
  // (HeldContact), and the state's p is what the body carried.
  void set_held(std::optional<HeldContact> held) { held_ = std::move(held); }
  // The largest diagonal entry of the body's stiffness at q: a scale for penalty stiffnesses.
  double stiffness_scale(const Vector& q) const;
  // The pairing and s at q, without solving (e.g. the reference configuration).
  EquilibriumState evaluate(const Vector& q) const;
  // q as it is where it already is an equilibrium under p at the current load factors: its
  // prescribed dofs at their values and Newton's residual test met at the current tests (one
  // residual evaluation, no factorization, nothing counted). Not a real solve: a state that
  // Newton would return at its first iterate without a correction. Only for given forces (no
  // penalty or held law) and a body without rigid amplitudes (docs/algorithm.md#load-stepping-and-cuts).
  std::optional<EquilibriumState> at_rest(const Vector& q, const Vector& p) const;
  // C = T^T K^-1 T over the given components, from the body's own tangent (symmetric), as
  // C = T_s^T G T_s: G = K^-1 restricted to the surface dofs of the candidates asked for so
  // far, one solve per surface dof with one factorization of K, and T_s the rows of T at
  // those dofs (two or three non-zeros per column), so each call costs O(components^2),
  // nothing per free dof. A constant tangent gives one G per run. A changing one gives G at state.q
  // (from Newton's factorization there, where the real solve that reached state took one and the
  // surface is small: newton_factor_serves), or, with reuse on, the G of an earlier state, of
  // this load step or an earlier one (refresh_compliance() renews it): the inner loop's linear
  // model is then approximate, the real solves still decide. The reference stays valid until
  // the next call.
  // From `sparse_from` components on (and for a body not held by contact, whose tangent is
  // Cholesky-factorized), the sparse form instead: T on the free dofs, K's factorization and C's
  // diagonal (t_j^T K^-1 t_j by partial forward solves), no G; its reference is a separate one,
  // valid until the next sparse call.
  const Compliance& compliance(const EquilibriumState& state, const std::vector<int>& components,
                               int sparse_from = kDenseCompliance);
  // Reuse G across real solves and load steps for a changing tangent.
  void set_compliance_reuse(bool on) { compliance_reuse_ = on; }
  // The next compliance() forms G afresh at its state.
  void refresh_compliance() { g_valid_ = constant_tangent_ && g_valid_; }
  // The last compliance() used a G formed at an earlier state (a changing tangent only).
  bool compliance_reused() const { return compliance_reused_; }
  // A dense G may carry the turning contact forces' stiffness where the sum with the body's
  // tangent is not positive definite (an LU factorization of it; then C is indefinite, the
  // exact linearization still): for cev's default loop, whose Coulomb model solves C's active
  // blocks by LU (docs/algorithm.md#the-contact-compliance). Off: the body's own tangent there.
  void set_indefinite_turning(bool on) { indefinite_turning_ = on; }
  // The last compliance() carries the stiffness of contact forces that turn with a curved
  // obstacle (a body stiff in its reference state): the exact linearization at its state, so
  // formed afresh at every update (docs/algorithm.md#the-contact-compliance).
  bool compliance_turns() const { return g_turns_; }
  // The linear model's displacement change K^-1 T dp for a force change dp, from the last
  // compliance (its components only, with the tangent its G came from): where the next
  // solve should start. One sparse solve.
  Vector predicted_change(const Compliance& C, const Vector& dp) const;
  // R = A(q) - lambda F - T(q) p on every dof, and (if asked) the triplets of dR/dq, with
  // the pairing evaluated at q.
  Vector residual(const Vector& q, const Vector& p, Triplets* tangent) const;
  // Newton's relative residual at (q, p): the largest free residual over the force scale (the
  // measure of its residual test, NewtonParams::residual_tolerance).
  double relative_residual(const Vector& q, const Vector& p) const;
  // The applied loads and the contact forces p on every dof at a paired state: F + T p.
  Vector applied_forces(const EquilibriumState& paired, const Vector& p) const;
  // Residual forces at the fixed dofs (the reactions on the body), full dof vector.
  Vector reactions(const EquilibriumState& state, const Vector& p) const;
  // The surface coordinate of every candidate's pairing point (for the next step's slips).
  std::vector<double> zetas(const EquilibriumState& state) const;

  const Problem& problem() const { return problem_; }
  bool is_free(int dof) const { return free_index_[dof] >= 0; }
  const EquilibriumCounters& counters() const { return counters_; }
  const NewtonParams& params() const { return params_; }
  NewtonParams& params() { return params_; }

 private:
  void pair(const Vector& q, EquilibriumState& state) const;
  EquilibriumState newton(const Vector& q_guess, const Vector& p);
  // A converged iterate: admissibility and the forces in equilibrium (penalty law).
  EquilibriumState& finish(EquilibriumState& state, const Vector& p) const;
  // R = A(q) - lambda F - T p on all dofs; tangent of R (with the contact load stiffness).
  // force_scale (if asked): the largest of |A(q)|, |lambda F| and |T p| over all dofs, in
  // force units (the scale Newton's residual test is relative to). Without body_tangent, the
  // tangent's contact terms only.
  Vector residual(const Vector& q, const EquilibriumState& paired, const Vector& p, TangentSink* tangent,
                  double* force_scale = nullptr, bool body_tangent = true) const;
  // The same into r: r and the work storage below keep their storage (Newton's loop).
  void residual_into(const Vector& q, const EquilibriumState& paired, const Vector& p, TangentSink* tangent, Vector& r,
                     double* force_scale = nullptr, bool body_tangent = true) const;
  // Newton's step K_t^-1 rhs for the constant body tangent plus the pair's stiffness (the
  // `contact` triplets): the body's factorization and a Krylov solve on the pair's dofs.
  Vector low_rank_step(const Triplets& contact, const Vector& rhs) const;
  // Its Krylov solve: relative residual, and the most iterations (then the step is inexact and
  // Newton's tests decide, as for any approximate tangent).
  static constexpr double kLowRankTolerance = 1e-13;
  static constexpr int kLowRankIterations = 60;
  // p(q) of the penalty law at a paired state of q, and (if asked) its stiffness entries. With an
  // increment dq (all dofs), p(q) + (dp/dq) dq: the law linearized at q.
  Vector penalty_forces(const Vector& q, const EquilibriumState& paired, TangentSink* tangent,
                        const Vector* increment = nullptr) const;
  // The held law's forces at a paired state of q (p_given elsewhere), and (if asked) their
  // stiffness entries (held_contact.cpp).
  Vector held_forces(const Vector& q, const EquilibriumState& paired, const Vector& p_given,
                     TangentSink* tangent) const;
  // A contact law's (penalty, held) shared parts: the gradients of candidate i's gap and (if
  // asked) zeta at q, as (dof, derivative); and d(T p)/dq into the tangent, from the law's change
  // of p_eta and p_xi per dof.
  using LawGradient = std::vector<std::pair<int, double>>;
  struct LawChange {
    int dof;
    double normal, tangential;
  };
  void law_gradients(const Vector& q, const EquilibriumState& paired, size_t i, bool with_zeta, LawGradient& gap,
                     LawGradient& zeta) const;
  void add_law_tangent(const EquilibriumState& paired, size_t i, const std::vector<LawChange>& dp,
                       TangentSink& tangent) const;
  // The penalty law's answer at a converged iterate q (paired): one more Newton correction dq,
  // and the forces p(q) + (dp/dq) dq at q + dq.
  EquilibriumState& finish_penalty(EquilibriumState& state);
  // Step length along the Newton correction dq at q: the natural monotonicity test with the
  // factorization `solver` of the step's tangent; at most the body's trust-region fraction.
  double line_search(const Vector& q, const Vector& dq, const Vector& p, const FreeBlockSolver& solver) const;
  // The chord test (newton.cpp): from q with its residual r, the correction with the tangent
  // Newton factorized last (an earlier iterate's, this solve's or the one before's). Where it
  // is within the correction test and a second chord correction from there shows that tangent
  // still contracts (at most kChordContraction of the first), state.q moves by both and the
  // solve is converged without a factorization. False (state unchanged) otherwise.
  bool chord_converges(EquilibriumState& state, const Vector& r, const Vector& p);
  // lu_ holds Newton's factorization of a changing tangent without the held or penalty law's
  // springs, the factorization of number chord_factorization_ (lu_.factorizations()), and the
  // body's tangent is the linearized-stress one (Saint Venant-Kirchhoff at finite strain): the
  // only kind measured to gain (bench/results/kernels.md, chords).
  bool chord_ready() const;
  double free_length_norm(const Vector& dq) const;
  // x = K^-1 r on the free dofs with `solver`'s factorization (r and x by dof, x zero on the
  // prescribed ones): the line search's simplified correction, the chords'. Into kept storage.
  void free_solve_into(const FreeBlockSolver& solver, const Vector& r, Vector& x) const;
  double scaled_free_max(const Vector& r) const;
  void add_rigid_border(const EquilibriumState& state);
  // free_index_ from the supports, the start-up's dofs and (unless pins_free_) the pins.
  void index_free_dofs();
  bool pins_free_ = false;
  // The penalty law's trial tangential force at each candidate: its sign (0 off contact or
  // without friction), at a paired state.
  std::vector<signed char> trial_signs(const EquilibriumState& paired) const;
  // Candidates that penalty_forces() takes on the stick branch of the law whatever their
  // trial (Newton's iterates only; empty otherwise): see solve().
  std::vector<char> stick_branch_;
  // Adds free dofs to G's surface: one solve with the body's factorization per dof.
  void extend_surface_compliance(const std::vector<int>& added);
  // The body's tangent that G (or the sparse form) comes from: kept, or factorized at state.q
  // (a changing tangent without reuse). False if it is singular.
  // `dense`: the compliance will be the dense form (then an indefinite turning sum may serve).
  bool compliance_tangent(const EquilibriumState& state, int surface_dofs, bool dense = false);
  const Compliance& sparse_compliance(const EquilibriumState& state, const std::vector<int>& components);

  const Problem& problem_;
  NewtonParams params_;
  LoadFactors factors_;
  std::vector<double> zeta_previous_;
  std::vector<Constraint> extra_;
  std::optional<PenaltyLaw> penalty_;
  std::optional<HeldContact> held_;
  std::vector<int> free_index_;  // dof -> free index, -1 if prescribed
  std::vector<char> is_pin_;     // dof holds a rigid amplitude (problem.rigid.pins)
  int free_count_ = 0;
  Vector length_scales_;
  EquilibriumCounters counters_;
  // The body's own tangent, factorized once when it is constant (linear kinematics): then
  // Newton is a modified Newton on it and the compliance reuses it. With `turning` (a changing
  // tangent of a body stiff in its reference state), plus the symmetrized stiffness of that
  // state's contact forces turning with curved obstacles, where it stays positive definite.
  // Up to `updates` moves of the body's multipliers (Body::update_multipliers) at a converged
  // state, Newton continued after each; none where the constraint already holds.
  void move_multipliers(EquilibriumState& state, const Vector& p, int updates);
  // With `indefinite`, a sum with the turning terms that is not positive definite is kept where
  // its LU factorization succeeds (g_indefinite_).
  bool factorize_body_tangent(const Vector& q, const EquilibriumState* turning = nullptr, bool indefinite = false);
  // Adds scale x the symmetrized turning stiffness -J^T sym(df/dx) J of every candidate of
  // `state` (emitted even where zero: the pattern stays); true if some term is not zero.
  bool add_turning_stiffness(const EquilibriumState& state, TangentSink& sink, double scale) const;
  bool multiplier_moves_ = true;     // solve() moves the body's multipliers (move_multipliers)
  bool moves_failed_ = false;        // a Newton solve after a move failed: no more moves (move_multipliers)
  bool turning_ = false;             // the compliance may carry the turning stiffness (factorize_body_tangent)
  bool g_turns_ = false;             // G does (its state's: real solve g_solve_ at g_turns_q_)
  bool indefinite_turning_ = false;  // set_indefinite_turning
  bool g_indefinite_ = false;        // G's tangent with the turning terms is LU-factorized (not definite)
  Vector g_turns_q_;
  bool constant_tangent_ = false;
  bool has_pairs_ = false;  // a contact pair of two bodies (a deformable master)
  bool body_factorized_ = false;
  FreeBlockSolver body_lu_;  // the body's own tangent (compliance, constant tangents)
  // Newton's tangent, with the contact terms. For a changing tangent (finite kinematics) the
  // pair's stiffness is among its entries and couples the bodies: one factorization of the
  // whole, since a low-rank correction of the bodies' own factors would need G on the pair's
  // dofs afresh at every iterate (13 such G's cost 6x one factorization, two cylinders).
  FreeBlockSolver lu_;
  // Where lu_ was last factorized: in the real solve of this number (counters_.solves; -1: a
  // failed factorization), and the state that solve converged at (its last iterate but one
  // carries the factorization). The compliance's G of a small contact zone comes from it
  // (compliance.cpp: newton_factor_serves).
  long newton_factor_solve_ = -1;
  Vector newton_factor_q_;
  long chord_factorization_ = -1;
  long held_factorization_ = -1;  // Newton's last factorization with the held springs
  bool held_chords_ = false;      // continue_held: chords may begin its Newton
  bool new_load_ = false;         // set_step since the last Newton solve: no chords (newton.cpp)
  // The last state a Newton solve converged at: the stress base of the next solve's first
  // tangent (newton.cpp, the linearized stress).
  Vector converged_q_;
  bool newton_factor_serves(const EquilibriumState& state, int surface_dofs) const;
  // The factorization G (and predicted_change) comes from: lu_ (g_from_newton_, valid during
  // the real solve g_solve_ only) or body_lu_.
  const FreeBlockSolver& g_factor() const { return g_from_newton_ ? lu_ : body_lu_; }
  bool g_from_newton_ = false;
  long g_solve_ = -1;
  // The contact terms of Newton's tangent for the low-rank step, kept so that their storage is
  // allocated once, not at every real solve (the factorized tangents are assembled in place).
  Triplets newton_triplets_;
  // Work storage of Newton's iterates, sized at the first and reused by the next (newton.cpp):
  // the residual (and the stick branch's), its free part, the correction on the free dofs and
  // on all; residual_into's applied and contact forces and its pair and follower terms.
  Vector r_work_, r_step_work_, r_free_work_, dq_free_work_, dq_work_;
  mutable Vector external_work_, contact_work_;
  // The trial iterates of the line search and the chords: the point, its pairing, residual and
  // simplified correction, and free_solve_into's free parts.
  mutable Vector trial_q_, trial_r_, trial_dq_, trial_r_free_, trial_x_free_;
  mutable EquilibriumState trial_state_;
  mutable Triplets pair_terms_work_, follow_work_;
  double body_tangent_norm_ = 0.0;  // |K|_inf of the constant body tangent (round-off scale)
  std::vector<int> surface_free_;   // surface row of G -> free index
  std::vector<int> surface_row_;    // free index -> surface row of G, -1 off the surface
  Matrix g_;                        // G = K^-1 on the surface dofs
  bool g_valid_ = false;
  bool compliance_reuse_ = false, compliance_reused_ = false;
  Eigen::SparseMatrix<double> t_surface_;  // the last compliance's T_s (surface rows x block)
  Compliance c_;
  long g_version_ = 0, c_version_ = -1;             // G's content; the G that c_ was formed from
  Compliance sparse_;                               // the sparse form
  long tangent_version_ = 0, sparse_version_ = -1;  // body_lu_'s content; the one sparse_ uses
};

}  // namespace grip
