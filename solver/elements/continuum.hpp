#pragma once
// A plane continuum body: isoparametric triangles and quadrilaterals (plane_element.hpp) in
// plane strain, plane stress or axisymmetry (x = r, y = z, every point
// weighted by 2 pi r so that forces are totals over the full circle, `thickness` unused), with
// an elastic law (plane_material.hpp).
//   linear: small strain, sigma = D eps; K is constant, assembled once and reused (traits()
//   says so, and the equilibrium oracle then factorizes it once).
//   finite: total Lagrangian, S(E) of the law, exact tangent.
// A law with history (j2_plasticity) makes the linear body's tangent change: every integration
// point answers from its committed history, which commit() advances to an accepted state
// (docs/algorithm.md#j2-plasticity); under finite kinematics the law's finite_response (the
// multiplicative split, docs/algorithm.md#finite-strain-j2-plasticity), with F-bar's F_bar
// where f_bar is on.
// Elements: t3 (1 Gauss point), t6 (6 points), q4 (2 x 2 Gauss), q4_bbar (q4 with the mean
// dilatation of B-bar: for nu -> 1/2 in plane strain, linear kinematics), q8 and q9 (3 x 3).
//
// Dofs: (ux, uy) per node, node after node. Contact sites are the nodes of the contact set
// in order along the boundary (counter-clockwise round the body): a SUBSET of the nodes.
// site_node(site) maps a site to its node; cells() and site_fields() index NODES (all of
// them), so a site's row in site_fields is site_node(site). A site's surface point is the
// node itself (no offset; `side` is ignored) and its contact force acts on the node's two
// dofs. Tributary area = integral of the node's shape function over the contact sides x
// thickness (half the adjacent side lengths for t3 and q4); axisymmetric: x 2 pi r instead. A quadratic side (t6, q8, q9) is
// two contact segments, corner - mid-side - corner: its mid-side node is a site like the corners.
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "solver/elements/dilatation.hpp"
#include "solver/elements/plane_mesh.hpp"
#include "solver/model/body.hpp"
#include "solver/model/parallel.hpp"

namespace grip {

enum class ContinuumElement { q4, q4_bbar, q9, t3, t6, q8 };
enum class ContinuumKinematics { linear, finite };
// Against volumetric locking (finite kinematics; linear kinematics has q4_bbar): none; F-bar
// (q4, plane strain and axisymmetric; plane_element.hpp, dilatation.hpp); mixed, the u-p-theta
// form with the pressure discontinuous and condensed per element: q9 with a linear pressure
// (Q2/P1), t6 with a constant one (P2/P0), the pairs that satisfy inf-sup (dilatation.hpp);
// exact, the same elements with the volume held (theta = 1 at every point) by the pressure as a
// Lagrange multiplier, found by an augmented Lagrangian: the law's bulk modulus is its penalty,
// update_multipliers its Uzawa update (docs/algorithm.md#exact-incompressibility).
enum class Incompressibility { none, f_bar, mixed, exact };

struct ContinuumOptions {
  ContinuumElement element = ContinuumElement::q4;
  ContinuumKinematics kinematics = ContinuumKinematics::finite;
  PlaneAnalysis analysis = PlaneAnalysis::plane_strain;
  double thickness = 1.0;  // out-of-plane depth (plane strain: the length the results are per)
  Incompressibility incompressibility = Incompressibility::none;
};

// Why `incompressibility` is not offered with the other options (empty if it is): the reason the
// scene reader puts at /body/incompressibility (docs/algorithm.md#element-formulation-pairs).
std::string incompressibility_issue(const ContinuumOptions& options);

// The exact form's penalty (the law's bulk modulus) at least this many times the shear modulus:
// each update of the multipliers shrinks the volume error by about shear / bulk.
inline constexpr double kExactMinBulkOverShear = 100.0;
// The exact form's volume constraint holds where |theta - 1| is below this at every point.
inline constexpr double kExactVolumeTolerance = 1e-9;
// Why `law` cannot be made exactly incompressible (empty if it can), as "field: reason": only
// the elastic neo-Hookean and Mooney-Rivlin laws, with bulk / shear of kExactMinBulkOverShear.
std::string exact_law_issue(const PlaneMaterial& law);

ElementShape element_shape(ContinuumElement element);
// Axisymmetric (docs/algorithm.md#axisymmetric): the nodes at r = x < 0 (refused), and those on
// the axis r = 0 (their u_r is held at zero by the scene reader).
std::vector<int> nodes_off_half_plane(const PlaneMesh& mesh);
std::vector<int> axis_nodes(const PlaneMesh& mesh);
std::string id_list(const std::vector<int>& ids);    // "3, 7, 12" (the first 20 and a count)
const char* element_name(ContinuumElement element);  // as the scene names it: "q4_bbar", ...

// Why a law with history (j2_plasticity) under finite kinematics in axisymmetry takes no shared
// dilatation yet: the dilatation element asks the law's hoop response without history.
class ContinuumBody final : public Body {
 public:
  // The mesh must pass check_mesh (InvalidMesh otherwise); contact_set is a node set on the
  // boundary (boundary_part). Throws std::invalid_argument otherwise, or for q4_bbar with
  // finite kinematics.
  // `materials`: one for every element, or one per element (a body of several materials: the
  // physical surfaces of a mesh file).
  ContinuumBody(PlaneMesh mesh, const std::vector<int>& contact_set,
                std::vector<std::shared_ptr<const PlaneMaterial>> materials, ContinuumOptions options);

  int dof_count() const override { return 2 * node_count(); }
  Vector dof_length_scales() const override { return Vector::Ones(dof_count()); }
  // Finite kinematics: the element kernels run through the ParallelFor given to set_parallel
  // where the mesh is large enough to pay for the threads' wake-up (continuum.cpp,
  // kParallelPoints); their sums stay on the calling thread, in element order, so the answer is
  // the serial one to the last bit.
  void internal_force(const Vector& q, Vector& force, TangentSink* tangent) const override;
  // The threads the element kernels may use (empty: the calling thread alone). The solver starts
  // none: `grip solve` passes its team (assemble_on below).
  void set_parallel(ParallelFor parallel) { parallel_ = std::move(parallel); }

  int site_count() const override { return static_cast<int>(contact_.nodes.size()); }
  int site_node(int site) const override { return contact_.nodes[site]; }
  Vec2 site_reference(int site) const override { return mesh_.nodes[contact_.nodes[site]]; }
  SurfacePoint surface_point(const VectorRef& q, int site, int side) const override;
  void surface_point_into(const VectorRef& q, int site, int side, SurfacePoint& out) const override;
  // The contact sides, a quadratic side (t6, q8, q9) as its two halves.
  std::vector<std::array<int, 2>> surface_segments() const override;
  std::vector<int> nodes_without_site() const override;
  Vec2 node_position(const VectorRef& q, int node) const override {
    return mesh_.nodes[node] + Vec2(q[node_dof(node, 0)], q[node_dof(node, 1)]);
  }
  std::vector<int> add_sites(const std::vector<int>& nodes) override;
  // Plane: length x thickness; axisymmetric: the revolved area (integral of N 2 pi r ds).
  double tributary_area(int site) const override {
    return axisymmetric() ? contact_.revolved_areas[site] : contact_.lengths[site] * options_.thickness;
  }
  double characteristic_length() const override { return length_; }

  Vector rigid_translation(const Vec2& d) const override;
  Vector rigid_rotation() const override;
  // Small strain with history: the linear rotation, which leaves every small strain unchanged.
  Vector own_rotation_at(const Vector& q) const override;
  Traits traits() const override;
  // The integration points' history advances to the state at q (a law with history).
  void commit(const Vector& q) override;
  // The exact form: the Uzawa update p += bulk (theta - 1) of every point's pressure, where some
  // point's |theta - 1| exceeds kExactVolumeTolerance (then says where it is worst).
  std::string update_multipliers(const Vector& q) override;
  // The deformed volume of element e over its reference volume, minus 1 (by its integration
  // points: exact for t6 and q9, whose J they integrate exactly).
  double element_volume_change(const Vector& q, int e) const;
  bool axisymmetric() const override { return options_.analysis == PlaneAnalysis::axisymmetric; }
  std::optional<ElementQuality> element_quality() const override { return grip::element_quality(mesh_); }
  std::vector<std::vector<int>> cells() const override;  // element corners (node ids): 3 or 4
  // Per node: x, y (deformed), ux, uy.
  FieldTable site_fields(const Vector& q) const override;
  // Per element, at its centroid: Cauchy stress sxx, syy, sxy, szz (axisymmetric: srr, szz,
  // srz under the names sxx, syy, sxy, and the hoop stress under szz). A body with history:
  // the stresses are the element's volume averages over its integration points, and two more
  // columns follow: equivalent_plastic_strain (volume average) and yielding (the volume
  // fraction of the element whose points flow plastically at q: 0 elastic, 1 all of it).
  FieldTable element_fields(const Vector& q) const override;

  static int node_dof(int node, int component) { return 2 * node + component; }
  int node_count() const override { return static_cast<int>(mesh_.nodes.size()); }
  int element_count() const { return static_cast<int>(mesh_.elements.size()); }
  const PlaneMesh& mesh() const { return mesh_; }
  const ContinuumOptions& options() const { return options_; }
  // The contact sides (boundary sides spanned by the contact set).
  const BoundaryPart& contact_surface() const { return contact_; }
  // The committed history of a law with history, per element and point (element e's from
  // e x its point count); empty otherwise.
  const std::vector<PointHistory>& committed_history() const { return history_; }
  // Cauchy stress (sxx, syy, sxy, szz) at the centroid of element e.
  Eigen::Vector4d centroid_stress(const Vector& q, int e) const;

 private:
  ShapeGradients element_displacements(const Vector& q, int e) const;
  // Finite kinematics: element e's force fe and tangent Ke (if asked) at q, u and base_u its
  // work storage; `base`: the tangent's stress base (TangentSink::stress_base), or null.
  void element_kernel(const Vector& q, int e, ShapeGradients& u, Vector& fe, Matrix* Ke, const Vector* base,
                      ShapeGradients& base_u) const;
  // Adds fe into `force` at element e's dofs and hands Ke to the sink.
  void add_element(int e, const Vector& fe, const Matrix& Ke, Vector& force, TangentSink* tangent) const;
  // internal_force's finite kinematics with the kernels over parallel_ (storage in blocks_).
  void parallel_internal_force(const Vector& q, Vector& force, TangentSink* tangent) const;
  const ShapeGradients* mean_gradient(int e) const;
  // A law with history: the response of each integration point of element e at q.
  std::vector<PointResponse> point_responses(const Vector& q, int e) const;
  // Finite kinematics: the deformation gradient the law sees at each point of element e (F_bar
  // with f_bar and mixed), and the responses of a law with history to them (axisymmetric: with
  // the hoop stretch at q; the response's C33 is its square).
  std::vector<Mat2> point_deformations(const Vector& q, int e) const;
  std::vector<FinitePointResponse> finite_point_responses(const Vector& q, const std::vector<Mat2>& F, int e) const;

  // Integration points and the linear stiffness: built at the first solve, not by the
  // constructor, so that reading and validating a large scene stays cheap (the service reads
  // every submission on its HTTP thread and builds the body again on a worker).
  struct Integration {
    std::vector<std::vector<ElementPoint>> points;  // per element, reference configuration
    std::vector<ElementPoint> centroids;
    std::vector<ShapeGradients> mean_dN;  // per element (q4_bbar)
    std::vector<Dilatation> dilatation;   // per element: mixed, and F-bar in axisymmetry
    Triplets linear_tangent;              // linear kinematics: the constant K
    Eigen::SparseMatrix<double> linear_K;
  };
  const Integration& integration() const;

  PlaneMesh mesh_;
  ContinuumOptions options_;
  ElementShape shape_;
  const PlaneMaterial& material(int e) const { return *materials_[materials_.size() == 1 ? 0 : e]; }
  std::vector<std::shared_ptr<const PlaneMaterial>> materials_;
  BoundaryPart contact_;
  double length_ = 0.0;
  bool has_history_ = false;           // some element's law keeps history
  std::vector<PointHistory> history_;  // committed, per element and point (element e from e x points)
  // The exact form: the pressure (Lagrange multiplier) at each integration point and at the
  // centre of every element, and the element's penalty (its law's bulk modulus).
  std::vector<Vector> pressure_;
  std::vector<double> centre_pressure_, penalty_;
  mutable std::once_flag integration_once_;
  mutable std::unique_ptr<const Integration> integration_;

  ParallelFor parallel_;
  // The kernels' answers of one round of elements, computed on the threads before the calling
  // thread sums them; kept from call to call (nothing allocated once sized). The mutex keeps
  // two callers at once from sharing it: the second one runs serially.
  struct ElementBlocks {
    std::vector<Vector> fe;
    std::vector<Matrix> Ke;
    std::vector<ShapeGradients> u;       // the element's displacements
    std::vector<ShapeGradients> base_u;  // and at the tangent's stress base
  };
  mutable std::mutex blocks_mutex_;
  mutable ElementBlocks blocks_;
};

// Every continuum body in `body` (itself, or a BodySet's parts) runs its kernels through
// `parallel` (ContinuumBody::set_parallel); other bodies are left as they are.
void assemble_on(Body& body, const ParallelFor& parallel);

}  // namespace grip
