#pragma once
// Prandtl's punch (docs/verification.md): a rigid flat punch of half-width b = 1 pressed into a
// block of elastic-perfectly plastic von Mises material (E = 1000, nu = 0.3, sigma_y = 1, plane
// strain, small strain, q4_bbar), 10 b wide and 10 b deep. The half model x >= 0: the symmetry
// line x = 0 held in x, the base in x and y, the far side in x. The punch is the nodes of the
// top with x <= b moved down together (smooth: y prescribed, x free; rough: x held too), as in
// de Souza Neto, Peric and Owen (Computational Methods for Plasticity, 2008). The limit load of
// the whole punch is (2 + pi) k 2b with k = sigma_y / sqrt(3) (Prandtl 1920; Hill 1950: the
// same for a smooth and a rough punch on a weightless body): (2 + pi) k b on the half model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <nlohmann/json.hpp>

#include "solver/elements/continuum.hpp"
#include "solver/materials/j2_plasticity.hpp"
#include "tests/support/newton_driver.hpp"

namespace grip::testing {

inline double prandtl_limit_half() { return (2 + std::numbers::pi) / std::sqrt(3.0); }

struct PunchCurve {
  std::vector<double> depth, load;  // the punch's penetration and force (half model), per step
  std::vector<int> newton;          // Newton iterations per step
  int punch_nodes = 0;
  double h = 0.0;  // the element size near the punch's edge
  // At the last step, per element: its centre and its equivalent plastic strain (volume mean).
  std::vector<Vec2> centre;
  std::vector<double> alpha;
};

// The block's mesh: elements of size h within 2.5 b of the punch's edge (growing beyond, nx x ny
// in all).
inline PlaneMesh punch_block_mesh(double h, int nx, int ny) {
  RectangleSpec spec;
  spec.origin = {0, -10};
  spec.size = {10, 10};
  spec.nx = nx;
  spec.ny = ny;
  spec.refine = Refinement{h, 2.5};
  spec.towards = {1, 0};
  return rectangle_mesh(spec, ElementShape::q4);
}

// The half model on punch_block_mesh(h, nx, ny), pressed to `depth` through the penetrations
// `fractions` of it; the punch the top's nodes with x <= half_width (b unless said).
inline PunchCurve press_punch(double h, int nx, int ny, double depth, const std::vector<double>& fractions, bool rough,
                              double half_width = 1.0) {
  PlaneMesh mesh = punch_block_mesh(h, nx, ny);
  std::vector<int> punch;
  for (int n : mesh.sets.at("top"))
    if (mesh.nodes[n].x() <= half_width + 1e-9) punch.push_back(n);
  auto law = std::make_shared<J2Material>(1000.0, 0.3, 1.0, IsotropicHardening{}, 0.0, PlaneAnalysis::plane_strain);
  ContinuumBody body(mesh, mesh.sets.at("top"), {law},
                     {ContinuumElement::q4_bbar, ContinuumKinematics::linear, PlaneAnalysis::plane_strain, 1.0});
  std::vector<char> held(body.dof_count(), 0);
  for (int n : mesh.sets.at("left")) held[2 * n] = 1;
  for (int n : mesh.sets.at("right")) held[2 * n] = 1;
  for (int n : mesh.sets.at("bottom")) held[2 * n] = held[2 * n + 1] = 1;
  for (int n : punch) held[2 * n + 1] = 1, held[2 * n] = held[2 * n] || rough;
  Driver d(body, held);
  d.line_search = true;  // a full Newton step can overshoot where the plastic zone first spreads
  PunchCurve c;
  c.punch_nodes = static_cast<int>(punch.size());
  for (double t : fractions) {
    d.solve(
        [&](Vector& q) {
          for (int n : punch) q[2 * n + 1] = -t * depth;
        },
        1e-9);
    const Vector f = d.force(nullptr);
    double load = 0.0;
    for (int n : punch) load += f[2 * n + 1];
    c.depth.push_back(t * depth);
    c.load.push_back(-load);
    c.newton.push_back(static_cast<int>(d.residuals.size()) - 1);
  }
  c.h = h;
  const auto rows = body.element_fields(d.q).rows;
  for (size_t e = 0; e < mesh.elements.size(); ++e) {
    Vec2 centre = Vec2::Zero();
    for (int n : mesh.elements[e]) centre += mesh.nodes[n];
    c.centre.push_back(centre / static_cast<double>(mesh.elements[e].size()));
    c.alpha.push_back(rows[e][4]);
  }
  return c;
}

// The element whose centre is nearest to p.
inline size_t element_near(const PunchCurve& c, Vec2 p) {
  size_t best = 0;
  for (size_t e = 1; e < c.centre.size(); ++e)
    if ((c.centre[e] - p).norm() < (c.centre[best] - p).norm()) best = e;
  return best;
}

// Where the plastic strain is at the last step: the largest in an element at the punch's edge
// (centre within 2 h of x = b and of the surface), that element's alpha more than `centre_ratio`
// times the one under the punch's centre at the same depth, and the one 2 b further along the
// surface below `far_fraction` of it. A plastic strain spread evenly fails all three.
inline void check_edge_localisation(const PunchCurve& c, double centre_ratio, double far_fraction, const char* name) {
  const size_t peak = std::max_element(c.alpha.begin(), c.alpha.end()) - c.alpha.begin();
  const Vec2 at = c.centre[peak];
  const double a = c.alpha[peak];
  const size_t under = element_near(c, {0.0, at.y()}), far = element_near(c, {at.x() + 2.0, at.y()});
  std::printf(
      "%s: largest alpha %.4e at (%.3f, %.3f) (h = %.2f); under the centre (%.3f, %.3f) %.3e (1/%.0f); 2 b along "
      "(%.3f, %.3f) %.3e (1/%.0f)\n",
      name, a, at.x(), at.y(), c.h, c.centre[under].x(), c.centre[under].y(), c.alpha[under],
      a / std::max(c.alpha[under], 1e-300), c.centre[far].x(), c.centre[far].y(), c.alpha[far],
      a / std::max(c.alpha[far], 1e-300));
  EXPECT_LE(std::abs(at.x() - 1.0), 2 * c.h);
  EXPECT_GE(at.y(), -2 * c.h);
  EXPECT_LT(std::abs(c.centre[under].y() - at.y()), 1e-9);
  EXPECT_LT(std::abs(c.centre[far].y() - at.y()), 1e-9);
  EXPECT_GT(a, centre_ratio * c.alpha[under]);
  EXPECT_LT(c.alpha[far], far_fraction * a);
}

// The curve against the limit: the last load within `within` of it, the last three steps within
// 0.5 % of each other (flat), at most 20 Newton iterations in each of them.
inline void check_punch_curve(const PunchCurve& c, double within, const char* name) {
  const double limit = prandtl_limit_half();
  std::printf("%s (%d punch nodes): depth/b, load/limit, Newton:", name, c.punch_nodes);
  for (size_t k = 0; k < c.load.size(); ++k) std::printf(" (%.3f %.4f %d)", c.depth[k], c.load[k] / limit, c.newton[k]);
  std::printf("\n");
  const size_t n = c.load.size();
  EXPECT_NEAR(c.load.back() / limit, 1.0, within);
  for (size_t k = n - 3; k < n; ++k) EXPECT_NEAR(c.load[k] / c.load.back(), 1.0, 0.005) << "step " << k + 1;
  const int most = *std::max_element(c.newton.begin(), c.newton.end());
  for (size_t k = n - 3; k < n; ++k) EXPECT_LE(c.newton[k], 20) << "step " << k + 1 << " (most " << most << ")";
}

// Penetrations as fractions of 0.1 b: fine steps while the plastic zone spreads, then coarser.
inline std::vector<double> punch_path() {
  std::vector<double> t;
  for (int k = 1; k <= 10; ++k) t.push_back(0.02 * k);
  for (int k = 5; k <= 10; ++k) t.push_back(0.1 * k);
  return t;
}

// The same block as a scene (the mesh written out, so that it is press_punch's node for node),
// pressed by the punch as a contact obstacle: a frictionless `profile` with a square edge (the
// flat from x = -2 b to b, its side x = b up to 5 b) moved down `depth` in `steps` equal steps,
// the top's nodes with x <= 2.5 b its contact set. The elastic-perfectly plastic law, or
// (plastic false) the linear elastic one with the same E and nu. `contact`: solver.contact.
inline nlohmann::json punch_obstacle_scene(double h, int nx, int ny, double depth, int steps, bool plastic,
                                           const nlohmann::json& contact) {
  const PlaneMesh mesh = punch_block_mesh(h, nx, ny);
  nlohmann::json nodes = nlohmann::json::array(), sets = nlohmann::json::object();
  for (const Vec2& x : mesh.nodes) nodes.push_back({x.x(), x.y()});
  for (const auto& [name, ids] : mesh.sets) sets[name] = ids;
  std::vector<int> near;
  for (int n : mesh.sets.at("top"))
    if (mesh.nodes[n].x() <= 2.5 + 1e-9) near.push_back(n);
  sets["near"] = near;
  nlohmann::json material = {{"young", 1000}, {"poisson", 0.3}};
  if (plastic) material.update({{"law", "j2_plasticity"}, {"yield_stress", 1}});
  const nlohmann::json punch = {{"type", "profile"},
                                {"pieces",
                                 {{{"type", "segment"}, {"from", {-2, 0}}, {"to", {1, 0}}},
                                  {{"type", "segment"}, {"from", {1, 0}}, {"to", {1, 5}}}}}};
  return {{"body",
           {{"model", "continuum"},
            {"kinematics", "linear"},
            {"analysis", "plane_strain"},
            {"element", "q4_bbar"},
            {"material", material},
            {"mesh", {{"nodes", nodes}, {"elements", mesh.elements}, {"sets", sets}}},
            {"contact_set", "near"},
            {"supports",
             {{{"set", "left"}, {"fix", {"x"}}},
              {{"set", "right"}, {"fix", {"x"}}},
              {{"set", "bottom"}, {"fix", {"x", "y"}}}}}}},
          {"obstacles", {{{"name", "punch"}, {"shape", punch}, {"motion", {{"translation", {0, -depth}}}}}}},
          {"steps", steps},
          {"solver", {{"contact", contact}}}};
}

}  // namespace grip::testing
