#pragma once
// SOLVE(U, p) of ALGORITHM.md section 5: equilibrium of eq. 1-2 for given contact forces p,
// by Newton's method with the pairing, T(u) and the stiffness of the follower contact load
// d(T(u) p)/du re-evaluated at every iterate. Also the contact compliance C = T^T K^-1 T.
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <optional>
#include <string>
#include <vector>

#include "solver/core/problem.hpp"
#include "solver/solve/free_block_solver.hpp"

namespace grip {

struct NewtonParams {
  int max_iterations = 40;
  // Converged when the largest correction, in length units (rotations times the body's
  // length), is below this. Set by the contact strategy from its tolerance.
  double displacement_tolerance = 1e-10;
  // Diverged when a correction exceeds this many body lengths.
  double divergence_lengths = 10.0;
  // Halvings of a Newton correction that does not lower the residual norm.
  int max_backtracks = 8;
};

// The kinematics of one candidate at a state.
struct PairedPoint {
  SurfacePoint point;
  Projection projection;  // in the obstacle's moved frame: point already translated
  Vec2 eta, xi;           // eta = -normal (into the obstacle), xi = tangent
};

struct EquilibriumState {
  Vector q;
  Vector p;                   // the contact forces in equilibrium (given, or from the penalty law)
  Vector s;                   // (s_eta, s_xi) per component
  std::vector<PairedPoint> points;
  std::vector<char> enabled;  // component has a non-zero column of T on the free dofs
  int newton_iterations = 0;
  bool converged = false;
  std::string reason;         // why Newton failed
};

struct EquilibriumCounters {
  long solves = 0;            // calls of solve(): real equilibrium solves
  long newton_iterations = 0;
  long factorizations = 0;
};

// The penalty baseline (strategy `penalty`): p_eta = -k_n <s_eta>, and a tangential spring
// k_t on the incremental slip from the previous step's force, returned to the Coulomb cone.
struct PenaltyLaw {
  double normal = 0.0;      // k_n, force / length
  double tangential = 0.0;  // k_t, force / length
  Vector previous;          // the previous step's forces (the tangential springs start there)
};

// The contact compliance C = T^T K^-1 T on a subset of the components (the ones that can
// take part in this iteration); zero elsewhere.
struct Compliance {
  std::vector<int> position;  // component -> row of `block`, -1 where not computed
  Matrix block;
  double operator()(int a, int b) const {
    const int i = position[a], j = position[b];
    return i < 0 || j < 0 ? 0.0 : block(i, j);
  }
  // C restricted to the given components, in their order.
  Matrix sub(const std::vector<int>& components) const;
};

class Equilibrium {
 public:
  // `extra` prescribes further dofs at absolute values (the start-up solve).
  Equilibrium(const Problem& problem, NewtonParams params, std::vector<Constraint> extra = {});

  // Sets the load factor (loads, prescribed dofs, obstacle positions) and the surface
  // coordinates zeta of the last converged step that the slips s_xi are measured from.
  void set_step(LoadFactors factors, std::vector<double> zeta_previous);
  const LoadFactors& factors() const { return factors_; }

  EquilibriumState solve(const Vector& q_guess, const Vector& p);
  // With a penalty law set, solve() ignores its p and finds p(q) from the law.
  void set_penalty(std::optional<PenaltyLaw> law) { penalty_ = std::move(law); }
  // The largest diagonal entry of the body's stiffness at q: a scale for penalty stiffnesses.
  double stiffness_scale(const Vector& q) const;
  // The pairing and s at q, without solving (e.g. the reference configuration).
  EquilibriumState evaluate(const Vector& q) const;
  // C = T^T K^-1 T over the given components, from the body's own tangent at state.q
  // (symmetric). The reference stays valid until the next call (the storage is reused).
  const Compliance& compliance(const EquilibriumState& state, const std::vector<int>& components);
  // The linear model's displacement change K^-1 T dp for a force change dp, from the last
  // compliance (its components only): where the next solve should start.
  Vector predicted_change(const Compliance& C, const Vector& dp) const;
  // R = A(q) - lambda F - T(q) p on every dof, and (if asked) the triplets of dR/dq, with
  // the pairing evaluated at q.
  Vector residual(const Vector& q, const Vector& p, Triplets* tangent) const;
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
  // R = A(q) - lambda F - T p on all dofs; tangent of R (with the contact load stiffness).
  Vector residual(const Vector& q, const EquilibriumState& paired, const Vector& p,
                  Triplets* tangent) const;
  // p(q) of the penalty law at a paired state, and (if asked) its stiffness triplets.
  Vector penalty_forces(const EquilibriumState& paired, Triplets* tangent) const;
  double free_residual_norm(const Vector& q, const Vector& p) const;
  double scaled_free_norm(const Vector& r) const;
  void fill_t_matrix(const EquilibriumState& state, const std::vector<int>& position);

  const Problem& problem_;
  NewtonParams params_;
  LoadFactors factors_;
  std::vector<double> zeta_previous_;
  std::vector<Constraint> extra_;
  std::optional<PenaltyLaw> penalty_;
  std::vector<int> free_index_;  // dof -> free index, -1 if prescribed
  int free_count_ = 0;
  Vector length_scales_;
  EquilibriumCounters counters_;
  // The body's own tangent, factorized once when it is constant (linear kinematics): then
  // Newton is a modified Newton on it and the compliance reuses it.
  bool factorize_body_tangent(const Vector& q);
  bool constant_tangent_ = false;
  bool body_factorized_ = false;
  FreeBlockSolver body_lu_;  // the body's own tangent (compliance, constant tangents)
  FreeBlockSolver lu_;       // Newton's tangent, with the contact terms
  Matrix t_, x_;  // compliance work storage, reused
  Compliance c_;
};

}  // namespace grip
