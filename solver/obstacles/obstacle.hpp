#pragma once
// Rigid obstacles: closest-point projection of a query point onto the obstacle surface.
//
// Conventions (docs/algorithm.md#notation):
// - `normal` is the obstacle's outward unit normal at the closest point; the paper's eta = -normal.
// - `tangent` = rot90(normal): the boundary is traversed with the solid on the LEFT
//   (counter-clockwise round a convex solid).
// - `gap` = (x - point) . normal, signed: > 0 outside the solid, < 0 inside (penetration = -gap).
// - `zeta` is the arc length of `point` along the surface, increasing along `tangent`,
//   continuous across the joints of a profile. For a closed circle it is periodic with
//   `period()`; use `zeta_difference` for slips.
// All functions are defined everywhere (no NaN), including at convex corners, at the ends
// of open profiles, and at the centre of a circle.
#include <memory>
#include <variant>
#include <vector>

#include "solver/model/types.hpp"

namespace grip {

struct Projection {
  Vec2 point = Vec2::Zero();
  Vec2 normal = Vec2::UnitY();
  Vec2 tangent = -Vec2::UnitX();
  double gap = 0.0;
  double zeta = 0.0;
  // d(normal)/d(x) at fixed obstacle: (I - n n^T) / (radius + gap) on a convex arc, zero on a
  // straight piece. Used for the stiffness of the follower contact load.
  Mat2 dnormal_dx = Mat2::Zero();
  // d(zeta) = zeta_rate * tangent . dx (radius / (radius + gap) on a convex arc, 1 on a segment).
  double zeta_rate = 1.0;
};

class Obstacle {
 public:
  virtual ~Obstacle() = default;
  // Projection of x, both in the obstacle's own (unmoved) frame.
  virtual Projection project(const Vec2& x) const = 0;
  // The smallest radius of curvature of its arcs (infinity for straight pieces only; a corner
  // between pieces does not count): an obstacle moving farther than this in one increment can
  // pass a point of the body from one side to the other (the step checks cut such increments).
  virtual double smallest_radius() const;
  // 0 for an open surface; the circumference for a closed circle.
  virtual double period() const { return 0.0; }
  // zeta1 - zeta0, taken modulo the period (into (-period/2, period/2]) on closed surfaces.
  double zeta_difference(double zeta1, double zeta0) const;
};

// A full circle, solid inside. zeta = radius * angle from the +x axis, period 2 pi radius.
std::unique_ptr<Obstacle> make_circle(Vec2 centre, double radius);

// Pieces of a profile, in the order of travel (solid on the left).
struct SegmentPiece {
  Vec2 from, to;
};
// Angles in radians. to_angle > from_angle: counter-clockwise, solid inside (convex, a die
// shoulder or punch nose); to_angle < from_angle: clockwise, solid outside (concave fillet).
struct ArcPiece {
  Vec2 centre;
  double radius;
  double from_angle, to_angle;
};
using ProfilePiece = std::variant<SegmentPiece, ArcPiece>;

// An open chain of pieces, each starting where the previous one ends. A lone segment or arc
// is a profile of one piece. Beyond its ends the surface continues along the end tangents.
// `closed`: the last piece ends where the first starts (a ring's boundary): no ends and no
// extensions (a tangent extension at the seam would cut through the loop's own neighbourhood),
// the seam a joint like the others, zeta periodic with the loop's length.
// Throws std::invalid_argument (with the piece index) on a gap between pieces, a zero-length
// piece or a non-positive radius.
std::unique_ptr<Obstacle> make_profile(std::vector<ProfilePiece> pieces, bool closed = false);

}  // namespace grip
