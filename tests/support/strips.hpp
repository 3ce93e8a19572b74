#pragma once
// Slender strips as continua (issue 13): a rectangle L x t clamped on its left side and bent
// by a dead vertical traction on its right side, totalling F = alpha EI / L^2, with nu = 0 so
// that plane strain gives EI = E t^3 / 12 exactly.
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "solver/elements/continuum.hpp"
#include "tests/support/elastica.hpp"
#include "tests/support/scenes.hpp"

namespace grip::testing {

struct StripSpec {
  double length = 1.0;
  double thickness = 0.02;
  int along = 50, across = 2;
  std::string element = "q9";
  std::string kinematics = "finite";
  double young = 1.5e6;     // EI = 1 for t = 0.02
  double alpha = 10.0;      // F L^2 / EI
  double load_angle = 0.0;  // the dead load's direction, turned from -y back toward -x (radians)
  int steps = 20;
  double scale = 1.0;  // multiplies every length (the load stays alpha EI / L^2)
  // The obstacle: a circle of `radius` whose top lies `gap` below the clamped end, or (radius
  // 0) a flat far below.
  double radius = 0.0, gap = 0.01, friction = 0.0;
};

inline double strip_bending_stiffness(const StripSpec& s) {
  const double t = s.thickness * s.scale;
  return s.young * t * t * t / 12.0;
}

inline nlohmann::json strip_scene(const StripSpec& s) {
  const double L = s.length * s.scale, t = s.thickness * s.scale;
  const double force = s.alpha * strip_bending_stiffness(s) / (L * L);
  nlohmann::json shape = s.radius > 0
                             ? nlohmann::json{{"type", "circle"},
                                              {"centre", {0.0, -(s.gap + s.radius) * s.scale}},
                                              {"radius", s.radius * s.scale}}
                             : nlohmann::json{{"type", "segment"}, {"from", {5 * L, -3 * L}}, {"to", {-5 * L, -3 * L}}};
  return {{"body",
           {{"model", "continuum"},
            {"kinematics", s.kinematics},
            {"analysis", "plane_strain"},
            {"element", s.element},
            {"thickness", 1},
            {"material", {{"young", s.young}, {"poisson", 0.0}, {"law", "saint_venant_kirchhoff"}}},
            {"mesh", {{"rectangle", {{"origin", {0.0, 0.0}}, {"size", {L, t}}, {"divisions", {s.along, s.across}}}}}},
            {"contact_set", "bottom"},
            {"supports", {{{"set", "left"}, {"fix", {"x", "y"}}}}},
            {"loads",
             {{{"set", "right"},
               {"traction", {-std::sin(s.load_angle) * force / t, -std::cos(s.load_angle) * force / t}}}}}}},
          {"obstacles", {{{"name", "tool"}, {"shape", shape}, {"friction", s.friction}}}},
          {"steps", s.steps},
          {"solver", {{"contact", {{"method", "cev"}, {"tolerance", 1e-8}}}}}};
}

// The free end's mid-surface point, over L: deflection (down), shortening, and the rotation
// of the end section (from its bottom to its top corner).
inline ElasticaTip strip_tip(const Solved& s, const StripSpec& spec, size_t step) {
  const auto& body = dynamic_cast<const ContinuumBody&>(*s.scene.problem.body);
  const PlaneMesh& mesh = body.mesh();
  const Vector& q = s.run.steps.at(step).state.q;
  const double L = spec.length * spec.scale, t = spec.thickness * spec.scale;
  int bottom = -1, top = -1, mid = -1;
  for (int n = 0; n < body.node_count(); ++n) {
    const Vec2& x = mesh.nodes[n];
    if (std::abs(x.x() - L) > 1e-9 * L) continue;
    if (std::abs(x.y()) < 1e-9 * L) bottom = n;
    if (std::abs(x.y() - t) < 1e-9 * L) top = n;
    if (std::abs(x.y() - t / 2) < 1e-9 * L) mid = n;
  }
  auto current = [&](int n) {
    return Vec2(mesh.nodes[n].x() + q[ContinuumBody::node_dof(n, 0)],
                mesh.nodes[n].y() + q[ContinuumBody::node_dof(n, 1)]);
  };
  const Vec2 m = mid >= 0 ? current(mid) : 0.5 * (current(bottom) + current(top));
  const Vec2 section = current(top) - current(bottom);
  return {(t / 2 - m.y()) / L, (L - m.x()) / L, std::atan2(section.x(), section.y())};
}

}  // namespace grip::testing
