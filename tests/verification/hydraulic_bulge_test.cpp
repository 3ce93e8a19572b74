// The rigid-plastic membrane under a pressure that follows it (docs/algorithm.md#membrane-pressure)
// and the hydraulic bulge (docs/verification.md#hydraulic-bulge):
// - the pressure's nodal forces and their derivative against central differences, in the
//   plane and about the axis;
// - a plane-strain sheet bulged between two clamps is a circular arc of uniform strain: its
//   pressure and strain against its height are closed form;
// - the circular diaphragm of schemas/examples/hydraulic-bulge-axisymmetric.json against an
//   independent integration of the axisymmetric membrane equations
//   (tests/support/hydraulic_bulge.hpp): the pole strain and the pressure against the pole
//   height within 2 %;
// - bad input, each named by its pointer.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <cmath>
#include <cstdio>
#include <random>

#include "solver/elements/rigid_plastic_membrane.hpp"
#include "tests/support/hydraulic_bulge.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using nlohmann::json;
using testing::Solved;

HillMaterial bulge_material() {
  HillMaterial m;
  m.r = 1.5;
  m.H = 589;
  m.n = 0.216;
  return m;
}

// The follower load's generalized force at q and its derivative, against central differences.
void expect_pressure_tangent(bool axisymmetric) {
  std::vector<Vec2> nodes;
  for (int k = 0; k <= 6; ++k) nodes.push_back({2.0 + 5.0 * k, 0.5 * k});
  RigidPlasticMembrane body(nodes, 1.0, bulge_material(), 2.0, axisymmetric);
  body.add_pressure(3.0, 0);
  body.add_pressure(-1.0, 1);
  const std::vector<double> factors{0.8, 0.5};
  const int n = body.dof_count();
  Vector q(n);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> shift(-1.0, 1.0);
  for (int i = 0; i < n; ++i) q[i] = shift(rng);
  Vector f = Vector::Zero(n);
  Triplets t;
  body.follower_load(q, factors, f, &t);
  Eigen::SparseMatrix<double> K(n, n);
  K.setFromTriplets(t.begin(), t.end());
  Matrix K_fd(n, n);
  for (int j = 0; j < n; ++j) {
    Vector qp = q, qm = q, fp = Vector::Zero(n), fm = Vector::Zero(n);
    const double h = 1e-6;
    qp[j] += h;
    qm[j] -= h;
    body.follower_load(qp, factors, fp, nullptr);
    body.follower_load(qm, factors, fm, nullptr);
    K_fd.col(j) = (fp - fm) / (2 * h);
  }
  const double error = (Matrix(K) - K_fd).lpNorm<Eigen::Infinity>() / K_fd.lpNorm<Eigen::Infinity>();
  std::printf("pressure tangent (%s): |K - K_fd| / |K| = %.1e\n", axisymmetric ? "axisymmetric" : "plane", error);
  EXPECT_LT(error, 1e-8);
  // The resultant is the pressure on the projected area: p times the chord's normal, per width
  // in the plane; about the axis, along y, p pi (r_last^2 - r_first^2).
  Vec2 total = Vec2::Zero();
  for (int k = 0; k < body.node_count(); ++k) total += f.segment<2>(2 * k);
  const double p = 0.8 * 3.0 - 0.5 * 1.0;
  const Vec2 first = nodes.front() + q.head<2>(), last = nodes.back() + q.tail<2>();
  const Vec2 expected = axisymmetric ? Vec2(0.0, p * std::numbers::pi * (last.x() * last.x() - first.x() * first.x()))
                                     : Vec2(p * 2.0 * -(last - first).y(), p * 2.0 * (last - first).x());
  // (About the axis the radial forces are no resultant: the hoops carry them.)
  if (axisymmetric) EXPECT_NEAR(total.y(), expected.y(), 1e-12 * expected.norm());
  else EXPECT_NEAR((total - expected).norm(), 0.0, 1e-12 * expected.norm());
}

TEST(MembranePressure, ForcesAndTangentAgainstCentralDifferences) {
  expect_pressure_tangent(false);
  expect_pressure_tangent(true);
}

// A plane-strain sheet of span 2a clamped at both ends (half of it: the pole x = 0 held in x)
// under a pressure p: the tension T is the same in every element, so every element strains
// alike and the sheet is a circular arc of radius rho = T / p through the clamps. At height h,
// rho = (a^2 + h^2) / (2 h), the strain eps = ln(rho theta / a) with sin theta = a / rho, and
// T = t0 exp(-eps) c sigma_bar(c eps), c the plane-strain factor (sigma1 = c sigma_bar).
TEST(MembranePressure, PlaneStrainBulgeIsAUniformArc) {
  constexpr double a = 50.0;
  json j = testing::example_scene("hydraulic-bulge-axisymmetric");
  j["body"].erase("analysis");
  j["body"]["width"] = 1.0;
  j["body"]["supports"] = {{{"node", 0}, {"fix", {"x"}}}, {{"node", 50}, {"fix", {"x", "y"}}}};
  // 7 MPa: a strain of 0.15, below the top of the tension t sigma1 at eps_bar = n (eps 0.173),
  // past which the uniform state is unstable and the strain localizes.
  j["body"]["loads"][0]["pressure"] = 7.0;
  j["steps"] = json::array({0.2, 0.4, 0.6, 0.8, 1.0});
  const Solved s = testing::solve_scene(j);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const HillMaterial m = bulge_material();
  const double c = m.plane_strain_factor();
  for (const StepRecord& rec : s.run.steps) {
    const double h = rec.state.q[RigidPlasticMembrane::node_dof(0, 1)];
    const double rho = (a * a + h * h) / (2 * h), theta = std::asin(a / rho);
    const double eps = std::log(rho * theta / a);
    const double p = std::exp(-eps) * c * m.flow_stress(c * eps) / rho;
    const FieldTable& el = rec.element_fields;
    const int col = static_cast<int>(std::find(el.names.begin(), el.names.end(), "major_strain") - el.names.begin());
    double lo = 1e9, hi = -1e9;
    for (const auto& row : el.rows) {
      lo = std::min(lo, row[col]);
      hi = std::max(hi, row[col]);
    }
    std::printf("plane bulge: h %6.3f mm, p %.4f MPa (closed form %.4f), strain %.5f to %.5f (closed form %.5f)\n", h,
                7.0 * rec.load_factor, p, lo, hi, eps);
    EXPECT_NEAR(7.0 * rec.load_factor, p, 5e-4 * p) << "step " << rec.index;
    EXPECT_NEAR(lo, eps, 5e-4 * eps) << "step " << rec.index;
    EXPECT_NEAR(hi, eps, 5e-4 * eps) << "step " << rec.index;
  }
}

// The reference at height h, linear in h between its points (which lie about evenly in h).
testing::BulgeState reference_at(const std::vector<testing::BulgeState>& ref, double h) {
  for (size_t k = 1; k < ref.size(); ++k)
    if (ref[k].height >= h) {
      const double w = (h - ref[k - 1].height) / (ref[k].height - ref[k - 1].height);
      return {h, (1 - w) * ref[k - 1].pole_strain + w * ref[k].pole_strain,
              (1 - w) * ref[k - 1].pressure + w * ref[k].pressure};
    }
  return {h, NAN, NAN};
}

// The shipped scene (50 elements, 16 pressure steps to 12.5 MPa, 98 % of the largest pressure)
// at each step's pole height: the pole strain (the pole element's, equal-biaxial, h / 2 from
// the axis) and the pressure within 2 % of the reference's. The reference marches 50 pole
// strains, evenly in their square root (so evenly in the height: the strain grows as h^2),
// on 200 radii.
TEST(HydraulicBulge, PoleStrainAgainstHeightMatchesTheMembraneEquations) {
  const json j = testing::example_scene("hydraulic-bulge-axisymmetric");
  const Solved s = testing::solve_scene(j);
  testing::expect_every_step_sound(s);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  const HillMaterial m = bulge_material();
  std::vector<double> strains;
  for (int k = 1; k <= 50; ++k) strains.push_back(0.27 * (k / 50.0) * (k / 50.0));
  const auto ref = testing::hydraulic_bulge({m.r, m.M, m.H, m.a0, m.n}, 50.0, 1.0, strains, 200);
  const double p_end = j["body"]["loads"][0]["pressure"];
  double worst = 0.0, worst_p = 0.0;
  for (const StepRecord& rec : s.run.steps) {
    const double h = rec.state.q[RigidPlasticMembrane::node_dof(0, 1)], p = p_end * rec.load_factor;
    const FieldTable& el = rec.element_fields;
    const int t = static_cast<int>(std::find(el.names.begin(), el.names.end(), "thickness_strain") - el.names.begin());
    const double pole = -0.5 * el.rows[0][t];
    const testing::BulgeState expected = reference_at(ref, h);
    std::printf(
        "bulge: pole height %6.3f mm: pole strain %.5f, reference %.5f (%+.2f %%); p %6.3f MPa, reference %.3f (%+.2f "
        "%%)\n",
        h, pole, expected.pole_strain, 100 * (pole / expected.pole_strain - 1), p, expected.pressure,
        100 * (p / expected.pressure - 1));
    EXPECT_NEAR(pole, expected.pole_strain, 0.02 * expected.pole_strain) << "step " << rec.index;
    EXPECT_NEAR(p, expected.pressure, 0.02 * expected.pressure) << "step " << rec.index;
    worst = std::max(worst, std::abs(pole / expected.pole_strain - 1));
    worst_p = std::max(worst_p, std::abs(p / expected.pressure - 1));
  }
  std::printf("largest differences: pole strain %.2f %%, pressure %.2f %%\n", 100 * worst, 100 * worst_p);
}

TEST(HydraulicBulge, RefusesWhatIsNotAPressure) {
  const auto pointer_of = [](const json& j) { return testing::first_refusal(j); };
  json j = testing::example_scene("hydraulic-bulge-axisymmetric");
  j["body"]["loads"][0]["node"] = 3;
  EXPECT_EQ(pointer_of(j).rfind("/body/loads/0/node: goes with a force: a pressure acts on every element", 0), 0u)
      << pointer_of(j);
  j = testing::example_scene("hydraulic-bulge-axisymmetric");
  j["body"]["loads"][0]["pressure"] = "high";
  EXPECT_EQ(pointer_of(j).rfind("/body/loads/0/pressure: \"high\" is not a number", 0), 0u) << pointer_of(j);
  j = testing::example_scene("hydraulic-bulge-axisymmetric");
  j["solver"]["start"]["obstacle"] = 1;
  EXPECT_EQ(pointer_of(j).rfind("/solver/start/obstacle: 1 is not a string", 0), 0u) << pointer_of(j);
}

}  // namespace
}  // namespace grip
