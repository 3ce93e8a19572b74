#include "solver/elements/rigid_plastic_membrane.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "solver/model/number_text.hpp"

namespace grip {

double HillMaterial::plane_strain_factor() const {
  return 0.5 * std::pow(2 * (1 + r), 1 / M) * std::pow(1 + std::pow(1 + 2 * r, -1 / (M - 1)), (M - 1) / M);
}
double HillMaterial::flow_stress(double eps_bar) const { return H * std::pow(eps_bar + a0, n); }
double HillMaterial::hardening_slope(double eps_bar) const { return n * H * std::pow(eps_bar + a0, n - 1); }

double HillMaterial::half_square_increment(const Vec2& d, Vec2* gradient, Mat2* hessian) const {
  // psi = A^2 / 2 g^(2/m), g = |s|^m + B |t|^m with s = d1 + d2, t = d1 - d2.
  const double m = M / (M - 1), A = 0.5 * std::pow(2 * (1 + r), 1 / M), B = std::pow(1 + 2 * r, -1 / (M - 1));
  const double s = d.x() + d.y(), t = d.x() - d.y();
  const double as = std::max(std::abs(s), 1e-300), at = std::max(std::abs(t), 1e-300);
  const double g = std::max(std::pow(as, m) + B * std::pow(at, m), 1e-300);
  const Vec2 u(1, 1), v(1, -1);
  const Vec2 dg = m * (std::copysign(std::pow(as, m - 1), s) * u + B * std::copysign(std::pow(at, m - 1), t) * v);
  const double k = A * A / m * std::pow(g, 2 / m - 1);  // d psi = k dg
  if (gradient) *gradient = k * dg;
  if (hessian) {
    const Mat2 ddg =
        m * (m - 1) * (std::pow(as, m - 2) * u * u.transpose() + B * std::pow(at, m - 2) * v * v.transpose());
    *hessian = k * ddg;
    if (m != 2) *hessian += A * A / m * (2 / m - 1) * std::pow(g, 2 / m - 2) * dg * dg.transpose();
  }
  return 0.5 * A * A * std::pow(g, 2 / m);
}

RigidPlasticMembrane::RigidPlasticMembrane(std::vector<Vec2> nodes, double thickness, HillMaterial material,
                                           double width, bool axisymmetric)
    : nodes_(std::move(nodes)), width_(width), material_(material), c_(material.plane_strain_factor()),
      initial_thickness_(thickness), axisymmetric_(axisymmetric) {
  if (nodes_.size() < 2) throw std::invalid_argument("a membrane needs at least two nodes");
  for (int e = 0; e < element_count(); ++e) {
    const double L = (nodes_[e + 1] - nodes_[e]).norm();
    if (!(L > 0)) throw std::invalid_argument("membrane element " + std::to_string(e) + " has zero length");
    initial_length_.push_back(L);
  }
  eps_bar_.assign(element_count(), 0.0);
  thickness_.assign(element_count(), thickness);
  length_ = initial_length_;
  if (!axisymmetric_) return;
  for (int e = 0; e < element_count(); ++e) {
    const double Rm = 0.5 * (nodes_[e].x() + nodes_[e + 1].x());
    if (!(nodes_[e].x() >= 0 && nodes_[e + 1].x() >= 0 && Rm > 0))
      throw std::invalid_argument("axisymmetric membrane element " + std::to_string(e) +
                                  " leaves the half-plane x = r >= 0 or lies on the axis");
    initial_radius_.push_back(Rm);
    volume_.push_back(2 * std::numbers::pi * Rm * thickness * initial_length_[e]);
  }
  radius_ = initial_radius_;
  committed_x_ = nodes_;
}

RigidPlasticMembrane::FrustumState RigidPlasticMembrane::frustum_state(const VectorRef& q, int e,
                                                                       Eigen::Matrix4d* K) const {
  FrustumState s;
  const Vec2 xa = nodes_[e] + q.segment<2>(node_dof(e, 0));
  const Vec2 xb = nodes_[e + 1] + q.segment<2>(node_dof(e + 1, 0));
  s.l = std::max((xb - xa).norm(), 1e-300);
  s.rm = std::max(0.5 * (xa.x() + xb.x()), 1e-300);
  const Vec2 dir = (xb - xa) / s.l;
  s.d1 = std::log(s.l / length_[e]);
  s.d2 = std::log(s.rm / radius_[e]);
  Vec2 dpsi;
  Mat2 ddpsi;
  const double psi = material_.half_square_increment({s.d1, s.d2}, &dpsi, K ? &ddpsi : nullptr);
  const double e0 = material_.regularization, root = std::sqrt(2 * psi + e0 * e0);
  s.deps = root - e0;
  const double eps = eps_bar_[e] + s.deps, V = volume_[e];
  s.sigma = material_.flow_stress(eps);
  s.thickness = V / (2 * std::numbers::pi * s.rm * s.l);
  // d(deps)/dd = dpsi / root; the strain increments' gradients in (xa, ya, xb, yb).
  const Vec2 grad = dpsi / root;
  Eigen::Vector4d g1, g2;
  g1 << -dir / s.l, dir / s.l;
  g2 << 0.5 / s.rm, 0, 0.5 / s.rm, 0;
  const Eigen::Vector4d gd = grad.x() * g1 + grad.y() * g2;
  s.force = V * s.sigma * gd;
  s.tension = V * s.sigma * grad.x() / (2 * std::numbers::pi * s.rm * s.l);
  if (!K) return s;
  const Mat2 hd = ddpsi / root - grad * grad.transpose() / root;  // Hessian of deps in d
  Eigen::Matrix<double, 4, 2> G;
  G << g1, g2;
  const Mat2 Q = (Mat2::Identity() - 2 * dir * dir.transpose()) / (s.l * s.l);  // of ln l
  Eigen::Matrix4d h1;
  h1 << Q, -Q, -Q, Q;
  const Eigen::Matrix4d H = G * hd * G.transpose() + grad.x() * h1 - grad.y() * g2 * g2.transpose();
  *K = V * (material_.hardening_slope(eps) * gd * gd.transpose() + s.sigma * H);
  return s;
}

double RigidPlasticMembrane::current_thickness(const VectorRef& q, int e) const {
  if (axisymmetric_) return frustum_state(q, e, nullptr).thickness;
  const Vec2 xa = nodes_[e] + q.segment<2>(node_dof(e, 0));
  const Vec2 xb = nodes_[e + 1] + q.segment<2>(node_dof(e + 1, 0));
  return thickness_[e] * length_[e] / std::max((xb - xa).norm(), 1e-300);
}

RigidPlasticMembrane::ElementState RigidPlasticMembrane::element_state(const Vector& q, int e) const {
  ElementState s;
  const Vec2 xa = nodes_[e] + q.segment<2>(node_dof(e, 0));
  const Vec2 xb = nodes_[e + 1] + q.segment<2>(node_dof(e + 1, 0));
  s.l = (xb - xa).norm();
  s.e = s.l > 0 ? Vec2((xb - xa) / s.l) : Vec2::UnitX();
  const double L0 = length_[e], e0 = material_.regularization;
  const double V = thickness_[e] * L0;  // volume per unit width, constant
  s.d1 = std::log(std::max(s.l, 1e-300) / L0);
  const double root = std::sqrt(c_ * c_ * s.d1 * s.d1 + e0 * e0);
  s.deps = root - e0;
  const double g = c_ * c_ * s.d1 / root;                      // d(deps)/d(d1)
  const double g1 = c_ * c_ * e0 * e0 / (root * root * root);  // d2(deps)/d(d1)^2
  const double eps = eps_bar_[e] + s.deps;
  s.sigma = material_.flow_stress(eps);
  s.tension = s.sigma * V * g / s.l;
  s.dtension_dl = V * (material_.hardening_slope(eps) * g * g + s.sigma * (g1 - g)) / (s.l * s.l);
  s.thickness = V / s.l;
  return s;
}

void RigidPlasticMembrane::internal_force(const Vector& q, Vector& force, TangentSink* tangent) const {
  if (axisymmetric_) {
    Eigen::Matrix4d K;
    for (int e = 0; e < element_count(); ++e) {
      const FrustumState s = frustum_state(q, e, tangent ? &K : nullptr);
      force.segment<4>(node_dof(e, 0)) += s.force;
      if (tangent)
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j) tangent->add(node_dof(e, 0) + i, node_dof(e, 0) + j, K(i, j));
    }
    return;
  }
  for (int e = 0; e < element_count(); ++e) {
    const ElementState s = element_state(q, e);
    const Vec2 f = width_ * s.tension * s.e;
    force.segment<2>(node_dof(e, 0)) -= f;
    force.segment<2>(node_dof(e + 1, 0)) += f;
    if (!tangent) continue;
    // d(T e)/dx_b = dT/dl e e^T + T / l (I - e e^T): stretch and the string's rotation.
    const Mat2 ee = s.e * s.e.transpose();
    const Mat2 k = width_ * (s.dtension_dl * ee + s.tension / s.l * (Mat2::Identity() - ee));
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        tangent->add(node_dof(e, i), node_dof(e, j), k(i, j));
        tangent->add(node_dof(e + 1, i), node_dof(e + 1, j), k(i, j));
        tangent->add(node_dof(e, i), node_dof(e + 1, j), -k(i, j));
        tangent->add(node_dof(e + 1, i), node_dof(e, j), -k(i, j));
      }
  }
}

void RigidPlasticMembrane::follower_load(const Vector& q, const std::vector<double>& factors, Vector& force,
                                         Triplets* tangent) const {
  double p = 0.0;
  for (const Pressure& pr : pressures_)
    if (pr.load_case < static_cast<int>(factors.size())) p += factors[pr.load_case] * pr.value;
  if (p == 0.0) return;
  Mat2 J;  // a quarter turn: J d is the element's left normal times its length
  J << 0, -1, 1, 0;
  for (int e = 0; e < element_count(); ++e) {
    const int a = node_dof(e, 0), b = node_dof(e + 1, 0);
    const Vec2 xa = nodes_[e] + q.segment<2>(a), xb = nodes_[e + 1] + q.segment<2>(b);
    const Vec2 n = J * (xb - xa);
    // Each node's share of p n over the element, with the linear shape functions: width / 2
    // each in the plane; 2 pi int N r ds about the axis, (2 ra + rb) / 6 and (ra + 2 rb) / 6.
    double wa = 0.5 * width_, wb = wa;
    if (axisymmetric_) {
      wa = std::numbers::pi / 3 * (2 * xa.x() + xb.x());
      wb = std::numbers::pi / 3 * (xa.x() + 2 * xb.x());
    }
    force.segment<2>(a) += p * wa * n;
    force.segment<2>(b) += p * wb * n;
    if (!tangent) continue;
    // d(w n) = w J (dxb - dxa) + n dw, dw = pi / 3 (2 dra + drb) or (dra + 2 drb) about the axis.
    Mat2 da[2] = {-p * wa * J, p * wa * J}, db[2] = {-p * wb * J, p * wb * J};  // by xa, xb
    if (axisymmetric_) {
      const double c = p * std::numbers::pi / 3;
      da[0].col(0) += 2 * c * n;
      da[1].col(0) += c * n;
      db[0].col(0) += c * n;
      db[1].col(0) += 2 * c * n;
    }
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int k = 0; k < 2; ++k) {
          const int col = (k == 0 ? a : b) + j;
          tangent->emplace_back(a + i, col, da[k](i, j));
          tangent->emplace_back(b + i, col, db[k](i, j));
        }
  }
}

SurfacePoint RigidPlasticMembrane::surface_point(const VectorRef& q, int site, int /*side*/) const {
  SurfacePoint p;
  p.x = nodes_[site] + q.segment<2>(node_dof(site, 0));
  p.jacobian = {{node_dof(site, 0), Vec2::UnitX()}, {node_dof(site, 1), Vec2::UnitY()}};
  double t = 0.0;
  int n = 0;
  for (int e : {site - 1, site}) {
    if (e < 0 || e >= element_count()) continue;
    t += current_thickness(q, e);
    ++n;
  }
  p.clearance = 0.5 * t / n;
  return p;
}

double RigidPlasticMembrane::tributary_area(int site) const {
  if (axisymmetric_) {  // the area its halves of the neighbouring frusta sweep, at the last commit
    double area = 0.0;
    for (int e : {site - 1, site}) {
      if (e < 0 || e >= element_count()) continue;
      const Vec2 xa = committed_x_[e], xb = committed_x_[e + 1];
      const double r_own = e == site ? xa.x() : xb.x(), r_other = e == site ? xb.x() : xa.x();
      area += 2 * std::numbers::pi * (xb - xa).norm() * (r_own / 3 + r_other / 6);  // int N 2 pi r ds
    }
    return area;
  }
  double length = 0.0;
  if (site > 0) length += 0.5 * length_[site - 1];
  if (site < element_count()) length += 0.5 * length_[site];
  return length * width_;
}

double RigidPlasticMembrane::characteristic_length() const {
  double L = 0.0;
  for (double l : initial_length_) L += l;
  return L;
}

Vector RigidPlasticMembrane::rigid_translation(const Vec2& d) const {
  Vector q(dof_count());
  for (int k = 0; k < node_count(); ++k) q.segment<2>(node_dof(k, 0)) = d;
  return q;
}

std::vector<std::vector<int>> RigidPlasticMembrane::cells() const {
  std::vector<std::vector<int>> c;
  for (int e = 0; e < element_count(); ++e) c.push_back({e, e + 1});
  return c;
}

FieldTable RigidPlasticMembrane::site_fields(const Vector& q) const {
  FieldTable t{{"x", "y", "ux", "uy"}, {}};
  for (int k = 0; k < node_count(); ++k) {
    const Vec2 u = q.segment<2>(node_dof(k, 0));
    t.rows.push_back({nodes_[k].x() + u.x(), nodes_[k].y() + u.y(), u.x(), u.y()});
  }
  return t;
}

FieldTable RigidPlasticMembrane::element_fields(const Vector& q) const {
  if (axisymmetric_) {
    FieldTable t{{"s0", "x", "y", "meridional_strain", "hoop_strain", "thickness_strain", "thickness", "eps_bar",
                  "tension", "strain_increment"},
                 {}};
    double s0 = 0.0;
    for (int e = 0; e < element_count(); ++e) {
      const FrustumState s = frustum_state(q, e, nullptr);
      const Vec2 mid =
          0.5 * (nodes_[e] + q.segment<2>(node_dof(e, 0)) + nodes_[e + 1] + q.segment<2>(node_dof(e + 1, 0)));
      t.rows.push_back({s0 + 0.5 * initial_length_[e], mid.x(), mid.y(), std::log(s.l / initial_length_[e]),
                        std::log(s.rm / initial_radius_[e]), std::log(s.thickness / initial_thickness_), s.thickness,
                        eps_bar_[e] + s.deps, s.tension, s.d1});
      s0 += initial_length_[e];
    }
    return t;
  }
  FieldTable t{
      {"s0", "x", "y", "major_strain", "thickness_strain", "thickness", "eps_bar", "tension", "strain_increment"}, {}};
  double s0 = 0.0;
  for (int e = 0; e < element_count(); ++e) {
    const ElementState s = element_state(q, e);
    const Vec2 mid =
        0.5 * (nodes_[e] + q.segment<2>(node_dof(e, 0)) + nodes_[e + 1] + q.segment<2>(node_dof(e + 1, 0)));
    t.rows.push_back({s0 + 0.5 * initial_length_[e], mid.x(), mid.y(), std::log(s.l / initial_length_[e]),
                      std::log(s.thickness / initial_thickness_), s.thickness, eps_bar_[e] + s.deps, s.tension, s.d1});
    s0 += initial_length_[e];
  }
  return t;
}

Vector RigidPlasticMembrane::start_guess(const Vector& prescribed, const std::vector<char>& is_prescribed) const {
  // Each component interpolated linearly (in initial arc length) between the nodes where it
  // is prescribed: a stretched, tensioned start instead of a slack flat sheet.
  Vector q = prescribed;
  std::vector<double> s(node_count(), 0.0);
  for (int k = 1; k < node_count(); ++k) s[k] = s[k - 1] + initial_length_[k - 1];
  for (int comp = 0; comp < 2; ++comp) {
    std::vector<int> known;
    for (int k = 0; k < node_count(); ++k)
      if (is_prescribed[node_dof(k, comp)]) known.push_back(k);
    if (known.empty()) continue;
    for (int k = 0; k < node_count(); ++k) {
      if (is_prescribed[node_dof(k, comp)]) continue;
      size_t j = 0;
      while (j < known.size() && known[j] < k) ++j;
      const int lo = j == 0 ? known.front() : known[j - 1];
      const int hi = j == known.size() ? known.back() : known[j];
      const double ql = prescribed[node_dof(lo, comp)], qh = prescribed[node_dof(hi, comp)];
      q[node_dof(k, comp)] = lo == hi ? ql : ql + (qh - ql) * (s[k] - s[lo]) / (s[hi] - s[lo]);
    }
  }
  return q;
}

double RigidPlasticMembrane::newton_step_fraction(const Vector& q, const Vector& dq) const {
  // At most 2 % of stretch per element and Newton iteration (the rigid-plastic law is stiff
  // across its small-strain regularization); rotations are not limited: the line search
  // measures them in the tangent's metric.
  double worst = 0.0;
  for (int e = 0; e < element_count(); ++e) {
    const Vec2 xa = nodes_[e] + q.segment<2>(node_dof(e, 0));
    const Vec2 xb = nodes_[e + 1] + q.segment<2>(node_dof(e + 1, 0));
    const double l = (xb - xa).norm();
    const Vec2 t = (xb - xa) / l;
    const Vec2 d = dq.segment<2>(node_dof(e + 1, 0)) - dq.segment<2>(node_dof(e, 0));
    worst = std::max(worst, std::abs(t.dot(d)) / (0.02 * l));
  }
  return worst > 1 ? 1 / worst : 1.0;
}

std::string RigidPlasticMembrane::inadmissible(const Vector& q) const {
  // A membrane carries no compression: the sheet would wrinkle. The regularized law gives
  // a small compressive stiffness near a zero increment; allow ten times its scale.
  for (int e = 0; e < element_count(); ++e) {
    const double d1 = axisymmetric_ ? frustum_state(q, e, nullptr).d1 : element_state(q, e).d1;
    if (d1 < -10 * material_.regularization)
      return "membrane element " + std::to_string(e) + " is compressed (stretch increment " + number_text(d1) +
             "): the sheet would wrinkle";
  }
  return {};
}

void RigidPlasticMembrane::commit(const Vector& q) {
  if (axisymmetric_) {
    for (int e = 0; e < element_count(); ++e) {
      const FrustumState s = frustum_state(q, e, nullptr);
      eps_bar_[e] += s.deps;
      thickness_[e] = s.thickness;
      length_[e] = s.l;
      radius_[e] = s.rm;
    }
    for (int k = 0; k < node_count(); ++k) committed_x_[k] = nodes_[k] + q.segment<2>(node_dof(k, 0));
    return;
  }
  for (int e = 0; e < element_count(); ++e) {
    const ElementState s = element_state(q, e);
    eps_bar_[e] += s.deps;
    thickness_[e] = s.thickness;
    length_[e] = s.l;
  }
}

}  // namespace grip
