#pragma once
// Nearly incompressible Mooney-Rivlin rubber (docs/algorithm.md#mooney-rivlin), decoupled:
//   W = c10 (I1b - 3) + c01 (I2b - 3) + bulk / 2 (J - 1)^2,
// I1b = J^(-2/3) I1 and I2b = J^(-4/3) I2 the invariants of the isochoric C. The shear
// modulus at small strain is mu = 2 (c10 + c01); bulk up to 1e4 x mu (and beyond) is accepted.
// Plane strain: C33 = 1; plane stress: C33 from S33 = 0 by Newton's method, the tangent
// condensed; axisymmetric: C33 = 1 + 2 E33 from the hoop stretch. The tangent dS/dE is the complex-step derivative of S (exact to round-off: no
// difference is taken, Squire and Trapp 1998), three or four evaluations of S per point.
#include <string>

#include "solver/materials/plane_material.hpp"

namespace grip {

// Why the constants are not a well-posed law (empty if they are), as "field: reason".
std::string mooney_rivlin_data_issue(double c10, double c01, double bulk);

class MooneyRivlinMaterial final : public PlaneMaterial {
 public:
  // Throws std::invalid_argument where mooney_rivlin_data_issue finds an issue.
  MooneyRivlinMaterial(double c10, double c01, double bulk, PlaneAnalysis analysis);
  MaterialResponse response(const Mat2& E) const override;
  HoopResponse hoop_response(const Mat2& E, double E33) const override;

 private:
  Eigen::Matrix4d tangent(double C11, double C22, double C12, double C33) const;

  double c10_, c01_, bulk_;
  PlaneAnalysis analysis_;
};

}  // namespace grip
