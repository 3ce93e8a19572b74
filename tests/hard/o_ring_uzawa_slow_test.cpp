// uzawa on the O-ring of tests/verification/rubber_contact_strategies_test.cpp (issue 37, point
// 3), measured, its real-solve ratio not asserted: 2.5 x (q9 mixed, 8 arc divisions) and 2.3 x
// (q4 F-bar, 16) the compressible ring's (neo-Hookean, the rubber's shear modulus, nu = 0.3),
// against 1.5 x asked (docs/algorithm.md#uzawa). Asserted: its answer against cev default's, and
// the contact that sets its rate: the rubber presses the groove's outer wall with two points at
// the last step, the compressible ring with one (a wall point's compliance is 20-50 x a flat
// point's; the two share the section's radial motion). About 35 s: a *Slow suite (label
// hard_slow, configuration slow).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "tests/support/o_ring.hpp"

namespace grip {
namespace {

using nlohmann::json;
using namespace grip::testing;

int real_solves(const Solved& s) {
  int n = 0;
  for (const StepRecord& rec : s.run.steps) n += rec.solves;
  return n;
}

// The points pressing obstacle `obstacle` at the last step.
int pressing(const Solved& s, int obstacle) {
  const StepRecord& rec = s.run.steps.back();
  int n = 0;
  for (const Candidate& c : s.scene.problem.candidates)
    if (c.obstacle == obstacle && rec.p[c.eta] < 0) ++n;
  return n;
}

TEST(RubberUzawaORingSlow, TheAnswerOfCevAndTheRatioMeasured) {
  struct Pair {
    const char* element;
    const char* incompressibility;
    int ns;
  };
  const json compressible = {{"law", "neo_hookean"}, {"young", 2.6}, {"poisson", 0.3}};
  for (const Pair& pair : {Pair{"q9", "mixed", 8}, Pair{"q4", "f_bar", 16}}) {
    const std::string body = std::string(pair.element) + " " + pair.incompressibility;
    SCOPED_TRACE(body);
    const auto ring = [&](const json& contact, bool incompressible) {
      return solve_o_ring(pair.ns, pair.element, pair.incompressibility, contact,
                          incompressible ? json(nullptr) : json(compressible));
    };
    const json cev = {{"method", "cev"}, {"tolerance", 1e-8}};
    const json uzawa = {{"method", "uzawa"}, {"tolerance", 1e-5}, {"max_iterations", 20000}};
    const Solved by_cev = ring(cev, true), elastic_cev = ring(cev, false);
    const Solved by_uzawa = ring(uzawa, true), elastic_uzawa = ring(uzawa, false);
    for (const Solved* s : {&by_cev, &elastic_cev, &by_uzawa, &elastic_uzawa}) expect_every_step_sound(*s);
    if (!by_cev.run.completed || !elastic_cev.run.completed || !by_uzawa.run.completed || !elastic_uzawa.run.completed)
      continue;
    const SealReading a = read_seal(by_cev), b = read_seal(by_uzawa);
    const double worst = worst_step_seal_difference(by_cev, by_uzawa);
    const double ratio = double(real_solves(by_uzawa)) / real_solves(elastic_uzawa);
    std::printf(
        "O-ring %s, uzawa: sealing force %.6f (worst step %.1e against cev default), width %+.1e; outer wall's points "
        "rubber %d, compressible %d; real solves rubber %d, compressible %d: %.2f x (not asserted)\n",
        body.c_str(), b.force, worst, b.width / a.width - 1, pressing(by_cev, 2), pressing(elastic_cev, 2),
        real_solves(by_uzawa), real_solves(elastic_uzawa), ratio);
    // uzawa to 1e-5 (linear convergence): measured 1.7e-5 (q9 mixed) and 6.5e-6 (q4 F-bar) in the
    // sealing force of the worst step, 1.2e-5 and 8e-6 in the width.
    EXPECT_LT(worst, 5e-5);
    EXPECT_NEAR(b.width / a.width, 1.0, 5e-5);
    EXPECT_EQ(pressing(by_cev, 2), 2);
    EXPECT_EQ(pressing(elastic_cev, 2), 1);
    EXPECT_EQ(pressing(by_uzawa, 2), 2);
  }
}

}  // namespace
}  // namespace grip
