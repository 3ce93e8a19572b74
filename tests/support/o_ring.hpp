#pragma once
// The O-ring of schemas/examples/seal-o-ring.json (axisymmetric, Mooney-Rivlin, q9) solved on
// its half-disc with `ns` divisions along the arc (ns / 2 from the pole to the centre), and
// what a seal's designer reads from it: the sealing force (the flat's contact force, total over
// the circle), the contact width and the groove walls' force.
// The contact width: that of the semi-elliptic (Hertz) line load with the same second moment,
// 4 (sum w (x - xc)^2 / sum w)^(1/2) with w the flat's nodal forces per unit circumference
// (p_n / 2 pi r) at their current positions: a smooth reading of the pressure that converges
// with the mesh, where the last node in contact moves by whole elements. The extent (the span
// of the nodes that press) is printed beside it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "tests/support/contact_profile.hpp"
#include "tests/support/scenes.hpp"

namespace grip::testing {

struct SealReading {
  double force = 0, width = 0, extent = 0, walls = 0;
  double reactions = 0;  // the diameter's reactions along y (they balance the flat's force)
};

// `element` and `incompressibility` other than the shipped q9 without one: the same ring in
// another element-formulation pair; `contact` (solver.contact) and `material` in place of the
// shipped ones where given.
inline Solved solve_o_ring(int ns, const std::string& element = "q9", const std::string& incompressibility = "none",
                           const nlohmann::json& contact = nullptr, const nlohmann::json& material = nullptr) {
  nlohmann::json j = example_scene("seal-o-ring");
  j["body"]["mesh"]["half_disc"]["divisions"] = {ns, ns / 2};
  j["body"]["element"] = element;
  j["body"]["incompressibility"] = incompressibility;
  if (!contact.is_null()) j["solver"]["contact"] = contact;
  if (!material.is_null()) j["body"]["material"] = material;
  return solve_scene(j);
}

inline SealReading read_seal(const Solved& s) {
  const Problem& problem = s.scene.problem;
  const StepRecord& rec = s.run.steps.back();
  SealReading r;
  r.force = -contact_resultant(problem, rec, 0).y();
  r.walls = contact_resultant(problem, rec, 1).x() - contact_resultant(problem, rec, 2).x();
  r.reactions = reaction_resultant(problem, rec).y();
  double sum = 0, first = 0, second = 0, lo = INFINITY, hi = -INFINITY;
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    if (c.obstacle != 0 || rec.p[c.eta] >= 0) continue;
    const double x = rec.state.points[i].point.x.x(), w = -rec.p[c.eta] / (2 * std::numbers::pi * x);
    sum += w;
    first += w * x;
    second += w * x * x;
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  const double centre = first / sum;
  r.width = 4 * std::sqrt(second / sum - centre * centre);
  r.extent = hi - lo;
  std::printf(
      "O-ring, %zu arc divisions: sealing force %.5f N, contact width %.5f mm (extent %.4f), walls %.4f N, %ld real "
      "solves\n",
      s.scene.effective["body"]["mesh"]["half_disc"]["divisions"][0].get<size_t>(), r.force, r.width, r.extent, r.walls,
      s.run.counters.solves);
  return r;
}

// The largest relative difference of the flat's force over the steps of two runs of a ring.
inline double worst_step_seal_difference(const Solved& reference, const Solved& s) {
  double worst = 0;
  for (size_t k = 0; k < reference.run.steps.size(); ++k) {
    const double fa = -contact_resultant(reference.scene.problem, reference.run.steps[k], 0).y();
    const double fb = -contact_resultant(s.scene.problem, s.run.steps.at(k), 0).y();
    worst = std::max(worst, std::abs(fb / fa - 1));
  }
  return worst;
}

// Every step converged and sound; the diameter's reactions carry the flat's force (the walls
// push along r only: frictionless and vertical).
inline SealReading expect_seal(const Solved& s) {
  expect_every_step_sound(s);
  const SealReading r = read_seal(s);
  EXPECT_NEAR(r.reactions, r.force, 1e-6 * r.force);
  return r;
}

}  // namespace grip::testing
