#pragma once
// Isoparametric plane elements, as plain functions that fill a local vector and matrix (the
// body assembles). Node orders are gmsh's:
//   t3  corners counter-clockwise; natural coordinates (xi, eta) on the triangle (0, 0),
//       (1, 0), (0, 1) (xi and eta are the area coordinates of corners 1 and 2);
//   t6  t3's corners, then the mid-sides of 0-1, 1-2, 2-0 (quadratic);
//   q4  corners counter-clockwise from (xi, eta) = (-1, -1) on the square [-1, 1]^2;
//   q8  q4's corners, then the mid-sides of 0-1, 1-2, 2-3, 3-0 (serendipity);
//   q9  q8's nodes and the centre (biquadratic Lagrange).
// Local dofs are (u0x, u0y, u1x, ...). Strains and stresses in Voigt order (11, 22, 12) with
// the engineering shear strain.
#include <Eigen/Core>
#include <functional>
#include <vector>

#include "solver/materials/plane_material.hpp"

namespace grip {

enum class ElementShape { t3, t6, q4, q8, q9 };

const char* shape_name(ElementShape shape);  // "t3", ...
int element_node_count(ElementShape shape);
int element_corner_count(ElementShape shape);  // 3 or 4
bool is_quadratic(ElementShape shape);         // t6, q8, q9: sides of 3 nodes
// The local nodes of each side, counter-clockwise: 2 (t3, q4) or 3 (corner, mid-side, corner).
const std::vector<std::vector<int>>& element_sides(ElementShape shape);

using ShapeGradients = Eigen::Matrix<double, Eigen::Dynamic, 2>;  // one row per node

// Natural coordinates (xi, eta) of node a, and of the centroid.
Vec2 node_natural(ElementShape shape, int a);
Vec2 centre_natural(ElementShape shape);
// Shape functions N and their derivatives dN/d(xi, eta) at (xi, eta).
void shape_functions(ElementShape shape, double xi, double eta, Vector& N, ShapeGradients& dN);

struct GaussPoint {
  double xi, eta, weight;
};
// t3: 1 point (constant strain: exact); t6: the 6-point rule of degree 4 (exact stiffness of
// straight-sided t6, whose integrand has degree 2, and room for the finite-strain integrand);
// q4: 2 x 2; q8 and q9: 3 x 3 (exact stiffness on parallelograms).
const std::vector<GaussPoint>& gauss_rule(ElementShape shape);

// The reference-configuration data of one integration point.
struct ElementPoint {
  Vector N;             // shape functions
  ShapeGradients dN;    // dN/dX in the reference configuration
  double detJ = 0.0;    // det dX/d(xi, eta); <= 0 means an inverted or degenerate element
  double dV = 0.0;      // weight * detJ * thickness (axisymmetric: weight * detJ * 2 pi r)
  double radius = 0.0;  // axisymmetric: r = sum N_a X_a (> 0 at every Gauss point); else 0
};

// X holds the element's node coordinates, one row per node.
ElementPoint element_point(ElementShape shape, const ShapeGradients& X, double xi, double eta, double weight_thickness);
std::vector<ElementPoint> element_points(ElementShape shape, const ShapeGradients& X, double thickness);

// The volume average of dN/dX over the element: the gradient of the mean dilatation.
ShapeGradients mean_gradients(const std::vector<ElementPoint>& points);

// Small strain: eps = B u (3 x 2n). With `mean_dN` (B-bar, plane strain), the in-plane
// volumetric part (eps11 + eps22) / 2 of both normal strains is replaced by the element mean,
// which removes volumetric locking as nu -> 1/2 and keeps the constant-strain patch test.
Matrix strain_matrix(const ElementPoint& point, const ShapeGradients* mean_dN);
// Axisymmetric (x = r, y = z): the point weighted by the full circle, dV = weight detJ 2 pi r,
// and its radius kept. Throws std::logic_error if r <= 0 there (no Gauss point of these
// elements lies on an edge, so only an element crossing the axis can get there).
void make_axisymmetric(ElementPoint& point, const ShapeGradients& X);
// Small strain in axisymmetry: (e_rr, e_zz, g_rz, e_tt) = B u (4 x 2n), e_tt = u_r / r.
Matrix axisymmetric_strain_matrix(const ElementPoint& point);
// Ke = sum B^T D B dV with the 4 x 4 D of (rr, zz, rz, tt).
Matrix axisymmetric_stiffness(const std::vector<ElementPoint>& points, const Eigen::Matrix4d& D);
// Ke = sum B^T D B dV.
Matrix small_strain_stiffness(const std::vector<ElementPoint>& points, const Eigen::Matrix3d& D,
                              const ShapeGradients* mean_dN);

// Total Lagrangian: F = I + sum u_a (x) dN_a/dX; internal force f_a = sum F S dN_a dV and, if
// Ke is given, its exact derivative B^T D B + (dN_a . S dN_b) I. u holds the nodal
// displacements, one row per node. Axisymmetric points (radius R > 0): F33 = 1 + u_r / R, the
// hoop strain E33 = (F33^2 - 1) / 2 from the law's hoop_response; f_a gains F33 S33 N_a / R in
// r, B the row dE33 = F33 N_a / R du_r, and Ke the hoop geometric term S33 N_a N_b / R^2 (r-r).
Mat2 deformation_gradient(const ElementPoint& point, const ShapeGradients& u);
// Node a's column pair of the in-plane rows of dE = B du (E11, E22, 2 E12) at F, from the
// node's shape gradient (gx, gy): the rows every total-Lagrangian kernel fills.
template <class BMatrix>
inline void green_lagrange_rows(BMatrix& B, int a, const Mat2& F, double gx, double gy) {
  B(0, 2 * a) = F(0, 0) * gx;
  B(0, 2 * a + 1) = F(1, 0) * gx;
  B(1, 2 * a) = F(0, 1) * gy;
  B(1, 2 * a + 1) = F(1, 1) * gy;
  B(2, 2 * a) = F(0, 0) * gy + F(0, 1) * gx;
  B(2, 2 * a + 1) = F(1, 0) * gy + F(1, 1) * gx;
}
// `law`, if given, answers for `material` in the plane at each integration point (index into
// `points`) from the Green-Lagrange strain E there: a law with history answers from that
// point's committed state.
using PointLaw = std::function<MaterialResponse(int point, const Mat2& E)>;
// `hoop_law`, if given, answers for `material` at axisymmetric points from E and the hoop E33.
using HoopLaw = std::function<HoopResponse(int point, const Mat2& E, double E33)>;
// `base_u`, if given with Ke: the element's displacements at the state the geometric stiffness's
// stress is linearized about (TangentSink::stress_base): Ke takes S - D dE, dE = H^T H / 2 with H
// the gradient of u - base_u, the stress of E(base) + dE/du (u - base_u) where S is linear in E
// (Saint Venant-Kirchhoff), to first order otherwise; axisymmetric: E33 likewise. fe is at u.
void total_lagrangian(const std::vector<ElementPoint>& points, const ShapeGradients& u, const PlaneMaterial& material,
                      Vector& fe, Matrix* Ke, const PointLaw& law = {}, const HoopLaw& hoop_law = {},
                      const ShapeGradients* base_u = nullptr);

// Small strain with a law that keeps history (J2 plasticity, linear kinematics): at each point k
// the strain (11, 22, 2 x 12, 33) = B u (B-bar's rows with `mean_dN`; the hoop row u_r / r at
// axisymmetric points, zero in the plane), the law's answer from that point's committed state
// history[k]; fe = sum B^T stress dV and, if Ke is given, sum B^T D B dV with D symmetrized
// ((D + D^T) / 2: the same Ke as B^T D B symmetrized). Fixed-size per element kind, like
// total_lagrangian: no allocation.
void small_strain_history(const std::vector<ElementPoint>& points, const ShapeGradients* mean_dN,
                          const ShapeGradients& u, const PlaneMaterial& material, const PointHistory* history,
                          Vector& fe, Matrix* Ke);

// F-bar in plane strain: the law sees F_bar = (J0 / J)^(1/2) F, whose in-plane determinant is
// J0 = det F at the element's centre (`centre`), so that every point changes volume as the
// centre does (no volumetric locking as the law nears incompressibility). The element's energy
// is sum W(F_bar) dV; its gradient, f_a = sum [dev(tau) h_a + tr(tau) / 2 h0_a] dV with tau =
// F_bar S F_bar^T, h_a = F^-T dN_a/dX and h0_a that of the centre, and Ke its exact (symmetric)
// derivative. `base` (the tangent's stress base, with Ke): Ke is taken at J0 linearized about
// it, det F0(u_b) (1 + h0(u_b) : (u - u_b)), in place of J0 (the force stays exact).
void f_bar_total_lagrangian(const std::vector<ElementPoint>& points, const ElementPoint& centre,
                            const ShapeGradients& u, const PlaneMaterial& material, Vector& fe, Matrix* Ke,
                            const PointLaw& law = {}, const ShapeGradients* base = nullptr);
// F-bar's F_bar = (J0 / J)^(1/2) F at a point, J0 = det F at the centre.
Mat2 f_bar(const ElementPoint& point, const ElementPoint& centre, const ShapeGradients& u);

// The Cauchy stress (sxx, syy, sxy, szz) for a deformation gradient F (in-plane) and the
// material response at E = (F^T F - I) / 2.
Eigen::Vector4d cauchy_stress(const Mat2& F, const MaterialResponse& response);

}  // namespace grip
