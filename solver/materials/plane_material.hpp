#pragma once
// Elastic laws for plane bodies, in total Lagrangian form: the second Piola-Kirchhoff stress S
// and its tangent dS/dE from the in-plane Green-Lagrange strain E. Under small strain E is the
// linear strain and S the Cauchy stress. Voigt order (11, 22, 12); strain vectors carry the
// engineering shear 2 E12, so that S . dE is the work per unit reference volume.
// Plane strain: E33 = 0, S33 follows. Plane stress: S33 = 0, E33 follows (condensed out of
// the tangent). Axisymmetric: the section in the r-z half-plane (x = r, y = z), direction 3 the
// hoop direction; the laws answer as in plane strain at E33 = 0 (S33 the hoop stress there) and
// give the hoop stiffness dS33/dE33, which the axisymmetric element (small strain) needs;
// under finite kinematics the axisymmetric element asks hoop_response with the hoop strain E33.
// Units are the scene's: young in force / length^2.
#include <Eigen/Core>
#include <memory>
#include <string>

#include "solver/model/types.hpp"

namespace grip {

enum class PlaneAnalysis { plane_strain, plane_stress, axisymmetric };

// Response of a law at one material point.
struct MaterialResponse {
  Eigen::Vector3d S = Eigen::Vector3d::Zero();           // (S11, S22, S12)
  Eigen::Matrix3d D = Eigen::Matrix3d::Zero();           // dS/dE, with E as (E11, E22, 2 E12); symmetric
  double S33 = 0.0;                                      // out-of-plane normal stress (zero in plane stress)
  Eigen::RowVector3d dS33 = Eigen::RowVector3d::Zero();  // dS33/dE (zero in plane stress)
  double C33 = 1.0;                                      // out-of-plane stretch squared (one in plane strain)
  double dS33_dE33 = 0.0;                                // hoop stiffness at E33 = 0 (zero in plane stress)
};

// What a law with history (J2 plasticity) keeps at one integration point between accepted
// steps; elastic laws keep nothing in it.
struct PointHistory {
  Eigen::Vector4d plastic_strain = Eigen::Vector4d::Zero();  // small strain: (11, 22, 2 x 12, 33)
  Eigen::Vector4d back_stress = Eigen::Vector4d::Zero();     // small strain: (11, 22, 12, 33)
  double equivalent_plastic_strain = 0.0;                    // alpha = integral of sqrt(2/3) |d eps_p|
  // Finite strain: Cp^-1 = Fp^-1 Fp^-T (11, 22, 12, 33), of determinant one (isochoric flow).
  Eigen::Vector4d plastic_metric_inverse = Eigen::Vector4d(1, 1, 0, 1);
};

// Finite-strain response of a point with history: the law's answer to E from the committed
// history, and the history at E (what a commit keeps).
struct FinitePointResponse {
  MaterialResponse law;
  PointHistory history;
  bool yielding = false;  // the point flows plastically from its committed state
};

// Response of a law to the in-plane and the hoop strain (axisymmetric finite kinematics), in the
// order (11, 22, 12, 33) with E as (E11, E22, 2 E12, E33).
struct HoopResponse {
  Eigen::Vector4d S = Eigen::Vector4d::Zero();
  Eigen::Matrix4d D = Eigen::Matrix4d::Zero();
};

// Axisymmetric finite strain of a point with history: the hoop response from the committed
// history, and the history at (E, E33) (what a commit keeps).
struct FiniteHoopResponse {
  HoopResponse law;
  PointHistory history;
  bool yielding = false;  // the point flows plastically from its committed state
};

// Small-strain response of a point with history, in the order (11, 22, 12, 33) of the
// axisymmetric element (rr, zz, rz, tt): strain with the engineering shear, 33 the hoop strain
// in axisymmetry and zero in plane strain.
struct PointResponse {
  Eigen::Vector4d stress = Eigen::Vector4d::Zero();
  // d stress / d strain (the consistent tangent). Plane stress: the in-plane block condensed
  // on s33 = 0, row and column 3 zero.
  Eigen::Matrix4d D = Eigen::Matrix4d::Zero();
  PointHistory history;   // the state at this strain: what a commit keeps
  bool yielding = false;  // the point flows plastically from its committed state
};

class PlaneMaterial {
 public:
  virtual ~PlaneMaterial() = default;
  // The response to the in-plane Green-Lagrange strain E (symmetric 2x2).
  virtual MaterialResponse response(const Mat2& E) const = 0;
  // The small-strain law: the response at E = 0 (the same Hooke's law for every law here).
  MaterialResponse small_strain() const { return response(Mat2::Zero()); }
  // The small-strain 4 x 4 law of (11, 22, 12, 33) from the plane block and the row of S33
  // (plane stress: row and column 3 zero).
  Eigen::Matrix4d small_strain_D4() const;
  // Whether the law keeps history at its points: then the body evaluates small_strain_response
  // (linear kinematics) or finite_response at every integration point and commits what it answers.
  virtual bool has_history() const { return false; }
  // The small-strain response to `strain` (11, 22, 2 x 12, 33; 33 ignored in plane stress)
  // from the committed history. Elastic laws: Hooke's law, history unchanged.
  virtual PointResponse small_strain_response(const Eigen::Vector4d& strain, const PointHistory& committed) const;
  // The finite-strain response to E from the committed history. Elastic laws: response(E).
  virtual FinitePointResponse finite_response(const Mat2& E, const PointHistory& committed) const {
    return {response(E), committed, false};
  }
  // K / G of the law at small strain, its nearness to incompressibility (plane strain and
  // axisymmetric; 0 in plane stress, which does not lock).
  double bulk_over_shear() const;
  // Whether plastic flow keeps the volume (J2): in the plastic range the body is then
  // incompressible whatever K / G (docs/algorithm.md#element-formulation-pairs).
  virtual bool isochoric_flow() const { return false; }
  // Axisymmetric finite strain: S (11, 22, 12, 33) and dS/dE (4 x 4, symmetric) for the
  // in-plane E and the hoop E33 = (F33^2 - 1) / 2 (F33 = r / R). Laws with history answer
  // finite_hoop_response instead.
  virtual HoopResponse hoop_response(const Mat2& E, double E33) const;
  // hoop_response from the committed history. Elastic laws: hoop_response(E, E33).
  virtual FiniteHoopResponse finite_hoop_response(const Mat2& E, double E33, const PointHistory& committed) const {
    return {hoop_response(E, E33), committed, false};
  }
};

// Lame constants from Young's modulus and Poisson's ratio (3D values: plane stress is
// obtained by condensation, not by a modified lambda).
struct Lame {
  double lambda, mu;
  static Lame from(double young, double poisson) {
    return {young * poisson / ((1 + poisson) * (1 - 2 * poisson)), young / (2 * (1 + poisson))};
  }
};

// Hooke's law S = D E; as a finite-strain law it is Saint Venant-Kirchhoff.
class HookeMaterial final : public PlaneMaterial {
 public:
  HookeMaterial(double young, double poisson, PlaneAnalysis analysis);
  MaterialResponse response(const Mat2& E) const override;
  HoopResponse hoop_response(const Mat2& E, double E33) const override;

 private:
  Lame lame_;
  PlaneAnalysis analysis_;
  Eigen::Matrix3d D_;
};

// Compressible neo-Hookean: W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2, so
// S = mu (I - C^-1) + lambda ln J C^-1 (3D); its small-strain limit is Hooke's law.
// Plane stress solves S33 = 0 for C33 by Newton's method at every call.
class NeoHookeMaterial final : public PlaneMaterial {
 public:
  NeoHookeMaterial(double young, double poisson, PlaneAnalysis analysis);
  MaterialResponse response(const Mat2& E) const override;
  HoopResponse hoop_response(const Mat2& E, double E33) const override;

 private:
  Lame lame_;
  PlaneAnalysis analysis_;
};

}  // namespace grip
