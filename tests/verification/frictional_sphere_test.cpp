// The frictional sphere (docs/verification.md#frictional-sphere): an elastic half-space
// pressed by a rigid sphere with friction, axisymmetric, against the ring boundary-element
// model of the same loading (tests/support/sphere_halfspace.hpp): nu 0.3, mu 0.3, 10 steps.
// - the model and the scene without friction give Hertz;
// - the scene (a cylinder of radius and depth 300 mm, elements of 0.025 mm near the contact,
//   under a rigid sphere R = 100 mm to a = 1 mm): the stick radius c/a from the solver's stick
//   states against the model's at every step of the second half of the loading; the peak
//   pressure's rise over frictionless Hertz against the model's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "tests/support/contact_profile.hpp"
#include "tests/support/scenes.hpp"
#include "tests/support/sphere_halfspace.hpp"

namespace grip {
namespace {

using namespace grip::testing;
using nlohmann::json;

constexpr double kNu = 0.3, kMu = 0.3, kSize = 0.025, kYoung = 200000, kRadius = 100;
constexpr int kPerA = 40;

// A cylinder of radius and depth `depth` (its bottom held) pressed by a rigid sphere moved down
// 0.0105 mm in `steps` equal steps: a = sqrt(R delta) = 1.02 mm at the end. Elements of `size`
// within 1.5 mm of the first touch, growing 1.3-fold beyond.
json sphere_on_block(double size, int steps, double mu, double depth = 300) {
  const double extent = 1.5;
  int n = static_cast<int>(std::lround(extent / size));
  for (double h = size, covered = extent; covered < depth; covered += h *= 1.3) ++n;
  json j = json::parse(R"({
    "name": "sphere-on-half-space", "units": {"force": "N", "length": "mm"},
    "body": {"model": "continuum", "kinematics": "linear", "analysis": "axisymmetric", "element": "q4",
             "material": {"young": 200000, "poisson": 0.3}, "contact_set": "top",
             "supports": [{"set": "bottom", "fix": ["x", "y"]}]},
    "obstacles": [{"name": "sphere", "shape": {"type": "circle"}, "motion": {"translation": [0, -0.0105]}}],
    "solver": {"contact": {"method": "cev", "tolerance": 1e-8}}})");
  j["body"]["material"]["poisson"] = kNu;
  j["body"]["mesh"]["rectangle"] = {{"origin", {0, -depth}},
                                    {"size", {depth, depth}},
                                    {"divisions", {n, n}},
                                    {"refine", {{"towards", {0, 0}}, {"size", size}, {"extent", extent}}}};
  j["obstacles"][0]["shape"]["centre"] = {0, kRadius};
  j["obstacles"][0]["shape"]["radius"] = kRadius;
  j["obstacles"][0]["friction"] = mu;
  j["steps"] = steps;
  return j;
}

struct SphereReading {
  double P = 0;     // the load, total over the circle
  double a = 0;     // midway between the last pressing node and the next
  double c = 0;     // midway between the last node of the stick run from the axis and the next
  double peak = 0;  // the largest nodal pressure over Hertz's p0 at P
  double a_hertz = 0;
};

SphereReading read_sphere(const Solved& s, const StepRecord& rec) {
  SphereReading r;
  r.P = std::abs(reaction_resultant(s.scene.problem, rec).y());
  const double Estar = kYoung / (1 - kNu * kNu);
  r.a_hertz = std::cbrt(3 * r.P * kRadius / (4 * Estar));
  const double p0 = 3 * r.P / (2 * std::numbers::pi * r.a_hertz * r.a_hertz);
  auto nodes = contact_profile(s.scene.problem, rec);
  std::sort(nodes.begin(), nodes.end(), [](const ContactNode& x, const ContactNode& y) { return x.x < y.x; });
  size_t k = 0;  // the axis node (u_r held) starts the run whatever its state
  while (k + 1 < nodes.size() && nodes[k + 1].state == ContactState::stick) ++k;
  if (k + 1 < nodes.size()) r.c = 0.5 * (nodes[k].x + nodes[k + 1].x);
  size_t last = 0;
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].sigma_n < 0) last = i;
    r.peak = std::max(r.peak, -nodes[i].sigma_n / p0);
  }
  if (last + 1 < nodes.size()) r.a = 0.5 * (nodes[last].x + nodes[last + 1].x);
  return r;
}

TEST(FrictionalSphere, RingModelWithoutFrictionGivesHertz) {
  const HalfSpaceSphere m = sphere_half_space(0.0, kNu, kPerA, 2);
  std::printf("ring model, mu 0: a %.4f (Hertz 1), peak %.4f of p0\n", m.a, m.peak);
  EXPECT_NEAR(m.a, 1.0, 1.0 / kPerA);
  EXPECT_NEAR(m.peak, 1.0, 0.005);
}

// The block's far field is a half-space's: without friction, Hertz's a (bracketed by the nodes
// where contact ends, to half an element) and p0 (the peak nodal pressure, within 0.5 %).
TEST(FrictionalSphere, FrictionlessBlockGivesHertz) {
  const Solved n = solve_scene(sphere_on_block(kSize, 2, 0.0));
  expect_every_step_sound(n);
  ASSERT_TRUE(n.run.completed) << n.run.reason;
  const SphereReading r = read_sphere(n, n.run.steps.back());
  std::printf("frictionless: P %.2f N, a %.4f mm (Hertz %.4f), peak %.4f of p0\n", r.P, r.a, r.a_hertz, r.peak);
  EXPECT_NEAR(r.a, r.a_hertz, 0.5 * kSize);
  EXPECT_NEAR(r.peak, 1.0, 0.005);
}

TEST(FrictionalSphere, StickRadiusMatchesTheRingModel) {
  const HalfSpaceSphere model = sphere_half_space(kMu, kNu, kPerA, 10);
  const double reference = model.c_stick / model.a;
  const Solved f = solve_scene(sphere_on_block(kSize, 10, kMu));
  expect_every_step_sound(f);
  ASSERT_TRUE(f.run.completed) << f.run.reason;
  std::printf("ring model (a/h %d, 10 increments): c/a %.4f, a %.4f, peak %.4f of Hertz's p0\n", kPerA, reference,
              model.a, model.peak);
  for (size_t k = f.run.steps.size() / 2; k < f.run.steps.size(); ++k) {
    const SphereReading r = read_sphere(f, f.run.steps[k]);
    std::printf("step %zu: P %.2f N, a %.4f mm (a/h %.1f, %+.2f %% of Hertz's), c/a %.4f, peak %+.2f %% over p0\n",
                k + 1, r.P, r.a, r.a / kSize, 100 * (r.a / r.a_hertz - 1), r.c / r.a, 100 * (r.peak - 1));
    EXPECT_NEAR(r.c / r.a, reference, 0.03) << "step " << k + 1;
  }
  const SphereReading last = read_sphere(f, f.run.steps.back());
  std::printf("%ld real solves, %.2f s\n", f.run.counters.solves, f.run.seconds);
  EXPECT_NEAR(last.peak, model.peak, 0.01);
}

}  // namespace
}  // namespace grip
