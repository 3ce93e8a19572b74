#include "solver/elements/timoshenko_beam.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace grip {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Vec9 = Eigen::Matrix<double, 9, 1>;

// Shape functions h (eq. B.3) and their x-derivatives b (eq. B.5) at phi in [-1, 1].
Vec3 shape(double phi) { return {0.5 * (1 - phi), 0.5 * (1 + phi), 1 - phi * phi}; }
Vec3 shape_dx(double phi, double L) { return Vec3(-1, 1, -4 * phi) / L; }

struct Gauss {
  std::vector<double> points, weights;
};
const Gauss kGauss2{{-1 / std::sqrt(3.0), 1 / std::sqrt(3.0)}, {1, 1}};
const Gauss kGauss3{{-std::sqrt(0.6), 0, std::sqrt(0.6)}, {5.0 / 9, 8.0 / 9, 5.0 / 9}};

}  // namespace

TimoshenkoBeam::TimoshenkoBeam(std::vector<double> node_x, double y0, BeamSection section, Kinematics kinematics)
    : StraightBeam(std::move(node_x), y0, section), kinematics_(kinematics) {
  if (kinematics_ == Kinematics::finite)
    throw std::invalid_argument("the beam supports linear and von_karman kinematics");
}

void TimoshenkoBeam::internal_force(const Vector& q, Vector& force, TangentSink* tangent) const {
  const bool nonlinear = kinematics_ == Kinematics::von_karman;
  const auto& s = section_;
  for (int e = 0; e < element_count(); ++e) {
    // Local order: u1 u2 uq | w1 w2 wq | t1 t2 tq.
    std::array<int, 9> dofs{};
    for (int c = 0; c < 3; ++c) {
      dofs[3 * c + 0] = node_dof(e, c);
      dofs[3 * c + 1] = node_dof(e + 1, c);
      dofs[3 * c + 2] = mid_dof(e, c);
    }
    Vec9 ql;
    for (int i = 0; i < 9; ++i) ql[i] = q[dofs[i]];
    const Vec3 u = ql.segment<3>(0), w = ql.segment<3>(3), t = ql.segment<3>(6);
    const double L = x_[e + 1] - x_[e];
    Vec9 f = Vec9::Zero();
    Mat9 K = Mat9::Zero();

    // Axial and bending terms, 3-point Gauss.
    for (size_t g = 0; g < kGauss3.points.size(); ++g) {
      const double phi = kGauss3.points[g], dx = kGauss3.weights[g] * L / 2;
      const Vec3 b = shape_dx(phi, L);
      const double bw = nonlinear ? b.dot(w) : 0.0;
      const double N = s.EA * (b.dot(u) + 0.5 * bw * bw);
      const double M = s.EI * b.dot(t);
      f.segment<3>(0) += dx * N * b;
      f.segment<3>(3) += dx * N * bw * b;
      f.segment<3>(6) += dx * M * b;
      const Eigen::Matrix3d bb = b * b.transpose();
      K.block<3, 3>(0, 0) += dx * s.EA * bb;
      K.block<3, 3>(0, 3) += dx * s.EA * bw * bb;
      K.block<3, 3>(3, 0) += dx * s.EA * bw * bb;
      K.block<3, 3>(3, 3) += dx * (s.EA * bw * bw + (nonlinear ? N : 0.0)) * bb;
      K.block<3, 3>(6, 6) += dx * s.EI * bb;
    }
    // Shear, 2-point (reduced) Gauss.
    for (size_t g = 0; g < kGauss2.points.size(); ++g) {
      const double phi = kGauss2.points[g], dx = kGauss2.weights[g] * L / 2;
      const Vec3 b = shape_dx(phi, L), h = shape(phi);
      const double Q = s.kGA * (b.dot(w) + h.dot(t));
      f.segment<3>(3) += dx * Q * b;
      f.segment<3>(6) += dx * Q * h;
      K.block<3, 3>(3, 3) += dx * s.kGA * b * b.transpose();
      K.block<3, 3>(3, 6) += dx * s.kGA * b * h.transpose();
      K.block<3, 3>(6, 3) += dx * s.kGA * h * b.transpose();
      K.block<3, 3>(6, 6) += dx * s.kGA * h * h.transpose();
    }
    for (int i = 0; i < 9; ++i) {
      force[dofs[i]] += f[i];
      if (tangent)
        for (int j = 0; j < 9; ++j) tangent->add(dofs[i], dofs[j], K(i, j));
    }
  }
}

SurfacePoint TimoshenkoBeam::surface_point(const VectorRef& q, int site, int side) const {
  const double z = side * section_.half_depth;
  const int du = node_dof(site, 0), dw = node_dof(site, 1), dt = node_dof(site, 2);
  SurfacePoint p;
  p.x = {x_[site] + q[du] + z * q[dt], y0_ + z + q[dw]};
  p.jacobian = {{du, Vec2::UnitX()}, {dw, Vec2::UnitY()}, {dt, z * Vec2::UnitX()}};
  return p;
}

SectionForces TimoshenkoBeam::section_forces(const Vector& q, int e) const {
  const double L = x_[e + 1] - x_[e];
  Vec3 u, w, t;
  for (int c = 0; c < 3; ++c) {
    Vec3& v = c == 0 ? u : (c == 1 ? w : t);
    v = {q[node_dof(e, c)], q[node_dof(e + 1, c)], q[mid_dof(e, c)]};
  }
  const Vec3 b = shape_dx(0.0, L), h = shape(0.0);
  const double bw = kinematics_ == Kinematics::von_karman ? b.dot(w) : 0.0;
  return {section_.EA * (b.dot(u) + 0.5 * bw * bw), section_.kGA * (b.dot(w) + h.dot(t)), section_.EI * b.dot(t)};
}

int TimoshenkoBeam::axis_shape(int element, double xi, int* slots, double* N, double* dN_dxi) const {
  const Vec3 h = shape(xi), b = shape_dx(xi, 1.0);
  const int k[3] = {element, element + 1, node_count() + element};
  for (int i = 0; i < 3; ++i) {
    slots[i] = k[i];
    N[i] = h[i];
    dN_dxi[i] = 0.5 * b[i];
  }
  return 3;
}

Vector TimoshenkoBeam::rigid_translation(const Vec2& d) const {
  Vector q = Vector::Zero(dof_count());
  for (int k = 0; k < node_count(); ++k) {
    q[node_dof(k, 0)] = d.x();
    q[node_dof(k, 1)] = d.y();
  }
  return q;  // hierarchical mid values stay zero: they measure departure from linear
}

Vector TimoshenkoBeam::rigid_rotation() const {
  // u = -y, w = x at the centre line; theta = -dw/dx = -1.
  Vector q = Vector::Zero(dof_count());
  for (int k = 0; k < node_count(); ++k) {
    q[node_dof(k, 0)] = -y0_;
    q[node_dof(k, 1)] = x_[k];
    q[node_dof(k, 2)] = -1.0;
  }
  return q;
}

Vector TimoshenkoBeam::own_rotation_at(const Vector& q) const {
  Vector rot = rigid_rotation();
  for (int k = 0; k < node_count(); ++k) rot[node_dof(k, 0)] -= q[node_dof(k, 1)];
  for (int e = 0; e < element_count(); ++e) rot[mid_dof(e, 0)] -= q[mid_dof(e, 1)];
  return rot;
}

Body::Traits TimoshenkoBeam::traits() const {
  const bool linear = kinematics_ == Kinematics::linear;
  return {!linear, false, linear};
}

std::string TimoshenkoBeam::validity_warning(const Vector& q) const {
  double largest = 0.0;
  for (int k = 0; k < node_count(); ++k) largest = std::max(largest, std::abs(q[node_dof(k, 2)]));
  if (largest <= kModerateRotation) return {};
  char text[320];
  std::snprintf(text, sizeof text,
                "rotation reaches %.3f rad (%.1f deg), beyond the %.2f rad up to which the %s beam is within "
                "about 1 %% of an exact-rotation model (its error grows like 0.45 theta^2): for large rotations "
                "use the continuum with finite kinematics",
                largest, largest * 180 / std::acos(-1.0), kModerateRotation,
                kinematics_ == Kinematics::linear ? "linear" : "von Karman");
  return text;
}

}  // namespace grip
