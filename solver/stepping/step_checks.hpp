#pragma once
// Checks of a converged state against the physics it claims, made before load stepping accepts
// it and independent of a strategy's own stopping test (||v|| in length units, which a state
// can pass while wrong: an obstacle through the body, a held body out of balance). See
// docs/robustness.md. Any floor above equilibrium may call them (load stepping does, on every
// converged attempt).
//   balance      the resultant force and moment of every body (the pins of a body held by contact
//                carry nothing real), over the loads, contact forces and reactions it carries
//   tension      the largest pull p_n > 0 at a contact point, over the largest |p_n|
//   cone         the largest |p_t| - mu |p_n|, over the largest |p_n|
//   penetration  the deepest boundary point inside a rigid obstacle (every site against every
//                obstacle, and the boundary nodes that carry no site), a length
//   normal_turn  the largest turn of a pressing point's contact normal since the last accepted
//                state (degrees)
//   obstacle_motion  before a solve: an obstacle's travel in the increment over the smallest of
//                the body's element size and the obstacle's radius of curvature
#include <string>
#include <vector>

#include "solver/contact/strategy.hpp"

namespace grip {

// The worst value of each check over a step's accepted increments.
struct StepChecks {
  double balance = 0.0;
  double tension = 0.0;
  double cone = 0.0;
  double penetration = 0.0;
  double normal_turn = 0.0;
  double obstacle_motion = 0.0;
  int boundary_points = 0;  // boundary points held against the obstacles
  void worst_of(const StepChecks& o);
};

// What a check refuses beyond (relative values as in StepChecks).
struct StepCheckLimits {
  double balance;
  double tension;
  double cone;
  double penetration;  // length
  double normal_turn = 90.0;
  double obstacle_motion = 1.0;
};
StepCheckLimits check_limits(const Problem& problem, const ContactParams& contact);

// A boundary point outside the candidates that entered an obstacle, or came within reach of one
// it is not paired with: `site` >= 0 for a site, else `node` carries no site.
struct OutsidePoint {
  int site = -1;
  int node = -1;
  int obstacle = 0;
  double gap = 0.0;
  bool entered = false;  // inside the obstacle (else only within reach)
};

// The last accepted state's contact normals and forces (normal_turn compares against them).
struct AcceptedContact {
  std::vector<Vec2> eta;  // per candidate
  Vector p;
};
AcceptedContact accepted_contact(const EquilibriumState& state, const Vector& p);

class StepChecker {
 public:
  // reach: the scene's contact reach (0: the body's characteristic length); a site within it of
  // an obstacle it is not paired with is reported (OutsidePoint, entered false).
  StepChecker(const Problem& problem, const ContactParams& contact, double reach);

  // Before solving the increment from -> to: the largest obstacle travel over its bound (an
  // increment beyond 1 is to be cut into at least that many parts), and why in `why`.
  double increment(const LoadFactors& from, const LoadFactors& to, StepChecks& worst, std::string& why) const;
  // A converged state with forces p (after the strategy's stopping test): why it cannot be
  // accepted (empty if it can); `outside` gets the boundary points outside the candidates that
  // entered an obstacle or came within reach (not a failure by itself: the caller decides).
  std::string state(const Equilibrium& eq, const EquilibriumState& s, const Vector& p, const AcceptedContact& before,
                    StepChecks& worst, std::vector<OutsidePoint>& outside) const;

  const StepCheckLimits& limits() const { return limits_; }

 private:
  struct Pairing {
    int site;
    int side;
    int obstacle;
  };
  // The rigid motions of each body (translations along x and y, the rotation where the model
  // has one), each on that body's dofs only, with the body's characteristic length.
  struct BodyModes {
    std::vector<Vector> modes;
    double length;
  };
  const Problem& problem_;
  bool penalty_;
  double reach_;
  StepCheckLimits limits_;
  std::vector<Pairing> outside_sites_;   // (site, rigid obstacle) not among the candidates
  std::vector<int> nodes_without_site_;  // held against every rigid obstacle
  double element_size_ = 0.0;            // the largest spacing of neighbouring sites
  std::vector<BodyModes> body_modes_;    // of the reference configuration, formed once
  static std::vector<BodyModes> body_modes(const Body& body);
  // The largest force a checked state carried in this run: the scale of round-off where a
  // state carries almost nothing (a punch lifted off).
  mutable double force_level_ = 0.0;
};

}  // namespace grip
