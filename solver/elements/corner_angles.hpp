#pragma once
// The half-disc generator's shape check (half_disc_mesh.cpp), in a header of its own so that
// plane_mesh.hpp, which every body and test includes, stays as it was.
#include "solver/elements/plane_mesh.hpp"

namespace grip {

// Whether every corner angle lies in [lo, hi] degrees: element_quality's min_angle >= lo and
// max_angle <= hi for a mesh with elements, at a fraction of its cost (atan2 only for corners
// within 1e-12 of a limit: element_quality for the 11,520 elements of Hertz a/h 40 took 9 M
// instructions at every scene read).
bool corner_angles_within(const PlaneMesh& mesh, double lo, double hi);

}  // namespace grip
