#pragma once
// The rigid motions that supports leave free and contact holds (problem.rigid, RigidModes in
// problem.hpp): their form at a state, the amplitudes fitted to a state, and which a model can
// hold. What contact must do to hold them: solver/contact/held_by_contact.hpp.
#include <string>
#include <vector>

#include "solver/problem/problem.hpp"

namespace grip {

// The change of the rigid amplitudes (problem.rigid, in their unit) that follows the supports
// from load factors `from` to `to`: for each body with free rigid motions, the rigid motion that
// fits the change of its prescribed values by least squares and has the least norm over its dofs
// (no part along the motions the supports leave free), read at its pins. A step then starts
// with a held body where its supports take it, not turned about them.
Vector amplitudes_following_supports(const Problem& problem, const LoadFactors& from, const LoadFactors& to);

// Why a free rotation of `body` cannot be held by contact with finite kinematics ("" where it
// can), its supported dofs `fixed` (the body's own numbering): the model must have a finite
// rotation of its own (the continuum, the von Karman beam: rigid_modes.cpp), and the
// supports may hold at most one node, about which the rotation then turns at any angle
// (supports at several nodes leave it free to first order only).
std::string finite_rotation_refusal(const Body& body, const std::vector<int>& fixed);

// The free rigid motions of problem.rigid at the state q, 1 at their own pin and 0 at the other
// pins. For a body with finite kinematics left free to rotate: the translations and the rotation
// at q (the continuum's about its current shape, the von Karman beam's own: rigid_modes.cpp),
// zero at its supports (docs/algorithm.md#bodies-held-only-by-contact): the internal forces of a deformed body do no work along
// it, so that is where the contact forces and the load must balance too. Elsewhere
// problem.rigid.modes itself (a constant tangent, or translations only: the same at every state).
Matrix rigid_modes_at(const Problem& problem, const Vector& q);
// Whether rigid_modes_at changes with the state for some body of the problem.
bool rigid_modes_follow_state(const Problem& problem);

// The rigid motion fitted to q: (x, y, rotation in radians; no rotation for a body without
// one), the translation that of the point at the origin. With finite kinematics (the continuum)
// the rotation and translation that carry the reference positions closest to the current ones
// (exact at any angle); otherwise by least squares over the body's infinitesimal translations
// and rotation about the origin (exact for those).
Vector rigid_amplitudes(const Body& body, const Vector& q);

}  // namespace grip
