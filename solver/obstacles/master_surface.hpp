#pragma once
// A deformable master surface (node-to-segment pairing): boundary segments of a body of the
// problem, in the current configuration. A slave point projects onto the polyline through the
// master sites' current positions as onto a rigid profile (make_profile: the same corners,
// ends and extensions, no NaN), and its pairing carries the Jacobian of the master point
// x_m = (1 - t) x_a + t x_b, so that the relative point x_slave - x_m moves with both bodies:
// T p = J^T f then puts f on the slave and -f, shared by (1 - t, t), on the master.
// The normal is smoothed: interpolated along each segment between the sites' mean normals
// (so it is continuous across the sites; the polyline's own corner normal, (x - x_site) /
// |x - x_site|, turns with a stiffness of force / gap, unbounded as the gap closes). The
// gap is (x - x_m) . n; the stiffness of the normal's turn is left out of dnormal_dx.
#include <memory>
#include <vector>

#include "solver/core/body.hpp"
#include "solver/obstacles/obstacle.hpp"

namespace grip {

struct MasterSurface {
  int body = -1;                         // the master body (index into the scene's bodies)
  std::vector<std::vector<int>> chains;  // sites of the problem's body along each run, body on the left
  std::vector<std::vector<double>> reference_zeta;  // per chain and site: reference arc length
};

// The chains through the given segments ([a, b], body on the left of a -> b), each followed
// from a segment that no other segment ends at (or any, for a closed loop); zeta from 0 along
// them in the reference configuration, continuing from one chain to the next.
MasterSurface make_master_surface(const Body& body, int body_index, const std::vector<std::array<int, 2>>& segments);

struct MasterPoint {
  Projection projection;  // zeta: the master's reference arc length (material, for slips)
  std::vector<PointJacobianEntry> jacobian;  // of -x_m: -(1 - t) dx_a and -t dx_b
};

class DeformedMaster {
 public:
  DeformedMaster(const Body& body, const Vector& q, const MasterSurface& surface);
  MasterPoint project(const Vec2& x) const;

 private:
  struct Chain {
    std::unique_ptr<Obstacle> profile;
    std::vector<SurfacePoint> points;
    std::vector<double> zeta;            // current arc length at each site
    std::vector<Vec2> normal;            // outward normal at each site: the mean of its sides' normals
    const std::vector<double>* reference;
  };
  std::vector<Chain> chains_;
};

}  // namespace grip
