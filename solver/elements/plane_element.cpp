#include "solver/elements/plane_element.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "solver/elements/node_count_dispatch.hpp"

namespace grip {
namespace {

using Vec3 = Eigen::Vector3d;

// Quadratic Lagrange functions on [-1, 1] at nodes -1, 0, 1 and their derivatives.
Vec3 lagrange2(double s) { return {0.5 * s * (s - 1), 1 - s * s, 0.5 * s * (s + 1)}; }
Vec3 lagrange2_ds(double s) { return {s - 0.5, -2 * s, s + 0.5}; }

// q9 node a -> (index along xi, index along eta) of the 1D node at -1, 0, 1 (q4 and q8 use
// the first 4 and 8 of these positions).
constexpr std::array<std::array<int, 2>, 9> kQ9Index{
    {{0, 0}, {2, 0}, {2, 2}, {0, 2}, {1, 0}, {2, 1}, {1, 2}, {0, 1}, {1, 1}}};

std::vector<GaussPoint> tensor_rule(const std::vector<double>& x, const std::vector<double>& w) {
  std::vector<GaussPoint> rule;
  for (size_t j = 0; j < x.size(); ++j)
    for (size_t i = 0; i < x.size(); ++i) rule.push_back({x[i], x[j], w[i] * w[j]});
  return rule;
}

// The symmetric triangle rule of degree 4 (Strang and Fix; Dunavant 1985): two orbits of three
// points; weights sum to the reference triangle's area 1/2.
std::vector<GaussPoint> triangle_rule6() {
  std::vector<GaussPoint> rule;
  const double a[2] = {0.445948490915965, 0.091576213509771}, w[2] = {0.223381589678011, 0.109951743655322};
  for (int k = 0; k < 2; ++k)
    for (const Vec2& p : {Vec2(a[k], a[k]), Vec2(1 - 2 * a[k], a[k]), Vec2(a[k], 1 - 2 * a[k])})
      rule.push_back({p.x(), p.y(), 0.5 * w[k]});
  return rule;
}

}  // namespace

const char* shape_name(ElementShape shape) {
  switch (shape) {
    case ElementShape::t3:
      return "t3";
    case ElementShape::t6:
      return "t6";
    case ElementShape::q4:
      return "q4";
    case ElementShape::q8:
      return "q8";
    case ElementShape::q9:
      return "q9";
  }
  return "?";
}

int element_node_count(ElementShape shape) {
  constexpr int n[] = {3, 6, 4, 8, 9};
  return n[static_cast<int>(shape)];
}

int element_corner_count(ElementShape shape) { return shape == ElementShape::t3 || shape == ElementShape::t6 ? 3 : 4; }

bool is_quadratic(ElementShape shape) { return shape != ElementShape::t3 && shape != ElementShape::q4; }

const std::vector<std::vector<int>>& element_sides(ElementShape shape) {
  static const std::vector<std::vector<int>> t3{{0, 1}, {1, 2}, {2, 0}};
  static const std::vector<std::vector<int>> t6{{0, 3, 1}, {1, 4, 2}, {2, 5, 0}};
  static const std::vector<std::vector<int>> q4{{0, 1}, {1, 2}, {2, 3}, {3, 0}};
  static const std::vector<std::vector<int>> q8{{0, 4, 1}, {1, 5, 2}, {2, 6, 3}, {3, 7, 0}};
  switch (shape) {
    case ElementShape::t3:
      return t3;
    case ElementShape::t6:
      return t6;
    case ElementShape::q4:
      return q4;
    default:
      return q8;  // q8 and q9: the centre is on no side
  }
}

Vec2 node_natural(ElementShape shape, int a) {
  if (element_corner_count(shape) == 3) {
    static const double xi[6] = {0, 1, 0, 0.5, 0.5, 0}, eta[6] = {0, 0, 1, 0, 0.5, 0.5};
    return {xi[a], eta[a]};
  }
  return {kQ9Index[a][0] - 1.0, kQ9Index[a][1] - 1.0};
}

Vec2 centre_natural(ElementShape shape) {
  return element_corner_count(shape) == 3 ? Vec2(1.0 / 3, 1.0 / 3) : Vec2(0, 0);
}

void shape_functions(ElementShape shape, double xi, double eta, Vector& N, ShapeGradients& dN) {
  const int n = element_node_count(shape);
  N.resize(n);
  dN.resize(n, 2);
  switch (shape) {
    case ElementShape::t3:
      N << 1 - xi - eta, xi, eta;
      dN << -1, -1, 1, 0, 0, 1;
      return;
    case ElementShape::t6: {
      // Area coordinates L and their constant gradients.
      const double L[3] = {1 - xi - eta, xi, eta};
      const Vec2 dL[3] = {{-1, -1}, {1, 0}, {0, 1}};
      for (int a = 0; a < 3; ++a) {
        N[a] = L[a] * (2 * L[a] - 1);
        dN.row(a) = (4 * L[a] - 1) * dL[a].transpose();
        const int b = (a + 1) % 3;  // mid-side node 3 + a on side a-b
        N[3 + a] = 4 * L[a] * L[b];
        dN.row(3 + a) = 4 * (L[a] * dL[b] + L[b] * dL[a]).transpose();
      }
      return;
    }
    case ElementShape::q4:
      for (int a = 0; a < 4; ++a) {
        const Vec2 p = node_natural(shape, a);
        N[a] = 0.25 * (1 + p.x() * xi) * (1 + p.y() * eta);
        dN(a, 0) = 0.25 * p.x() * (1 + p.y() * eta);
        dN(a, 1) = 0.25 * p.y() * (1 + p.x() * xi);
      }
      return;
    case ElementShape::q8:
      for (int a = 0; a < 8; ++a) {
        const double s = node_natural(shape, a).x(), t = node_natural(shape, a).y();
        if (a < 4) {  // corners
          N[a] = 0.25 * (1 + s * xi) * (1 + t * eta) * (s * xi + t * eta - 1);
          dN(a, 0) = 0.25 * s * (1 + t * eta) * (2 * s * xi + t * eta);
          dN(a, 1) = 0.25 * t * (1 + s * xi) * (s * xi + 2 * t * eta);
        } else if (s == 0) {  // mid-sides of the sides along xi
          N[a] = 0.5 * (1 - xi * xi) * (1 + t * eta);
          dN(a, 0) = -xi * (1 + t * eta);
          dN(a, 1) = 0.5 * (1 - xi * xi) * t;
        } else {  // mid-sides of the sides along eta
          N[a] = 0.5 * (1 + s * xi) * (1 - eta * eta);
          dN(a, 0) = 0.5 * s * (1 - eta * eta);
          dN(a, 1) = -eta * (1 + s * xi);
        }
      }
      return;
    case ElementShape::q9: {
      const Vec3 lx = lagrange2(xi), ly = lagrange2(eta), dx = lagrange2_ds(xi), dy = lagrange2_ds(eta);
      for (int a = 0; a < 9; ++a) {
        const int i = kQ9Index[a][0], j = kQ9Index[a][1];
        N[a] = lx[i] * ly[j];
        dN(a, 0) = dx[i] * ly[j];
        dN(a, 1) = lx[i] * dy[j];
      }
      return;
    }
  }
}

const std::vector<GaussPoint>& gauss_rule(ElementShape shape) {
  static const std::vector<GaussPoint> one{{1.0 / 3, 1.0 / 3, 0.5}};
  static const std::vector<GaussPoint> six = triangle_rule6();
  static const std::vector<GaussPoint> two = tensor_rule({-1 / std::sqrt(3.0), 1 / std::sqrt(3.0)}, {1, 1});
  static const std::vector<GaussPoint> three =
      tensor_rule({-std::sqrt(0.6), 0, std::sqrt(0.6)}, {5.0 / 9, 8.0 / 9, 5.0 / 9});
  switch (shape) {
    case ElementShape::t3:
      return one;
    case ElementShape::t6:
      return six;
    case ElementShape::q4:
      return two;
    default:
      return three;
  }
}

ElementPoint element_point(ElementShape shape, const ShapeGradients& X, double xi, double eta,
                           double weight_thickness) {
  ElementPoint p;
  ShapeGradients dN_nat;
  shape_functions(shape, xi, eta, p.N, dN_nat);
  const Mat2 J = X.transpose() * dN_nat;  // J(i, k) = dX_i / d xi_k
  p.detJ = J.determinant();
  p.dV = weight_thickness * p.detJ;
  // dN/dX = dN/dxi * dxi/dX = dN_nat * J^-1 (J invertible only when detJ != 0).
  p.dN = p.detJ != 0.0 ? ShapeGradients(dN_nat * J.inverse()) : ShapeGradients::Zero(X.rows(), 2);
  return p;
}

std::vector<ElementPoint> element_points(ElementShape shape, const ShapeGradients& X, double thickness) {
  std::vector<ElementPoint> points;
  for (const GaussPoint& g : gauss_rule(shape))
    points.push_back(element_point(shape, X, g.xi, g.eta, g.weight * thickness));
  return points;
}

ShapeGradients mean_gradients(const std::vector<ElementPoint>& points) {
  ShapeGradients mean = ShapeGradients::Zero(points.front().dN.rows(), 2);
  double volume = 0.0;
  for (const ElementPoint& p : points) {
    mean += p.dV * p.dN;
    volume += p.dV;
  }
  return mean / volume;
}

Matrix strain_matrix(const ElementPoint& point, const ShapeGradients* mean_dN) {
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

Matrix small_strain_stiffness(const std::vector<ElementPoint>& points, const Eigen::Matrix3d& D,
                              const ShapeGradients* mean_dN) {
  const int n = 2 * static_cast<int>(points.front().dN.rows());
  Matrix Ke = Matrix::Zero(n, n);
  for (const ElementPoint& p : points) {
    const Matrix B = strain_matrix(p, mean_dN);
    Ke.noalias() += p.dV * B.transpose() * D * B;
  }
  return 0.5 * (Ke + Ke.transpose());
}

void make_axisymmetric(ElementPoint& point, const ShapeGradients& X) {
  point.radius = point.N.dot(X.col(0));
  if (!(point.radius > 0)) throw std::logic_error("axisymmetric element: a Gauss point at r <= 0");
  point.dV *= 2 * std::numbers::pi * point.radius;
}

Matrix axisymmetric_strain_matrix(const ElementPoint& point) {
  const int n = static_cast<int>(point.dN.rows());
  Matrix B = Matrix::Zero(4, 2 * n);
  B.topRows(3) = strain_matrix(point, nullptr);
  for (int a = 0; a < n; ++a) B(3, 2 * a) = point.N[a] / point.radius;
  return B;
}

Matrix axisymmetric_stiffness(const std::vector<ElementPoint>& points, const Eigen::Matrix4d& D) {
  const int n = 2 * static_cast<int>(points.front().dN.rows());
  Matrix Ke = Matrix::Zero(n, n);
  for (const ElementPoint& p : points) {
    const Matrix B = axisymmetric_strain_matrix(p);
    Ke.noalias() += p.dV * B.transpose() * D * B;
  }
  return 0.5 * (Ke + Ke.transpose());
}

Mat2 deformation_gradient(const ElementPoint& point, const ShapeGradients& u) {
  return Mat2::Identity() + u.transpose() * point.dN;  // F_ij = delta_ij + sum_a u_ai dN_a/dX_j
}

namespace {

// total_lagrangian for N nodes and R strain rows (3 in the plane, 4 with the hoop strain), in
// fixed-size matrices: no allocation, and B^T D B and the geometric stiffness as closed loops
// over the upper triangle (Ke is symmetric: D is, and so is dN_a . S dN_b), mirrored once.
template <int N, int R>
void total_lagrangian_fixed(const std::vector<ElementPoint>& points, const ShapeGradients& u_dynamic,
                            const PlaneMaterial& material, Vector& fe_out, Matrix* Ke_out, const PointLaw& law,
                            const HoopLaw& hoop_law, const ShapeGradients* base_u) {
  constexpr int M = 2 * N;
  using Nodes2 = Eigen::Matrix<double, N, 2>;
  const Nodes2 u = u_dynamic;
  const bool linearized = base_u && Ke_out;
  Nodes2 h = Nodes2::Zero();  // the displacement from the stress's base
  if (linearized) h = u - *base_u;
  Eigen::Matrix<double, M, 1> fe = Eigen::Matrix<double, M, 1>::Zero();
  Eigen::Matrix<double, M, M> Ke;
  if (Ke_out) Ke.setZero();
  Eigen::Matrix<double, R, M> B, DB;
  Eigen::Matrix<double, M, R> Bt;
  for (size_t k = 0; k < points.size(); ++k) {
    const ElementPoint& p = points[k];
    const Eigen::Map<const Nodes2> dN(p.dN.data());
    const Mat2 F = Mat2::Identity() + u.transpose() * dN;
    const Mat2 E = 0.5 * (F.transpose() * F - Mat2::Identity());
    // Axisymmetric: the hoop stretch F33 = r / R = 1 + u_r / R and its strain (F33^2 - 1) / 2.
    double F33 = 1.0, S33 = 0.0;
    Eigen::Vector3d S_voigt;
    Eigen::Matrix<double, R, R> D;
    if constexpr (R == 4) {
      F33 = 1 + p.N.dot(u.col(0)) / p.radius;
      const double E33 = 0.5 * (F33 * F33 - 1);
      const HoopResponse r = hoop_law ? hoop_law(static_cast<int>(k), E, E33) : material.hoop_response(E, E33);
      S_voigt = r.S.head<3>();
      S33 = r.S[3];
      D = r.D;
    } else {
      const MaterialResponse r = law ? law(static_cast<int>(k), E) : material.response(E);
      S_voigt = r.S;
      D = r.D;
    }
    Mat2 S;
    S << S_voigt[0], S_voigt[2], S_voigt[2], S_voigt[1];
    const Mat2 P = F * S;  // first Piola-Kirchhoff stress
    // The geometric stiffness's stress: S, or that of the linearized strain E - H^T H / 2.
    Mat2 S_g = S;
    double S33_g = S33;
    if (linearized) {
      const Mat2 H = h.transpose() * dN;
      const Mat2 dE = 0.5 * H.transpose() * H;
      Eigen::Matrix<double, R, 1> dE_voigt;
      dE_voigt.template head<3>() << dE(0, 0), dE(1, 1), 2 * dE(0, 1);
      if constexpr (R == 4) {
        const double hoop = p.N.dot(h.col(0)) / p.radius;
        dE_voigt[3] = 0.5 * hoop * hoop;
      }
      const Eigen::Matrix<double, R, 1> dS = D * dE_voigt;
      S_g << S(0, 0) - dS[0], S(0, 1) - dS[2], S(1, 0) - dS[2], S(1, 1) - dS[1];
      if constexpr (R == 4) S33_g = S33 - dS[3];
    }
    // dE = B du: rows E11, E22, 2 E12 (and E33 in axisymmetry); column pair of node a.
    for (int a = 0; a < N; ++a) {
      const double gx = dN(a, 0), gy = dN(a, 1);
      fe[2 * a] += p.dV * (P(0, 0) * gx + P(0, 1) * gy);
      fe[2 * a + 1] += p.dV * (P(1, 0) * gx + P(1, 1) * gy);
      green_lagrange_rows(B, a, F, gx, gy);
      if constexpr (R == 4) {
        B(3, 2 * a) = F33 * p.N[a] / p.radius;  // dE33 = F33 du_r / R
        B(3, 2 * a + 1) = 0.0;
        fe[2 * a] += p.dV * S33 * B(3, 2 * a);
      }
    }
    if (!Ke_out) continue;
    DB.noalias() = (p.dV * D) * B;
    // Column j's entries i <= j from B^T (rows i contiguous): the same sums, entry by entry, as
    // B's columns would give, two entries at a time in the vector registers.
    Bt = B.transpose();
    for (int j = 0; j < M; ++j) {
      double* column = &Ke(0, j);
      for (int i = 0; i <= j; ++i) {
        double sum = 0.0;
        for (int r = 0; r < R; ++r) sum += Bt(i, r) * DB(r, j);
        column[i] += sum;
      }
    }
    // Geometric stiffness dN_a . S dN_b on both components (and the hoop term S33 N_a N_b / R^2).
    for (int b = 0; b < N; ++b) {
      const double sx = p.dV * (S_g(0, 0) * dN(b, 0) + S_g(0, 1) * dN(b, 1));
      const double sy = p.dV * (S_g(1, 0) * dN(b, 0) + S_g(1, 1) * dN(b, 1));
      for (int a = 0; a <= b; ++a) {
        const double g = dN(a, 0) * sx + dN(a, 1) * sy;
        Ke(2 * a, 2 * b) += g;
        Ke(2 * a + 1, 2 * b + 1) += g;
        if constexpr (R == 4) Ke(2 * a, 2 * b) += p.dV * S33_g * p.N[a] * p.N[b] / (p.radius * p.radius);
      }
    }
  }
  fe_out = fe;
  if (!Ke_out) return;
  for (int j = 0; j < M; ++j)
    for (int i = j + 1; i < M; ++i) Ke(i, j) = Ke(j, i);
  *Ke_out = Ke;
}

template <int N>
void total_lagrangian_nodes(const std::vector<ElementPoint>& points, const ShapeGradients& u,
                            const PlaneMaterial& material, Vector& fe, Matrix* Ke, const PointLaw& law,
                            const HoopLaw& hoop_law, const ShapeGradients* base_u) {
  if (points.front().radius > 0) total_lagrangian_fixed<N, 4>(points, u, material, fe, Ke, law, hoop_law, base_u);
  else total_lagrangian_fixed<N, 3>(points, u, material, fe, Ke, law, hoop_law, base_u);
}

// small_strain_history for N nodes: B (4 x 2N) as strain_matrix (and B-bar) builds it, with the
// hoop row at axisymmetric points; B^T D B over the upper triangle, mirrored once.
template <int N>
void small_strain_history_fixed(const std::vector<ElementPoint>& points, const ShapeGradients* mean_dN,
                                const ShapeGradients& u, const PlaneMaterial& material, const PointHistory* history,
                                Vector& fe_out, Matrix* Ke_out) {
  constexpr int M = 2 * N;
  using Nodes2 = Eigen::Matrix<double, N, 2>;
  Eigen::Matrix<double, M, 1> ue, fe = Eigen::Matrix<double, M, 1>::Zero();
  for (int a = 0; a < N; ++a) ue.template segment<2>(2 * a) = u.row(a).transpose();
  Eigen::Matrix<double, M, M> Ke;
  if (Ke_out) Ke.setZero();
  Eigen::Matrix<double, 4, M> B, DB;
  Eigen::Matrix<double, M, 4> Bt;
  for (size_t k = 0; k < points.size(); ++k) {
    const ElementPoint& p = points[k];
    const Eigen::Map<const Nodes2> dN(p.dN.data());
    const bool hoop = p.radius > 0;
    for (int a = 0; a < N; ++a) {
      const double nx = dN(a, 0), ny = dN(a, 1);
      B.col(2 * a) << nx, 0.0, ny, hoop ? p.N[a] / p.radius : 0.0;
      B.col(2 * a + 1) << 0.0, ny, nx, 0.0;
      if (mean_dN && !hoop) {
        // eps11 and eps22 each gain half the difference of mean and local dilatation.
        const double dx = 0.5 * ((*mean_dN)(a, 0) - nx), dy = 0.5 * ((*mean_dN)(a, 1) - ny);
        B(0, 2 * a) += dx;
        B(0, 2 * a + 1) += dy;
        B(1, 2 * a) += dx;
        B(1, 2 * a + 1) += dy;
      }
    }
    Eigen::Vector4d strain = Eigen::Vector4d::Zero();
    for (int i = 0; i < M; ++i) strain += B.col(i) * ue[i];
    const PointResponse r = material.small_strain_response(strain, history[k]);
    for (int i = 0; i < M; ++i) fe[i] += p.dV * B.col(i).dot(r.stress);
    if (!Ke_out) continue;
    const Eigen::Matrix4d D = 0.5 * (r.D + r.D.transpose());
    DB.noalias() = (p.dV * D) * B;
    Bt = B.transpose();
    for (int j = 0; j < M; ++j) {
      double* column = &Ke(0, j);
      for (int i = 0; i <= j; ++i) {
        double sum = 0.0;
        for (int s = 0; s < 4; ++s) sum += Bt(i, s) * DB(s, j);
        column[i] += sum;
      }
    }
  }
  fe_out = fe;
  if (!Ke_out) return;
  for (int j = 0; j < M; ++j)
    for (int i = j + 1; i < M; ++i) Ke(i, j) = Ke(j, i);
  *Ke_out = Ke;
}

}  // namespace

void total_lagrangian(const std::vector<ElementPoint>& points, const ShapeGradients& u, const PlaneMaterial& material,
                      Vector& fe, Matrix* Ke, const PointLaw& law, const HoopLaw& hoop_law,
                      const ShapeGradients* base_u) {
  with_node_count<3, 4, 6, 8, 9>(u.rows(), "total_lagrangian", [&](auto n) {
    total_lagrangian_nodes<n()>(points, u, material, fe, Ke, law, hoop_law, base_u);
  });
}

void small_strain_history(const std::vector<ElementPoint>& points, const ShapeGradients* mean_dN,
                          const ShapeGradients& u, const PlaneMaterial& material, const PointHistory* history,
                          Vector& fe, Matrix* Ke) {
  with_node_count<3, 4, 6, 8, 9>(u.rows(), "small_strain_history", [&](auto n) {
    small_strain_history_fixed<n()>(points, mean_dN, u, material, history, fe, Ke);
  });
}

Mat2 f_bar(const ElementPoint& point, const ElementPoint& centre, const ShapeGradients& u) {
  const Mat2 F = deformation_gradient(point, u);
  return std::sqrt(deformation_gradient(centre, u).determinant() / F.determinant()) * F;
}

namespace {

// f_bar_total_lagrangian for N nodes, in fixed-size matrices (no allocation): h and h0 a row per node.
template <int N>
void f_bar_fixed(const std::vector<ElementPoint>& points, const ElementPoint& centre, const ShapeGradients& u_dynamic,
                 const PlaneMaterial& material, Vector& fe_out, Matrix* Ke_out, const PointLaw& law,
                 const ShapeGradients* base) {
  constexpr int M = 2 * N;
  using Nodes2 = Eigen::Matrix<double, N, 2>;
  const Nodes2 u = u_dynamic;
  Eigen::Matrix<double, M, 1> fe = Eigen::Matrix<double, M, 1>::Zero();
  Eigen::Matrix<double, M, M> Ke;
  if (Ke_out) Ke.setZero();
  const Eigen::Map<const Nodes2> dN0(centre.dN.data());
  const Mat2 F0 = Mat2::Identity() + u.transpose() * dN0;
  const Nodes2 h0 = dN0 * F0.inverse();  // row a: (F0^-T dN_a)^T
  const auto sym = [](const Mat2& A) { return Mat2(0.5 * (A + A.transpose())); };
  // The tangent's J0 linearized about the stress base u_b (TangentSink::stress_base): det F0(u_b)
  // + J0(u_b) h0(u_b) : (u - u_b) (docs/algorithm.md#newtons-tangent-the-linearized-dilatation).
  double J0_lin = 0.0;
  if (Ke_out && base) {
    const Nodes2 ub = *base;
    const Mat2 F0b = Mat2::Identity() + ub.transpose() * dN0;
    const double J0b = F0b.determinant();
    const Nodes2 h0b = dN0 * F0b.inverse();
    const Nodes2 du = u - ub;
    J0_lin = J0b * (1.0 + (du.array() * h0b.array()).sum());
  }
  for (size_t i = 0; i < points.size(); ++i) {
    const ElementPoint& p = points[i];
    const Eigen::Map<const Nodes2> dN(p.dN.data());
    const Mat2 F = Mat2::Identity() + u.transpose() * dN;
    const double alpha = std::sqrt(F0.determinant() / F.determinant());
    const Mat2 Fb = alpha * F;
    const Mat2 Eb = 0.5 * (Fb.transpose() * Fb - Mat2::Identity());
    const MaterialResponse r = law ? law(static_cast<int>(i), Eb) : material.response(Eb);
    Mat2 S;
    S << r.S[0], r.S[2], r.S[2], r.S[1];
    const Mat2 tau = Fb * S * Fb.transpose();
    const double half_trace = 0.5 * tau.trace();
    const Nodes2 h = dN * F.inverse();  // row a: (F^-T dN_a)^T
    for (int a = 0; a < N; ++a)
      fe.template segment<2>(2 * a) +=
          p.dV * ((tau - half_trace * Mat2::Identity()) * h.row(a).transpose() + half_trace * h0.row(a).transpose());
    if (!Ke_out) continue;
    double at = alpha, ht = half_trace;
    Mat2 Fbt = Fb, St = S, taut = tau;
    MaterialResponse rt = r;
    if (J0_lin > 0) {  // the law at the linearized J0
      at = std::sqrt(J0_lin / F.determinant());
      Fbt = at * F;
      rt = law ? law(static_cast<int>(i), Mat2(0.5 * (Fbt.transpose() * Fbt - Mat2::Identity())))
               : material.response(Mat2(0.5 * (Fbt.transpose() * Fbt - Mat2::Identity())));
      St << rt.S[0], rt.S[2], rt.S[2], rt.S[1];
      taut = Fbt * St * Fbt.transpose();
      ht = 0.5 * taut.trace();
    }
    for (int b = 0; b < N; ++b)
      for (int k = 0; k < 2; ++k) {
        const Vec2 w = Vec2::Unit(k);
        // d alpha = alpha / 2 (w . h0_b - w . h_b); d F_bar = alpha (w (x) g_b) + F d alpha.
        const double s = 0.5 * (h0(b, k) - h(b, k));
        const Mat2 dFb = at * (w * dN.row(b) + F * s);
        const Mat2 dE = sym(Fbt.transpose() * dFb);
        const Eigen::Vector3d dS_voigt = rt.D * Eigen::Vector3d(dE(0, 0), dE(1, 1), 2 * dE(0, 1));
        Mat2 dS;
        dS << dS_voigt[0], dS_voigt[2], dS_voigt[2], dS_voigt[1];
        const Mat2 dtau = dFb * St * Fbt.transpose() + Fbt * dS * Fbt.transpose() + Fbt * St * dFb.transpose();
        const double dhalf = 0.5 * dtau.trace();
        for (int a = 0; a < N; ++a) {
          // d h_a = -h_b (w . h_a), d h0_a = -h0_b (w . h0_a).
          const Vec2 ha = h.row(a).transpose(), h0a = h0.row(a).transpose();
          const Vec2 dha = -h.row(b).transpose() * ha[k], dh0a = -h0.row(b).transpose() * h0a[k];
          const Vec2 df =
              (dtau - dhalf * Mat2::Identity()) * ha + (taut - ht * Mat2::Identity()) * dha + dhalf * h0a + ht * dh0a;
          Ke.template block<2, 1>(2 * a, 2 * b + k) += p.dV * df;
        }
      }
  }
  fe_out = fe;
  if (Ke_out) *Ke_out = Ke;
}

}  // namespace

void f_bar_total_lagrangian(const std::vector<ElementPoint>& points, const ElementPoint& centre,
                            const ShapeGradients& u, const PlaneMaterial& material, Vector& fe, Matrix* Ke,
                            const PointLaw& law, const ShapeGradients* base) {
  with_node_count<3, 4, 6, 8, 9>(u.rows(), "f_bar_total_lagrangian",
                                 [&](auto n) { f_bar_fixed<n()>(points, centre, u, material, fe, Ke, law, base); });
}

Eigen::Vector4d cauchy_stress(const Mat2& F, const MaterialResponse& r) {
  Mat2 S;
  S << r.S[0], r.S[2], r.S[2], r.S[1];
  const double J = F.determinant() * std::sqrt(r.C33);
  const Mat2 sigma = F * S * F.transpose() / J;
  return {sigma(0, 0), sigma(1, 1), sigma(0, 1), r.C33 * r.S33 / J};
}

}  // namespace grip
