// A manufactured solution of linear plane-strain elasticity: the smooth displacement
//   ux = A sin(a x) cos(b y),  uy = A cos(c x) sin(d y)
// on the unit square, held at its value on the whole boundary and loaded by the body force
// b = -div sigma(u) = -((lambda + mu) grad div u + mu lap u) that makes it exact. The square is
// meshed by the generator with every node moved by a smooth map that keeps the boundary (so
// that the quadratic kinds have curved sides), at 4, 8, 16 and 32 divisions a side. The L2 error
// of the displacement falls as h^2 for t3 and q4 and as h^3 for t6, q8 and q9; and meshes of
// different kinds converge to the same displacements: at the nodes they share, the
// differences between them fall at the rate of the lower-order kind.
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>

#include "solver/elements/continuum.hpp"

namespace grip {
namespace {

using std::numbers::pi;

constexpr double kYoung = 1000.0, kPoisson = 0.3, kAmplitude = 0.01;
constexpr double ka = pi, kb = 1.5 * pi, kc = 2 * pi, kd = 0.5 * pi;  // the field's wave numbers

Vec2 exact(const Vec2& x) {
  return kAmplitude * Vec2(std::sin(ka * x.x()) * std::cos(kb * x.y()), std::cos(kc * x.x()) * std::sin(kd * x.y()));
}

Vec2 body_force(const Vec2& x) {
  const Lame l = Lame::from(kYoung, kPoisson);
  const double sx = std::sin(ka * x.x()), cx = std::cos(ka * x.x()), sy = std::sin(kb * x.y()),
               cy = std::cos(kb * x.y());
  const double Sx = std::sin(kc * x.x()), Cx = std::cos(kc * x.x()), Sy = std::sin(kd * x.y()),
               Cy = std::cos(kd * x.y());
  // Second derivatives of ux = sx cy and uy = Cx Sy (times the amplitude).
  const double ux_xx = -ka * ka * sx * cy, ux_yy = -kb * kb * sx * cy, ux_xy = -ka * kb * cx * sy;
  const double uy_xx = -kc * kc * Cx * Sy, uy_yy = -kd * kd * Cx * Sy, uy_xy = -kc * kd * Sx * Cy;
  const Vec2 grad_div(ux_xx + uy_xy, ux_xy + uy_yy), laplacian(ux_xx + ux_yy, uy_xx + uy_yy);
  return -kAmplitude * ((l.lambda + l.mu) * grad_div + l.mu * laplacian);
}

// The unit square of n x n divisions (2 n^2 triangles), every node moved by a map that is the
// identity on the boundary.
PlaneMesh mapped_square(ElementShape shape, int n) {
  RectangleSpec spec;
  spec.nx = spec.ny = n;
  PlaneMesh mesh = rectangle_mesh(spec, shape);
  for (Vec2& p : mesh.nodes) {
    const double x = p.x(), y = p.y();
    p = Vec2(x + 0.06 * std::sin(2 * pi * x) * std::sin(pi * y), y + 0.06 * std::sin(pi * x) * std::sin(2 * pi * y));
  }
  return mesh;
}

struct Solution {
  PlaneMesh mesh;
  Vector u;               // nodal displacements
  double l2_error = 0.0;  // ||u_h - u|| / ||u|| over the square
};

Solution solve(ContinuumElement element, int n) {
  const ElementShape shape = element_shape(element);
  Solution s{mapped_square(shape, n), {}, 0.0};
  const PlaneMesh& mesh = s.mesh;
  const ContinuumBody body(mesh, mesh.sets.at("bottom"),
                           {std::make_shared<HookeMaterial>(kYoung, kPoisson, PlaneAnalysis::plane_strain)},
                           {element, ContinuumKinematics::linear, PlaneAnalysis::plane_strain, 1.0});
  const int dofs = body.dof_count();
  Vector f = Vector::Zero(dofs);
  Triplets triplets;
  TripletSink sink(triplets);
  body.internal_force(Vector::Zero(dofs), f, &sink);
  // The consistent body force, by the element's own rule.
  const int nodes = element_node_count(shape);
  auto coordinates = [&](const std::vector<int>& el) {
    ShapeGradients X(nodes, 2);
    for (int a = 0; a < nodes; ++a) X.row(a) = mesh.nodes[el[a]].transpose();
    return X;
  };
  for (const auto& el : mesh.elements) {
    const ShapeGradients X = coordinates(el);
    for (const ElementPoint& p : element_points(shape, X, 1.0)) {
      const Vec2 b = body_force(X.transpose() * p.N);
      for (int a = 0; a < nodes; ++a) f.segment<2>(2 * el[a]) += p.N[a] * p.dV * b;
    }
  }
  // The boundary held at the exact field; K_ff u_f = f_f - K_fb u_b.
  s.u = Vector::Zero(dofs);
  std::vector<int> index(dofs, 0);
  for (const auto& side : boundary_sides(mesh, shape))
    for (int k : side) {
      s.u.segment<2>(2 * k) = exact(mesh.nodes[k]);
      index[2 * k] = index[2 * k + 1] = -1;
    }
  int free = 0;
  for (int& i : index)
    if (i == 0) i = free++;
  Eigen::SparseMatrix<double> K(dofs, dofs);
  K.setFromTriplets(triplets.begin(), triplets.end());
  const Vector rhs = f - K * s.u;
  Triplets reduced;
  for (const auto& t : triplets)
    if (index[t.row()] >= 0 && index[t.col()] >= 0) reduced.emplace_back(index[t.row()], index[t.col()], t.value());
  Eigen::SparseMatrix<double> Kff(free, free);
  Kff.setFromTriplets(reduced.begin(), reduced.end());
  Vector rhs_f(free);
  for (int i = 0; i < dofs; ++i)
    if (index[i] >= 0) rhs_f[index[i]] = rhs[i];
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(Kff);
  EXPECT_EQ(ldlt.info(), Eigen::Success);
  const Vector u_f = ldlt.solve(rhs_f);
  for (int i = 0; i < dofs; ++i)
    if (index[i] >= 0) s.u[i] = u_f[index[i]];
  // The L2 error by a rule richer than the elements' own: the t6 rule (degree 4) on triangles,
  // 3 x 3 Gauss on quadrilaterals.
  const ElementShape rich = element_corner_count(shape) == 3 ? ElementShape::t6 : ElementShape::q9;
  double error = 0.0, norm = 0.0;
  for (const auto& el : mesh.elements) {
    const ShapeGradients X = coordinates(el);
    for (const GaussPoint& g : gauss_rule(rich)) {
      const ElementPoint p = element_point(shape, X, g.xi, g.eta, g.weight);
      Vec2 uh = Vec2::Zero();
      for (int a = 0; a < nodes; ++a) uh += p.N[a] * s.u.segment<2>(2 * el[a]);
      const Vec2 ue = exact(X.transpose() * p.N);
      error += (uh - ue).squaredNorm() * p.dV;
      norm += ue.squaredNorm() * p.dV;
    }
  }
  s.l2_error = std::sqrt(error / norm);
  return s;
}

// The largest difference of two solutions' displacements at the nodes they share (the same
// position), over the largest displacement.
double nodal_difference(const Solution& a, const Solution& b) {
  std::map<std::pair<long, long>, int> at;
  auto key = [](const Vec2& x) { return std::make_pair(std::lround(x.x() * 1e9), std::lround(x.y() * 1e9)); };
  for (size_t k = 0; k < b.mesh.nodes.size(); ++k) at[key(b.mesh.nodes[k])] = static_cast<int>(k);
  double diff = 0.0;
  int shared = 0;
  for (size_t k = 0; k < a.mesh.nodes.size(); ++k)
    if (const auto it = at.find(key(a.mesh.nodes[k])); it != at.end()) {
      diff = std::max(diff, (a.u.segment<2>(2 * k) - b.u.segment<2>(2 * it->second)).norm());
      ++shared;
    }
  EXPECT_GT(shared, 0);
  return diff / std::max(a.u.lpNorm<Eigen::Infinity>(), b.u.lpNorm<Eigen::Infinity>());
}

constexpr int kLevels[] = {4, 8, 16, 32};

TEST(ManufacturedSolution, ErrorFallsAtTheElementsOrder) {
  const ContinuumElement kinds[] = {ContinuumElement::t3, ContinuumElement::q4, ContinuumElement::t6,
                                    ContinuumElement::q8, ContinuumElement::q9};
  std::map<ContinuumElement, std::vector<Solution>> solved;
  std::printf("%-4s %6s %12s %6s\n", "kind", "n", "L2 error", "rate");
  for (ContinuumElement kind : kinds) {
    const bool quadratic = is_quadratic(element_shape(kind));
    for (int n : kLevels) {
      solved[kind].push_back(solve(kind, n));
      const auto& s = solved[kind];
      const double rate = s.size() > 1 ? std::log2(s[s.size() - 2].l2_error / s.back().l2_error) : 0.0;
      std::printf("%-4s %6d %12.4e %6.2f\n", element_name(kind), n, s.back().l2_error, rate);
      // Asymptotic from 8 divisions on: each halving of h divides the error by 2^2 or 2^3.
      if (s.size() > 2) EXPECT_GE(rate, quadratic ? 2.7 : 1.8) << element_name(kind) << " at n = " << n;
    }
    EXPECT_LT(solved[kind].back().l2_error, quadratic ? 1e-4 : 1e-2);  // 5.5e-5 (t6), 5.4e-3 (t3) measured
  }
  // The same body meshed as q4, q9, t3 and t6 (and q8): the nodal differences fall with h at
  // the rate of the lower-order kind of each pair, so all converge to one field.
  struct Pair {
    ContinuumElement a, b;
    double rate;
  };
  const Pair pairs[] = {{ContinuumElement::q4, ContinuumElement::t3, 1.8},
                        {ContinuumElement::q4, ContinuumElement::q9, 1.8},
                        {ContinuumElement::t3, ContinuumElement::t6, 1.8},
                        {ContinuumElement::q9, ContinuumElement::t6, 2.7},
                        {ContinuumElement::q9, ContinuumElement::q8, 2.7}};
  for (const Pair& p : pairs) {
    std::printf("%s - %s nodal difference:", element_name(p.a), element_name(p.b));
    std::vector<double> d;
    for (size_t k = 0; k < std::size(kLevels); ++k) {
      d.push_back(nodal_difference(solved[p.a][k], solved[p.b][k]));
      std::printf(" %.3e", d.back());
      if (k > 1) EXPECT_GE(std::log2(d[k - 1] / d[k]), p.rate) << element_name(p.a) << " " << element_name(p.b);
    }
    std::printf("\n");
  }
}

}  // namespace
}  // namespace grip
