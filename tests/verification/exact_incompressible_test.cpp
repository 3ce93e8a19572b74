// The exactly incompressible form (docs/algorithm.md#exact-incompressibility): the mixed
// elements (q9 Q2/P1, t6 P2/P0) with theta = 1 held at every point by the element pressure, an
// augmented Lagrangian whose penalty is the law's bulk modulus:
// - a Mooney-Rivlin cylinder (axisymmetric) stretched uniaxially along its axis and
//   equibiaxially (radius and hoop) to 3: the Cauchy stresses against the closed form of the
//   incompressible law, sigma = 2 (l^2 - 1/l) (c10 + c01 / l) and 2 (l^2 - l^-4) (c10 + c01 l^2),
//   the free stretch l^(-1/2) (l^-2), and the volume kept; the tangent with the pressures'
//   term p (theta - 1) against differences at stretch 3;
//   the same for the neo-Hookean law (young and poisson), its closed form mu (l^2 - 1/l) and
//   mu (l^2 - l^-4);
// - a block compressed 10 % between rough rigid plates through contact (plane strain, a quarter
//   by symmetry), meshes 4, 8, 16: the plate's force and the bulge converging with the mesh,
//   the volume of every element kept to 1e-6, where the mixed form at bulk 1e4 x shear changes
//   it by about 1e-4 (why 10 %: docs/verification.md#bulging-block);
// - contact's cost: the block (4, 8) and the shipped O-ring take at most 1.5 x the real solves of
//   the same scene with a compressible body (the pressures move inside each real solve);
// - the scene refuses the settings and the laws it cannot hold, with their pointer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>

#include "solver/elements/continuum.hpp"
#include "solver/materials/mooney_rivlin.hpp"
#include "solver/materials/plane_material.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/newton_driver.hpp"
#include "tests/support/scenes.hpp"
#include "tests/support/tangent_check.hpp"

namespace grip {
namespace {

using nlohmann::json;
using testing::Driver;

constexpr double kC10 = 0.4, kC01 = 0.1, kShear = 2 * (kC10 + kC01);

// Newton's method, then the multipliers' updates each followed by Newton again until the volume
// holds; returns the updates taken.
int solve_exactly(Driver& d, const std::function<void(Vector&)>& prescribe) {
  d.solve(prescribe, 1e-10 * kShear);
  int updates = 0;
  while (!d.body.update_multipliers(d.q).empty() && updates < 20) {
    ++updates;
    d.solve(prescribe, 1e-10 * kShear);
  }
  return updates;
}

// A cylinder of the law stretched uniaxially along its axis and equibiaxially to 3 in the exact
// form, against the incompressible law's closed form sigma(l, equibiaxial).
void stretch_to_three(const std::string& law_name, const std::shared_ptr<const PlaneMaterial>& law,
                      const std::function<double(double, bool)>& closed_form) {
  for (ContinuumElement element : {ContinuumElement::q9, ContinuumElement::t6})
    for (bool equibiaxial : {false, true}) {
      const std::string name =
          law_name + " " + std::string(element_name(element)) + (equibiaxial ? " equibiaxial" : " uniaxial");
      SCOPED_TRACE(name);
      // A cylinder of radius 1 and height 1 (2 x 2 elements), axis at x = 0.
      RectangleSpec spec;
      spec.nx = spec.ny = 2;
      const PlaneMesh mesh = rectangle_mesh(spec, element_shape(element));
      ContinuumBody body(
          mesh, mesh.sets.at("top"), {law},
          {element, ContinuumKinematics::finite, PlaneAnalysis::axisymmetric, 1.0, Incompressibility::exact});
      // u_r held on the axis (equibiaxial: everywhere, u_r = (l - 1) r), u_z at the bottom
      // (uniaxial: at the top too, u_z = (l - 1) z).
      std::vector<char> held(body.dof_count(), 0);
      for (int k = 0; k < body.node_count(); ++k) {
        const Vec2 X = mesh.nodes[k];
        held[2 * k] = equibiaxial || X.x() < 1e-12;
        held[2 * k + 1] = X.y() < 1e-12 || (!equibiaxial && X.y() > 1 - 1e-12);
      }
      Driver d(body, held);
      d.line_search = true;
      double worst = 0.0, worst_free = 0.0, worst_volume = 0.0;
      int most_updates = 0;
      for (int k = 1; k <= 20; ++k) {
        const double l = 1 + 0.1 * k;  // to 3
        most_updates = std::max(most_updates, solve_exactly(d, [&](Vector& q) {
                                  for (int n = 0; n < body.node_count(); ++n) {
                                    const Vec2 X = mesh.nodes[n];
                                    if (equibiaxial) q[2 * n] = (l - 1) * X.x();
                                    else if (X.y() > 1 - 1e-12) q[2 * n + 1] = l - 1;
                                  }
                                }));
        // The closed form of the incompressible law; the free stretch (the top's or the rim's).
        const double sigma = closed_form(l, equibiaxial);
        const double free = equibiaxial ? 1 / (l * l) : 1 / std::sqrt(l);
        for (int n = 0; n < body.node_count(); ++n) {
          const Vec2 X = mesh.nodes[n];
          if (equibiaxial && X.y() > 1 - 1e-12) worst_free = std::max(worst_free, std::abs(1 + d.q[2 * n + 1] - free));
          if (!equibiaxial && X.x() > 1 - 1e-12) worst_free = std::max(worst_free, std::abs(1 + d.q[2 * n] - free));
        }
        for (int e = 0; e < body.element_count(); ++e) {
          const std::vector<double> row = d.element_row(e);  // srr, szz, srz, hoop
          const double along = equibiaxial ? row[0] : row[1], across = equibiaxial ? row[1] : row[0];
          worst = std::max({worst, std::abs(along - sigma) / sigma, std::abs(across) / sigma,
                            std::abs(row[3] - (equibiaxial ? sigma : 0.0)) / sigma});
          worst_volume = std::max(worst_volume, std::abs(body.element_volume_change(d.q, e)));
        }
      }
      std::printf(
          "exact %s to stretch 3: worst |sigma - closed form| / sigma %.1e, free stretch %.1e, volume change %.1e, "
          "at most %d updates of the pressures a step\n",
          name.c_str(), worst, worst_free, worst_volume, most_updates);
      EXPECT_LT(worst, 1e-7);
      EXPECT_LT(worst_free, 1e-9);
      EXPECT_LT(worst_volume, 1e-9);
      // Each update shrinks the volume error by about the tangent stiffness over the bulk modulus
      // (shear / bulk = 1e-3 at small strain; equibiaxial at 3 the law stiffens some 20 times).
      EXPECT_LE(most_updates, 6);
      // The tangent at stretch 3, where the pressures are large (about the stress), on a wobble.
      Vector q = d.q;
      for (int i = 0; i < q.size(); ++i) q[i] += 0.005 * std::sin(0.7 + 2.3 * i);
      const auto check = testing::check_tangent(body, q, 1e-6);
      EXPECT_LT(check.error(), 1e-7);
      EXPECT_LT(check.asymmetry(), 1e-12);
    }
}

TEST(ExactIncompressibility, UniaxialAndEquibiaxialStretchFollowTheClosedForm) {
  stretch_to_three("mooney-rivlin",
                   std::make_shared<MooneyRivlinMaterial>(kC10, kC01, 1e3 * kShear, PlaneAnalysis::axisymmetric),
                   [](double l, bool equibiaxial) {
                     return equibiaxial ? 2 * (l * l - std::pow(l, -4)) * (kC10 + kC01 * l * l)
                                        : 2 * (l * l - 1 / l) * (kC10 + kC01 / l);
                   });
}

// The neo-Hookean law (young, poisson; its bulk modulus the exact form's penalty: nu = 0.4995,
// bulk about 1e3 x shear) held to J = 1: the incompressible neo-Hookean solid of shear modulus
// mu, sigma = mu (l^2 - 1/l) uniaxially and mu (l^2 - l^-4) equibiaxially (Mooney-Rivlin with
// c10 = mu / 2, c01 = 0).
TEST(ExactIncompressibility, NeoHookeanStretchFollowsTheIncompressibleClosedForm) {
  constexpr double nu = 0.4995, young = 2 * (1 + nu) * kShear;
  stretch_to_three(
      "neo-hookean", std::make_shared<NeoHookeMaterial>(young, nu, PlaneAnalysis::axisymmetric),
      [](double l, bool equibiaxial) { return kShear * (equibiaxial ? l * l - std::pow(l, -4) : l * l - 1 / l); });
}

struct Bulged {
  double force = 0.0;                       // the plate's, per unit thickness, on the quarter
  double bulge = 0.0;                       // u_x of the side's middle (the corner on the symmetry plane y = 0)
  double worst_element = 0.0, whole = 0.0;  // relative volume changes
  int solves = 0, updates = 0;
};

// A 2 x 2 block compressed 10 % between two rough rigid plates, plane strain: its quarter
// [0, 1] x [0, 1] on n x n elements, symmetric about x = 0 and y = 0, the upper plate moving down
// by 0.1. The plate is frictionless and the top nodes' x held: sticking without a friction
// coefficient (with Coulomb friction cev's solves under given contact forces fail from 12 %; to
// 30 % with a rounded corner: tests/hard/bulging_block_slow_test.cpp), the normal force through
// contact.
Bulged bulge_block(int n, const std::string& element, const std::string& incompressibility, double bulk) {
  const json j = testing::compressed_block(element, incompressibility,
                                           {{"law", "mooney_rivlin"}, {"c10", kC10}, {"c01", kC01}, {"bulk", bulk}}, n,
                                           {{"method", "cev"}, {"tolerance", 1e-9}});
  const testing::Solved s = testing::solve_scene(j);
  EXPECT_TRUE(s.run.completed) << s.run.reason;
  Bulged out;
  if (!s.run.completed) return out;
  const StepRecord& last = s.run.steps.back();
  out.force = -testing::contact_resultant(s.scene.problem, last).y();
  const auto& body = dynamic_cast<const ContinuumBody&>(*s.scene.problem.body);
  for (int k = 0; k < body.node_count(); ++k)
    if ((body.mesh().nodes[k] - Vec2(1, 0)).norm() < 1e-12) out.bulge = last.state.q[2 * k];
  double volume = 0.0;
  for (int e = 0; e < body.element_count(); ++e) {
    const double change = body.element_volume_change(last.state.q, e);
    out.worst_element = std::max(out.worst_element, std::abs(change));
    volume += (1 + change) / body.element_count();  // the elements are alike: the unit area shared
  }
  out.whole = volume - 1;
  for (const StepRecord& rec : s.run.steps) {
    out.solves += rec.solves;
    out.updates += rec.multiplier_updates;
  }
  return out;
}

TEST(ExactIncompressibility, BulgingBlockConvergesWithTheMeshAndKeepsItsVolume) {
  const Bulged b4 = bulge_block(4, "q9", "exact", 1e3 * kShear), b8 = bulge_block(8, "q9", "exact", 1e3 * kShear),
               b16 = bulge_block(16, "q9", "exact", 1e3 * kShear);
  const auto observed = [](double a, double b, double c) { return std::log2((a - b) / (b - c)); };
  const double force_order = observed(b4.force, b8.force, b16.force);
  const double force_ref = b16.force + (b16.force - b8.force) / (std::pow(2.0, force_order) - 1);
  for (const auto& [n, b] : {std::pair{4, &b4}, std::pair{8, &b8}, std::pair{16, &b16}})
    std::printf(
        "bulging block q9 exact %2d x %2d: force %.6f (%+.3f %%), bulge %.6f (%+.3f %%), volume change worst element "
        "%.1e, whole %.1e; %d real solves, %d updates of the pressures\n",
        n, n, b->force, 100 * (b->force / force_ref - 1), b->bulge, 100 * (b->bulge / b16.bulge - 1), b->worst_element,
        b->whole, b->solves, b->updates);
  std::printf("observed order of the force %.2f, extrapolated %.6f (bulges against 16 x 16)\n", force_order, force_ref);
  // The nearly incompressible mixed form, bulk 1e4 x shear, and t6 (P2/P0) exact, on 8 x 8.
  const Bulged mixed = bulge_block(8, "q9", "mixed", 1e4 * kShear);
  const Bulged t6 = bulge_block(8, "t6", "exact", 1e3 * kShear);
  std::printf(
      "q9 mixed bulk 1e4 x shear 8 x 8: force %.6f (%+.3f %%), bulge %.6f, volume change worst element %.1e, whole "
      "%.1e\nt6 exact 8 x 8: force %.6f (%+.3f %%), bulge %.6f (%+.3f %%), volume change worst element %.1e\n",
      mixed.force, 100 * (mixed.force / force_ref - 1), mixed.bulge, mixed.worst_element, mixed.whole, t6.force,
      100 * (t6.force / force_ref - 1), t6.bulge, 100 * (t6.bulge / b16.bulge - 1), t6.worst_element);
  for (const Bulged* b : {&b4, &b8, &b16, &t6}) {
    EXPECT_LT(b->worst_element, 1e-6);
    EXPECT_LT(std::abs(b->whole), 1e-6);
    EXPECT_GT(b->updates, 0);
  }
  // The force converges from above at the order of the sticking corner's singularity (about
  // 1/2); the bulge, far from the corners, is converged on 4 x 4 to the corner's noise (1e-3).
  EXPECT_GT(b4.force, b8.force);
  EXPECT_GT(b8.force, b16.force);
  EXPECT_GT(force_order, 0.3);
  EXPECT_LT(force_order, 1.5);
  EXPECT_NEAR(b16.force / force_ref, 1.0, 5e-3);
  for (const Bulged* b : {&b4, &b8}) EXPECT_NEAR(b->bulge / b16.bulge, 1.0, 1e-3);
  EXPECT_NEAR(t6.force / force_ref, 1.0, 1e-2);  // P2/P0 from below, as in the locking table
  EXPECT_NEAR(t6.bulge / b16.bulge, 1.0, 1.5e-2);
  EXPECT_GT(mixed.worst_element, 1e-5);  // the penalty alone leaves the volume 1e-4-ish off
  EXPECT_GT(std::abs(mixed.whole), 1e-5);
}

int real_solves(const testing::Solved& s) {
  int n = 0;
  for (const StepRecord& rec : s.run.steps) n += rec.solves;
  return n;
}

// Issue 37's cost of contact on these bodies: the real solves of the exact form against the same
// scene with a compressible neo-Hookean body of the same shear modulus (nu 0.3), within 1.5 x.
// The pressures move inside each real solve (docs/algorithm.md#exact-incompressibility); with
// the updates only after each contact solve, every increment was solved three or four times:
// 45 and 47 real solves on the 4 x 4 and 8 x 8 blocks, 135 on the O-ring.
TEST(ExactIncompressibility, ContactTakesRealSolvesWithinOneAndAHalfOfTheCompressibleBody) {
  const json compressible = {{"law", "neo_hookean"}, {"young", 2 * kShear * 1.3}, {"poisson", 0.3}};
  for (int n : {4, 8}) {
    SCOPED_TRACE(n);
    const Bulged exact = bulge_block(n, "q9", "exact", 1e3 * kShear);
    const testing::Solved elastic = testing::solve_scene(
        testing::compressed_block("q9", "none", compressible, n, {{"method", "cev"}, {"tolerance", 1e-9}}));
    ASSERT_TRUE(elastic.run.completed) << elastic.run.reason;
    const double ratio = double(exact.solves) / real_solves(elastic);
    std::printf("bulging block q9 %d x %d: real solves exact %d (%d moves of the pressures), compressible %d: %.2f x\n",
                n, n, exact.solves, exact.updates, real_solves(elastic), ratio);
    EXPECT_LE(ratio, 1.5);
    EXPECT_LT(exact.worst_element, 1e-6);
  }
  // The shipped O-ring (axisymmetric, bulk 2000 x shear), squeezed 25 % in 10 steps.
  json ring = testing::example_scene("seal-o-ring");
  ring["body"]["incompressibility"] = "exact";
  const testing::Solved exact = testing::solve_scene(ring);
  ring["body"]["incompressibility"] = "none";
  ring["body"]["material"] = compressible;
  const testing::Solved elastic = testing::solve_scene(ring);
  ASSERT_TRUE(exact.run.completed) << exact.run.reason;
  ASSERT_TRUE(elastic.run.completed) << elastic.run.reason;
  const auto& body = dynamic_cast<const ContinuumBody&>(*exact.scene.problem.body);
  double worst = 0.0;
  for (int e = 0; e < body.element_count(); ++e)
    worst = std::max(worst, std::abs(body.element_volume_change(exact.run.steps.back().state.q, e)));
  const double ratio = double(real_solves(exact)) / real_solves(elastic);
  std::printf("O-ring q9 exact: real solves %d, compressible %d: %.2f x; worst element volume change %.1e\n",
              real_solves(exact), real_solves(elastic), ratio, worst);
  EXPECT_LE(ratio, 1.5);
  EXPECT_LT(worst, 1e-6);
}

TEST(ExactIncompressibility, SceneRefusesWhatItCannotHoldWithThePointer) {
  const json j = json::parse(R"({
    "body": {
      "model": "continuum", "kinematics": "finite", "element": "q9", "incompressibility": "exact",
      "material": {"law": "mooney_rivlin", "c10": 0.4, "c01": 0.1, "bulk": 1e3},
      "mesh": {"rectangle": {"origin": [1, 0], "size": [4, 1], "divisions": [4, 2]}},
      "supports": [{"set": "top", "fix": ["x", "y"], "values": {"y": -0.01}}]
    },
    "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [10, 0], "to": [-10, 0]}}]
  })");
  struct Edit {
    json body;
    const char* pointer;  // empty: the scene reads
    const char* because;
  };
  const std::vector<Edit> edits = {
      {{{"element", "t6"}}, "", ""},
      {{{"analysis", "axisymmetric"}}, "", ""},
      {{{"material", {{"young", 3.0}, {"poisson", 0.4999}}}}, "", ""},
      {{{"element", "q8"}}, "/body/incompressibility", "\"exact\" is not offered for q8"},
      {{{"element", "q4"}}, "/body/incompressibility", "\"exact\" is not offered for q4"},
      {{{"element", "t3"}}, "/body/incompressibility", "\"exact\" is not offered for t3"},
      {{{"analysis", "plane_stress"}}, "/body/incompressibility", "plane stress does not lock"},
      {{{"kinematics", "linear"}, {"material", {{"young", 3.0}, {"poisson", 0.4999}}}},
       "/body/incompressibility",
       "for finite kinematics"},
      {{{"material", {{"law", "mooney_rivlin"}, {"c10", 0.4}, {"c01", 0.1}, {"bulk", 50}}}},
       "/body/material/bulk",
       "penalty"},
      {{{"material", {{"young", 3.0}, {"poisson", 0.45}}}},
       "/body/material/poisson",
       "at least 100 x the shear modulus"},
      {{{"material", {{"law", "saint_venant_kirchhoff"}, {"young", 3.0}, {"poisson", 0.4999}}}},
       "/body/material/law",
       "takes the elastic laws"},
      {{{"material", {{"law", "j2_plasticity"}, {"young", 3.0}, {"poisson", 0.4999}, {"yield_stress", 0.1}}}},
       "/body/material/law",
       "takes the elastic laws"},
  };
  for (const Edit& e : edits) {
    json scene = j;
    scene["body"].update(e.body);
    std::string pointer, detail;
    try {
      read_scene(scene);
    } catch (const SceneErrors& err) {
      pointer = err.issues().at(0).pointer;
      detail = err.issues().at(0).detail;
    }
    EXPECT_EQ(pointer, e.pointer) << e.body << ": " << detail;
    EXPECT_NE(detail.find(e.because), std::string::npos) << e.body << ": " << detail;
  }
}

}  // namespace
}  // namespace grip
