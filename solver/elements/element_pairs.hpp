#pragma once
// Which element and formulation pairs a nearly incompressible body may use
// (docs/algorithm.md#element-formulation-pairs). A displacement element imposes the volume
// constraint at each of its integration points; where those outnumber what its nodes can
// follow, a nearly incompressible body locks (too stiff by a factor that grows with K / G).
// Refused, in plane strain and axisymmetry: t3 and the plain q4 with a law of K / G above
// kLockingBulkOverShear or with plastic flow (isochoric). Accepted: q4_bbar, q4 with F-bar
// (one dilatation per element: the Q1-P0 pair), t6, q8, q9 (measured:
// tests/verification/element_pairs_test.cpp). Plane stress does not lock.
#include <string>

#include "solver/elements/continuum.hpp"

namespace grip {

// K / G above which the plain q4 and t3 are refused (nu above 0.476): there the plain q4 on
// 8 x 8 is already 4 % too stiff on a volume-keeping deformation, and 13 % at K / G = 50.
inline constexpr double kLockingBulkOverShear = 20.0;

// Why `element` with `options` locks with `law` (empty if it does not): a sentence that says
// why and what to use instead.
std::string element_pair_issue(const ContinuumOptions& options, const PlaneMaterial& law);

}  // namespace grip
