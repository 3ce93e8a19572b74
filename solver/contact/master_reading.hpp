#pragma once
// The contact stresses of a pair of bodies read on its master body: the slave's traction field
// (its nodal stresses p / tributary length) interpolated linearly along the slave surface to
// where each master site meets it (the closest point on the slave polyline, current
// configuration). The interface carries one traction field, whichever body it is read from
// (what a mortar method's multiplier field is); the master's nodal forces are instead its
// consistent loads, smeared by one slave element at a contact edge. A master site presses
// where every slave node of its slave segment with a weight above 1e-6 presses: the zone read
// from the master is the slave's. Signs as the slave's: sigma_n <= 0 presses, sigma_t along
// the slave's tangent xi.
#include <vector>

#include "solver/problem/problem.hpp"

namespace grip {

struct MasterReading {
  int site = 0;  // a site of the problem's body (on the master body)
  double sigma_n = 0.0, sigma_t = 0.0;
  bool pressing = false;
};

// One reading per site of the master body of the pair on `obstacle`, in site order, at the
// displacements q, contact forces p and friction bounds tau of a step.
std::vector<MasterReading> master_readings(const Problem& problem, const Vector& q, const Vector& p, const Vector& tau,
                                           int obstacle);

}  // namespace grip
