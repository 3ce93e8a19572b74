#pragma once
// A deformable body model: internal force A(q), its tangent K(q), and the surface points
// where contact candidates sit (eq. 1-3).
#include <Eigen/SparseCore>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "solver/model/tangent_sink.hpp"
#include "solver/model/types.hpp"

namespace grip {

// Named columns of per-site or per-element output values.
struct FieldTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;
};

// dx / dq for one degree of freedom: the point moves by `dx` per unit of q[dof].
struct PointJacobianEntry {
  int dof;
  Vec2 dx;
};

// A point on the body's surface in the current configuration and its Jacobian. By virtual
// work, a force f at the point is the generalized force J^T f (for a beam this includes the
// moment of f about the node through the offset, eq. 3).
struct SurfacePoint {
  Vec2 x = Vec2::Zero();
  std::vector<PointJacobianEntry> jacobian;
  // The contact surface lies this far from x toward the obstacle (a membrane's half
  // thickness about its mid-surface node); it shortens the gap and is frozen in T.
  double clearance = 0.0;
};

class Body {
 public:
  virtual ~Body() = default;
  virtual int dof_count() const = 0;
  // Length that one unit of each dof moves the body by (1 for translations, a length for
  // rotations): makes Newton's displacement test unit-consistent.
  virtual Vector dof_length_scales() const = 0;
  // Adds the internal force A(q) into `force` (sized dof_count) and, if `tangent` is given,
  // the entries of dA/dq, the same ones in the same order at every call.
  virtual void internal_force(const Vector& q, Vector& force, TangentSink* tangent) const = 0;

  // Sites that can carry a contact candidate (beam and membrane: the element end nodes).
  virtual int site_count() const = 0;
  // Nodes of the model's mesh (what the service's size limit counts): the sites themselves
  // where every node is a site.
  virtual int node_count() const { return site_count(); }
  // Reference (undeformed centre-line) position of a site.
  virtual Vec2 site_reference(int site) const = 0;
  // The node that carries a site: its row of site_fields and its index in cells. The site
  // itself where every node is a site (beam, membrane); a node of the contact boundary for
  // the continuum, whose sites are a subset of its nodes.
  virtual int site_node(int site) const { return site; }
  // The surface point of `site` on side +1 (upper) or -1 (lower), at state q.
  virtual SurfacePoint surface_point(const VectorRef& q, int site, int side) const = 0;
  // The same point into `out`, whose Jacobian's storage a model may reuse (Newton's pairing at
  // every iterate then allocates nothing). Default: surface_point's, moved in.
  virtual void surface_point_into(const VectorRef& q, int site, int side, SurfacePoint& out) const {
    out = surface_point(q, site, side);
  }
  // The straight pieces of the contact surface between sites, each [a, b] with the body on
  // the left of a -> b: what a slave surface of another body pairs with (mortar segments).
  // Empty where the model offers no master surface.
  virtual std::vector<std::array<int, 2>> surface_segments() const { return {}; }
  // Nodes of the boundary that carry no site (the continuum's boundary outside its contact
  // set): with the sites, every boundary point that the step checks hold against the obstacles.
  virtual std::vector<int> nodes_without_site() const { return {}; }
  // The current position of such a node (an index of node_count()).
  virtual Vec2 node_position(const VectorRef& /*q*/, int /*node*/) const { return Vec2::Zero(); }
  // Makes boundary nodes sites, with the boundary sides that join them to the boundary (their
  // indices after the existing sites, which keep theirs): a node that entered an obstacle outside
  // the contact set becomes a contact candidate. Returns the sites added; none where the model
  // cannot (its every boundary node is already a site).
  virtual std::vector<int> add_sites(const std::vector<int>& /*nodes*/) { return {}; }
  // Surface area that a site's contact force acts on (tributary length x width).
  virtual double tributary_area(int site) const = 0;
  // Characteristic length (size of the undeformed body): the scale of relative tolerances.
  virtual double characteristic_length() const = 0;

  // The generalized displacement that translates the whole body by d.
  virtual Vector rigid_translation(const Vec2& d) const = 0;
  // An infinitesimal rigid rotation by one radian about the origin (empty if the model has
  // none): with the translations, the motions that supports must remove.
  virtual Vector rigid_rotation() const { return {}; }
  // For a model with a changing tangent whose own finite rotation is not the turn of its current
  // positions (the von Karman beam): the rate of that rotation at q, by one radian about the
  // origin. Empty (default): the model has none of its own (solver/problem/rigid_modes.cpp).
  virtual Vector own_rotation_at(const Vector& /*q*/) const { return {}; }
  // The node that a dof moves (default: two dofs a node, x and y).
  virtual int dof_node(int dof) const { return dof / 2; }

  // A body made of several (BodySet: a scene of several bodies) answers for its parts: their
  // number, each part, and the dof and the site each part starts at (b = part_count(): the
  // totals). A single body is not made of parts (part_count() 0) and is its own part 0.
  virtual int part_count() const { return 0; }
  virtual const Body& part(int /*b*/) const { return *this; }
  virtual int dof_offset(int b) const { return b == 0 ? 0 : dof_count(); }
  virtual int site_offset(int b) const { return b == 0 ? 0 : site_count(); }

  // What the model simulates, for the result's effects block; a constant tangent lets one
  // factorization serve every solve.
  struct Traits {
    bool geometric_nonlinearity = true;
    bool plasticity = false;
    bool constant_tangent = false;
    // Stiff in its reference state (a continuum, a beam). A membrane is not: its transverse
    // stiffness is its tension's, which the stiffness of contact forces turning with a curved
    // obstacle may nearly cancel (docs/algorithm.md#the-contact-compliance).
    bool reference_stiffness = true;
    // Its tangent takes TangentSink::stress_base (a finite-strain continuum).
    bool linearized_stress = false;
    // Its elements hold the volume by a dilatation of their own (incompressibility mixed, f_bar;
    // finite strain, a law without history): its tangent takes the dilatation linearized about
    // TangentSink::stress_base, and a load step's Newton starts from the last converged state,
    // not one extrapolated from it (docs/algorithm.md#newtons-tangent-the-linearized-dilatation).
    bool volume_constrained = false;
  };
  virtual Traits traits() const { return {}; }
  // A section of a body of revolution (x = r, y = z: the axis): of its rigid motions only the
  // translation along y is one (u_r = const strains the hoops, and the section does not rotate).
  virtual bool axisymmetric() const { return false; }
  // Shape of the elements of a plane mesh (none for line models).
  virtual std::optional<ElementQuality> element_quality() const { return std::nullopt; }

  // Sites of each cell, for plots and VTK: pairs for lines, the corners (counter-clockwise) of
  // triangles (3) and quadrilaterals (4).
  virtual std::vector<std::vector<int>> cells() const = 0;

  // Output: deformed position and displacements per site; stresses or section forces per element.
  virtual FieldTable site_fields(const Vector& q) const = 0;
  virtual FieldTable element_fields(const Vector& q) const = 0;

  // A Newton start for a body that has no stiffness in its reference state (a flat membrane):
  // given the prescribed values (and where they are prescribed), a displacement consistent
  // with them. Default: the prescribed values, zero elsewhere.
  virtual Vector start_guess(const Vector& prescribed, const std::vector<char>& /*is_prescribed*/) const {
    return prescribed;
  }

  // Newton's trust region: the fraction (0, 1] of the correction dq at q that keeps the
  // iterate on the physical branch (a membrane must not fold). Default: all of it.
  virtual double newton_step_fraction(const Vector& /*q*/, const Vector& /*dq*/) const { return 1.0; }
  // Why a converged state is not physical (empty if it is): e.g. a membrane in compression.
  virtual std::string inadmissible(const Vector& /*q*/) const { return {}; }
  // Where a converged state lies beyond the range the model is accurate for (empty if it
  // does not): the answer stands, with this warning (e.g. a von Karman beam rotated far).
  virtual std::string validity_warning(const Vector& /*q*/) const { return {}; }

  // Loads that turn with the body (a reissner_beam's follower forces): adds their generalized
  // force at q and the load cases' factors into `force` and, if `tangent` is given, the triplets
  // of its derivative (unsymmetric: a follower load has no potential). Default: none.
  virtual bool has_follower_loads() const { return false; }
  virtual void follower_load(const Vector& /*q*/, const std::vector<double>& /*factors*/, Vector& /*force*/,
                             Triplets* /*tangent*/) const {}

  // Bodies with history (plasticity) keep old/new state; commit after a converged step.
  virtual void commit(const Vector& /*q*/) {}
  // Constraints held by multipliers that an augmented Lagrangian updates (Uzawa), the exactly
  // incompressible continuum's: at a converged state q, empty where they hold; otherwise the
  // multipliers move and the answer says how far off q is (the increment is solved again).
  virtual std::string update_multipliers(const Vector& /*q*/) { return {}; }
};

}  // namespace grip
