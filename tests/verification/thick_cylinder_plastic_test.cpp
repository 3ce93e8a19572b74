// A thick-walled cylinder (a = 1, b = 2) of elastic-perfectly plastic von Mises material under
// internal pressure, plane strain, small strain (docs/verification.md): a quarter of the
// section on q4_bbar (60 radial x 8 hoop elements), the bore's radial displacement u_a
// prescribed and the pressure read from its reactions. nu = 0.499: the material is then
// incompressible to O(1 - 2 nu), and Hill's closed form (The Mathematical Theory of
// Plasticity, 1950, ch. V) is exact: with k = sigma_y / sqrt(3) and u = A / r everywhere,
//   the elastic-plastic boundary c = sqrt(2 G a u_a / k),
//   the pressure p = k [2 ln(c / a) + 1 - c^2 / b^2] (a <= c <= b),
//   the collapse pressure 2 k ln(b / a), reached at u_a = k b^2 / (2 G a) and kept beyond.
// Checked: the pressure within 1 % at every step; the boundary c inside the outermost ring that
// has flowed, whose middle is within 1 % of c; the plateau at the collapse pressure.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "solver/elements/continuum.hpp"
#include "solver/materials/j2_plasticity.hpp"
#include "tests/support/newton_driver.hpp"

namespace grip {
namespace {

constexpr double kA = 1.0, kB = 2.0, kE = 1000.0, kNu = 0.499, kYield = 1.0;

TEST(ThickCylinderPlastic, PressureAndPlasticBoundaryFollowHill) {
  const int nr = 60, nt = 8;
  PlaneMesh mesh;
  for (int j = 0; j <= nt; ++j)
    for (int i = 0; i <= nr; ++i) {
      const double r = kA + (kB - kA) * i / nr, t = 0.5 * std::numbers::pi * j / nt;
      mesh.nodes.emplace_back(r * std::cos(t), r * std::sin(t));
    }
  const auto id = [&](int i, int j) { return j * (nr + 1) + i; };
  for (int j = 0; j < nt; ++j)
    for (int i = 0; i < nr; ++i) mesh.elements.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  std::vector<int> bore;
  for (int j = 0; j <= nt; ++j) bore.push_back(id(0, j));
  mesh.sets["bore"] = bore;
  auto law = std::make_shared<J2Material>(kE, kNu, kYield, IsotropicHardening{}, 0.0, PlaneAnalysis::plane_strain);
  ContinuumBody body(mesh, bore, {law},
                     {ContinuumElement::q4_bbar, ContinuumKinematics::linear, PlaneAnalysis::plane_strain, 1.0});
  // Symmetry: y = 0 held in y, x = 0 in x; the bore's nodes held in both (radial u_a).
  std::vector<char> held(body.dof_count(), 0);
  for (int i = 0; i <= nr; ++i) held[2 * id(i, 0) + 1] = held[2 * id(i, nt)] = 1;
  for (int node : bore) held[2 * node] = held[2 * node + 1] = 1;
  testing::Driver d(body, held);

  const double G = kE / (2 * (1 + kNu)), k = kYield / std::sqrt(3.0);
  const double u_collapse = k * kB * kB / (2 * G * kA), p_collapse = 2 * k * std::log(kB / kA);
  double worst_p = 0.0, worst_c = 0.0;
  const int steps = 24;
  for (int s = 1; s <= steps; ++s) {
    const double ua = 1.2 * u_collapse * s / steps;
    d.solve(
        [&](Vector& q) {
          for (int node : bore) q.segment<2>(2 * node) = ua * mesh.nodes[node].normalized();
        },
        1e-10);
    const Vector f = d.force(nullptr);
    double radial = 0.0;
    for (int node : bore) radial += f.segment<2>(2 * node).dot(mesh.nodes[node].normalized());
    const double p = radial / (kA * std::numbers::pi / 2);
    const double c = std::min(std::sqrt(2 * G * kA * ua / k), kB);
    const double p_hill =
        c <= kA ? 2 * G * ua / kA * (1 - kA * kA / (kB * kB)) : k * (2 * std::log(c / kA) + 1 - c * c / (kB * kB));
    worst_p = std::max(worst_p, std::abs(p / p_hill - 1));
    // The boundary lies in the outermost ring that has flowed (rings along the x axis: element
    // i of row 0; loading is monotone, so the plastic zone is where alpha > 0).
    int last_plastic = -1;
    for (int i = 0; i < nr; ++i)
      if (d.element_row(i)[4] > 0) last_plastic = i;
    const double h = (kB - kA) / nr, inner = kA + last_plastic * h, outer = inner + h;
    std::printf("u_a / u_collapse %.3f: p / p_hill %.5f (p_hill %.5f), c %.4f, plastic ring [%.4f, %.4f]\n",
                ua / u_collapse, p / p_hill, p_hill, c, inner, outer);
    if (c > kA && c < kB) {
      EXPECT_GE(c, inner - 1e-9) << "step " << s;
      EXPECT_LE(c, outer + 1e-9) << "step " << s;
      worst_c = std::max(worst_c, std::abs(0.5 * (inner + outer) - c) / c);
    }
    if (ua > u_collapse) EXPECT_NEAR(p / p_collapse, 1.0, 0.01) << "collapse plateau, step " << s;
  }
  std::printf("worst |p / p_hill - 1| %.2e, worst |ring middle - c| / c %.2e; collapse pressure 2 k ln(b/a) = %.5f\n",
              worst_p, worst_c, p_collapse);
  EXPECT_LT(worst_p, 0.01);
  EXPECT_LT(worst_c, 0.01);
}

}  // namespace
}  // namespace grip
