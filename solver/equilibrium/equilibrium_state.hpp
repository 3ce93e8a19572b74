#pragma once
// An equilibrium solve's answer: the state, its pairing and s, and the solver's counters.
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "solver/model/failure.hpp"
#include "solver/problem/problem.hpp"

namespace grip {

// The kinematics of one candidate at a state.
struct PairedPoint {
  SurfacePoint point;
  Projection projection;  // in the obstacle's moved frame: point already translated
  Vec2 eta, xi;           // eta = -normal (into the obstacle), xi = tangent
};

struct EquilibriumState {
  Vector q;
  Vector p;  // the contact forces in equilibrium (given, or from the penalty law)
  Vector s;  // (s_eta, s_xi) per component
  std::vector<PairedPoint> points;
  // Per obstacle: the master surface of a pair of bodies in this state's configuration (null
  // for a rigid obstacle); its force_derivative() is the pair's stiffness.
  std::vector<std::shared_ptr<const DeformedMaster>> masters;
  std::vector<char> enabled;  // component has a non-zero column of T on the free dofs
  int newton_iterations = 0;
  bool converged = false;
  // Converged at the round-off floor (not by the correction or residual test); then the
  // last correction (length units) is the noise of the displacements.
  bool at_floor = false;
  double noise = 0.0;
  double relative_residual = 0.0;           // final free residual over the force scale
  std::string reason;                       // why Newton failed
  FailureKind failure = FailureKind::none;  // newton_diverged, or invalid_state (the body refuses q)
};

struct EquilibriumCounters {
  long solves = 0;  // calls of solve(): real equilibrium solves
  long newton_iterations = 0;
  // Solves (and continued ones) that chord corrections ended, without a factorization of their own.
  long chord_solves = 0;
  // Moves of the body's multipliers inside real solves (exact incompressibility).
  long multiplier_updates = 0;
  // newton_ and body_factorizations together (docs/algorithm.md#where-factorizations-come-from)
  long factorizations = 0;
  long newton_factorizations = 0;     // Newton's tangent, and the penalty law's last correction
  long body_factorizations = 0;       // the body's own tangent: the compliance's, or a constant one
  long dissected_factorizations = 0;  // the body's tangent again, in nested-dissection order, for G only
  // Symbolic analyses (a fill-reducing ordering and the elimination tree; SparseLU's for a block
  // that is not positive definite): one per sparsity pattern of each block, and one more where
  // its order changes to nested dissection (FreeBlockSolver::analyses). Newton's tangent's, and
  // the body's own tangent's (with its second, nested-dissection factor's for G).
  long newton_analyses = 0;
  long body_analyses = 0;
  long compliance_forms = 0;    // G formed afresh (each on a factorization of its own)
  long compliance_columns = 0;  // columns of G solved for, all forms together
  // Process CPU seconds inside Newton's solves and inside the compliance's forms: where a run's
  // time goes, for the benchmarks (bench/kernels.py). Not in the result: they differ from run
  // to run.
  double newton_cpu_s = 0.0;
  double compliance_cpu_s = 0.0;

  EquilibriumCounters& operator+=(const EquilibriumCounters& o) {
    solves += o.solves;
    newton_iterations += o.newton_iterations;
    chord_solves += o.chord_solves;
    multiplier_updates += o.multiplier_updates;
    factorizations += o.factorizations;
    newton_factorizations += o.newton_factorizations;
    body_factorizations += o.body_factorizations;
    dissected_factorizations += o.dissected_factorizations;
    newton_analyses += o.newton_analyses;
    body_analyses += o.body_analyses;
    compliance_forms += o.compliance_forms;
    compliance_columns += o.compliance_columns;
    newton_cpu_s += o.newton_cpu_s;
    compliance_cpu_s += o.compliance_cpu_s;
    return *this;
  }
};

// Adds the process CPU time of its scope to `seconds`.
class CpuSpan {
 public:
  explicit CpuSpan(double& seconds) : seconds_(seconds), start_(std::clock()) {}
  ~CpuSpan() { seconds_ += static_cast<double>(std::clock() - start_) / CLOCKS_PER_SEC; }
  CpuSpan(const CpuSpan&) = delete;
  CpuSpan& operator=(const CpuSpan&) = delete;

 private:
  double& seconds_;
  std::clock_t start_;
};

}  // namespace grip
