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
// the exponential-map return (plastic flow exact in volume: det Fp = 1); plane strain, plane
// stress and axisymmetric (the hoop stretch r / R the third direction). With kinematic hardening
// or Hill's anisotropy, whose back stress and axes the principal-space return cannot carry: the
// small-strain return on the Lagrangian log strain log(C) / 2 (additive, also exact in volume).
#include <optional>
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

// Hill's 1948 anisotropy (docs/algorithm.md#hill-1948-anisotropy) from the Lankford
// coefficients r = width / thickness plastic strain ratio in uniaxial tension at 0, 45 and 90
// degrees to the rolling direction; the yield stress is that in the rolling direction. The
// sheet's axes in the plane: plane stress, x rolling, y transverse, z the thickness (r0, r45,
// r90); plane strain, the section through the thickness, x rolling, y the thickness, z
// transverse (r0 and r90: the sheet-plane shear that r45 sets is zero there); axisymmetric, r
// and theta in the sheet, z its normal: a normal r only (r0 = r45 = r90; planar anisotropy
// would vary round the circle). The through-thickness shears, which no r fixes, keep their
// isotropic coefficient 3/2.
struct Hill48 {
  double r0 = 1.0, r45 = 1.0, r90 = 1.0;
};

// Why the r-values are not usable in `analysis` (empty if they are), as "field: reason" with the
// field relative to the material ("hill48/r0", ...).
std::string hill48_data_issue(const Hill48& hill, PlaneAnalysis analysis);
// Hill's M of sigma_bar^2 = s . M s, s = (11, 22, 12, 33) in the analysis' axes (von Mises at r = 1).
Eigen::Matrix4d hill48_metric(const Hill48& hill, PlaneAnalysis analysis);

// Why the data are not a well-posed J2 law (empty if they are), as "field: reason" with the
// field relative to the material ("yield_stress", "hardening/table/2/1", ...).
std::string j2_data_issue(double yield_stress, const IsotropicHardening& hardening, double kinematic_modulus);

class J2Material final : public PlaneMaterial {
 public:
  // Throws std::invalid_argument where j2_data_issue finds an issue.
  // With `hill`, Hill's 1948 yield function in place of von Mises' (j2_hill48.cpp).
  J2Material(double young, double poisson, double yield_stress, IsotropicHardening hardening, double kinematic_modulus,
             PlaneAnalysis analysis, std::optional<Hill48> hill = std::nullopt);
  // The elastic law (Hooke's), what the material is until it yields.
  MaterialResponse response(const Mat2& E) const override;
  bool has_history() const override { return true; }
  bool isochoric_flow() const override { return true; }
  PointResponse small_strain_response(const Eigen::Vector4d& strain, const PointHistory& committed) const override;
  FinitePointResponse finite_response(const Mat2& E, const PointHistory& committed) const override;
  // Axisymmetric finite strain: the return of finite_response with the hoop stretch as the
  // third principal direction (E33 = (F33^2 - 1) / 2 given, as the plane-strain one at E33 = 0).
  FiniteHoopResponse finite_hoop_response(const Mat2& E, double E33, const PointHistory& committed) const override;

  double yield_stress(double alpha) const;     // sigma_y(alpha)
  double hardening_slope(double alpha) const;  // d sigma_y / d alpha (right derivative)

 private:
  // The 3D return with eps33 given (Hill's where the law has it).
  PointResponse return_map(const Eigen::Vector4d& strain, const PointHistory& committed) const;
  // The closest-point return in Hill's metric (j2_hill48.cpp).
  PointResponse hill_return(const Eigen::Vector4d& strain, const PointHistory& committed) const;
  // Finite strain at the in-plane E and E33: S (11, 22, 12, 33) and dS/dE (4 x 4, E as
  // (11, 22, 2 x 12, 33)) in `law.S`, `law.S33` and `D`.
  FinitePointResponse finite_point(const Mat2& E, double E33, const PointHistory& committed, Eigen::Matrix4d& D) const;
  // The same with kinematic hardening or Hill's anisotropy: additive plasticity in the Lagrangian
  // logarithmic strain (j2_finite.cpp).
  FinitePointResponse log_strain_point(const Mat2& E, double E33, const PointHistory& committed,
                                       Eigen::Matrix4d& D) const;

  HookeMaterial elastic_;
  Lame lame_;
  PlaneAnalysis analysis_;
  double yield_stress_;
  IsotropicHardening hardening_;
  double kinematic_;
  double alpha0_ = 0.0;  // power law
  // Hill: sigma_bar^2 = s . M s with s = (11, 22, 12, 33); M s is the flow direction (engineering
  // shear). Von Mises: no M.
  std::optional<Hill48> hill_;
  Eigen::Matrix4d hill_metric_ = Eigen::Matrix4d::Zero();
};

}  // namespace grip
