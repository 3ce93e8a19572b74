#pragma once
// A contact problem in typed form: one deformable body, rigid obstacles, supports, loads, and
// the contact candidates. Built from a scene by solver/io; solved by solver/stepping.
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solver/model/body.hpp"
#include "solver/obstacles/master_surface.hpp"
#include "solver/obstacles/obstacle.hpp"

namespace grip {

// Loads, prescribed displacements and obstacle motions belong to load cases; each load step
// gives every case a factor (one case, "main", unless the scene has stages).
using LoadFactors = std::vector<double>;

// What a body's surface points pair with: a rigid obstacle (`shape`), or in a scene of several
// bodies a contact pair whose master is another body's surface (`master`, no shape).
struct ObstacleInstance {
  std::string name;
  std::unique_ptr<Obstacle> shape;
  // Coulomb coefficient (the paper's nu) in force at the current step: the load stepping
  // sets it from the step's stage.
  double friction = 0.0;
  bool frictional = false;         // friction > 0 in some stage: tangential unknowns exist
  std::vector<Vec2> translations;  // prescribed translation per load case at factor 1
  std::optional<MasterSurface> master;
  // The sites that pair with it (a contact's slave set); empty: every site of the body.
  std::vector<int> slaves;
  int slave_body = -1;  // the slave body of a contact pair (index into the scene's bodies)
  Vec2 offset(const LoadFactors& factors) const {
    Vec2 d = Vec2::Zero();
    for (size_t k = 0; k < translations.size() && k < factors.size(); ++k) d += factors[k] * translations[k];
    return d;
  }
};

// A prescribed dof: its value at factor 1 of its load case (zero for a plain support).
struct Constraint {
  int dof;
  double value = 0.0;
  int load_case = 0;
  // A finite rigid rotation (a `rotation` support of a body with finite kinematics): the dof is
  // component `axis` (0: x, 1: y) of a node at `arm` from the centre, `value` the angle at factor
  // 1; at factor t the node sits at R(t value) arm, on its circle, not on the chord.
  int axis = -1;
  Vec2 arm = Vec2::Zero();
  // The prescribed value at the factor t of its load case.
  double at(double t) const {
    if (axis < 0) return t * value;
    const double c = std::cos(t * value), s = std::sin(t * value);
    const Vec2 turned(c * arm.x() - s * arm.y(), s * arm.x() + c * arm.y());
    return (turned - arm)[axis];
  }
};

// One load step's target: a factor per load case and the friction per obstacle.
struct LoadStep {
  LoadFactors factors;
  std::vector<double> friction;
  int stage = 0;
};

// A candidate contact point: a body site's surface point on `side`, paired with `obstacle`.
// Its unknowns p are the components `eta` (normal) and `xi` (tangential; -1 without friction).
struct Candidate {
  int site;
  int side;
  int obstacle;
  int eta;
  int xi = -1;
};

// A body with no stiffness in its reference state (a flat membrane) starts its first step
// from a preliminary solve with one dof prescribed and no contact; the reaction there is the
// starting force of the candidate at `site` on `obstacle`
// (docs/algorithm.md#load-stepping-and-cuts).
struct StartUp {
  int dof;
  double value;
  int site;
  int obstacle;
};

// Rigid motions that the supports leave free and contact holds
// (docs/algorithm.md#bodies-held-only-by-contact). Each equilibrium solve prescribes one pin dof
// per mode at the mode's amplitude, so the body is held there and q = u + modes alpha, u zero at
// the pins; the amplitudes alpha join the contact unknowns as the components first.., and the pins'
// reactions -R^T (F + T p) must vanish: that equilibrium of the whole body is the component's s. In
// p an amplitude is stored divided by `scale` (length per force: 1 / the largest stiffness), and
// its s multiplied by it, so the compliance with its border [C, G; G^T, 0] stays symmetric and the
// error vector in length. In a scene of several bodies each mode moves one body (zero on the
// others' dofs): its s is that body's equilibrium, with the forces of its pairs on it (the mortar
// Jacobian moves both sides).
struct RigidModes {
  Matrix modes;  // dof x count, column k is 1 at pins[k] and 0 at the other pins
  std::vector<int> pins;
  std::vector<std::string> names;  // "translate along x", ...; "BODY: ..." in a scene of several bodies
  std::vector<int> body;           // the body each mode moves (index into the scene's bodies; 0 for one body)
  int first = 0;
  double scale = 1.0;
  int count() const { return static_cast<int>(pins.size()); }
  bool is_amplitude(int component) const { return component >= first && component < first + count(); }
};

struct Problem {
  std::unique_ptr<Body> body;
  std::vector<ObstacleInstance> obstacles;
  std::vector<Constraint> constraints;
  std::vector<Vector> loads;            // generalized external force per load case at factor 1
  std::vector<std::string> case_names;  // the load cases' names, in the order of the factors
  // The generalized external force at the given factors.
  Vector load(const LoadFactors& factors) const {
    Vector f = Vector::Zero(body->dof_count());
    for (size_t k = 0; k < loads.size() && k < factors.size(); ++k) f += factors[k] * loads[k];
    return f;
  }
  std::vector<Candidate> candidates;
  int component_count = 0;  // number of contact unknowns (with the rigid amplitudes, last)
  RigidModes rigid;
  std::optional<StartUp> start;
};

// Pairs every site with every obstacle, on the surface side that faces the obstacle in the
// reference configuration; tangential unknowns only where the obstacle has friction.
//
// With a load path and a reach: a site is paired with an obstacle only if the obstacle comes
// within `reach` of the site's reference position somewhere along the path (an obstacle that
// cannot reach the body contributes no candidates). reach <= 0: every site is paired.
void add_candidates(Problem& problem, const std::vector<LoadStep>& path = {}, double reach = 0.0);

}  // namespace grip
