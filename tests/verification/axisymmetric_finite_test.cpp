// Axisymmetric continuum under finite kinematics (docs/algorithm.md#axisymmetric): total
// Lagrangian with the hoop stretch F33 = r / R = 1 + u_r / R.
// - patch test: the homogeneous stretch u_r = a R, u_z = b Z (F = diag(1 + a, 1 + b, 1 + a))
//   held on the boundary of a distorted mesh that touches the axis (raised in ten increments) is
//   found by Newton at every interior node by every element kind, and the reactions are the closed form's: the axial
//   force P_zz pi R_o^2 on the top, the radial P_rr 2 pi R_o H on the outer side;
// - the tangent against central differences of the internal force (both laws, every kind);
// - Lame's thick cylinder (u_z held) under an internal pressure (a dead load): at p / E = 1e-5
//   the linear closed form within 1e-4 at every node; at p / E = 0.1 (hoop stretch 1.20) the
//   inner radius against an independent integration of the radial equilibrium of the same
//   neo-Hookean law (shooting, RK4), converging with the mesh;
// - Hertz's sphere (schemas/examples/hertz-sphere.json) under finite kinematics: the load P at
//   the same prescribed approach within 0.5 % of the linear run's.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>

#include "solver/elements/continuum.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/distorted_mesh.hpp"
#include "tests/support/scenes.hpp"
#include "tests/support/tangent_check.hpp"

namespace grip {
namespace {

using nlohmann::json;
using std::numbers::pi;
using namespace grip::testing;

constexpr double kYoung = 1000.0, kPoisson = 0.3;

const ContinuumElement kElements[] = {ContinuumElement::t3, ContinuumElement::t6, ContinuumElement::q4,
                                      ContinuumElement::q8, ContinuumElement::q9};

std::shared_ptr<const PlaneMaterial> law(bool neo_hookean) {
  if (neo_hookean) return std::make_shared<NeoHookeMaterial>(kYoung, kPoisson, PlaneAnalysis::axisymmetric);
  return std::make_shared<HookeMaterial>(kYoung, kPoisson, PlaneAnalysis::axisymmetric);
}

ContinuumBody finite_body(const PlaneMesh& mesh, ContinuumElement element, bool neo_hookean) {
  return ContinuumBody(mesh, mesh.sets.at("bottom"), {law(neo_hookean)},
                       {element, ContinuumKinematics::finite, PlaneAnalysis::axisymmetric, 1.0});
}

TEST(AxisymmetricFinite, HomogeneousStretchIsReproducedWithTheClosedFormReactions) {
  constexpr double a = 0.3, b = -0.2, Ro = 3.0, H = 2.0;
  // Neo-Hookean, F = diag(lr, lz, lt) with lt = lr: S_ii = mu (1 - 1 / l_i^2) + lambda ln J / l_i^2.
  const Lame l = Lame::from(kYoung, kPoisson);
  const double lr = 1 + a, lz = 1 + b, lnJ = std::log(lr * lr * lz);
  const double Prr = lr * (l.mu * (1 - 1 / (lr * lr)) + l.lambda * lnJ / (lr * lr));
  const double Pzz = lz * (l.mu * (1 - 1 / (lz * lz)) + l.lambda * lnJ / (lz * lz));
  for (ContinuumElement element : kElements) {
    const ElementShape shape = element_shape(element);
    const PlaneMesh mesh = axis_section(shape);
    const ContinuumBody body = finite_body(mesh, element, true);
    const int n = body.dof_count();
    Vector exact(n);
    for (int k = 0; k < body.node_count(); ++k)
      exact.segment<2>(2 * k) = Vec2(a * mesh.nodes[k].x(), b * mesh.nodes[k].y());
    std::vector<char> held(n, 0);
    for (const auto& side : boundary_sides(mesh, shape))
      for (int k : side) held[2 * k] = held[2 * k + 1] = 1;
    std::vector<int> free;
    for (int i = 0; i < n; ++i)
      if (!held[i]) free.push_back(i);
    ASSERT_FALSE(free.empty());
    // Newton on the interior dofs, the boundary values raised in ten increments.
    Vector q = Vector::Zero(n), f;
    for (int inc = 1; inc <= 10; ++inc) {
      for (int i = 0; i < n; ++i)
        if (held[i]) q[i] = inc / 10.0 * exact[i];
      for (int it = 0; it < 30; ++it) {
        const Matrix K = assembled_tangent(body, q, f);
        Matrix Kff(free.size(), free.size());
        Vector rhs(free.size());
        for (size_t i = 0; i < free.size(); ++i) {
          rhs[i] = -f[free[i]];
          for (size_t j = 0; j < free.size(); ++j) Kff(i, j) = K(free[i], free[j]);
        }
        const Vector dq = Kff.partialPivLu().solve(rhs);
        for (size_t i = 0; i < free.size(); ++i) q[free[i]] += dq[i];
        if (dq.lpNorm<Eigen::Infinity>() < 1e-14) break;
      }
    }
    EXPECT_LT((q - exact).lpNorm<Eigen::Infinity>(), 1e-10 * a * Ro) << element_name(element);
    f = Vector::Zero(n);
    body.internal_force(exact, f, nullptr);
    double axial = 0.0, radial = 0.0;
    for (int k = 0; k < body.node_count(); ++k) {
      if (mesh.nodes[k].y() == H) axial += f[2 * k + 1];
      if (mesh.nodes[k].x() == Ro) radial += f[2 * k];
    }
    std::printf("%s: |q - exact| = %.1e; axial %.10g (closed form %.10g), radial %.10g (%.10g)\n",
                element_name(element), (q - exact).lpNorm<Eigen::Infinity>(), axial, Pzz * pi * Ro * Ro, radial,
                Prr * 2 * pi * Ro * H);
    EXPECT_NEAR(axial, Pzz * pi * Ro * Ro, 1e-10 * std::abs(Pzz * pi * Ro * Ro)) << element_name(element);
    EXPECT_NEAR(radial, Prr * 2 * pi * Ro * H, 1e-10 * std::abs(Prr * 2 * pi * Ro * H)) << element_name(element);
    // The Cauchy stress at every centroid: sigma_ii = l_i P_ii / J, the hoop equal to the radial.
    const double J = lr * lr * lz;
    for (int e = 0; e < body.element_count(); ++e) {
      const Eigen::Vector4d s = body.centroid_stress(exact, e);
      EXPECT_NEAR(s[0], lr * Prr / J, 1e-9 * std::abs(lr * Prr / J)) << element_name(element);
      EXPECT_NEAR(s[1], lz * Pzz / J, 1e-9 * std::abs(lr * Prr / J)) << element_name(element);
      EXPECT_NEAR(s[3], lr * Prr / J, 1e-9 * std::abs(lr * Prr / J)) << element_name(element);
    }
  }
}

TEST(AxisymmetricFinite, TangentMatchesCentralDifferences) {
  for (const bool neo_hookean : {true, false})
    for (ContinuumElement element : kElements) {
      const PlaneMesh mesh = axis_section(element_shape(element));
      const ContinuumBody body = finite_body(mesh, element, neo_hookean);
      const int n = body.dof_count();
      // A smooth field of strains near 10 % with u_r = 0 on the axis, and some noise off it.
      Vector q(n);
      std::mt19937 rng(3);
      std::uniform_real_distribution<double> noise(-0.01, 0.01);
      for (int k = 0; k < body.node_count(); ++k) {
        const Vec2 X = mesh.nodes[k];
        q.segment<2>(2 * k) = Vec2(0.1 * X.x() * (1 + 0.2 * X.y()) + (X.x() > 0 ? noise(rng) : 0.0),
                                   -0.05 * X.y() + 0.03 * X.x() * X.x() + noise(rng));
      }
      const TangentCheck c = check_tangent(body, q, 1e-6);
      std::printf("%s %s: |K - K_fd| / |K| = %.1e\n", neo_hookean ? "neo-Hookean" : "SVK", element_name(element),
                  c.worst());
      EXPECT_LT(c.worst(), 1e-6) << element_name(element);
      EXPECT_LT((c.K - c.K.transpose()).lpNorm<Eigen::Infinity>(), 1e-12 * c.K.lpNorm<Eigen::Infinity>());  // symmetric
    }
}

constexpr double kInner = 1.0, kOuter = 2.0;

// The thick cylinder kInner <= R <= kOuter, height 0.25, u_z held on both ends, the pressure p
// on the inner side as a traction (per unit reference area: a dead load).
Solved finite_cylinder(double p, int divisions) {
  json j = {
      {"body",
       {{"model", "continuum"},
        {"kinematics", "finite"},
        {"analysis", "axisymmetric"},
        {"element", "q8"},
        {"material", {{"young", kYoung}, {"poisson", kPoisson}, {"law", "neo_hookean"}}},
        {"mesh",
         {{"rectangle", {{"origin", {kInner, 0}}, {"size", {kOuter - kInner, 0.25}}, {"divisions", {divisions, 1}}}}}},
        {"contact_set", "right"},
        {"supports", json::array({{{"set", "bottom"}, {"fix", {"y"}}}, {{"set", "top"}, {"fix", {"y"}}}})},
        {"loads", json::array({{{"set", "left"}, {"traction", {p, 0}}}})}}},
      {"obstacles",
       json::array({{{"name", "far"}, {"shape", {{"type", "segment"}, {"from", {100, 50}}, {"to", {200, 50}}}}}})},
      {"steps", 4},
      {"solver", {{"contact", {{"reach", 0.01}}}}}};
  return solve_scene(j);
}

// The inner radius r(a) of the same cylinder from the radial equilibrium in the reference
// configuration, dP_rr/dR = (P_tt - P_rr) / R, P_rr(a) = -p, P_rr(b) = 0, with F = diag(r', 1,
// r / R) and the compressible neo-Hookean law: RK4 in (r, P_rr), r' from P_rr by Newton, and
// the secant method on r(a).
double shooting_inner_radius(double p) {
  const Lame l = Lame::from(kYoung, kPoisson);
  const auto P = [&](double s, double t) {  // P_ii for the stretch s of i and the other stretch t
    const double lnJ = std::log(s * t);
    return l.mu * (s - 1 / s) + l.lambda * lnJ / s;
  };
  const auto slope = [&](double R, double r, double Prr) {  // r' from P_rr(r', r / R) = Prr
    double s = 1.0;
    for (int it = 0; it < 50; ++it) {
      const double t = r / R, g = P(s, t) - Prr;
      const double dg = l.mu * (1 + 1 / (s * s)) + l.lambda * (1 - std::log(s * t)) / (s * s);
      s -= g / dg;
      if (std::abs(g) < 1e-14 * kYoung) break;
    }
    return s;
  };
  const auto rhs = [&](double R, const Eigen::Vector2d& y) {
    const double s = slope(R, y[0], y[1]);
    return Eigen::Vector2d(s, (P(y[0] / R, s) - y[1]) / R);
  };
  const auto outer_stress = [&](double ra) {
    Eigen::Vector2d y(ra, -p);
    const int steps = 4000;
    const double h = (kOuter - kInner) / steps;
    for (int k = 0; k < steps; ++k) {
      const double R = kInner + k * h;
      const Eigen::Vector2d k1 = rhs(R, y), k2 = rhs(R + h / 2, y + h / 2 * k1), k3 = rhs(R + h / 2, y + h / 2 * k2),
                            k4 = rhs(R + h, y + h * k3);
      y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    return y[1];
  };
  double x0 = kInner, x1 = kInner * (1 + 2 * p / kYoung), f0 = outer_stress(x0), f1 = outer_stress(x1);
  for (int it = 0; it < 50 && std::abs(f1) > 1e-13 * p; ++it) {
    const double x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
    x0 = x1;
    f0 = f1;
    x1 = x2;
    f1 = outer_stress(x1);
  }
  return x1;
}

double inner_displacement(const Solved& s) {
  const FieldTable& nodes = s.run.steps.back().site_fields;
  for (const auto& row : nodes.rows)
    if (std::abs(row[0] - row[2] - kInner) < 1e-12 && std::abs(row[1] - row[3]) < 1e-12) return row[2];
  ADD_FAILURE() << "no node at (a, 0)";
  return 0.0;
}

TEST(AxisymmetricFinite, ThickCylinderAtSmallLoadIsLame) {
  const double a = kInner, b = kOuter, p = 1e-5 * kYoung, E = kYoung, nu = kPoisson;
  auto lame = [&](double r) { return p * a * a / (E * (b * b - a * a)) * (1 + nu) * ((1 - 2 * nu) * r + b * b / r); };
  const Solved s = finite_cylinder(p, 16);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  double worst = 0.0;
  for (const auto& row : s.run.steps.back().site_fields.rows)
    worst = std::max(worst, std::abs(row[2] / lame(row[0] - row[2]) - 1));
  std::printf("p / E = 1e-5: worst |u_r / Lame - 1| = %.2e\n", worst);
  EXPECT_LT(worst, 1e-4);
}

TEST(AxisymmetricFinite, ThickCylinderAtLargeLoadConvergesToTheRadialIntegration) {
  const double p = 0.1 * kYoung;
  const double reference = shooting_inner_radius(p) - kInner;
  double previous = 1.0;
  for (const int divisions : {2, 4, 8, 16}) {
    const Solved s = finite_cylinder(p, divisions);
    ASSERT_TRUE(s.run.completed) << s.run.reason;
    const double error = std::abs(inner_displacement(s) / reference - 1);
    std::printf("p / E = 0.1, %2d q8 across: u_r(a) = %.8f, integration %.8f, error %.2e\n", divisions,
                inner_displacement(s), reference, error);
    EXPECT_LT(error, previous);
    previous = error;
  }
  EXPECT_GT(reference / kInner, 0.15);  // a finite strain indeed
  EXPECT_LT(previous, 1e-5);
}

TEST(AxisymmetricFinite, HertzSphereAtSmallLoadAgreesWithLinear) {
  json linear = example_scene("hertz-sphere");
  linear["body"]["supports"][0]["values"]["y"] = -0.01;
  linear["steps"] = 1;
  json finite = linear;
  finite["body"]["kinematics"] = "finite";
  const Solved sl = solve_scene(linear), sf = solve_scene(finite);
  ASSERT_TRUE(sl.run.completed) << sl.run.reason;
  ASSERT_TRUE(sf.run.completed) << sf.run.reason;
  expect_every_step_sound(sf);
  const double Pl = -reaction_resultant(sl.scene.problem, sl.run.steps.back()).y();
  const double Pf = -reaction_resultant(sf.scene.problem, sf.run.steps.back()).y();
  std::printf("Hertz sphere at 0.01 mm: P linear %.2f N, finite %.2f N (%+.3f %%)\n", Pl, Pf, 100 * (Pf / Pl - 1));
  EXPECT_NEAR(Pf, Pl, 0.005 * Pl);
}

}  // namespace
}  // namespace grip
