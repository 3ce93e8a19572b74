#pragma once
// Contact strategies behind one step contract (solve_contact_step): the paper's accelerated
// contact error vector scheme `cev` (docs/algorithm.md), `uzawa` (the same
// literal loop with n = 1 and a fixed alpha), and the `penalty` baseline (one Newton solve
// with a penalty law; its error falls as k grows). Each solves one load step given an
// equilibrium oracle, and reports every real solve to an observer. One file per strategy
// (cev.cpp, uzawa.cpp, penalty.cpp); what they share is in step.hpp.
#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "solver/equilibrium/equilibrium.hpp"

namespace grip {

enum class ContactMethod { cev, uzawa, penalty, ssn };
enum class ContactLoop { inner, paper };  // inner: section 5's default; paper: the literal loop
// inner: Coulomb's bound mu |p_eta| moves with p_eta inside the inner loop (cev's default);
// passes: the tau passes of eq. 14, each a Tresca problem (the paper's loop always uses them).
enum class FrictionLoop { inner, passes };
enum class RealSolve { given, held };
enum class EpsilonSource { exact, warmup };

// Acceleration level n: kInfinity = a Cholesky solve with the active block (default);
// kAuto = the smallest n whose condition number reaches 1.1; otherwise 1, 2, ...
inline constexpr int kAccelerationInfinity = 0;
inline constexpr int kAccelerationAuto = -1;

struct ContactParams {
  ContactMethod method = ContactMethod::cev;
  ContactLoop loop = ContactLoop::inner;
  FrictionLoop friction_loop = FrictionLoop::inner;
  // A step ends when ||v||_2 <= tolerance x the body's largest displacement (at most its
  // characteristic length; never below the round-off of the gaps), and a body held by contact
  // balances its loads to tolerance x their size (docs/algorithm.md#tolerance).
  double tolerance = 1e-8;
  int acceleration = kAccelerationInfinity;
  EpsilonSource epsilon = EpsilonSource::exact;
  int warmup_first = 3, warmup_last = 10;  // I and J of eq. 30
  double warmup_alpha = 1.99;
  double uzawa_alpha = 1.0;  // fixed alpha of the multiplier update
  int max_iterations = 500;  // real solves per load step, all tau passes together
  int max_inner_iterations = 2000;
  // The Alart-Curnier augmentation r of the semismooth Newton iterations: cev's model uses
  // r_i = augmentation / C_ii (each component's own contact stiffness), ssn r = augmentation x
  // the largest diagonal entry of the body's stiffness. It changes the path, not the answer.
  double augmentation = 1.0;
  int max_halvings = 40;             // halvings of the step inside the inner loop, or of alpha (paper)
  int halvings_before_fallback = 4;  // paper loop: then n -> n - 1
  int line_search_steps = 10;        // H of the line search along p -> prediction
  int max_tau_passes = 30;
  // Passes end when max |p_eta - p*| <= tau_tolerance * max |p_eta| (section 9: 1e-5 settles
  // in a few passes; much tighter makes p* cycle at the precision ||v|| pins p to).
  double tau_tolerance = 1e-5;
  // Newton's displacement tolerance, as a fraction of the contact tolerance: the contact
  // error has a floor of about ||K^-1|| x the Newton residual (section 9).
  double newton_fraction = 1e-3;
  // A tangent that changes with the displacement, cev's inner loops (the default and the tau
  // passes; the paper's loop always forms G afresh): true lets the compliance's G = K^-1 on
  // the surface dofs serve later real solves, across load steps too, while its updates accept
  // at the first trial and lower ||v|| at least 30-fold (cev.cpp); else it is formed afresh.
  // The answer agrees to what the contact tolerance pins it to (the forces to C_EE^-1 v_E),
  // but the stale model converges linearly, so a step stops nearer the tolerance than with a
  // fresh G (bench/results/coulomb_loop.md: the paper's beam 30 % fewer instructions; the
  // tests' checks of forces derive from C_EE^-1 v_E, tests/support/force_precision.hpp). On
  // by default; false forms G afresh at every update.
  bool reuse_compliance = true;
  // From this many contact unknowns in an iteration on, cev's default loop (and ssn's
  // augmentation) take the compliance in sparse form (Equilibrium::compliance): no dense C,
  // G or factor of C's active block, but one sparse solve per product with C and a sparse LU
  // of a saddle-point system for the inner model's Newton steps (saddle_rows.hpp). Measured on
  // the flat of bench/scaling.py (bench/results/inner_profile.md, CPU seconds of the whole run,
  // dense / sparse): 1000 unknowns 0.48-0.66 / 0.57-0.64, 1400 unknowns 1.08-1.13 / 0.78-0.87,
  // 2000 unknowns 1.53-2.06 / 1.35-1.38. The paper's beam and sheet and Hertz up to a/h 40 (242)
  // stay dense.
  int sparse_compliance_from = 1200;
  // cev's default loop: the real solves of its line search under the given forces (given), or
  // held by the obstacles where the linear model presses or sticks (held: springs of stiffness
  // held_stiffness / C_jj toward the model's kinematics; docs/algorithm.md#the-held-real-solve).
  // A scene's default is held where a body has plasticity, given otherwise (read_solver).
  RealSolve real_solve = RealSolve::given;
  double held_stiffness = 300.0;
  // penalty: k_n and k_t (force / length); 0 means penalty_factor times the largest diagonal
  // entry of the body's stiffness (k_t defaults to k_n).
  double penalty_normal = 0.0;
  double penalty_tangential = 0.0;
  double penalty_factor = 1e3;
};

// The contact tolerance Newton's tests are coupled to (couple_newton): the step's own, but at
// most the default for penalty, whose answer's error |p| / k no Newton precision changes (its
// tolerance only judges that answer: docs/algorithm.md#tolerance).
inline double newton_coupling_tolerance(const ContactParams& c) {
  return c.method == ContactMethod::penalty ? std::min(c.tolerance, ContactParams{}.tolerance) : c.tolerance;
}

struct IterationEvent {
  int step = 0;    // load step, 1-based
  int pass = 0;    // tau pass, 1-based
  int m = 0;       // accepted update in this pass (0: the pass's starting solve)
  int trials = 1;  // real solves this update took (rejected line-search trials too)
  int inner_iterations = 0;
  int halvings = 0;
  int n = 0;  // acceleration level (0 = infinity)
  double alpha = 0.0;
  double v2 = 0.0, v_inf = 0.0;
  int open = 0, stick = 0, slip = 0;
  int newton_iterations = 0;
  double elapsed_ms = 0.0;
};
using IterationObserver = std::function<void(const IterationEvent&)>;
// Asked before every real solve; true stops the step at once (dismissal, a wall-time limit).
using StopRequest = std::function<bool()>;

struct StepOutcome {
  bool converged = false;
  bool stopped = false;  // by the StopRequest, not by the numerics
  std::string reason;
  FailureKind failure = FailureKind::none;  // the kind of the reason
  Vector p;
  Vector tau;
  EquilibriumState state;
  int passes = 0;
  int solves = 0;
  int newton_iterations = 0;
  int inner_iterations = 0;
  double v2 = 0.0;
  double bound = 0.0;         // the bound ||v|| was held to at the last accepted state
  double scale = 0.0;         // the displacement that bound is relative to
  bool at_round_off = false;  // the round-off of the gaps set the bound
  bool definitive = false;    // no retry or cut of the increment can help (penalty's error)
  bool budget_spent = false;  // ended by max_iterations real solves
  std::string epsilon_used;   // "exact" or "warmup", where a finite n needed it
  std::vector<IterationEvent> history;
};

// One load step: p_start is the first guess of the force (the previous steps' forces
// extrapolated, like q_guess, the displacement to start Newton from), p_star the previous
// step's force (the first pass's friction bound, penalty's springs). v_previous: the contact
// error of the previous step's first solve (0: none), which cev's first solve of this step
// takes as the scale of its own (its Newton tolerance, StepSolver::fresh_solve).
StepOutcome solve_contact_step(Equilibrium& equilibrium, const Vector& q_guess, const Vector& p_start,
                               const Vector& p_star, const ContactParams& params, int step,
                               const IterationObserver& observer, const StopRequest& stop = {},
                               double v_previous = 0.0);

}  // namespace grip
