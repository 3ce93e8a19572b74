// Issue 9, units: the beam bent round the cylinder with Young's modulus and the load scaled
// together, and with every length in another unit (E rescaled to match). A consistent change of
// units changes nothing the solver decides, and the tests show it two ways:
// - by a power of two (2^20, 2^-20 for E and the loads, 2^10, 2^-10 for lengths), which scales
//   every floating-point value exactly: the results are the same bit for bit, every step takes the
//   same real solves and Newton iterations. Any dimensional constant in the solver (an absolute
//   tolerance, a length or force written as a number) would show as a difference here.
// - by the powers of ten users change units by (Pa and MPa, mm and m), which round differently:
//   displacements and forces agree to 1e-9 relative (the forces of the scaled modulus 1e-7), and
//   every step takes the same real solves. Newton's iterations may differ by one in a step: a
//   Newton stopping test whose residual lies within rounding of its tolerance is decided by the
//   rounding (the beam's step 19: the continued solve after a loose line-search trial starts at
//   0.95-1.02 x its tolerance in the four unit systems).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "tests/hard/hard_scenes.hpp"
#include "tests/support/result_checks.hpp"
#include "tests/support/strips.hpp"

namespace grip {
namespace {

using namespace grip::testing;
using nlohmann::json;

json scaled_forces(double f) {  // E and the load times f: the same strains
  json j = beam_on_cylinder(0.2);
  j["body"]["material"]["young"] = j["body"]["material"]["young"].get<double>() * f;
  j["body"]["loads"][0]["force"][1] = j["body"]["loads"][0]["force"][1].get<double>() * f;
  return j;
}

json scaled_lengths(double l) {  // every length times l, E (force / length^2) over l^2, forces kept
  json j = beam_on_cylinder(0.2);
  json& b = j["body"];
  b["material"]["young"] = b["material"]["young"].get<double>() / (l * l);
  for (const char* k : {"width", "depth"}) b["section"][k] = b["section"][k].get<double>() * l;
  b["mesh"]["length"] = b["mesh"]["length"].get<double>() * l;
  json& c = j["obstacles"][0]["shape"];
  c["radius"] = c["radius"].get<double>() * l;
  for (int a = 0; a < 2; ++a) c["centre"][a] = c["centre"][a].get<double>() * l;
  return j;
}

// Relative difference of a and b / scale, against b's size.
double relative(const Vector& a, const Vector& b, double scale) {
  return (a / scale - b).lpNorm<Eigen::Infinity>() / b.lpNorm<Eigen::Infinity>();
}

// Exact unit changes: powers of two. Decimal ones: what users do.
constexpr double kExactForce = 1048576.0;  // 2^20
constexpr double kExactLength = 1024.0;    // 2^10

// The scaled run is sound and takes the reference's real solves, step by step, and its Newton
// iterations to within `newton_slack` a step.
void expect_same_work(const Solved& ref, const Solved& s, const std::string& what, int newton_slack) {
  print_work(what, s);
  expect_hard_case_sound(s);
  ASSERT_TRUE(s.run.completed) << what << ": " << s.run.reason;
  ASSERT_EQ(s.run.steps.size(), ref.run.steps.size()) << what;
  for (size_t k = 0; k < ref.run.steps.size(); ++k) {
    const StepRecord &a = s.run.steps[k], &b = ref.run.steps[k];
    EXPECT_EQ(a.solves, b.solves) << what << ", step " << k + 1;
    EXPECT_LE(std::abs(a.newton_iterations - b.newton_iterations), newton_slack) << what << ", step " << k + 1;
    EXPECT_EQ(a.passes, b.passes) << what << ", step " << k + 1;
  }
}

TEST(Scaling, YoungsModulusAndLoadsTogether) {
  const Solved ref = solve_scene(beam_on_cylinder(0.2));
  print_work("reference", ref);
  ASSERT_TRUE(ref.run.completed) << ref.run.reason;
  for (const double f : {kExactForce, 1 / kExactForce, 1e6, 1e-6}) {
    const bool exact = f == kExactForce || f == 1 / kExactForce;
    const Solved s = solve_scene(scaled_forces(f));
    expect_same_work(ref, s, "E and loads x " + std::to_string(f), exact ? 0 : 1);
    double worst = 0.0;
    for (size_t k = 0; k < ref.run.steps.size(); ++k)
      worst = std::max(worst, relative(s.run.steps[k].state.q, ref.run.steps[k].state.q, 1.0));
    EXPECT_LE(worst, exact ? 0.0 : 1e-9) << "E and loads x " << f;
    double worst_p = 0.0;
    for (size_t k = 0; k < ref.run.steps.size(); ++k)
      worst_p = std::max(worst_p, relative(s.run.steps[k].p, ref.run.steps[k].p, f));
    std::printf("E and loads x %g: displacements differ by %.3g, forces by %.3g\n", f, worst, worst_p);
    // The forces are the gaps' image through the compliance's inverse, formed afresh at each
    // update on the cylinder (the turning contact forces' stiffness): each factorization's
    // rounding, 1e6 being no power of two, reaches them amplified by the beam's stiffness
    // (measured 1.6e-8 at E x 1e6 and 5.9e-11 at 1e-6, with every decision the same above).
    EXPECT_LE(worst_p, exact ? 0.0 : 1e-7) << "E and loads x " << f;
  }
}

TEST(Scaling, LengthsInAnotherUnit) {
  const Solved ref = solve_scene(beam_on_cylinder(0.2));
  ASSERT_TRUE(ref.run.completed) << ref.run.reason;
  for (const double l : {1 / kExactLength, kExactLength, 1e-3, 1e3}) {
    const bool exact = l == kExactLength || l == 1 / kExactLength;
    const Solved s = solve_scene(scaled_lengths(l));
    expect_same_work(ref, s, "lengths x " + std::to_string(l), exact ? 0 : 1);
    // u and w scale with l, theta does not; forces are unchanged.
    double worst = 0.0, worst_p = 0.0;
    for (size_t k = 0; k < ref.run.steps.size(); ++k) {
      const Vector &a = s.run.steps[k].state.q, &b = ref.run.steps[k].state.q;
      Vector unscaled = a;
      for (Eigen::Index d = 0; d < a.size(); ++d) unscaled[d] = d % 3 == 2 ? a[d] : a[d] / l;
      worst = std::max(worst, relative(unscaled, b, 1.0));
      worst_p = std::max(worst_p, relative(s.run.steps[k].p, ref.run.steps[k].p, 1.0));
    }
    std::printf("lengths x %g: displacements differ by %.3g, forces by %.3g\n", l, worst, worst_p);
    EXPECT_LE(worst, exact ? 0.0 : 1e-9) << "lengths x " << l;
    EXPECT_LE(worst_p, exact ? 0.0 : 1e-9) << "lengths x " << l;
  }
}

// The same for a slender continuum in finite strain (issue 13): Newton's stopping tests and line
// search are relative, so a strip bent to F L^2 / EI = 5 takes the same work with E times 2^+-20
// and 1e+-6 and with lengths in a unit 2^+-10 or 1e+-3 larger.
TEST(Scaling, SlenderStripInOtherUnits) {
  StripSpec base;
  base.alpha = 5.0;
  base.steps = 10;
  const Solved ref = solve_scene(strip_scene(base));
  ASSERT_TRUE(ref.run.completed) << ref.run.reason;
  auto check = [&](const StripSpec& spec, double length_factor, bool exact, const std::string& what) {
    const Solved s = solve_scene(strip_scene(spec));
    expect_same_work(ref, s, what, exact ? 0 : 1);
    double worst = 0.0;
    for (size_t k = 0; k < ref.run.steps.size(); ++k)
      worst = std::max(worst, relative(s.run.steps[k].state.q, ref.run.steps[k].state.q, length_factor));
    std::printf("%s: displacements differ by %.3g\n", what.c_str(), worst);
    EXPECT_LE(worst, exact ? 0.0 : 1e-7) << what;
  };
  for (const double f : {kExactForce, 1 / kExactForce, 1e6, 1e-6}) {
    StripSpec spec = base;
    spec.young *= f;
    check(spec, 1.0, f == kExactForce || f == 1 / kExactForce, "strip, E x " + std::to_string(f));
  }
  for (const double l : {1 / kExactLength, kExactLength, 1e-3, 1e3}) {
    StripSpec spec = base;
    spec.scale = l;
    check(spec, l, l == kExactLength || l == 1 / kExactLength, "strip, lengths x " + std::to_string(l));
  }
}

}  // namespace
}  // namespace grip
