#include "solver/elements/quad_element.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>

namespace grip {
namespace {

using Vec3 = Eigen::Vector3d;

// Quadratic Lagrange functions on [-1, 1] at nodes -1, 0, 1 and their derivatives.
Vec3 lagrange2(double s) { return {0.5 * s * (s - 1), 1 - s * s, 0.5 * s * (s + 1)}; }
Vec3 lagrange2_ds(double s) { return {s - 0.5, -2 * s, s + 0.5}; }

// q9 node a -> (index along xi, index along eta) of the 1D node at -1, 0, 1.
constexpr std::array<std::array<int, 2>, 9> kQ9Index{
    {{0, 0}, {2, 0}, {2, 2}, {0, 2}, {1, 0}, {2, 1}, {1, 2}, {0, 1}, {1, 1}}};

std::vector<GaussPoint> tensor_rule(const std::vector<double>& x, const std::vector<double>& w) {
  std::vector<GaussPoint> rule;
  for (size_t j = 0; j < x.size(); ++j)
    for (size_t i = 0; i < x.size(); ++i) rule.push_back({x[i], x[j], w[i] * w[j]});
  return rule;
}

}  // namespace

int quad_node_count(QuadShape shape) { return shape == QuadShape::q4 ? 4 : 9; }

Vec2 quad_node_natural(QuadShape shape, int a) {
  if (shape == QuadShape::q4) {
    static const double xi[4] = {-1, 1, 1, -1}, eta[4] = {-1, -1, 1, 1};
    return {xi[a], eta[a]};
  }
  return {kQ9Index[a][0] - 1.0, kQ9Index[a][1] - 1.0};
}

void quad_shape_functions(QuadShape shape, double xi, double eta, Vector& N, ShapeGradients& dN) {
  const int n = quad_node_count(shape);
  N.resize(n);
  dN.resize(n, 2);
  if (shape == QuadShape::q4) {
    for (int a = 0; a < 4; ++a) {
      const Vec2 p = quad_node_natural(shape, a);
      N[a] = 0.25 * (1 + p.x() * xi) * (1 + p.y() * eta);
      dN(a, 0) = 0.25 * p.x() * (1 + p.y() * eta);
      dN(a, 1) = 0.25 * p.y() * (1 + p.x() * xi);
    }
    return;
  }
  const Vec3 lx = lagrange2(xi), ly = lagrange2(eta), dx = lagrange2_ds(xi), dy = lagrange2_ds(eta);
  for (int a = 0; a < 9; ++a) {
    const int i = kQ9Index[a][0], j = kQ9Index[a][1];
    N[a] = lx[i] * ly[j];
    dN(a, 0) = dx[i] * ly[j];
    dN(a, 1) = lx[i] * dy[j];
  }
}

const std::vector<GaussPoint>& quad_gauss_rule(QuadShape shape) {
  static const std::vector<GaussPoint> two = tensor_rule({-1 / std::sqrt(3.0), 1 / std::sqrt(3.0)}, {1, 1});
  static const std::vector<GaussPoint> three =
      tensor_rule({-std::sqrt(0.6), 0, std::sqrt(0.6)}, {5.0 / 9, 8.0 / 9, 5.0 / 9});
  return shape == QuadShape::q4 ? two : three;
}

QuadPoint quad_point(QuadShape shape, const ShapeGradients& X, double xi, double eta, double weight_thickness) {
  QuadPoint p;
  ShapeGradients dN_nat;
  quad_shape_functions(shape, xi, eta, p.N, dN_nat);
  const Mat2 J = X.transpose() * dN_nat;  // J(i, k) = dX_i / d xi_k
  p.detJ = J.determinant();
  p.dV = weight_thickness * p.detJ;
  // dN/dX = dN/dxi * dxi/dX = dN_nat * J^-1 (J invertible only when detJ != 0).
  p.dN = p.detJ != 0.0 ? ShapeGradients(dN_nat * J.inverse()) : ShapeGradients::Zero(X.rows(), 2);
  return p;
}

std::vector<QuadPoint> quad_points(QuadShape shape, const ShapeGradients& X, double thickness) {
  std::vector<QuadPoint> points;
  for (const GaussPoint& g : quad_gauss_rule(shape))
    points.push_back(quad_point(shape, X, g.xi, g.eta, g.weight * thickness));
  return points;
}

ShapeGradients mean_gradients(const std::vector<QuadPoint>& points) {
  ShapeGradients mean = ShapeGradients::Zero(points.front().dN.rows(), 2);
  double volume = 0.0;
  for (const QuadPoint& p : points) {
    mean += p.dV * p.dN;
    volume += p.dV;
  }
  return mean / volume;
}

Matrix strain_matrix(const QuadPoint& point, const ShapeGradients* mean_dN) {
  const int n = static_cast<int>(point.dN.rows());
  Matrix B = Matrix::Zero(3, 2 * n);
  for (int a = 0; a < n; ++a) {
    const double nx = point.dN(a, 0), ny = point.dN(a, 1);
    B(0, 2 * a) = nx;
    B(1, 2 * a + 1) = ny;
    B(2, 2 * a) = ny;
    B(2, 2 * a + 1) = nx;
    if (mean_dN) {
      // eps11 and eps22 each gain half the difference of mean and local dilatation.
      const double dx = 0.5 * ((*mean_dN)(a, 0) - nx), dy = 0.5 * ((*mean_dN)(a, 1) - ny);
      B(0, 2 * a) += dx;
      B(0, 2 * a + 1) += dy;
      B(1, 2 * a) += dx;
      B(1, 2 * a + 1) += dy;
    }
  }
  return B;
}

Matrix small_strain_stiffness(const std::vector<QuadPoint>& points, const Eigen::Matrix3d& D,
                              const ShapeGradients* mean_dN) {
  const int n = 2 * static_cast<int>(points.front().dN.rows());
  Matrix Ke = Matrix::Zero(n, n);
  for (const QuadPoint& p : points) {
    const Matrix B = strain_matrix(p, mean_dN);
    Ke.noalias() += p.dV * B.transpose() * D * B;
  }
  return 0.5 * (Ke + Ke.transpose());
}

Mat2 deformation_gradient(const QuadPoint& point, const ShapeGradients& u) {
  return Mat2::Identity() + u.transpose() * point.dN;  // F_ij = delta_ij + sum_a u_ai dN_a/dX_j
}

void total_lagrangian(const std::vector<QuadPoint>& points, const ShapeGradients& u, const PlaneMaterial& material,
                      Vector& fe, Matrix* Ke) {
  const int n = static_cast<int>(u.rows());
  fe = Vector::Zero(2 * n);
  if (Ke) *Ke = Matrix::Zero(2 * n, 2 * n);
  Matrix B(3, 2 * n);
  for (const QuadPoint& p : points) {
    const Mat2 F = deformation_gradient(p, u);
    const Mat2 E = 0.5 * (F.transpose() * F - Mat2::Identity());
    const MaterialResponse r = material.response(E);
    Mat2 S;
    S << r.S[0], r.S[2], r.S[2], r.S[1];
    const Mat2 P = F * S;  // first Piola-Kirchhoff stress
    for (int a = 0; a < n; ++a) {
      const Vec2 g = p.dN.row(a).transpose();
      fe.segment<2>(2 * a) += p.dV * P * g;
      // dE = B du: rows E11, E22, 2 E12; column pair of node a.
      B(0, 2 * a) = F(0, 0) * g.x();
      B(0, 2 * a + 1) = F(1, 0) * g.x();
      B(1, 2 * a) = F(0, 1) * g.y();
      B(1, 2 * a + 1) = F(1, 1) * g.y();
      B(2, 2 * a) = F(0, 0) * g.y() + F(0, 1) * g.x();
      B(2, 2 * a + 1) = F(1, 0) * g.y() + F(1, 1) * g.x();
    }
    if (!Ke) continue;
    Ke->noalias() += p.dV * B.transpose() * r.D * B;
    const Matrix G = p.dN * S * p.dN.transpose();  // geometric stiffness dN_a . S dN_b
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        (*Ke)(2 * a, 2 * b) += p.dV * G(a, b);
        (*Ke)(2 * a + 1, 2 * b + 1) += p.dV * G(a, b);
      }
  }
}

Eigen::Vector4d cauchy_stress(const Mat2& F, const MaterialResponse& r) {
  Mat2 S;
  S << r.S[0], r.S[2], r.S[2], r.S[1];
  const double J = F.determinant() * std::sqrt(r.C33);
  const Mat2 sigma = F * S * F.transpose() / J;
  return {sigma(0, 0), sigma(1, 1), sigma(0, 1), r.C33 * r.S33 / J};
}

}  // namespace grip
