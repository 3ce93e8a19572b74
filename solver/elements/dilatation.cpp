#include "solver/elements/dilatation.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "solver/elements/node_count_dispatch.hpp"

namespace grip {
namespace {

double exponent(const ElementPoint& p) { return p.radius > 0 ? 1.0 / 3.0 : 0.5; }

Vector ratios_at(const Dilatation& dilatation, const ShapeGradients& u) {
  Vector J(dilatation.points.size());
  for (size_t j = 0; j < dilatation.points.size(); ++j) J[j] = volume_ratio(dilatation.points[j], u);
  return J;
}

}  // namespace

Dilatation projected_dilatation(const std::vector<ElementPoint>& points, const ElementPoint& centre,
                                const ShapeGradients& X, int order) {
  const int m = order == 0 ? 1 : 3;
  double volume = 0.0;
  Vec2 mean = Vec2::Zero();
  for (const ElementPoint& p : points) {
    volume += p.dV;
    mean += p.dV * (X.transpose() * p.N);
  }
  mean /= volume;
  double h = 0.0;  // the points' spread: scales X - mean to order one
  for (const ElementPoint& p : points) h = std::max(h, (X.transpose() * p.N - mean).norm());
  const auto basis = [&](const ElementPoint& p) {
    Vector phi(m);
    phi[0] = 1.0;
    if (m == 3) phi.tail<2>() = (X.transpose() * p.N - mean) / h;
    return phi;
  };
  Matrix Phi(m, points.size()), M = Matrix::Zero(m, m);
  for (size_t j = 0; j < points.size(); ++j) {
    Phi.col(j) = basis(points[j]);
    M += points[j].dV * Phi.col(j) * Phi.col(j).transpose();
  }
  Vector weights(points.size());
  for (size_t j = 0; j < points.size(); ++j) weights[j] = points[j].dV;
  const Matrix projector = M.ldlt().solve(Phi * weights.asDiagonal());  // m x points: the modes from J
  Dilatation d;
  d.points = points;
  d.A = Phi.transpose() * projector;
  d.centre = basis(centre).transpose() * projector;
  return d;
}

double volume_ratio(const ElementPoint& point, const ShapeGradients& u) {
  const double J = deformation_gradient(point, u).determinant();
  return point.radius > 0 ? J * (1 + point.N.dot(u.col(0)) / point.radius) : J;
}

Vector dilatation_scales(const std::vector<ElementPoint>& points, const Dilatation& dilatation,
                         const ShapeGradients& u) {
  const Vector theta = dilatation.A * ratios_at(dilatation, u);
  Vector s(points.size());
  for (size_t k = 0; k < points.size(); ++k)
    s[k] = std::pow(theta[k] / volume_ratio(points[k], u), exponent(points[k]));
  return s;
}

Vector projected_ratios(const Dilatation& dilatation, const ShapeGradients& u) {
  return dilatation.A * ratios_at(dilatation, u);
}

double centre_projected_ratio(const Dilatation& dilatation, const ShapeGradients& u) {
  return dilatation.centre.dot(ratios_at(dilatation, u));
}

double centre_dilatation_scale(const ElementPoint& centre, const Dilatation& dilatation, const ShapeGradients& u) {
  const double theta = dilatation.centre.dot(ratios_at(dilatation, u));
  return std::pow(theta / volume_ratio(centre, u), exponent(centre));
}

namespace {

// J at a point with its first and (if asked) second derivatives, for N nodes: volume_of in
// fixed-size matrices.
template <int N>
struct FixedVolume {
  static constexpr int M = 2 * N;
  double J = 1.0;
  Eigen::Matrix<double, M, 1> dJ;
  Eigen::Matrix<double, M, M> d2J;
};

template <int N>
void fixed_volume(const ElementPoint& p, const Eigen::Matrix<double, N, 2>& u, bool second, FixedVolume<N>& v) {
  constexpr int M = 2 * N;
  using Nodes2 = Eigen::Matrix<double, N, 2>;
  const Eigen::Map<const Nodes2> dN(p.dN.data());
  const Mat2 F = Mat2::Identity() + u.transpose() * dN;
  v.J = F.determinant();
  for (int a = 0; a < N; ++a) {
    const double gx = dN(a, 0), gy = dN(a, 1);
    v.dJ[2 * a] = F(1, 1) * gx - F(1, 0) * gy;
    v.dJ[2 * a + 1] = F(0, 0) * gy - F(0, 1) * gx;
  }
  if (second) {
    v.d2J.setZero();
    for (int a = 0; a < N; ++a)
      for (int b = 0; b < N; ++b) {
        const double c = dN(a, 0) * dN(b, 1) - dN(a, 1) * dN(b, 0);
        v.d2J(2 * a, 2 * b + 1) = c;
        v.d2J(2 * a + 1, 2 * b) = -c;
      }
  }
  if (p.radius > 0) {  // times the hoop stretch F33 = 1 + u_r / R, linear in u
    const double F33 = 1 + p.N.dot(u.col(0)) / p.radius;
    Eigen::Matrix<double, M, 1> dF33 = Eigen::Matrix<double, M, 1>::Zero();
    for (int a = 0; a < N; ++a) dF33[2 * a] = p.N[a] / p.radius;
    if (second) v.d2J = F33 * v.d2J + v.dJ * dF33.transpose() + dF33 * v.dJ.transpose();
    v.dJ = F33 * v.dJ + v.J * dF33;
    v.J *= F33;
  }
}

// dilatation_total_lagrangian for N nodes and R strain rows (3 in the plane, 4 with the hoop
// strain), in fixed-size matrices: no allocation. The points' volumes are computed once: the
// dilatation's points are the element's integration points (projected_dilatation).
template <int N, int R>
void dilatation_fixed(const std::vector<ElementPoint>& points, const Dilatation& dilatation,
                      const ShapeGradients& u_dynamic, const PlaneMaterial& material, Vector& fe_out, Matrix* Ke_out,
                      const PointLaw& law, const HoopLaw& hoop_law, const Vector* pressure,
                      const ShapeGradients* base_dynamic) {
  constexpr int M = 2 * N, kMaxPoints = 9;
  using Nodes2 = Eigen::Matrix<double, N, 2>;
  using VecM = Eigen::Matrix<double, M, 1>;
  using MatM = Eigen::Matrix<double, M, M>;
  using VecR = Eigen::Matrix<double, R, 1>;
  const int count = static_cast<int>(dilatation.points.size());
  if (count > kMaxPoints || points.size() != dilatation.points.size())
    throw std::logic_error("dilatation_total_lagrangian: the dilatation's points are not the element's");
  const Nodes2 u = u_dynamic;
  const bool second = Ke_out != nullptr;
  std::array<FixedVolume<N>, kMaxPoints> at;
  for (int j = 0; j < count; ++j) fixed_volume<N>(dilatation.points[j], u, second, at[j]);
  // The tangent's dilatation linearized about the stress base u_b (TangentSink::stress_base):
  // J_j(u_b) + dJ_j(u_b) . (u - u_b) at each dilatation point.
  const bool linearized = second && base_dynamic != nullptr;
  std::array<double, kMaxPoints> J_lin{};
  if (linearized) {
    const Nodes2 ub = *base_dynamic;
    const Nodes2 du = u - ub;
    for (int j = 0; j < count; ++j) {
      FixedVolume<N> b;
      fixed_volume<N>(dilatation.points[j], ub, false, b);
      double change = 0.0;
      for (int a = 0; a < N; ++a) change += b.dJ[2 * a] * du(a, 0) + b.dJ[2 * a + 1] * du(a, 1);
      J_lin[j] = b.J + change;
    }
  }
  VecM fe = VecM::Zero();
  MatM Ke;
  if (second) Ke.setZero();
  VecR Cv, Iv = VecR::Zero(), S;
  Iv.template head<2>().setOnes();
  if constexpr (R == 4) Iv[3] = 1.0;
  Eigen::Matrix<double, R, M> B0;
  Eigen::Matrix<double, R, R> D;
  double theta = 0.0, theta_lin = 0.0;
  VecM dtheta;
  MatM d2theta, G;
  for (size_t k = 0; k < points.size(); ++k) {
    const ElementPoint& p = points[k];
    const FixedVolume<N>& own = at[k];
    const Eigen::Map<const Nodes2> dN(p.dN.data());
    // theta = A J at point k; a row of A equal to the last one's (P0: every row) gives the same
    // theta and derivatives, kept.
    if (k == 0 || dilatation.A.row(k) != dilatation.A.row(k - 1)) {
      theta = theta_lin = 0.0;
      dtheta.setZero();
      if (second) d2theta.setZero();
      for (int j = 0; j < count; ++j) {
        const double a = dilatation.A(k, j);
        theta += a * at[j].J;
        theta_lin += a * J_lin[j];
        dtheta += a * at[j].dJ;
        if (second) d2theta += a * at[j].d2J;
      }
    }
    const Mat2 F = Mat2::Identity() + u.transpose() * dN;
    const Mat2 C = F.transpose() * F;
    Cv.template head<3>() << C(0, 0), C(1, 1), 2 * C(0, 1);
    double F33 = 1.0;
    if constexpr (R == 4) {
      F33 = 1 + p.N.dot(u.col(0)) / p.radius;
      Cv[3] = F33 * F33;
    }
    // dE = B0 du for the plain E = (C - I) / 2.
    B0.setZero();
    for (int a = 0; a < N; ++a) {
      green_lagrange_rows(B0, a, F, dN(a, 0), dN(a, 1));
      if constexpr (R == 4) B0(3, 2 * a) = F33 * p.N[a] / p.radius;
    }
    // beta = s^2 = (th / J)^(2/d): C_bar = beta C (and C33_bar = beta C33); E_bar = (beta C -
    // I) / 2 and dE_bar = B_bar du; the law's S and D at E_bar.
    const double c = 2 * exponent(p);
    double beta = 0.0;
    VecM dg, dbeta;
    Eigen::Matrix<double, R, M> Bbar;
    const auto at_dilatation = [&](double th) {
      beta = std::pow(th / own.J, c);
      dg = c * (dtheta / th - own.dJ / own.J);
      dbeta = beta * dg;
      const VecR Ebar = 0.5 * (beta * Cv - Iv);
      Bbar = 0.5 * Cv * dbeta.transpose() + beta * B0;
      Mat2 E;
      E << Ebar[0], 0.5 * Ebar[2], 0.5 * Ebar[2], Ebar[1];
      if constexpr (R == 4) {
        const HoopResponse r =
            hoop_law ? hoop_law(static_cast<int>(k), E, Ebar[3]) : material.hoop_response(E, Ebar[3]);
        S = r.S;
        D = r.D;
      } else {
        const MaterialResponse r = law ? law(static_cast<int>(k), E) : material.response(E);
        S = r.S;
        D = r.D;
      }
    };
    at_dilatation(theta);
    fe.noalias() += p.dV * Bbar.transpose() * S;
    if (pressure) {  // the multiplier's term p (theta - 1): its gradient and second derivative
      fe.noalias() += p.dV * (*pressure)[k] * dtheta;
      if (second) Ke.noalias() += p.dV * (*pressure)[k] * d2theta;
    }
    if (!second) continue;
    // The tangent at the linearized dilatation (docs/algorithm.md#newtons-tangent-the-linearized-dilatation):
    // the law's pressure there, not the bulk modulus times the second-order volume change of
    // the last correction.
    const double th = linearized && theta_lin > 0 ? theta_lin : theta;
    if (th != theta) at_dilatation(th);
    // The second derivative of sum W(E_bar): the material part, the second derivative of beta
    // times S . C / 2, the cross terms of d beta with dC, and beta times the plain geometric part.
    const MatM d2g = c * (d2theta / th - dtheta * dtheta.transpose() / (th * th) - own.d2J / own.J +
                          own.dJ * own.dJ.transpose() / (own.J * own.J));
    const MatM d2beta = beta * (dg * dg.transpose() + d2g);
    const VecM w = B0.transpose() * S;
    G.setZero();
    for (int a = 0; a < N; ++a)
      for (int b = 0; b < N; ++b) {
        const double g =
            dN(a, 0) * (S[0] * dN(b, 0) + S[2] * dN(b, 1)) + dN(a, 1) * (S[2] * dN(b, 0) + S[1] * dN(b, 1));
        G(2 * a, 2 * b) += g;
        G(2 * a + 1, 2 * b + 1) += g;
        if constexpr (R == 4) G(2 * a, 2 * b) += S[3] * p.N[a] * p.N[b] / (p.radius * p.radius);
      }
    Ke.noalias() += p.dV * (Bbar.transpose() * D * Bbar + 0.5 * S.dot(Cv) * d2beta + dbeta * w.transpose() +
                            w * dbeta.transpose() + beta * G);
  }
  fe_out = fe;
  if (second) *Ke_out = 0.5 * (Ke + Ke.transpose());
}

template <int N>
void dilatation_nodes(const std::vector<ElementPoint>& points, const Dilatation& dilatation, const ShapeGradients& u,
                      const PlaneMaterial& material, Vector& fe, Matrix* Ke, const PointLaw& law,
                      const HoopLaw& hoop_law, const Vector* pressure, const ShapeGradients* base) {
  if (points.front().radius > 0)
    dilatation_fixed<N, 4>(points, dilatation, u, material, fe, Ke, law, hoop_law, pressure, base);
  else dilatation_fixed<N, 3>(points, dilatation, u, material, fe, Ke, law, hoop_law, pressure, base);
}

}  // namespace

// q9 and t6 (mixed and exact), q4 (F-bar in axisymmetry): the element kinds with a dilatation.
void dilatation_total_lagrangian(const std::vector<ElementPoint>& points, const Dilatation& dilatation,
                                 const ShapeGradients& u, const PlaneMaterial& material, Vector& fe, Matrix* Ke,
                                 const PointLaw& law, const HoopLaw& hoop_law, const Vector* pressure,
                                 const ShapeGradients* base) {
  with_node_count<4, 6, 9>(u.rows(), "dilatation_total_lagrangian", [&](auto n) {
    dilatation_nodes<n()>(points, dilatation, u, material, fe, Ke, law, hoop_law, pressure, base);
  });
}

}  // namespace grip
