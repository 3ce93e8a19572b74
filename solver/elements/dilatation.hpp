#pragma once
// A volume change shared by an element's integration points (docs/algorithm.md#mixed-u-p),
// finite kinematics, total Lagrangian. Every point k hands the law F_bar = s_k F with
// s_k = (theta_k / J_k)^(1/d): J_k the volume ratio there (det F, times the hoop stretch F33 in
// axisymmetry, where F33 is scaled too), d = 2 in plane strain (in-plane) and 3 in axisymmetry,
// and theta_k = sum_j A(k, j) J_j: the mixed u-p-theta form (Simo, Taylor and Pister, CMAME 51,
// 1985) with the pressure and the dilatation discontinuous, in one space per element: theta is
// the L2 projection of J onto that space (constant: P0; linear in X, Y: P1), and the pressure,
// the projection of dW/dtheta, is condensed at element level (it never reaches the global
// system). F-bar in axisymmetry is its P0 case on q4 (the element's mean J).
// The element's energy is sum W(F_bar) dV; the internal force is its gradient and the tangent
// its exact second derivative (symmetric), through dtheta and dJ.
#include <vector>

#include "solver/elements/plane_element.hpp"

namespace grip {

struct Dilatation {
  std::vector<ElementPoint> points;  // where J is read: the element's Gauss points
  Matrix A;                          // theta = A J: a row per integration point, a column per dilatation point
  Eigen::RowVectorXd centre;         // theta at the element's centre (the stress the results report)
};

// The L2 projection of J onto the pressure space of `order` 0 (constant) or 1 (1, X, Y) over
// the element's points (weights dV, so axisymmetry weighs by 2 pi r); X the element's node
// coordinates (a row per node), `centre` its centre point.
Dilatation projected_dilatation(const std::vector<ElementPoint>& points, const ElementPoint& centre,
                                const ShapeGradients& X, int order);

// The volume ratio at a point: det F, times F33 = 1 + u_r / R in axisymmetry.
double volume_ratio(const ElementPoint& point, const ShapeGradients& u);
// s_k = (theta_k / J_k)^(1/d) of each point: F_bar = s F (and F33_bar = s F33 in axisymmetry).
Vector dilatation_scales(const std::vector<ElementPoint>& points, const Dilatation& dilatation,
                         const ShapeGradients& u);
// theta = A J at each point, and at the centre.
Vector projected_ratios(const Dilatation& dilatation, const ShapeGradients& u);
double centre_projected_ratio(const Dilatation& dilatation, const ShapeGradients& u);
// The same s at the element's centre.
double centre_dilatation_scale(const ElementPoint& centre, const Dilatation& dilatation, const ShapeGradients& u);
// Internal force fe and (if given) the tangent Ke of the element. `law` and `hoop_law` as for
// total_lagrangian, asked at each point's E_bar (and E33_bar in axisymmetry). `pressure` (the
// exact form), a multiplier per point: the energy gains sum p_k (theta_k - 1) dV. `base` (the
// tangent's stress base, with Ke): Ke is taken at the dilatation linearized about it, theta_lin
// = A (J(u_b) + dJ(u_b) (u - u_b)), in place of theta (the force stays exact).
void dilatation_total_lagrangian(const std::vector<ElementPoint>& points, const Dilatation& dilatation,
                                 const ShapeGradients& u, const PlaneMaterial& material, Vector& fe, Matrix* Ke,
                                 const PointLaw& law = {}, const HoopLaw& hoop_law = {},
                                 const Vector* pressure = nullptr, const ShapeGradients* base = nullptr);

}  // namespace grip
