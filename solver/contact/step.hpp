#pragma once
// What every contact strategy shares (internal to solver/contact): one load step's state, the
// oracle calls (real equilibrium solves), the budgets (iterations, stop requests), the events,
// the tau passes of eq. 14, the direction of eq. 13, the line search of real solves along a
// predicted force change, the paper's literal loop (cev's `loop: paper`, and uzawa) and the
// final check of eq. 12. Each strategy derives from StepSolver in its own file (cev.cpp,
// uzawa.cpp, penalty.cpp, ssn.cpp); strategy.cpp picks one. Layering: the equilibrium oracle
// below, load stepping above.
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "solver/contact/contact_error.hpp"
#include "solver/contact/coulomb_model.hpp"
#include "solver/contact/strategy.hpp"

namespace grip {

// The direction d of eq. 13 (pbar = p - d) on the active block, scattered to all components.
struct Direction {
  Vector d;
  int n = 0;
  double alpha = 1.0;
  bool ok = false;
};

std::vector<int> active_indices(const ContactError& e);

// cev's held real solves (ContactParams::real_solve): the law of the line search's trials, its
// springs' target at the trial p + f (pl - p) the model's s + f ds, ds = C (pl - p).
struct HeldPlan {
  HeldContact law;
  Vector s, ds;
};

class StepSolver {
 public:
  StepSolver(Equilibrium& eq, const ContactParams& params, int step, const IterationObserver& obs,
             const StopRequest& stop);
  virtual ~StepSolver() = default;

  // Couples Newton to the contact tolerance, runs the strategy, counts solves and iterations.
  StepOutcome run(const Vector& q_guess, const Vector& p_start, const Vector& p_star);

 protected:
  // The strategy itself: fills out_ (converged, reason, p, tau, state).
  virtual void solve(const Vector& q_guess, const Vector& p_start, const Vector& p_star) = 0;

  // The tau passes of eq. 14 (docs/algorithm.md#friction_loop-passes-the-tau-passes): each pass
  // holds tau = mu |p*| and runs `pass` (a Tresca problem); passes end when p* settles. They start
  // from p_star_in, or from p_start where the free motions follow the state (step.cpp).
  void tau_passes(const Vector& q_guess, const Vector& p_start, const Vector& p_star_in,
                  const std::function<bool()>& pass);

  // One real solve at out_.p from q, accepted as the new state (an event with m = 0). With
  // v_scale > 0 (the contact error expected there), Newton stops at kInexactNewton x v_scale;
  // it is finished to the full precision where the error found is within the tolerance, and
  // to kInexactNewton x that error where it is more than 10x below v_scale.
  // Where the step starts at rest (at_rest_: q an equilibrium under out_.p, solve_cev_step),
  // its first call takes q as it is if Equilibrium::at_rest confirms it: no real solve, an event
  // with no trials.
  bool fresh_solve(const Vector& q, double v_scale = 0.0);
  bool at_rest_ = false;
  // Some normal force of p presses.
  bool presses(const Vector& p) const;
  // Coulomb's law on the linear model C at the current state, from out_.p, solved to `target`
  // with the step's inner limits (coulomb_model.hpp; no real solve).
  CoulombModelSolution solve_model(const Compliance& C, double target) const;
  // A body held by contact at its first contact (p* presses nowhere) has no friction bound in
  // its first pass, and a motion that only friction holds (a disc turned between two flats) no
  // equilibrium then: p* is taken instead from Coulomb's law on the linear model at the step's
  // first state (coulomb_model.hpp; no real solve), and out_.tau with it.
  bool bound_from_model(Vector& p_star);
  // A free rigid motion that no pressing contact holds yet, pushed by the load, is moved until
  // its first contact point closes its gap (and presses by the tolerance), then solved again:
  // while every point is open the linear model knows nothing that stops the motion.
  bool approach_contact();
  // That motion alone (dq, and the amplitudes in out_.p), from out_.state; false if none.
  bool approach_motion(Vector& dq);
  Vec2 mode_rates(size_t candidate, int mode) const;
  bool mode_held(int mode) const;
  void accept(EquilibriumState s, const Vector& p);
  // Records the first failure of the step (its kind and reason); false.
  bool fail(FailureKind kind, std::string reason);
  // False (with the reason) once the step's real-solve budget is spent or a stop is asked.
  bool budget_left();

  // Real solves along p -> pl: the first trial is pl itself, then p + 2^-h (pl - p); the first
  // with a smaller ||v|| is accepted. du is the linear model's displacement change for pl - p
  // (Newton starts from it). `trials` counts the real solves.
  // With `held`, each trial is a held real solve, judged (and accepted) at the forces the body
  // carried; a trial whose carried forces leave the cone where it held them is solved once more
  // with those points let go (released_from_cone), and rejected if it leaves the cone again.
  bool line_search(const Vector& pl, const Vector& du, int& trials, const HeldPlan* held = nullptr);
  // The carried forces p meet the cone where the law held them: no tension, a sticking force
  // within mu |p_eta| (to 1e-9).
  bool held_admissible(const HeldContact& law, const Vector& p) const;
  // Moves a held trial's base forces to what its springs carry (base: the trial's given forces)
  // and continues its Newton, until the springs hold the model's kinematics (step.cpp).
  void move_held(EquilibriumState& trial, Vector& base, const Vector& target, const Vector& stiffness);
  // Lets go the points whose carried forces left the cone where `plan` held them: one pulled
  // across its obstacle carries the given force zero (its components appended to `let_go`), one
  // stuck beyond mu |p_eta| slips the way its force pointed.
  void released_from_cone(HeldPlan& plan, const Vector& carried, std::vector<int>& let_go) const;
  // No real solve lowers ||v|| any more (the line search, or alpha's halvings) where it is
  // within tolerance x L, the bound before it moved with D: the precision the real solves allow
  // is reached (their round-off: the mortar pairs of two bodies). The step converges there with
  // that error as its bound, and says so (at_round_off). True if so.
  bool reached_precision();
  // Inexact real solves (kInexactNewton, step.cpp): Newton's correction test for a trial
  // whose contact error starts at v_ref, loosened to that fraction of v_ref (true if looser
  // than the full precision); and back to the full precision. Both divided by
  // newton_amplification_ (a held trial's: line_search), not below newton_floor_.
  bool loosen_newton(double v_ref);
  void tighten_newton();

  // Direction of eq. 13 for the active block of v: n = infinity solves with C'_EE; a finite n
  // uses the polynomial accelerator (normalized, section 8); level 1 with alpha_fixed > 0 is
  // the multiplier update.
  Direction direction(const Compliance& C, const ContactError& err, int level, double alpha_fixed);
  // The same on the bordered block of a body held by contact (bordered_direction.cpp): the
  // amplitudes eliminated, eq. 13 on the positive definite block of the null space of G^T.
  Direction bordered_direction(const Compliance& C, const ContactError& err, int level, double alpha_fixed);
  // While on, bordered_direction keeps the factors of one active set's bordered block (Z, Z^T C Z
  // and its Cholesky: O(m^3)) from call to call: for the inner iterations on one linear model,
  // whose compliance does not change meanwhile. Turning it on or off drops them.
  void keep_bordered_factors(bool on) {
    keep_bordered_ = on;
    bordered_.reset();
  }
  // eq. 13's projection of pbar (project_forces), keeping a held body's equilibrium rows met.
  // `asked` (if given): the forces the direction's step assumed, where they differ from pbar
  // (held_direction's forces put on their bound): the rows are kept against those.
  Vector project(const Compliance& C, const Vector& p, const Vector& pbar, const ContactError& e, const Vector& tau,
                 const Vector* asked = nullptr) const;

  // eq. 13's direction for the literal loop, on the components that eq. 13's projection lets
  // move: a force on its bound (|p_xi| = tau, or p_eta = 0) that the direction pushes beyond it
  // keeps its value at every alpha, as on the slipping branch, so M_n is formed without it (the
  // others' step assumed it moved: with it the step was no descent of ||v|| at any alpha, the
  // free beam). Its error stays in ||v||; repeated until no such force is left.
  // With the trial length a: a force that p - a d carries beyond its bound is put on it (the
  // projection's value) and held the same way; pbar gets the trial's forces, `asked` the same
  // with the held forces where they were (what the direction assumed; project keeps the rows).
  Direction held_direction(const Compliance& C, const ContactError& e, int level, double alpha_fixed, double a,
                           Vector& pbar, Vector& asked);
  // The paper's literal loop: one real solve per eq. 13 update at acceleration `level` (cev's
  // `loop: paper`), or the multiplier update with a fixed alpha (uzawa).
  bool literal_pass(int level, double alpha_fixed);

  // The components that can take part in this iteration (see step.cpp).
  std::vector<int> relevant_components() const;
  // The largest normal-force correction that the remaining contact error asks for.
  double force_precision();
  // eq. 12 with the current tau.
  void final_check();
  // own_newton: Newton iterations made outside the oracle since the last event (ssn).
  void emit(int trials, int inner, int halvings, int n, double alpha, int own_newton = 0);

  bool frictionless() const;
  // The step's bound on ||v|| at state s (docs/algorithm.md#tolerance): tolerance x the body's
  // largest displacement there (at most its characteristic length), never below the round-off
  // of the gaps and slips at their coordinates' size (then *round_off is set).
  double bound_at(const EquilibriumState& s, double* scale = nullptr, bool* round_off = nullptr) const;
  // The size of the contact points' coordinates at s (their positions, pairings and zeta; at
  // least the body's length): what their rounding is relative to.
  double coordinate_size(const EquilibriumState& s) const;
  // The largest displacement of q, a rotation times its length scale.
  double displacement_size(const Vector& q) const;
  // The step's stopping test: ||v|| <= tol, and where the body's free motions follow its state
  // (rigid_modes_at: finite kinematics, a free rotation) its amplitudes' rows, the residuals at
  // its pins, to Newton's residual tolerance (newton_fraction x tolerance) relative to the size
  // of the forces, as every other residual: the linear model is not exact there, so ||v|| <= tol
  // alone left the moment unbalanced by up to 3e-7 of the forces (a disc turned between two
  // flats), where elsewhere the model's rows hold to rounding.
  bool error_met(const ContactError& e) const { return e.norm2 <= tol_ && unbalance(e) <= balance_tol_; }
  // A trial is better than the accepted state with error v0: a smaller ||v||, or, within the
  // bound (tolerance x L, ceiling, where the free motions follow the state: strict_balance_), a
  // smaller unbalance on the free motions (error_met's second test).
  // Not within the bound tol_ alone: where it is far below tolerance x L (the turned disc, D =
  // the 0.1 mm squeeze, L = 28.3 mm: 1e-9 against 2.8e-7), the update that balanced the moment
  // raised ||v|| from 1.3e-9 to 2.5e-9 before the next brought it to 3e-11; refused, every
  // trial after it stalled (cev_passes, 5 cuts).
  bool improves(const ContactError& e, double v0) const {
    return e.norm2 < v0 || (e.norm2 <= (strict_balance_ ? ceiling() : tol_) && unbalance(e) < unbalance(error_));
  }
  // tolerance x L: the bound before it moved with the displacement, never exceeded (bound_at).
  double ceiling() const { return params_.tolerance * problem_.body->characteristic_length(); }
  // The largest amplitude row of e (every body held by contact), else 0.
  double unbalance(const ContactError& e) const;
  // The contact error at (p, s): with the bounds out_.tau of the pass, or with Coulomb's
  // bounds mu |p_eta| of p itself.
  ContactError error_at(const Vector& p, const Vector& s, const std::vector<char>& enabled) const {
    return contact_error(problem_, p, s, coulomb_ ? friction_bounds(problem_, p) : out_.tau, enabled);
  }

  Equilibrium& eq_;
  const Problem& problem_;
  const ContactParams& params_;
  int step_;
  const IterationObserver& observer_;
  const StopRequest& stop_;
  std::chrono::steady_clock::time_point start_;
  double tol_ = 0.0;             // the bound on ||v|| at the accepted state (bound_at)
  double scale_ = 0.0;           // the displacement it is relative to
  bool at_round_off_ = false;    // the round-off of the gaps set it, not tolerance x scale_
  Vector length_scales_;         // of the body's dofs (a rotation's: a length)
  Vector s_before_;              // the gaps of the state accepted before out_.state (relevant_components)
  bool strict_balance_ = false;  // error_met tests the amplitudes' rows
  double balance_tol_ = 0.0;     // their bound, at the accepted state (accept)
  NewtonParams newton_base_;     // Newton's tests at the contact tolerance (couple_newton)

  // The rounding of the positions: no correction test below it.
  double newton_floor_ = 0.0;
  // A held trial's 1 + held_stiffness while its line search runs (line_search), else 1.
  double newton_amplification_ = 1.0;
  int pass_ = 0, m_ = 0;
  long solves_at_start_ = 0;
  long newton_emitted_ = 0;  // the Newton counter at the last event
  double warmup_eps_ = 0.0;
  bool coulomb_ = false;            // the friction bound moves with p (no tau passes)
  bool literal_ = false;            // the passes run the literal loop (literal_pass)
  double pin_forces_ = 0.0;         // > 0: the literal loop's passes pin p_eta to this (tau_passes)
  bool passes_to_budget_ = false;   // the tau passes end at the budget, not max_tau_passes (uzawa)
  long own_newton_iterations_ = 0;  // Newton iterations made outside the oracle (ssn)
  std::vector<char> is_normal_;
  int beyond_friction_ = 0;              // accepted states in a row beyond what friction holds (accept)
  std::string friction_limit_;           // why, once shown: budget_left ends the step with it
  std::vector<double> accepted_errors_;  // ||v|| at each accepted state of the attempt
  std::string crawl_;                    // why the budget cannot reach the bound (accept)
  ContactError error_;
  StepOutcome out_;

 private:
  struct BorderedFactors;  // bordered_direction.cpp
  bool keep_bordered_ = false;
  std::shared_ptr<const BorderedFactors> bordered_;
};

// One entry per strategy file. cev's at_rest (load stepping calls it directly for that): q_guess
// is an equilibrium under p_start (= p_star) at the step's load factors (Equilibrium::at_rest:
// the last converged state of a plastic body, where only obstacles moved), which cev's first
// solve takes as it is, without a real solve, where Newton's residual test holds there; model_at
// (with at_rest): where the step did start at rest, the displacement its first update's
// compliance is formed at (the last increment extrapolated; docs/algorithm.md#load-stepping-and-cuts).
StepOutcome solve_cev_step(Equilibrium& eq, const Vector& q_guess, const Vector& p_start, const Vector& p_star,
                           const ContactParams& params, int step, const IterationObserver& observer,
                           const StopRequest& stop, double v_previous, bool at_rest = false,
                           const Vector* model_at = nullptr);
StepOutcome solve_uzawa_step(Equilibrium& eq, const Vector& q_guess, const Vector& p_start, const Vector& p_star,
                             const ContactParams& params, int step, const IterationObserver& observer,
                             const StopRequest& stop);
StepOutcome solve_ssn_step(Equilibrium& eq, const Vector& q_guess, const Vector& p_start, const Vector& p_star,
                           const ContactParams& params, int step, const IterationObserver& observer,
                           const StopRequest& stop);
StepOutcome solve_penalty_step(Equilibrium& eq, const Vector& q_guess, const Vector& p_start, const Vector& p_star,
                               const ContactParams& params, int step, const IterationObserver& observer,
                               const StopRequest& stop);

}  // namespace grip
