// Axisymmetric continuum (docs/algorithm.md#axisymmetric), linear kinematics:
// - patch test: u_r = c r, u_z = d z (e_rr = e_tt = c, e_zz = d, constant stress with
//   s_rr = s_tt, which is in equilibrium) held on the boundary of a distorted mesh that touches
//   the axis is reproduced at every interior node by every element kind;
// - Lame's thick-walled cylinder (a <= r <= b) under internal pressure p with u_z held at both
//   ends (plane strain): u_r = p a^2 / (E (b^2 - a^2)) (1 + nu) ((1 - 2 nu) r + b^2 / r);
// - Lame's thick-walled sphere as a quarter annulus of the r-z plane: u_R = p a^3 / (E (b^3 -
//   a^3)) ((1 - 2 nu) R + (1 + nu) b^3 / (2 R^2)); its nodes on the axis get u_r = 0 by themselves.
// Both Lame cases run as scenes: the pressure as a traction (cylinder) or as nodal forces
// totalled over the circle (sphere), within 0.5 % of the closed form at every node.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <cmath>
#include <map>
#include <numbers>

#include "solver/elements/continuum.hpp"
#include "solver/io/result.hpp"
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

TEST(Axisymmetric, UniformExpansionIsReproducedByEveryElement) {
  constexpr double c = 2e-3, d = -1e-3;
  for (ContinuumElement element : kElements) {
    const ElementShape shape = element_shape(element);
    const PlaneMesh mesh = axis_section(shape);
    const ContinuumBody body(mesh, mesh.sets.at("bottom"),
                             {std::make_shared<NeoHookeMaterial>(kYoung, kPoisson, PlaneAnalysis::axisymmetric)},
                             {element, ContinuumKinematics::linear, PlaneAnalysis::axisymmetric, 1.0});
    const int n = body.dof_count();
    Vector exact(n);
    for (int k = 0; k < body.node_count(); ++k)
      exact.segment<2>(2 * k) = Vec2(c * mesh.nodes[k].x(), d * mesh.nodes[k].y());
    std::vector<char> held(n, 0);
    for (const auto& side : boundary_sides(mesh, shape))
      for (int k : side) held[2 * k] = held[2 * k + 1] = 1;
    Vector f;
    const Matrix Kd = assembled_tangent(body, Vector::Zero(n), f);
    // Interior rows: K_ff u_f = -K_fb u_b.
    std::vector<int> free;
    for (int i = 0; i < n; ++i)
      if (!held[i]) free.push_back(i);
    ASSERT_FALSE(free.empty());
    Matrix Kff(free.size(), free.size());
    Vector rhs(free.size());
    Vector boundary = exact;
    for (int i : free) boundary[i] = 0.0;
    const Vector Kb = Kd * boundary;
    for (size_t i = 0; i < free.size(); ++i) {
      rhs[i] = -Kb[free[i]];
      for (size_t j = 0; j < free.size(); ++j) Kff(i, j) = Kd(free[i], free[j]);
    }
    const Vector u = Kff.ldlt().solve(rhs);
    double worst = 0.0;
    for (size_t i = 0; i < free.size(); ++i) worst = std::max(worst, std::abs(u[i] - exact[free[i]]));
    EXPECT_LT(worst, 1e-12 * 3 * c) << element_name(element);
    // The stress: s_rr = s_tt = (2 (l + m) c + l d), s_zz = 2 l c + (l + 2 m) d, s_rz = 0.
    const Lame l = Lame::from(kYoung, kPoisson);
    const double srr = 2 * (l.lambda + l.mu) * c + l.lambda * d, szz = 2 * l.lambda * c + (l.lambda + 2 * l.mu) * d;
    for (int e = 0; e < body.element_count(); ++e) {
      const Eigen::Vector4d s = body.centroid_stress(exact, e);
      EXPECT_NEAR(s[0], srr, 1e-9 * std::abs(srr)) << element_name(element);
      EXPECT_NEAR(s[1], szz, 1e-9 * std::abs(srr)) << element_name(element);
      EXPECT_NEAR(s[2], 0.0, 1e-9 * std::abs(srr)) << element_name(element);
      EXPECT_NEAR(s[3], srr, 1e-9 * std::abs(srr)) << element_name(element);
    }
  }
}

// A scene of one axisymmetric body with an obstacle far out of reach.
json axisymmetric_scene(const std::string& element, json mesh, json supports, json loads) {
  return {{"body",
           {{"model", "continuum"},
            {"kinematics", "linear"},
            {"analysis", "axisymmetric"},
            {"element", element},
            {"material", {{"young", kYoung}, {"poisson", kPoisson}, {"law", "saint_venant_kirchhoff"}}},
            {"mesh", mesh},
            {"contact_set", "outer"},
            {"supports", supports},
            {"loads", loads}}},
          {"obstacles",
           json::array({{{"name", "far"}, {"shape", {{"type", "segment"}, {"from", {100, 50}}, {"to", {200, 50}}}}}})},
          {"steps", 1},
          {"solver", {{"contact", {{"reach", 0.01}}}}}};
}

constexpr double kInner = 1.0, kOuter = 2.0, kPressure = 10.0;

TEST(Axisymmetric, ThickCylinderUnderInternalPressure) {
  const double a = kInner, b = kOuter, p = kPressure, E = kYoung, nu = kPoisson;
  auto lame = [&](double r) { return p * a * a / (E * (b * b - a * a)) * (1 + nu) * ((1 - 2 * nu) * r + b * b / r); };
  for (const char* element : {"q4", "q8", "t6"}) {
    json mesh = {{"rectangle", {{"origin", {a, 0}}, {"size", {b - a, 0.5}}, {"divisions", {16, 2}}}}};
    json supports = json::array({{{"set", "bottom"}, {"fix", {"y"}}}, {{"set", "top"}, {"fix", {"y"}}}});
    json loads = json::array({{{"set", "left"}, {"traction", {p, 0}}}});
    json j = axisymmetric_scene(element, mesh, supports, loads);
    j["body"]["contact_set"] = "right";
    const Solved s = solve_scene(j);
    ASSERT_TRUE(s.run.completed) << s.run.reason;
    const FieldTable& nodes = s.run.steps.back().site_fields;
    double worst = 0.0;
    for (const auto& row : nodes.rows) {
      const double r = row[0] - row[2];
      worst = std::max(worst, std::abs(row[2] / lame(r) - 1));
    }
    std::printf("cylinder %s: worst |u_r / Lame - 1| = %.2e over %zu nodes\n", element, worst, nodes.rows.size());
    EXPECT_LT(worst, 5e-3) << element;
    // No node on the axis: nothing held, but the conventions stated.
    const json effects = effects_json(s.scene);
    ASSERT_TRUE(effects.contains("axisymmetric"));
    EXPECT_TRUE(effects["axisymmetric"][0]["axis_nodes_held"].empty());
  }
}

// The quarter annulus a <= R <= b, 0 <= phi <= 90 degrees (phi from the z axis), nr x nphi q9 or
// q8 elements (q8: without centre nodes), sets inner, outer, equator (z = 0).
json quarter_annulus(int nr, int nphi, bool centre) {
  json nodes = json::array(), elements = json::array(), inner = json::array(), outer = json::array(),
       equator = json::array();
  std::vector<std::vector<int>> id(2 * nr + 1, std::vector<int>(2 * nphi + 1, -1));
  for (int i = 0; i <= 2 * nr; ++i)
    for (int k = 0; k <= 2 * nphi; ++k) {
      if (!centre && i % 2 == 1 && k % 2 == 1) continue;
      const double R = kInner + (kOuter - kInner) * i / (2.0 * nr), phi = pi / 2 * k / (2.0 * nphi);
      id[i][k] = static_cast<int>(nodes.size());
      // phi = 90 degrees on the equator z = 0; phi = 0 on the axis r = 0 (exactly).
      nodes.push_back({k == 0 ? 0.0 : R * std::sin(phi), k == 2 * nphi ? 0.0 : R * std::cos(phi)});
      if (i == 0) inner.push_back(id[i][k]);
      if (i == 2 * nr) outer.push_back(id[i][k]);
      if (k == 2 * nphi) equator.push_back(id[i][k]);
    }
  for (int i = 0; i < nr; ++i)
    for (int k = 0; k < nphi; ++k) {
      const int I = 2 * i, K = 2 * k;
      // Counter-clockwise in (r, z): R grows along the first side, phi along the second.
      json el = {id[I][K + 2],     id[I + 2][K + 2], id[I + 2][K], id[I][K],
                 id[I + 1][K + 2], id[I + 2][K + 1], id[I + 1][K], id[I][K + 1]};
      if (centre) el.push_back(id[I + 1][K + 1]);
      elements.push_back(el);
    }
  return {
      {"nodes", nodes}, {"elements", elements}, {"sets", {{"inner", inner}, {"outer", outer}, {"equator", equator}}}};
}

TEST(Axisymmetric, ThickSphereUnderInternalPressure) {
  const double a = kInner, b = kOuter, p = kPressure, E = kYoung, nu = kPoisson;
  auto lame = [&](double R) {
    return p * a * a * a / (E * (b * b * b - a * a * a)) * ((1 - 2 * nu) * R + (1 + nu) * b * b * b / (2 * R * R));
  };
  for (const bool centre : {true, false}) {
    const json mesh = quarter_annulus(8, 12, centre);
    // The pressure on the inner arc as consistent nodal forces, totals over the circle:
    // f_a = p int N_a n 2 pi r ds with the outward normal n of the body at R = a pointing to the
    // centre, so the traction on the body is + p e_R. Integrated by the quadratic side's 3 points.
    const auto& xs = mesh["nodes"];
    std::map<int, Vec2> force;
    const json& inner = mesh["sets"]["inner"];
    for (size_t k = 0; k + 2 < inner.size(); k += 2) {
      const int side[3] = {inner[k], inner[k + 1], inner[k + 2]};
      // The exact arc through the three nodes, 6 Gauss points in the angle.
      const double phi0 = std::atan2(double(xs[side[0]][0]), double(xs[side[0]][1]));
      const double phi2 = std::atan2(double(xs[side[2]][0]), double(xs[side[2]][1]));
      const double g[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, w[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
      for (int q = 0; q < 3; ++q) {
        const double s = g[q], phi = 0.5 * (phi0 + phi2) + 0.5 * (phi2 - phi0) * s;
        const double N[3] = {s * (s - 1) / 2, 1 - s * s, s * (s + 1) / 2};
        const Vec2 eR(std::sin(phi), std::cos(phi));
        const double ds = a * std::abs(phi2 - phi0) / 2 * w[q];
        for (int m = 0; m < 3; ++m)
          force.try_emplace(side[m], Vec2::Zero()).first->second += N[m] * p * eR * 2 * pi * a * std::sin(phi) * ds;
      }
    }
    json loads = json::array();
    for (const auto& [node, f] : force) loads.push_back({{"node", node}, {"force", {f.x(), f.y()}}});
    json supports = json::array({{{"set", "equator"}, {"fix", {"y"}}}});
    const Solved s = solve_scene(axisymmetric_scene(centre ? "q9" : "q8", mesh, supports, loads));
    ASSERT_TRUE(s.run.completed) << s.run.reason;
    // The axis nodes (phi = 0, 2 nr + 1 of them) are held by the reader.
    ASSERT_EQ(s.scene.axis_holds.size(), 1u);
    EXPECT_EQ(s.scene.axis_holds[0].nodes.size(), 2u * 8 + 1);
    const FieldTable& nodes = s.run.steps.back().site_fields;
    double worst = 0.0;
    for (const auto& row : nodes.rows) {
      const Vec2 X(row[0] - row[2], row[1] - row[3]), u(row[2], row[3]);
      const double R = X.norm();
      worst = std::max(worst, (u - lame(R) * X / R).norm() / lame(R));
    }
    std::printf("sphere %s: worst |u - u_Lame| / |u_Lame| = %.2e over %zu nodes\n", centre ? "q9" : "q8", worst,
                nodes.rows.size());
    EXPECT_LT(worst, 5e-3);
  }
}

TEST(Axisymmetric, RefusesNodesOffTheHalfPlaneAndQ4Bbar) {
  json mesh = {{"rectangle", {{"origin", {-0.5, 0}}, {"size", {1, 1}}, {"divisions", {2, 2}}}}};
  json j = axisymmetric_scene("q4", mesh, json::array({{{"set", "bottom"}, {"fix", {"y"}}}}), json::array());
  j["body"]["contact_set"] = "right";
  try {
    read_scene(j);
    FAIL() << "a node at x < 0 was accepted";
  } catch (const SceneErrors& e) {
    ASSERT_FALSE(e.issues().empty());
    EXPECT_EQ(e.issues()[0].pointer, "/body/mesh");
    EXPECT_NE(e.issues()[0].detail.find("nodes at x < 0: 0, 3, 6"), std::string::npos) << e.issues()[0].detail;
  }
  j["body"]["mesh"]["rectangle"]["origin"] = {0, 0};
  j["body"]["element"] = "q4_bbar";  // its mean dilatation omits the hoop strain
  try {
    read_scene(j);
    FAIL() << "q4_bbar was accepted";
  } catch (const SceneErrors& e) {
    EXPECT_EQ(e.issues()[0].pointer, "/body/element");
  }
}

}  // namespace
}  // namespace grip
