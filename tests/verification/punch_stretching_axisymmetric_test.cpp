// The rigid-plastic membrane in axisymmetry (docs/algorithm.md#axisymmetric-membrane) and the
// hemispherical punch stretching of a circular blank
// (schemas/examples/punch-stretching-axisymmetric.json):
// - the tangent against central differences of the internal force, from a committed state;
// - the pole is stretched equal-biaxially: the pole element's meridional and hoop strains agree;
// - volume constancy: t = t0 exp(-(e1 + e2)) in every element at every step;
// - the punch force rises with the depth, at every step;
// - the punch force, the pole strain and the peak strain at 20 mm converge with the number of
//   elements (30, 60, 120);
// - bad input: a node at x < 0, an element on the axis, a width, each named by its pointer.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "solver/elements/rigid_plastic_membrane.hpp"
#include "tests/support/scenes.hpp"
#include "tests/support/tangent_check.hpp"

namespace grip {
namespace {

using nlohmann::json;
using testing::Solved;

HillMaterial sheet_material(double r = 1.0, double M = 2.0) {
  HillMaterial m;
  m.r = r;
  m.M = M;
  m.H = 589;
  m.n = 0.216;
  return m;
}

TEST(AxisymmetricMembrane, EffectiveIncrementIsHillsConjugate) {
  // M = 2, r = 1 is von Mises: phi^2 = 4/3 (d1^2 + d1 d2 + d2^2); plane strain: phi = c |d1|.
  const HillMaterial m = sheet_material();
  const Vec2 d(0.03, -0.01);
  EXPECT_NEAR(2 * m.half_square_increment(d, nullptr, nullptr), 4.0 / 3 * (9e-4 - 3e-4 + 1e-4), 1e-15);
  for (const double r : {0.5, 1.0, 2.0})
    for (const double M : {1.5, 2.0, 3.0}) {
      const HillMaterial h = sheet_material(r, M);
      const double phi = std::sqrt(2 * h.half_square_increment({0.02, 0.0}, nullptr, nullptr));
      EXPECT_NEAR(phi, h.plane_strain_factor() * 0.02, 1e-14) << r << " " << M;
      // The gradient and Hessian against central differences.
      Vec2 g;
      Mat2 H;
      const Vec2 x(0.02, 0.013);
      h.half_square_increment(x, &g, &H);
      for (int k = 0; k < 2; ++k) {
        const double e = 1e-7;
        Vec2 gp, gm;
        const double fp = h.half_square_increment(x + e * Vec2::Unit(k), &gp, nullptr);
        const double fm = h.half_square_increment(x - e * Vec2::Unit(k), &gm, nullptr);
        EXPECT_NEAR((fp - fm) / (2 * e), g[k], 1e-7 * g.norm());
        EXPECT_NEAR(((gp - gm) / (2 * e) - H.col(k)).norm(), 0.0, 1e-6 * H.norm());
      }
    }
}

TEST(AxisymmetricMembrane, TangentMatchesCentralDifferences) {
  std::vector<Vec2> nodes;
  for (int k = 0; k <= 8; ++k) nodes.push_back({5.0 * k, 0.0});
  RigidPlasticMembrane body(nodes, 1.0, sheet_material(1.5, 2.0), 1.0, true);
  const int n = body.dof_count();
  // A dome, committed; then a further, non-uniform stretch.
  Vector q0(n), q(n);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> noise(-0.05, 0.05);
  for (int k = 0; k <= 8; ++k) {
    const double r = nodes[k].x();
    q0.segment<2>(2 * k) = Vec2(0.01 * r, -0.002 * (1600 - r * r) / 40);
    q.segment<2>(2 * k) = q0.segment<2>(2 * k) + Vec2(0.02 * r + (k ? noise(rng) : 0.0), -0.5 + 0.01 * r + noise(rng));
  }
  body.commit(q0);
  const auto c = testing::check_tangent(body, q, 1e-7);
  std::printf("axisymmetric membrane: |K - K_fd| / |K| = %.1e\n", c.worst());
  EXPECT_LT(c.worst(), 1e-6);
  EXPECT_LT((c.K - c.K.transpose()).lpNorm<Eigen::Infinity>(), 1e-9 * c.K.lpNorm<Eigen::Infinity>());  // a potential
}

Vec2 obstacle_force(const Problem& problem, const StepRecord& rec, const std::string& name) {
  Vec2 f = Vec2::Zero();  // on the body
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    if (problem.obstacles[c.obstacle].name != name) continue;
    f += rec.p[c.eta] * rec.state.points[i].eta + (c.xi >= 0 ? rec.p[c.xi] : 0.0) * rec.state.points[i].xi;
  }
  return f;
}

// The shipped scene with `elements` elements and the punch driven to `depth` in 1 mm steps.
const Solved& punch(int elements, int depth = 30) {
  static std::map<std::pair<int, int>, Solved> cache;
  auto it = cache.find({elements, depth});
  if (it != cache.end()) return it->second;
  json j = testing::example_scene("punch-stretching-axisymmetric");
  j["body"]["mesh"]["elements"] = elements;
  j["body"]["supports"][0]["node"] = elements;
  j["obstacles"][0]["motion"]["translation"] = {0, -depth};
  j["steps"] = depth;
  return cache.emplace(std::make_pair(elements, depth), testing::solve_scene(j)).first->second;
}

TEST(PunchStretchingAxisymmetric, ShippedSceneIsSoundAndConsistent) {
  const Solved& s = punch(60);
  testing::expect_every_step_sound(s);
  ASSERT_TRUE(s.run.completed) << s.run.reason;
  ASSERT_EQ(s.run.steps.size(), 30u);
  std::printf("punch stretching, 60 elements: %ld real solves\n", s.run.counters.solves);
  double previous = 0.0;
  for (const StepRecord& rec : s.run.steps) {
    const double P = -obstacle_force(s.scene.problem, rec, "punch").y();
    const FieldTable& el = rec.element_fields;
    const auto col = [&](const char* name) {
      return static_cast<int>(std::find(el.names.begin(), el.names.end(), name) - el.names.begin());
    };
    const int e1 = col("meridional_strain"), e2 = col("hoop_strain"), e3 = col("thickness_strain"),
              t = col("thickness");
    ASSERT_LT(t, static_cast<int>(el.names.size()));
    for (const auto& row : el.rows) {
      EXPECT_NEAR(row[t], std::exp(-(row[e1] + row[e2])), 1e-12);  // t0 = 1 mm
      EXPECT_NEAR(row[e3], -(row[e1] + row[e2]), 1e-12);
    }
    const double pole_1 = el.rows[0][e1], pole_2 = el.rows[0][e2];
    if (rec.index % 10 == 0)
      std::printf("depth %2d mm: P = %.0f N; pole strains %.4f (meridional), %.4f (hoop); peak meridional %.4f\n",
                  rec.index, P, pole_1, pole_2,
                  std::max_element(el.rows.begin(), el.rows.end(), [&](const auto& a, const auto& b) {
                    return a[e1] < b[e1];
                  })->at(e1));
    EXPECT_GT(P, previous) << "step " << rec.index;  // the force rises with the depth
    previous = P;
    // Equal-biaxial at the pole (the pole element's two strains, h / 2 from the axis).
    EXPECT_NEAR(pole_1, pole_2, 0.01 * pole_2 + 1e-4) << "step " << rec.index;
    // The punch force is carried by the clamp and the die.
    const double die = obstacle_force(s.scene.problem, rec, "die").y();
    const double clamp = rec.reactions[RigidPlasticMembrane::node_dof(60, 1)];
    EXPECT_NEAR(P, clamp + die, 1e-7 * P) << "step " << rec.index;
  }
}

// The punch force, the pole strain and the peak meridional strain at 20 mm for 30, 60 and 120
// elements: each difference between successive meshes is smaller than the one before, and the
// last within 1 % (force), 2 % (strains).
TEST(PunchStretchingAxisymmetric, ForceAndStrainsConvergeWithTheMesh) {
  std::vector<double> force, pole, peak;
  for (const int elements : {30, 60, 120}) {
    const Solved& s = punch(elements, 20);
    ASSERT_TRUE(s.run.completed) << elements << ": " << s.run.reason;
    const StepRecord& rec = s.run.steps.back();
    force.push_back(-obstacle_force(s.scene.problem, rec, "punch").y());
    const FieldTable& el = rec.element_fields;
    const int e1 =
        static_cast<int>(std::find(el.names.begin(), el.names.end(), "meridional_strain") - el.names.begin());
    pole.push_back(el.rows[0][e1]);  // the pole element's, h / 2 from the axis
    double top = 0.0;
    for (const auto& row : el.rows) top = std::max(top, row[e1]);
    peak.push_back(top);
    std::printf("%3d elements at 20 mm: punch force %.1f N, pole strain %.5f, peak meridional strain %.5f\n", elements,
                force.back(), pole.back(), peak.back());
  }
  const auto expect_converging = [](const std::vector<double>& v, double bound, const char* what) {
    const double d1 = std::abs(v[1] - v[0]), d2 = std::abs(v[2] - v[1]);
    std::printf("%s: differences %.3f %%, %.3f %% (observed order %.2f)\n", what, 100 * d1 / v[2], 100 * d2 / v[2],
                std::log2(d1 / d2));
    EXPECT_LT(d2, d1) << what;
    EXPECT_LT(d2, bound * std::abs(v[2])) << what;
  };
  expect_converging(force, 0.01, "punch force");
  expect_converging(pole, 0.02, "pole strain");
  expect_converging(peak, 0.02, "peak meridional strain");
}

TEST(PunchStretchingAxisymmetric, RefusesWhatIsNotAMeridian) {
  const auto pointer_of = [](const json& j) { return testing::first_refusal(j); };
  json j = testing::example_scene("punch-stretching-axisymmetric");
  j["body"]["mesh"]["origin"] = {-1, 0};
  EXPECT_EQ(pointer_of(j).rfind("/body/mesh: axisymmetric: the meridian lies in the half-plane", 0), 0u)
      << pointer_of(j);
  j = testing::example_scene("punch-stretching-axisymmetric");
  j["body"]["mesh"] = {{"nodes", {{0, 0}, {0, 1}, {5, 1}}}};
  j["body"]["supports"][0]["node"] = 2;
  EXPECT_EQ(pointer_of(j), "/body/mesh: axisymmetric: element 0 lies on the axis");
  j = testing::example_scene("punch-stretching-axisymmetric");
  j["body"]["width"] = 2.0;
  EXPECT_EQ(pointer_of(j).rfind("/body/width: is not used in axisymmetry", 0), 0u) << pointer_of(j);
}

}  // namespace
}  // namespace grip
