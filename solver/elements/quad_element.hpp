#pragma once
// Isoparametric quadrilaterals for plane bodies, as plain functions that fill a local vector
// and matrix (the body assembles). Four-node (bilinear) and nine-node (biquadratic Lagrange)
// elements. Node order: corners counter-clockwise from (xi, eta) = (-1, -1); for q9 then the
// mid-sides of edges 0-1, 1-2, 2-3, 3-0 and the centre. Local dofs are (u0x, u0y, u1x, ...).
// Strains and stresses in Voigt order (11, 22, 12) with the engineering shear strain.
#include <Eigen/Core>
#include <vector>

#include "solver/materials/plane_material.hpp"

namespace grip {

enum class QuadShape { q4, q9 };

using ShapeGradients = Eigen::Matrix<double, Eigen::Dynamic, 2>;  // one row per node

int quad_node_count(QuadShape shape);
// Natural coordinates (xi, eta) of node a.
Vec2 quad_node_natural(QuadShape shape, int a);
// Shape functions N and their derivatives dN/d(xi, eta) at (xi, eta).
void quad_shape_functions(QuadShape shape, double xi, double eta, Vector& N, ShapeGradients& dN);

struct GaussPoint {
  double xi, eta, weight;
};
// 2 x 2 Gauss points for q4, 3 x 3 for q9: exact stiffness on parallelograms.
const std::vector<GaussPoint>& quad_gauss_rule(QuadShape shape);

// The reference-configuration data of one integration point.
struct QuadPoint {
  Vector N;           // shape functions
  ShapeGradients dN;  // dN/dX in the reference configuration
  double detJ = 0.0;  // det dX/d(xi, eta); <= 0 means an inverted or degenerate element
  double dV = 0.0;    // weight * detJ * thickness
};

// X holds the element's node coordinates, one row per node.
QuadPoint quad_point(QuadShape shape, const ShapeGradients& X, double xi, double eta, double weight_thickness);
std::vector<QuadPoint> quad_points(QuadShape shape, const ShapeGradients& X, double thickness);

// The volume average of dN/dX over the element: the gradient of the mean dilatation.
ShapeGradients mean_gradients(const std::vector<QuadPoint>& points);

// Small strain: eps = B u (3 x 2n). With `mean_dN` (B-bar, plane strain), the in-plane
// volumetric part (eps11 + eps22) / 2 of both normal strains is replaced by the element mean,
// which removes volumetric locking as nu -> 1/2 and keeps the constant-strain patch test.
Matrix strain_matrix(const QuadPoint& point, const ShapeGradients* mean_dN);
// Ke = sum B^T D B dV.
Matrix small_strain_stiffness(const std::vector<QuadPoint>& points, const Eigen::Matrix3d& D,
                              const ShapeGradients* mean_dN);

// Total Lagrangian: F = I + sum u_a (x) dN_a/dX; internal force f_a = sum F S dN_a dV and, if
// Ke is given, its exact derivative B^T D B + (dN_a . S dN_b) I. u holds the nodal
// displacements, one row per node.
Mat2 deformation_gradient(const QuadPoint& point, const ShapeGradients& u);
void total_lagrangian(const std::vector<QuadPoint>& points, const ShapeGradients& u, const PlaneMaterial& material,
                      Vector& fe, Matrix* Ke);

// The Cauchy stress (sxx, syy, sxy, szz) for a deformation gradient F (in-plane) and the
// material response at E = (F^T F - I) / 2.
Eigen::Vector4d cauchy_stress(const Mat2& F, const MaterialResponse& response);

}  // namespace grip
