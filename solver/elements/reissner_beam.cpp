#include "solver/elements/reissner_beam.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <stdexcept>

namespace grip {
namespace {

// Lagrange shape functions at xi in [-1, 1] in local order (ends, then the mid node) and their
// xi-derivatives.
template <int n>
void shape(double xi, Eigen::Matrix<double, n, 1>& N, Eigen::Matrix<double, n, 1>& dN) {
  if constexpr (n == 2) {
    N << 0.5 * (1 - xi), 0.5 * (1 + xi);
    dN << -0.5, 0.5;
  } else {
    N << 0.5 * xi * (xi - 1), 0.5 * xi * (xi + 1), 1 - xi * xi;
    dN << xi - 0.5, xi + 0.5, -2 * xi;
  }
}

// Strains and their first variations at one point: B rows over the element's 3n dofs (u, w,
// theta per node), and the geometric coefficients of N d2eps + Q d2gamma.
template <int n>
struct Point {
  static constexpr int m = 3 * n;
  using Row = Eigen::Matrix<double, 1, m>;
  double eps, gamma, kappa;
  Row b_eps = Row::Zero(), b_gamma = Row::Zero(), b_kappa = Row::Zero();
  Eigen::Matrix<double, n, 1> N, dN;  // dN: d/dx

  Point(const Eigen::Matrix<double, m, 1>& q, double xi, double length) {
    shape<n>(xi, N, dN);
    dN *= 2 / length;
    double a = 1, b = 0, theta = 0;
    kappa = 0;
    for (int k = 0; k < n; ++k) {
      a += dN[k] * q[3 * k];
      b += dN[k] * q[3 * k + 1];
      theta += N[k] * q[3 * k + 2];
      kappa += dN[k] * q[3 * k + 2];
    }
    const double c = std::cos(theta), s = std::sin(theta);
    eps = a * c - b * s - 1;
    gamma = a * s + b * c;
    for (int k = 0; k < n; ++k) {
      b_eps(3 * k) = c * dN[k];
      b_eps(3 * k + 1) = -s * dN[k];
      b_eps(3 * k + 2) = -gamma * N[k];
      b_gamma(3 * k) = s * dN[k];
      b_gamma(3 * k + 1) = c * dN[k];
      b_gamma(3 * k + 2) = (1 + eps) * N[k];
      b_kappa(3 * k + 2) = dN[k];
    }
    sin_theta = s;
    cos_theta = c;
  }
  double sin_theta, cos_theta;
};

template <int n>
void element_force(const Eigen::Matrix<double, 3 * n, 1>& q, double length, const BeamSection& sec,
                   Eigen::Matrix<double, 3 * n, 1>& f, Eigen::Matrix<double, 3 * n, 3 * n>* K) {
  constexpr int points = n - 1;  // reduced: 1 point for b2, 2 for b3
  const double xi_g[2] = {n == 2 ? 0.0 : -1 / std::sqrt(3.0), 1 / std::sqrt(3.0)};
  const double w_g = n == 2 ? 2.0 : 1.0;
  f.setZero();
  if (K) K->setZero();
  for (int g = 0; g < points; ++g) {
    const Point<n> p(q, xi_g[g], length);
    const double dx = w_g * length / 2;
    const double Nf = sec.EA * p.eps, Q = sec.kGA * p.gamma, M = sec.EI * p.kappa;
    f += dx * (Nf * p.b_eps + Q * p.b_gamma + M * p.b_kappa).transpose();
    if (!K) continue;
    *K += dx * (sec.EA * p.b_eps.transpose() * p.b_eps + sec.kGA * p.b_gamma.transpose() * p.b_gamma +
                sec.EI * p.b_kappa.transpose() * p.b_kappa);
    // Geometric stiffness N d2eps + Q d2gamma: the rotation couples with u', w' and itself.
    const double s = p.sin_theta, c = p.cos_theta;
    const double g_u = -Nf * s + Q * c, g_w = -Nf * c - Q * s, g_t = -Nf * (1 + p.eps) - Q * p.gamma;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const double ut = dx * g_u * p.dN[a] * p.N[b], wt = dx * g_w * p.dN[a] * p.N[b];
        (*K)(3 * a, 3 * b + 2) += ut;
        (*K)(3 * b + 2, 3 * a) += ut;
        (*K)(3 * a + 1, 3 * b + 2) += wt;
        (*K)(3 * b + 2, 3 * a + 1) += wt;
        (*K)(3 * a + 2, 3 * b + 2) += dx * g_t * p.N[a] * p.N[b];
      }
  }
}

template <int n>
void add_element(const Vector& q, const int* nodes, double length, const BeamSection& sec, Vector& force,
                 TangentSink* tangent) {
  constexpr int m = 3 * n;
  Eigen::Matrix<double, m, 1> ql, f;
  Eigen::Matrix<double, m, m> K;
  std::array<int, m> dofs{};
  for (int k = 0; k < n; ++k)
    for (int c = 0; c < 3; ++c) dofs[3 * k + c] = 3 * nodes[k] + c;
  for (int i = 0; i < m; ++i) ql[i] = q[dofs[i]];
  element_force<n>(ql, length, sec, f, tangent ? &K : nullptr);
  for (int i = 0; i < m; ++i) {
    force[dofs[i]] += f[i];
    if (tangent)
      for (int j = 0; j < m; ++j) tangent->add(dofs[i], dofs[j], K(i, j));
  }
}

template <int n>
SectionForces centre_forces(const Vector& q, const int* nodes, double length, const BeamSection& sec) {
  Eigen::Matrix<double, 3 * n, 1> ql;
  for (int k = 0; k < n; ++k)
    for (int c = 0; c < 3; ++c) ql[3 * k + c] = q[3 * nodes[k] + c];
  const Point<n> p(ql, 0.0, length);
  return {sec.EA * p.eps, sec.kGA * p.gamma, sec.EI * p.kappa};
}

}  // namespace

ReissnerBeam::ReissnerBeam(std::vector<double> node_x, double y0, BeamSection section, BeamElement element)
    : StraightBeam(std::move(node_x), y0, section), element_(element) {}

int ReissnerBeam::element_nodes(int e, int* nodes, double* x) const {
  nodes[0] = e;
  nodes[1] = e + 1;
  x[0] = x_[e];
  x[1] = x_[e + 1];
  if (element_ == BeamElement::b2) return 2;
  nodes[2] = node_count() + e;
  x[2] = 0.5 * (x[0] + x[1]);
  return 3;
}

void ReissnerBeam::internal_force(const Vector& q, Vector& force, TangentSink* tangent) const {
  for (int e = 0; e < element_count(); ++e) {
    int nodes[3];
    double x[3];
    const int n = element_nodes(e, nodes, x);
    if (n == 2) add_element<2>(q, nodes, x[1] - x[0], section_, force, tangent);
    else add_element<3>(q, nodes, x[1] - x[0], section_, force, tangent);
  }
}

void ReissnerBeam::follower_load(const Vector& q, const std::vector<double>& factors, Vector& force,
                                 Triplets* tangent) const {
  for (const FollowerLoad& l : followers_) {
    const double t = l.load_case < static_cast<int>(factors.size()) ? factors[l.load_case] : 0.0;
    const int du = node_dof(l.node, 0), dw = node_dof(l.node, 1), dt = node_dof(l.node, 2);
    const double c = std::cos(q[dt]), s = std::sin(q[dt]);
    // The force turned with the section (clockwise by theta); at height z its point moves by
    // z (cos, -sin) dtheta, the same turn of e_x: its moment about the axis stays z F_x.
    const Vec2 f = t * Vec2(c * l.force.x() + s * l.force.y(), -s * l.force.x() + c * l.force.y());
    const Vec2 df = t * Vec2(-s * l.force.x() + c * l.force.y(), -c * l.force.x() - s * l.force.y());
    force[du] += f.x();
    force[dw] += f.y();
    force[dt] += t * l.z * l.force.x();
    if (!tangent) continue;
    tangent->emplace_back(du, dt, df.x());
    tangent->emplace_back(dw, dt, df.y());
  }
  for (const FollowerTraction& l : follower_tractions_) {
    const double t = l.load_case < static_cast<int>(factors.size()) ? factors[l.load_case] : 0.0;
    if (t == 0.0) continue;
    // f = T x' with T = [[ta, -tc], [tc, ta]]: linear in the axis' slope, so dT x' / dq is T
    // times the shape functions' slopes.
    const double ta = t * l.traction.x(), tc = t * l.traction.y();
    over_span(l.from, l.to, [&](int e, double xi, double dx) {
      int slots[3];
      double N[3], dN[3];
      const int n = axis_shape(e, xi, slots, N, dN);
      const double to_x = 2 / (x_[e + 1] - x_[e]);
      Vec2 slope(1.0, 0.0);
      for (int k = 0; k < n; ++k) slope += to_x * dN[k] * Vec2(q[3 * slots[k]], q[3 * slots[k] + 1]);
      const Vec2 f(ta * slope.x() - tc * slope.y(), tc * slope.x() + ta * slope.y());
      for (int i = 0; i < n; ++i) {
        force[3 * slots[i]] += N[i] * f.x() * dx;
        force[3 * slots[i] + 1] += N[i] * f.y() * dx;
        if (!tangent) continue;
        for (int j = 0; j < n; ++j) {
          const double c = N[i] * to_x * dN[j] * dx;
          tangent->emplace_back(3 * slots[i], 3 * slots[j], c * ta);
          tangent->emplace_back(3 * slots[i], 3 * slots[j] + 1, -c * tc);
          tangent->emplace_back(3 * slots[i] + 1, 3 * slots[j], c * tc);
          tangent->emplace_back(3 * slots[i] + 1, 3 * slots[j] + 1, c * ta);
        }
      }
    });
  }
}

int ReissnerBeam::axis_shape(int element, double xi, int* slots, double* N, double* dN_dxi) const {
  slots[0] = element;
  slots[1] = element + 1;
  if (element_ == BeamElement::b2) {
    Eigen::Vector2d n, d;
    shape<2>(xi, n, d);
    for (int k = 0; k < 2; ++k) N[k] = n[k], dN_dxi[k] = d[k];
    return 2;
  }
  slots[2] = node_count() + element;
  Eigen::Vector3d n, d;
  shape<3>(xi, n, d);
  for (int k = 0; k < 3; ++k) N[k] = n[k], dN_dxi[k] = d[k];
  return 3;
}

SurfacePoint ReissnerBeam::surface_point(const VectorRef& q, int site, int side) const {
  const double z = side * section_.half_depth;
  const int du = node_dof(site, 0), dw = node_dof(site, 1), dt = node_dof(site, 2);
  const double c = std::cos(q[dt]), s = std::sin(q[dt]);
  SurfacePoint p;
  p.x = {x_[site] + q[du] + z * s, y0_ + q[dw] + z * c};
  p.jacobian = {{du, Vec2::UnitX()}, {dw, Vec2::UnitY()}, {dt, z * Vec2(c, -s)}};
  return p;
}

SectionForces ReissnerBeam::section_forces(const Vector& q, int e) const {
  int nodes[3];
  double x[3];
  const int n = element_nodes(e, nodes, x);
  return n == 2 ? centre_forces<2>(q, nodes, x[1] - x[0], section_) : centre_forces<3>(q, nodes, x[1] - x[0], section_);
}

Vector ReissnerBeam::rigid_translation(const Vec2& d) const {
  Vector q = Vector::Zero(dof_count());
  for (int k = 0; k < dof_count() / 3; ++k) {
    q[3 * k] = d.x();
    q[3 * k + 1] = d.y();
  }
  return q;
}

Vector ReissnerBeam::rigid_rotation() const { return own_rotation_at(Vector::Zero(dof_count())); }

Vector ReissnerBeam::own_rotation_at(const Vector& q) const {
  Vector rot(dof_count());
  for (int k = 0; k < dof_count() / 3; ++k) {
    const double X = k < node_count() ? x_[k] : 0.5 * (x_[k - node_count()] + x_[k - node_count() + 1]);
    rot[3 * k] = -(y0_ + q[3 * k + 1]);
    rot[3 * k + 1] = X + q[3 * k];
    rot[3 * k + 2] = -1.0;  // a counter-clockwise turn: theta is clockwise
  }
  return rot;
}

}  // namespace grip
