#pragma once
// A deformable master surface: boundary segments of a body of the problem, in the current
// configuration, paired segment-to-segment with a slave surface (a mortar method with dual
// Lagrange multipliers, Wohlmuth 2000, Popp et al. 2010, in 2D).
//
// The unknown of slave site j stays a force at that site (p_j = D_j lambda_j, D_j = int N_j
// its tributary length): the dual basis psi_j (2 N_j - N_other on each slave segment,
// int psi_j N_i = delta_ij D_j) makes the slave's side of the mortar coupling diagonal. The
// master takes -w_jk p_j at its site k, w_jk = M_jk / D_j, M_jk = int psi_j N_k over the slave
// segments: the consistent load of the slave's traction field, whichever side is finer. So a
// uniform pressure across a flat interface is carried exactly with either surface as slave
// (the patch test), where node-to-segment's split (1 - t, t) of each slave force between the
// two ends of one master segment is not consistent unless the slave is the finer side.
// The gap of site j is (x_j - x_m) . n with the mortar point x_m = sum_k w_jk x_k (the
// psi_j-weighted mean of the master surface over the slave segments around j: int psi_j
// (x_slave - x_master) . n / D_j), so T p = J^T f with the Jacobian of x_j - x_m.
// Integration: each slave segment is cut at the projections of the master sites onto its
// line; on each piece the integrand is quadratic, and two Gauss points make it exact.
// A slave site whose slave segments the master covers by less than half of D_j (a surface
// end beyond the master's) pairs node-to-segment: its closest point on the polyline through
// the master sites, as on a rigid profile (make_profile: corners, ends and extensions, no
// NaN), shared by (1 - t, t).
// The normal is smoothed: interpolated along each segment between the sites' mean normals
// (so it is continuous across the sites; the polyline's own corner normal turns with a
// stiffness of force / gap, unbounded as the gap closes).
// The pair's forces depend on both bodies' positions through the normal (its turn with the
// slave point's place along the segment and with the master's sites) and through the mortar
// weights (the slave's force redistributed over the master as the surfaces move along each
// other): force_derivative() gives that stiffness, by forward-mode differentiation of the
// same pairing code.
#include <array>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "solver/model/body.hpp"
#include "solver/obstacles/obstacle.hpp"

namespace grip {

struct MasterSurface {
  int body = -1;                                    // the master body (index into the scene's bodies)
  std::vector<std::vector<int>> chains;             // sites of the problem's body along each run, body on the left
  std::vector<std::vector<double>> reference_zeta;  // per chain and site: reference arc length
  // Per chain: a closed loop (a ring's boundary: its last site is its first again). Its seam is
  // a joint like the others: normals, mortar integrals and zeta run across it (zeta modulo the
  // loop's length).
  std::vector<char> closed;
  std::vector<std::vector<int>> slave_chains;  // the slave surface's runs (sites, body on the left)
  // The sides (Body::surface_point) of the master's and the slave's sites: 0 for a continuum's
  // boundary nodes; +1 (upper) or -1 (lower) for a beam's surface, its axis offset by half its depth.
  int side = 0, slave_side = 0;
};

// The chains through the given segments ([a, b], body on the left of a -> b), each followed
// from a segment that no other segment ends at (or any, for a closed loop); zeta from 0 along
// the master's chains in the reference configuration, continuing from one chain to the next.
MasterSurface make_master_surface(const Body& body, int body_index, const std::vector<std::array<int, 2>>& segments,
                                  const std::vector<std::array<int, 2>>& slave_segments, int side = 0,
                                  int slave_side = 0);

// zeta1 - zeta0 on the master: on a closed chain taken modulo its length (into (-L/2, L/2]).
double master_zeta_difference(const MasterSurface& surface, double zeta1, double zeta0);

struct MasterPoint {
  Projection projection;                     // zeta: the master's reference arc length (material, for slips)
  std::vector<PointJacobianEntry> jacobian;  // of -x_m: -w_k dx_k over the master sites
};

class DeformedMaster {
 public:
  DeformedMaster(const Body& body, const Vector& q, const MasterSurface& surface);
  // The pairing of slave point x; `slave_site` (a site of a slave chain, or -1) selects its
  // mortar weights where it has them.
  MasterPoint project(const Vec2& x, int slave_site = -1) const;
  // d(T p)/dq of the pair's generalized forces at the slave point `slave` (of `slave_site`)
  // for given (p_eta, p_xi): the slave takes J^T f, f = p_eta eta + p_xi xi, master site k
  // -w_k J_k^T f, and f and w move with the normal and the weights. Triplets (row, col,
  // d force_row / d q_col) for the pair alone (continuum sites: constant point Jacobians),
  // each with its transpose's place (a zero): the pattern stays symmetric.
  void force_derivative(const SurfacePoint& slave, int slave_site, double p_eta, double p_xi, Triplets& out) const;
  // The gradients over the dofs of the gap (x - x_m) . n and of the surface coordinate zeta of
  // the slave point `slave` (of `slave_site`), both bodies' dofs, as (dof, derivative) entries
  // (a dof may repeat: add them): d(s_eta)/dq = -gap gradient, d(s_xi)/dq = zeta gradient. Beside
  // the Jacobian's part n . J, they hold the normal's turn and the mortar weights' shift, which
  // a law p(s) (penalty) needs in its tangent: with k the penalty stiffness, these are k x the
  // master's curvature terms, where force_derivative's are p x them.
  void gradients(const SurfacePoint& slave, int slave_site, std::vector<std::pair<int, double>>& gap,
                 std::vector<std::pair<int, double>>& zeta) const;

 private:
  struct Chain {
    std::unique_ptr<Obstacle> profile;
    std::vector<SurfacePoint> points;
    std::vector<double> zeta;  // current arc length at each site
    const std::vector<double>* reference;
    bool closed = false;
    // The reference zeta of site k, on a closed chain the one of its values (k's, plus or minus
    // the loop's length) nearest to `near`.
    double reference_near(int k, double near) const;
  };
  struct Closest {
    Projection projection;
    int chain = 0, segment = 0;
    double t = 0.0;  // along the segment, unclamped beyond the chain's ends
  };
  Closest closest(const Vec2& x) const;
  // The pairing of a slave point in dual numbers over the positions it reads (master_surface.cpp).
  struct DualPairing;
  DualPairing dual_pairing(const SurfacePoint& slave, int slave_site) const;
  void integrate_mortar(const Body& body, const Vector& q, const MasterSurface& surface);
  // The master chain and runs of segments (first, last) that slave segment a -> b integrates
  // against (two runs where it spans a closed chain's seam); none where its ends are closest to
  // different chains.
  std::vector<std::array<int, 3>> mortar_ranges(const Vec2& a, const Vec2& b) const;
  std::vector<Chain> chains_;
  const MasterSurface* surface_ = nullptr;
  std::map<int, SurfacePoint> slave_points_;  // the slave surface's sites (their surface points)
  // Per slave site: (chain, index) of master sites and the weights w_jk.
  std::map<int, std::vector<std::pair<std::array<int, 2>, double>>> mortar_;
};

}  // namespace grip
