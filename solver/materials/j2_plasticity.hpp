#pragma once
// J2 (von Mises) elastoplasticity at small strain (docs/algorithm.md#j2-plasticity): Hooke's
// law on the elastic strain eps - eps_p, the yield function
//   f = |dev(sigma) - beta| - sqrt(2/3) sigma_y(alpha),
// associative flow, isotropic hardening sigma_y(alpha) of the equivalent plastic strain alpha
// and linear kinematic hardening of the back stress beta (d beta = 2/3 H_k d eps_p). In
// uniaxial tension sigma = sigma_y(alpha) + H_k alpha on the plastic branch.
// The return is the radial return of Simo and Hughes (Computational Inelasticity, box 3.1)
// with its consistent tangent; plane stress finds eps33 from s33 = 0 by Newton's method on
// that return (and condenses the tangent), so that the plane-stress state is exact.
// Finite strain (j2_finite.cpp; docs/algorithm.md#finite-strain-j2-plasticity): F = Fe Fp,
// Hooke's law on the logarithmic elastic strain, and the same radial return on it, which is
// the exponential-map return (plastic flow exact in volume: det Fp = 1); isotropic hardening
// only, plane strain and plane stress.
#include <string>
#include <utility>
#include <vector>

#include "solver/materials/plane_material.hpp"

namespace grip {

// sigma_y(alpha), nondecreasing.
struct IsotropicHardening {
  enum class Kind { linear, power, table };
  Kind kind = Kind::linear;
  double modulus = 0.0;  // linear: sigma_y = yield_stress + modulus alpha
  // power (Swift): sigma_y = K (alpha0 + alpha)^n, alpha0 = (yield_stress / K)^(1/n) so that
  // sigma_y(0) = yield_stress.
  double K = 0.0, n = 0.0;
  // table: (alpha, sigma_y) points, alpha from 0 increasing, sigma_y nondecreasing; linear
  // between them and constant beyond the last (as Abaqus *PLASTIC).
  std::vector<std::pair<double, double>> table;
};

// Why the data are not a well-posed J2 law (empty if they are), as "field: reason" with the
// field relative to the material ("yield_stress", "hardening/table/2/1", ...).
std::string j2_data_issue(double yield_stress, const IsotropicHardening& hardening, double kinematic_modulus);

class J2Material final : public PlaneMaterial {
 public:
  // Throws std::invalid_argument where j2_data_issue finds an issue.
  J2Material(double young, double poisson, double yield_stress, IsotropicHardening hardening, double kinematic_modulus,
             PlaneAnalysis analysis);
  // The elastic law (Hooke's), what the material is until it yields.
  MaterialResponse response(const Mat2& E) const override;
  bool has_history() const override { return true; }
  bool isochoric_flow() const override { return true; }
  PointResponse small_strain_response(const Eigen::Vector4d& strain, const PointHistory& committed) const override;
  FinitePointResponse finite_response(const Mat2& E, const PointHistory& committed) const override;
  std::string finite_strain_issue() const override;

  double yield_stress(double alpha) const;     // sigma_y(alpha)
  double hardening_slope(double alpha) const;  // d sigma_y / d alpha (right derivative)

 private:
  // The 3D return with eps33 given.
  PointResponse return_map(const Eigen::Vector4d& strain, const PointHistory& committed) const;
  // Finite strain at the in-plane E and E33: S (11, 22, 12, 33) and dS/dE (4 x 4, E as
  // (11, 22, 2 x 12, 33)) in `law.S`, `law.S33` and `D`.
  FinitePointResponse finite_point(const Mat2& E, double E33, const PointHistory& committed, Eigen::Matrix4d& D) const;

  HookeMaterial elastic_;
  Lame lame_;
  PlaneAnalysis analysis_;
  double yield_stress_;
  IsotropicHardening hardening_;
  double kinematic_;
  double alpha0_ = 0.0;  // power law
};

}  // namespace grip
