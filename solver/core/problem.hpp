#pragma once
// A contact problem in typed form: one deformable body, rigid obstacles, supports, loads, and
// the contact candidates. Built from a scene by solver/io; solved by solver/solve.
#include <memory>
#include <string>
#include <vector>

#include "solver/core/body.hpp"
#include "solver/obstacles/obstacle.hpp"

namespace grip {

struct ObstacleInstance {
  std::string name;
  std::unique_ptr<Obstacle> shape;
  double friction = 0.0;                 // Coulomb coefficient (the paper's nu)
  Vec2 translation = Vec2::Zero();       // prescribed translation at load factor 1, ramped
  Vec2 offset(double load_factor) const { return load_factor * translation; }
};

// A prescribed dof: its value at load factor 1, ramped (zero for a plain support).
struct Constraint {
  int dof;
  double value = 0.0;
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

struct Problem {
  std::unique_ptr<Body> body;
  std::vector<ObstacleInstance> obstacles;
  std::vector<Constraint> constraints;
  Vector load;  // generalized external force at load factor 1
  std::vector<Candidate> candidates;
  int component_count = 0;  // number of contact unknowns
};

// Pairs every site with every obstacle, on the surface side that faces the obstacle in the
// reference configuration; tangential unknowns only where the obstacle has friction.
void add_candidates(Problem& problem);

}  // namespace grip
