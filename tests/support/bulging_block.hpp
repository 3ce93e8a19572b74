#pragma once
// The bulging block of docs/verification.md#bulging-block pressed through Coulomb friction on
// the plate: the exactly incompressible Mooney-Rivlin block (2 x 2, plane strain, its quarter by
// symmetry), the plate moving down `travel` (0.3: 30 %) in `steps` steps. Two corners: the sharp
// one (the q9 rectangle, its top the contact set) and the fillet of radius 0.1 meshed by gmsh
// (tests/data/gmsh/bulging_block_fillet.py, three nested levels; its side, fillet and top the
// contact set). What each step is read for: the plate's force, the contact's reach along the
// surface, the volume kept, the force balanced, the Coulomb cone held.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "solver/elements/continuum.hpp"
#include "solver/io/gmsh_mesh.hpp"
#include "solver/io/quantities.hpp"
#include "tests/support/contact_profile.hpp"
#include "tests/support/scenes.hpp"

namespace grip::testing {

namespace bulging {
constexpr double kC10 = 0.4, kC01 = 0.1, kShear = 2 * (kC10 + kC01);
// The reference length of the top and the fillet: a contact length beyond it lies on the side.
const double kFilletEnd = 0.9 + 0.05 * std::numbers::pi;
}  // namespace bulging

// The strategies as the verification page runs them: cev and ssn to 1e-9, penalty at factor 1e4
// and tolerance 1e-4 (its error |p| / k is below that).
inline nlohmann::json bulging_contact(const std::string& method) {
  if (method == "penalty") return {{"method", "penalty"}, {"tolerance", 1e-4}, {"penalty", {{"factor", 1e4}}}};
  return {{"method", method}, {"tolerance", 1e-9}};
}

// level >= 0: the filleted block on that gmsh level; -1: the sharp block on 4 x 4 q9.
inline nlohmann::json bulging_block(int level, double mu, int steps,
                                    const nlohmann::json& contact = bulging_contact("penalty"), double travel = 0.3) {
  using nlohmann::json;
  const json mesh = level >= 0 ? json{{"gmsh", {{"file", "bulging-block-fillet-" + std::to_string(level) + ".msh"}}}}
                               : json{{"rectangle", {{"size", {1, 1}}, {"divisions", {4, 4}}}}};
  return {
      {"body",
       {{"model", "continuum"},
        {"kinematics", "finite"},
        {"element", "q9"},
        {"incompressibility", "exact"},
        {"material",
         {{"law", "mooney_rivlin"}, {"c10", bulging::kC10}, {"c01", bulging::kC01}, {"bulk", 1e3 * bulging::kShear}}},
        {"mesh", mesh},
        {"contact_set", level >= 0 ? "surface" : "top"},
        {"supports", {{{"set", "left"}, {"fix", {"x"}}}, {{"set", "bottom"}, {"fix", {"y"}}}}}}},
      {"obstacles",
       {{{"name", "plate"},
         {"shape", {{"type", "segment"}, {"from", {-1, 1}}, {"to", {3, 1}}}},
         {"friction", mu},
         {"motion", {{"translation", {0, -travel}}}}}}},
      {"steps", steps},
      {"outputs", {{{"name", "length"}, {"kind", "contact_width"}, {"obstacle", "plate"}}}},
      {"solver", {{"contact", contact}}}};
}

// Where X lies along the undeformed surface from the top's middle: the top, the fillet, the side
// (on the sharp block: along the top).
inline double along_surface(const Vec2& X) {
  if (X.x() <= 0.9 || X.y() >= 1.0) return X.x();
  if (X.y() <= 0.9) return bulging::kFilletEnd + 0.9 - X.y();
  return 0.9 + 0.1 * std::atan2(X.x() - 0.9, X.y() - 0.9);
}

struct Pressed {
  // Per converged step: the plate's force on the quarter, the contact length (extrapolated to
  // where the pressure vanishes), the farthest pressing node along the surface, the largest
  // penetration (penalty's error), the cuts of the step's increment.
  std::vector<double> force, length, reach, penetration;
  std::vector<int> cuts;
  // The steps (from 1) where load stepping's last resort, ssn's semismooth Newton from the last
  // converged state, took an increment (docs/algorithm.md#load-stepping-and-cuts).
  std::vector<int> by_ssn;
  double travel_step = 0;  // the plate's travel in one step
  double bulge = 0;        // u_x of the side's middle (1, 0) at the last step
  double worst_volume = 0, balance = 0, cone = 0;
  int most_solves = 0, solves = 0, points = 0;
  bool all_stick = true;  // every pressing point sticks at every step
  bool completed = false;
  std::string reason;  // why the run stopped
};

// The run's converged steps read; a run that stops short is reported, not failed: the caller
// asserts how far each strategy goes.
inline Pressed press_block_with(int level, double mu, int steps, const nlohmann::json& contact, double travel = 0.3) {
  const auto meshes = [](const nlohmann::json& ref) {
    return std::make_shared<const GmshMesh>(
        read_gmsh_file(std::string(GRIP_SOURCE_DIR) + "/tests/data/gmsh/" + ref["file"].get<std::string>()));
  };
  const Solved s = solve_scene(bulging_block(level, mu, steps, contact, travel), meshes);
  const std::string method = contact["method"].get<std::string>() + (contact.contains("real_solve") ? " held" : "");
  const Problem& problem = s.scene.problem;
  const auto& body = dynamic_cast<const ContinuumBody&>(*problem.body);
  Pressed out;
  out.completed = s.run.completed;
  out.travel_step = travel / steps;
  out.reason = s.run.reason;
  for (const StepRecord& rec : s.run.steps) {
    if (!rec.converged) break;
    const Vec2 contact = contact_resultant(problem, rec), reactions = reaction_resultant(problem, rec);
    out.force.push_back(-contact.y());
    out.length.push_back(quantity_value(problem, rec, s.scene.output.quantities.at(0)));
    out.cuts.push_back(rec.cuts);
    if (std::ranges::any_of(rec.notes, [](const std::string& n) {
          return n.find("the increment by ssn's semismooth Newton") != std::string::npos;
        }))
      out.by_ssn.push_back(rec.index);
    out.balance = std::max(out.balance, (contact + reactions).norm() / -contact.y());
    for (int e = 0; e < body.element_count(); ++e)
      out.worst_volume = std::max(out.worst_volume, std::abs(body.element_volume_change(rec.state.q, e)));
    out.points = 0;
    double reach = 0, penetration = 0;
    for (size_t i = 0; i < problem.candidates.size(); ++i) {
      const Candidate& c = problem.candidates[i];
      penetration = std::max(penetration, -rec.state.points[i].projection.gap);
      const double p_n = rec.p[c.eta], p_t = c.xi >= 0 ? rec.p[c.xi] : 0.0;
      if (p_n >= 0) continue;
      ++out.points;
      reach = std::max(reach, along_surface(problem.body->site_reference(c.site)));
      out.cone = std::max(out.cone, mu > 0 ? std::abs(p_t) / (mu * -p_n) - 1 : std::abs(p_t));
      out.all_stick = out.all_stick && contact_state(problem, i, rec.p, rec.tau) == ContactState::stick;
    }
    out.reach.push_back(reach);
    out.penetration.push_back(penetration);
    out.most_solves = std::max(out.most_solves, rec.solves);
    out.solves += rec.solves;
    for (int k = 0; k < body.node_count(); ++k)
      if ((body.mesh().nodes[k] - Vec2(1, 0)).norm() < 1e-12) out.bulge = rec.state.q[2 * k];
  }
  std::printf(
      "%s block%s, %s, mu %g, %zu of %d steps: force %.6f, bulge %.6f, contact length %.6f, %d points; "
      "farthest pressing node %.4f; volume change worst element %.1e, balance %.1e, cone %+.1e, %d real solves, at "
      "most %d a step%s%s\n",
      level >= 0 ? "filleted" : "sharp", level >= 0 ? (" level " + std::to_string(level)).c_str() : " 4 x 4",
      method.c_str(), mu, out.force.size(), steps, out.force.empty() ? 0.0 : out.force.back(), out.bulge,
      out.length.empty() ? 0.0 : out.length.back(), out.points, out.reach.empty() ? 0.0 : out.reach.back(),
      out.worst_volume, out.balance, out.cone, out.solves, out.most_solves,
      out.completed ? "" : "; stopped: ", out.reason.c_str());
  return out;
}

inline Pressed press_block(int level, double mu, int steps = 30, const std::string& method = "penalty",
                           double travel = 0.3) {
  return press_block_with(level, mu, steps, bulging_contact(method), travel);
}

// Sound at every converged step, whatever the friction and the strategy: the volume kept, the
// force balanced, the cone held, the force rising, the contact never receding (its farthest
// pressing node; the extrapolated length drops by up to 0.02 on level 0 where a node starts to
// press with a small force).
inline void expect_sound(const Pressed& p) {
  EXPECT_LT(p.worst_volume, 1e-6);
  EXPECT_LT(p.balance, 1e-6);
  EXPECT_LE(p.cone, 1e-6);
  for (size_t k = 1; k < p.force.size(); ++k) {
    EXPECT_GT(p.force[k], p.force[k - 1]) << "step " << k + 1;
    EXPECT_GE(p.reach[k], p.reach[k - 1]) << "step " << k + 1;
  }
}

// Penalty's error at step k (from 0): its points sit `penetration` inside the plate, so its body
// is pressed that much less, and its force low by about penetration x dF/d(travel), relative to
// the force (dF/d(travel) by differences of its own steps).
inline double penalty_force_error(const Pressed& penalty, size_t k) {
  const double step = penalty.travel_step;
  const size_t hi = std::min(k + 1, penalty.force.size() - 1);
  const double lo_force = k == 0 ? 0.0 : penalty.force[k - 1];
  const double slope = (penalty.force[hi] - lo_force) / (step * static_cast<double>(hi - k + 1));
  return penalty.penetration[k] * slope / penalty.force[k];
}

}  // namespace grip::testing
