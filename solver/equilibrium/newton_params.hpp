#pragma once
// Newton's parameters for the equilibrium solves (Equilibrium, newton.cpp).
#include "solver/model/parallel.hpp"

namespace grip {

// Newton's stopping tests, each always reachable in floating point (docs/algorithm.md#newtons-stopping-tests-and-the-round-off-floor). An
// iterate is converged when one of them holds:
// - correction: the largest correction, in length units (rotations times their dof's length
//   scale), is below `displacement_tolerance` (the contact loop's precision);
// - residual: the largest free residual, in force units (moments over the length scale), is
//   below `residual_tolerance` times the force scale (the largest of the applied loads, the
//   internal forces, which hold the reactions, and the contact forces);
// - round-off floor: after a first correction, the residual is within `floor_factor` x
//   machine precision of the scale of the sums that form it (|K| |q| + force scale), where
//   a further correction is noise. Recorded in the state.
// couple_newton() sets the first two from the contact tolerance.
struct NewtonParams {
  int max_iterations = 40;
  double displacement_tolerance = 1e-10;  // length
  double residual_tolerance = 1e-11;      // relative to the force scale
  double floor_factor = 1e2;
  // Diverged when a correction exceeds this many body lengths.
  double divergence_lengths = 10.0;
  // Steps of the line search along a Newton correction.
  int max_backtracks = 8;
  // Runs the bodies' own factorizations and solves of a scene of several bodies (the solver
  // starts no threads of its own); empty: one after another.
  ParallelFor parallel;
};

// Newton's tests as a fraction of the contact tolerance (relative to `length`, the body's
// characteristic length): the contact error has a floor of about ||K^-1|| x the Newton
// residual, so Newton must be that much tighter (docs/algorithm.md#newtons-stopping-tests-and-the-round-off-floor).
inline void couple_newton(NewtonParams& newton, double contact_tolerance, double fraction, double length) {
  newton.displacement_tolerance = fraction * contact_tolerance * length;
  newton.residual_tolerance = fraction * contact_tolerance;
}

}  // namespace grip
