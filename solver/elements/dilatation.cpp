#include "solver/elements/dilatation.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace grip {
namespace {

// J at a point with its first and (if asked) second derivatives in the element's dofs.
struct Volume {
  double J = 1.0;
  Vector dJ;
  Matrix d2J;
};

Volume volume_of(const ElementPoint& p, const ShapeGradients& u, bool second) {
  const int n = static_cast<int>(p.dN.rows());
  const Mat2 F = deformation_gradient(p, u);
  Volume v;
  v.J = F.determinant();
  v.dJ.resize(2 * n);
  for (int a = 0; a < n; ++a) {
    const double gx = p.dN(a, 0), gy = p.dN(a, 1);
    v.dJ[2 * a] = F(1, 1) * gx - F(1, 0) * gy;
    v.dJ[2 * a + 1] = F(0, 0) * gy - F(0, 1) * gx;
  }
  if (second) {
    v.d2J = Matrix::Zero(2 * n, 2 * n);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const double c = p.dN(a, 0) * p.dN(b, 1) - p.dN(a, 1) * p.dN(b, 0);
        v.d2J(2 * a, 2 * b + 1) = c;
        v.d2J(2 * a + 1, 2 * b) = -c;
      }
  }
  if (p.radius > 0) {  // times the hoop stretch F33 = 1 + u_r / R, linear in u
    const double F33 = 1 + p.N.dot(u.col(0)) / p.radius;
    Vector dF33 = Vector::Zero(2 * n);
    for (int a = 0; a < n; ++a) dF33[2 * a] = p.N[a] / p.radius;
    if (second) v.d2J = F33 * v.d2J + v.dJ * dF33.transpose() + dF33 * v.dJ.transpose();
    v.dJ = F33 * v.dJ + v.J * dF33;
    v.J *= F33;
  }
  return v;
}

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

void dilatation_total_lagrangian(const std::vector<ElementPoint>& points, const Dilatation& dilatation,
                                 const ShapeGradients& u, const PlaneMaterial& material, Vector& fe, Matrix* Ke,
                                 const PointLaw& law, const HoopLaw& hoop_law, const Vector* pressure) {
  const int n = static_cast<int>(u.rows()), m = 2 * n;
  const bool hoop = points.front().radius > 0;
  const int R = hoop ? 4 : 3;
  const bool second = Ke != nullptr;
  std::vector<Volume> at;
  for (const ElementPoint& p : dilatation.points) at.push_back(volume_of(p, u, second));
  fe = Vector::Zero(m);
  if (Ke) *Ke = Matrix::Zero(m, m);
  Vector Cv(R), Iv = Vector::Zero(R), S(R), dtheta(m);
  Iv.head<2>().setOnes();
  if (hoop) Iv[3] = 1.0;
  Matrix B0(R, m), D(R, R), d2theta;
  for (size_t k = 0; k < points.size(); ++k) {
    const ElementPoint& p = points[k];
    const Volume own = volume_of(p, u, second);
    double theta = 0.0;
    dtheta.setZero();
    if (second) d2theta = Matrix::Zero(m, m);
    for (size_t j = 0; j < at.size(); ++j) {
      const double a = dilatation.A(k, j);
      theta += a * at[j].J;
      dtheta += a * at[j].dJ;
      if (second) d2theta += a * at[j].d2J;
    }
    // beta = s^2 = (theta / J)^(2/d): C_bar = beta C (and C33_bar = beta C33).
    const double c = 2 * exponent(p);
    const double beta = std::pow(theta / own.J, c);
    const Vector dg = c * (dtheta / theta - own.dJ / own.J);
    const Vector dbeta = beta * dg;
    const Mat2 F = deformation_gradient(p, u);
    const Mat2 C = F.transpose() * F;
    const double F33 = hoop ? 1 + p.N.dot(u.col(0)) / p.radius : 1.0;
    Cv.head<3>() << C(0, 0), C(1, 1), 2 * C(0, 1);
    if (hoop) Cv[3] = F33 * F33;
    // dE = B0 du for the plain E = (C - I) / 2.
    B0.setZero();
    for (int a = 0; a < n; ++a) {
      const double gx = p.dN(a, 0), gy = p.dN(a, 1);
      green_lagrange_rows(B0, a, F, gx, gy);
      if (hoop) B0(3, 2 * a) = F33 * p.N[a] / p.radius;
    }
    // E_bar = (beta C - I) / 2 and dE_bar = B_bar du.
    const Vector Ebar = 0.5 * (beta * Cv - Iv);
    const Matrix Bbar = 0.5 * Cv * dbeta.transpose() + beta * B0;
    Mat2 E;
    E << Ebar[0], 0.5 * Ebar[2], 0.5 * Ebar[2], Ebar[1];
    if (hoop) {
      const HoopResponse r = hoop_law ? hoop_law(static_cast<int>(k), E, Ebar[3]) : material.hoop_response(E, Ebar[3]);
      S = r.S;
      D = r.D;
    } else {
      const MaterialResponse r = law ? law(static_cast<int>(k), E) : material.response(E);
      S = r.S;
      D = r.D;
    }
    fe.noalias() += p.dV * Bbar.transpose() * S;
    if (pressure) {  // the multiplier's term p (theta - 1): its gradient and second derivative
      fe.noalias() += p.dV * (*pressure)[k] * dtheta;
      if (Ke) Ke->noalias() += p.dV * (*pressure)[k] * d2theta;
    }
    if (!Ke) continue;
    // The second derivative of sum W(E_bar): the material part, the second derivative of beta
    // times S . C / 2, the cross terms of d beta with dC, and beta times the plain geometric part.
    const Matrix d2g = c * (d2theta / theta - dtheta * dtheta.transpose() / (theta * theta) - own.d2J / own.J +
                            own.dJ * own.dJ.transpose() / (own.J * own.J));
    const Matrix d2beta = beta * (dg * dg.transpose() + d2g);
    const Vector w = B0.transpose() * S;
    Matrix G = Matrix::Zero(m, m);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const double g =
            p.dN(a, 0) * (S[0] * p.dN(b, 0) + S[2] * p.dN(b, 1)) + p.dN(a, 1) * (S[2] * p.dN(b, 0) + S[1] * p.dN(b, 1));
        G(2 * a, 2 * b) += g;
        G(2 * a + 1, 2 * b + 1) += g;
        if (hoop) G(2 * a, 2 * b) += S[3] * p.N[a] * p.N[b] / (p.radius * p.radius);
      }
    Ke->noalias() += p.dV * (Bbar.transpose() * D * Bbar + 0.5 * S.dot(Cv) * d2beta + dbeta * w.transpose() +
                             w * dbeta.transpose() + beta * G);
  }
  if (Ke) *Ke = 0.5 * (*Ke + Ke->transpose());
}

}  // namespace grip
