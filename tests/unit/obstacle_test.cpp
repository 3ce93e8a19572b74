// Obstacles: closest-point projection onto circles and open profiles of segments and arcs.
#include "solver/obstacles/obstacle.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace grip {
namespace {

constexpr double kPi = std::numbers::pi;

bool all_finite(const Projection& p) {
  return p.point.allFinite() && p.normal.allFinite() && p.tangent.allFinite() && std::isfinite(p.gap) &&
         std::isfinite(p.zeta) && p.dnormal_dx.allFinite() && std::isfinite(p.zeta_rate);
}

// Invariants that hold for every query: finite, unit normal, tangent = rot90(normal), and the
// query is the surface point moved by the gap along the normal.
void expect_consistent(const Projection& p, const Vec2& x) {
  SCOPED_TRACE("x = (" + std::to_string(x.x()) + ", " + std::to_string(x.y()) + ")");
  ASSERT_TRUE(all_finite(p));
  EXPECT_NEAR(p.normal.norm(), 1.0, 1e-14);
  EXPECT_LE((p.tangent - rot90(p.normal)).norm(), 1e-15);
  EXPECT_LE((p.point + p.gap * p.normal - x).norm(), 1e-12 * std::max(1.0, x.norm()));
}

// Compares dnormal_dx and zeta_rate with central finite differences of normal and zeta.
void expect_derivatives_match(const Obstacle& obstacle, const Vec2& x, double h = 1e-6) {
  SCOPED_TRACE("x = (" + std::to_string(x.x()) + ", " + std::to_string(x.y()) + ")");
  const Projection p = obstacle.project(x);
  Mat2 dnormal_fd;
  Eigen::RowVector2d dzeta_fd;
  for (int j = 0; j < 2; ++j) {
    const Vec2 step = h * Vec2::Unit(j);
    const Projection plus = obstacle.project(x + step);
    const Projection minus = obstacle.project(x - step);
    dnormal_fd.col(j) = (plus.normal - minus.normal) / (2 * h);
    dzeta_fd(j) = obstacle.zeta_difference(plus.zeta, minus.zeta) / (2 * h);
  }
  EXPECT_LE((p.dnormal_dx - dnormal_fd).norm(), 1e-7) << "analytic\n" << p.dnormal_dx << "\nfd\n" << dnormal_fd;
  const Eigen::RowVector2d dzeta = p.zeta_rate * p.tangent.transpose();
  EXPECT_LE((dzeta - dzeta_fd).norm(), 1e-7) << "analytic " << dzeta << " fd " << dzeta_fd;
}

// Dense samples of a profile's surface, extensions included, for brute-force nearest distances.
class SurfaceSamples {
 public:
  explicit SurfaceSamples(const std::vector<ProfilePiece>& pieces, double spacing, double extension) {
    const auto add_line = [&](const Vec2& a, const Vec2& b) {
      const int n = static_cast<int>(std::ceil((b - a).norm() / spacing));
      for (int i = 0; i <= n; ++i) points_.push_back(a + (b - a) * (double(i) / n));
    };
    Vec2 first_tangent = Vec2::Zero(), last_tangent = Vec2::Zero(), first = Vec2::Zero(), last = Vec2::Zero();
    for (std::size_t k = 0; k < pieces.size(); ++k) {
      Vec2 start, end, t0, t1;
      if (const auto* s = std::get_if<SegmentPiece>(&pieces[k])) {
        add_line(s->from, s->to);
        start = s->from;
        end = s->to;
        t0 = t1 = (s->to - s->from).normalized();
      } else {
        const auto& a = std::get<ArcPiece>(pieces[k]);
        const int n = static_cast<int>(std::ceil(a.radius * std::abs(a.to_angle - a.from_angle) / spacing));
        for (int i = 0; i <= n; ++i) {
          const double angle = a.from_angle + (a.to_angle - a.from_angle) * (double(i) / n);
          points_.push_back(a.centre + a.radius * Vec2(std::cos(angle), std::sin(angle)));
        }
        const double sense = a.to_angle > a.from_angle ? 1.0 : -1.0;
        start = a.centre + a.radius * Vec2(std::cos(a.from_angle), std::sin(a.from_angle));
        end = a.centre + a.radius * Vec2(std::cos(a.to_angle), std::sin(a.to_angle));
        t0 = sense * Vec2(-std::sin(a.from_angle), std::cos(a.from_angle));
        t1 = sense * Vec2(-std::sin(a.to_angle), std::cos(a.to_angle));
      }
      if (k == 0) first = start, first_tangent = t0;
      last = end;
      last_tangent = t1;
    }
    add_line(first, first - extension * first_tangent);
    add_line(last, last + extension * last_tangent);
  }
  double distance(const Vec2& x) const {
    double best = std::numeric_limits<double>::infinity();
    for (const Vec2& s : points_) best = std::min(best, (x - s).norm());
    return best;
  }

 private:
  std::vector<Vec2> points_;
};

// Checks every projection invariant on a grid, that |gap| is the true distance to the surface
// (against dense samples) and that the sign of the gap says inside/outside correctly.
void check_profile_on_grid(const std::vector<ProfilePiece>& pieces, Vec2 lo, Vec2 hi, double step,
                           const std::function<bool(const Vec2&)>& inside) {
  const auto obstacle = make_profile(pieces);
  const double spacing = 0.05 * step;
  const SurfaceSamples samples(pieces, spacing, 2 * (hi - lo).norm());
  int count = 0;
  for (double x = lo.x(); x <= hi.x(); x += step) {
    for (double y = lo.y(); y <= hi.y(); y += step) {
      const Vec2 q(x, y);
      const Projection p = obstacle->project(q);
      expect_consistent(p, q);
      const double nearest = samples.distance(q);
      EXPECT_LE(std::abs(p.gap), nearest + 1e-9) << "at (" << x << ", " << y << ")";
      EXPECT_GE(std::abs(p.gap), nearest - spacing) << "at (" << x << ", " << y << ")";
      EXPECT_LE(samples.distance(p.point), spacing) << "point off the surface at (" << x << ", " << y << ")";
      if (std::abs(p.gap) > 1e-9) {
        EXPECT_EQ(p.gap < 0, inside(q)) << "wrong side at (" << x << ", " << y << ")";
      }
      ++count;
    }
  }
  EXPECT_GT(count, 100);
}

// The paper's sheet-stretching die: flat top, convex shoulder of radius 6.35, vertical wall.
std::vector<ProfilePiece> die_pieces() {
  return {SegmentPiece{{99.18, -0.5}, {59.18, -0.5}}, ArcPiece{{59.18, -6.85}, 6.35, kPi / 2, kPi},
          SegmentPiece{{52.83, -6.85}, {52.83, -46.85}}};
}
bool inside_die(const Vec2& x) {
  if (x.x() <= 52.83 || x.y() >= -0.5) return false;
  const Vec2 c(59.18, -6.85);
  return !(x.x() < c.x() && x.y() > c.y() && (x - c).norm() > 6.35);
}
constexpr double kDieShoulderEnd = 40.0 + 6.35 * kPi / 2;

// A flat-topped punch with two sharp convex corners; solid is the strip |x| < 2, y < 0.
std::vector<ProfilePiece> punch_pieces() {
  return {SegmentPiece{{2, -4}, {2, 0}}, SegmentPiece{{2, 0}, {-2, 0}}, SegmentPiece{{-2, 0}, {-2, -4}}};
}
bool inside_punch(const Vec2& x) { return std::abs(x.x()) < 2 && x.y() < 0; }

// A rectangular groove in a flat solid: convex lips at (+-1, 0), concave bottom corners.
std::vector<ProfilePiece> groove_pieces() {
  return {SegmentPiece{{4, 0}, {1, 0}}, SegmentPiece{{1, 0}, {1, -2}}, SegmentPiece{{1, -2}, {-1, -2}},
          SegmentPiece{{-1, -2}, {-1, 0}}, SegmentPiece{{-1, 0}, {-4, 0}}};
}
bool inside_groove(const Vec2& x) { return x.y() < 0 && !(std::abs(x.x()) < 1 && x.y() > -2); }

// A round-bottomed (concave) bowl between two flats, meeting them at sharp convex lips.
std::vector<ProfilePiece> bowl_pieces() {
  return {SegmentPiece{{5, 0}, {2, 0}}, ArcPiece{{0, 0}, 2.0, 0.0, -kPi}, SegmentPiece{{-2, 0}, {-5, 0}}};
}
bool inside_bowl(const Vec2& x) { return x.y() < 0 && x.norm() > 2; }

// A convex half-disc nose continued by its end tangents: a round-nosed bar along -x.
std::vector<ProfilePiece> nose_pieces() { return {ArcPiece{{0, 0}, 1.0, -kPi / 2, kPi / 2}}; }
bool inside_nose(const Vec2& x) { return x.x() < 0 ? std::abs(x.y()) < 1 : x.norm() < 1; }

// ---------------------------------------------------------------------------------------------
// Circle

TEST(CircleProjection, GapNormalAndZetaOnGrid) {
  const Vec2 c(1.5, -0.7);
  const double radius = 2.0;
  const auto circle = make_circle(c, radius);
  EXPECT_DOUBLE_EQ(circle->period(), 2 * kPi * radius);
  for (double x = -5.03; x <= 7; x += 0.37) {
    for (double y = -7.01; y <= 6; y += 0.41) {
      const Vec2 q(x, y);
      const Projection p = circle->project(q);
      expect_consistent(p, q);
      EXPECT_NEAR(p.gap, (q - c).norm() - radius, 1e-13);
      EXPECT_LE((p.normal - (q - c).normalized()).norm(), 1e-14);
      EXPECT_NEAR((p.point - c).norm(), radius, 1e-13);
      EXPECT_NEAR(p.zeta, radius * std::atan2(q.y() - c.y(), q.x() - c.x()), 1e-13);
    }
  }
  // Counter-clockwise tangent at the right-most point, solid inside.
  const Projection right = circle->project(c + Vec2(3, 0));
  EXPECT_NEAR(right.tangent.y(), 1.0, 1e-15);
  EXPECT_NEAR(right.gap, 1.0, 1e-15);
  EXPECT_NEAR(circle->project(c + Vec2(0, 0.5)).gap, -1.5, 1e-15);
}

TEST(CircleProjection, CentreIsDefined) {
  const Vec2 c(3, 4);
  const auto circle = make_circle(c, 2.0);
  for (const Vec2& q : {c, Vec2(c + Vec2(1e-300, 0)), Vec2(c + Vec2(0, -1e-14))}) {
    const Projection p = circle->project(q);
    expect_consistent(p, q);
    EXPECT_NEAR(p.gap, -2.0, 1e-13);
  }
  const Projection p = circle->project(c);
  EXPECT_EQ(p.normal, Vec2::UnitY());
  EXPECT_EQ(p.point, Vec2(3, 6));
}

TEST(CircleProjection, HugeQueriesStayFinite) {
  const auto circle = make_circle({0, 0}, 1.0);
  for (const Vec2& q : {Vec2(1e300, -1e300), Vec2(-1e307, 1e306), Vec2(1e-320, 0)})
    expect_consistent(circle->project(q), q);
}

TEST(CircleZeta, DifferenceWrapsAcrossBranchCut) {
  const double radius = 2.0;
  const auto circle = make_circle({0, 0}, radius);
  const double period = 2 * kPi * radius;
  // Just above and just below the -x axis: zeta jumps by a period, the difference must not.
  const double above = circle->project(Vec2(std::cos(kPi - 0.01), std::sin(kPi - 0.01))).zeta;
  const double below = circle->project(Vec2(std::cos(-kPi + 0.01), std::sin(-kPi + 0.01))).zeta;
  EXPECT_NEAR(above - below, period - 0.04, 1e-12);
  EXPECT_NEAR(circle->zeta_difference(below, above), 0.04, 1e-12);
  EXPECT_NEAR(circle->zeta_difference(above, below), -0.04, 1e-12);
  EXPECT_NEAR(circle->zeta_difference(3 * period + 0.1, 0.0), 0.1, 1e-12);
  EXPECT_NEAR(circle->zeta_difference(-5 * period - 0.1, 0.0), -0.1, 1e-12);
  EXPECT_NEAR(circle->zeta_difference(0.3, 0.1), 0.2, 1e-15);
  // Half a period lands on +period/2 from either side.
  EXPECT_DOUBLE_EQ(circle->zeta_difference(period / 2, 0.0), period / 2);
  EXPECT_DOUBLE_EQ(circle->zeta_difference(-period / 2, 0.0), period / 2);
  // An open profile does not wrap.
  const auto die = make_profile(die_pieces());
  EXPECT_EQ(die->period(), 0.0);
  EXPECT_DOUBLE_EQ(die->zeta_difference(100.0, -30.0), 130.0);
}

TEST(CircleDerivatives, MatchFiniteDifferences) {
  const auto circle = make_circle({0.5, -1}, 3.0);
  for (const Vec2& q : {Vec2(4, 1), Vec2(0.2, -0.5), Vec2(-4, -1.001), Vec2(-2.4, -1.0), Vec2(0.5, 8)})
    expect_derivatives_match(*circle, q);
  // Outside: dnormal = (I - n n^T) / (R + gap), zeta_rate = R / (R + gap).
  const Projection p = circle->project({0.5, 4});
  EXPECT_NEAR(p.zeta_rate, 0.6, 1e-15);
  EXPECT_NEAR(p.dnormal_dx(0, 0), 0.2, 1e-15);
  EXPECT_NEAR(p.dnormal_dx(1, 1), 0.0, 1e-15);
}

TEST(CircleValidation, RejectsBadRadius) {
  EXPECT_THROW(make_circle({0, 0}, 0.0), std::invalid_argument);
  EXPECT_THROW(make_circle({0, 0}, -1.0), std::invalid_argument);
  EXPECT_THROW(make_circle({0, 0}, std::nan("")), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Profiles

TEST(ProfileProjection, DieNearestPointAndSideOnGrid) {
  check_profile_on_grid(die_pieces(), {40.13, -60.07}, {112.0, 12.0}, 0.93, inside_die);
}

TEST(ProfileProjection, PunchWithConvexCornersOnGrid) {
  check_profile_on_grid(punch_pieces(), {-4.03, -7.01}, {4.0, 3.0}, 0.127, inside_punch);
}

TEST(ProfileProjection, GrooveWithConcaveCornersOnGrid) {
  check_profile_on_grid(groove_pieces(), {-6.01, -5.03}, {6.0, 3.0}, 0.131, inside_groove);
}

TEST(ProfileProjection, ConcaveBowlOnGrid) {
  check_profile_on_grid(bowl_pieces(), {-7.01, -5.03}, {7.0, 3.0}, 0.133, inside_bowl);
}

TEST(ProfileProjection, ConvexNoseOnGrid) {
  check_profile_on_grid(nose_pieces(), {-3.01, -3.03}, {3.0, 3.0}, 0.071, inside_nose);
}

TEST(ProfileProjection, DieReferencePoints) {
  const auto die = make_profile(die_pieces());
  const Vec2 c(59.18, -6.85);
  const double r = 6.35;

  // Above the top face.
  Projection p = die->project({80, 3});
  EXPECT_LE((p.point - Vec2(80, -0.5)).norm(), 1e-12);
  EXPECT_LE((p.normal - Vec2(0, 1)).norm(), 1e-15);
  EXPECT_NEAR(p.gap, 3.5, 1e-12);
  EXPECT_NEAR(p.zeta, 19.18, 1e-12);
  EXPECT_EQ(p.zeta_rate, 1.0);
  EXPECT_EQ(p.dnormal_dx, Mat2::Zero());

  // Above the shoulder, at 135 degrees, 2 outside it.
  const Vec2 u(-std::sqrt(0.5), std::sqrt(0.5));
  p = die->project(c + (r + 2) * u);
  EXPECT_LE((p.point - (c + r * u)).norm(), 1e-12);
  EXPECT_LE((p.normal - u).norm(), 1e-14);
  EXPECT_NEAR(p.gap, 2.0, 1e-12);
  EXPECT_NEAR(p.zeta, 40 + r * kPi / 4, 1e-12);
  EXPECT_NEAR(p.zeta_rate, r / (r + 2), 1e-14);
  EXPECT_LE((p.dnormal_dx - (Mat2::Identity() - u * u.transpose()) / (r + 2)).norm(), 1e-14);

  // Left of the wall.
  p = die->project({50, -20});
  EXPECT_LE((p.point - Vec2(52.83, -20)).norm(), 1e-12);
  EXPECT_LE((p.normal - Vec2(-1, 0)).norm(), 1e-15);
  EXPECT_NEAR(p.gap, 2.83, 1e-12);
  EXPECT_NEAR(p.zeta, kDieShoulderEnd + 13.15, 1e-12);

  // Inside the die under the shoulder: the shoulder is nearest, the gap is negative.
  const Vec2 q(57, -3);
  p = die->project(q);
  EXPECT_NEAR(p.gap, (q - c).norm() - r, 1e-12);
  EXPECT_LT(p.gap, -1.9);
  EXPECT_LE((p.normal - (q - c).normalized()).norm(), 1e-14);
  // Inside under the top face.
  p = die->project({70, -2});
  EXPECT_NEAR(p.gap, -1.5, 1e-12);
  EXPECT_LE((p.normal - Vec2(0, 1)).norm(), 1e-15);

  // Beyond the first point: the top face continues, zeta goes negative.
  p = die->project({110, 1});
  EXPECT_LE((p.point - Vec2(110, -0.5)).norm(), 1e-12);
  EXPECT_LE((p.normal - Vec2(0, 1)).norm(), 1e-15);
  EXPECT_NEAR(p.gap, 1.5, 1e-12);
  EXPECT_NEAR(p.zeta, -10.82, 1e-12);
  p = die->project({110, -3});
  EXPECT_NEAR(p.gap, -2.5, 1e-12);
  EXPECT_NEAR(p.zeta, -10.82, 1e-12);

  // Beyond the last point: the wall continues, zeta exceeds the total length.
  const double total = kDieShoulderEnd + 40;
  p = die->project({50, -60});
  EXPECT_LE((p.point - Vec2(52.83, -60)).norm(), 1e-12);
  EXPECT_LE((p.normal - Vec2(-1, 0)).norm(), 1e-15);
  EXPECT_NEAR(p.gap, 2.83, 1e-12);
  EXPECT_NEAR(p.zeta, total + 13.15, 1e-12);
  p = die->project({55, -60});
  EXPECT_NEAR(p.gap, -2.17, 1e-12);
  EXPECT_NEAR(p.zeta, total + 13.15, 1e-12);
}

TEST(ProfileProjection, ConvexCornerWedge) {
  const auto punch = make_profile(punch_pieces());
  // Outer wedge of the corner (2, 0): the corner is the nearest point, radial normal.
  const Projection p = punch->project({3, 1});
  EXPECT_LE((p.point - Vec2(2, 0)).norm(), 1e-15);
  EXPECT_LE((p.normal - Vec2(1, 1) / std::sqrt(2.0)).norm(), 1e-15);
  EXPECT_NEAR(p.gap, std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(p.zeta, 4.0, 1e-15);
  EXPECT_EQ(p.zeta_rate, 0.0);
  // At the corner itself: the mean of the two face normals, zero gap.
  const Projection at = punch->project({2, 0});
  expect_consistent(at, {2, 0});
  EXPECT_LE((at.normal - Vec2(1, 1) / std::sqrt(2.0)).norm(), 1e-15);
  EXPECT_EQ(at.gap, 0.0);
  EXPECT_EQ(at.zeta, 4.0);
  // Just off the corner along a face still lands on that face.
  const Projection face = punch->project({1.9, 0.5});
  EXPECT_LE((face.normal - Vec2(0, 1)).norm(), 1e-15);
  EXPECT_NEAR(face.zeta, 4.1, 1e-14);
}

TEST(ProfileProjection, ConcaveCornerFromInsideTheSolid) {
  const auto groove = make_profile(groove_pieces());
  // Below and right of the bottom corner (1, -2), inside the solid: the corner is nearest,
  // and the normal points from the query towards it (out of the solid).
  const Vec2 q(1.6, -2.8);
  const Projection p = groove->project(q);
  EXPECT_LE((p.point - Vec2(1, -2)).norm(), 1e-15);
  EXPECT_NEAR(p.gap, -1.0, 1e-15);
  EXPECT_LE((p.normal - Vec2(-0.6, 0.8)).norm(), 1e-15);
  EXPECT_NEAR(p.zeta, 5.0, 1e-15);
  // In the free groove near that corner the nearer wall wins.
  const Projection free = groove->project({0.9, -1.7});
  EXPECT_LE((free.normal - Vec2(-1, 0)).norm(), 1e-15);
  EXPECT_NEAR(free.gap, 0.1, 1e-14);
}

TEST(ProfileProjection, HugeAndDegenerateQueriesStayFinite) {
  for (const auto& pieces : {die_pieces(), punch_pieces(), groove_pieces(), bowl_pieces(), nose_pieces()}) {
    const auto obstacle = make_profile(pieces);
    for (const Vec2& q : {Vec2(1e300, -1e300), Vec2(-1e306, 3e305), Vec2(0, 0), Vec2(59.18, -6.85), Vec2(1e-320, 0)})
      expect_consistent(obstacle->project(q), q);
  }
  // The centre of an arc: every point of the arc is equally near.
  const auto nose = make_profile(nose_pieces());
  const Projection p = nose->project({0, 0});
  expect_consistent(p, {0, 0});
  EXPECT_NEAR(p.gap, -1.0, 1e-15);
}

TEST(ProfileZeta, ContinuousAcrossJointsAndCumulative) {
  const auto die = make_profile(die_pieces());
  struct Joint {
    Vec2 point, normal, tangent;
    double zeta;
  };
  const Joint joints[] = {{{59.18, -0.5}, {0, 1}, {-1, 0}, 40.0}, {{52.83, -6.85}, {-1, 0}, {0, -1}, kDieShoulderEnd}};
  for (const Joint& j : joints) {
    for (const double offset : {0.0, 0.3, -0.3}) {
      const Vec2 on = j.point + offset * j.normal;
      const double before = die->project(on - 1e-7 * j.tangent).zeta;
      const double after = die->project(on + 1e-7 * j.tangent).zeta;
      EXPECT_NEAR(die->project(on).zeta, j.zeta, 1e-12);
      EXPECT_LT(before, j.zeta);
      EXPECT_GT(after, j.zeta);
      EXPECT_NEAR(before, j.zeta, 2e-7);
      EXPECT_NEAR(after, j.zeta, 2e-7);
    }
  }
  // The groove's joints are corners: zeta is the cumulative length 3, 5, 7, 9 at them,
  // and stays continuous through the corner wedges.
  const auto groove = make_profile(groove_pieces());
  EXPECT_NEAR(groove->project({0.5, 0.5}).zeta, 3.0, 1e-15);                // wedge of the lip (1, 0)
  EXPECT_NEAR(groove->project({1.5, -2.5}).zeta, 5.0, 1e-15);               // reflex side of (1, -2)
  EXPECT_NEAR(groove->project({-1.5, -2.5}).zeta, 7.0, 1e-15);              // reflex side of (-1, -2)
  EXPECT_NEAR(groove->project({-0.5, 0.5}).zeta, 9.0, 1e-15);               // wedge of the lip (-1, 0)
  EXPECT_NEAR(groove->project({1.0 + 1e-9, 0.5}).zeta, 3.0 - 1e-9, 1e-14);  // top face
  EXPECT_NEAR(groove->project({1.0 - 1e-9, 0.5}).zeta, 3.0, 1e-14);         // wedge
  EXPECT_NEAR(groove->project({0.5, -1e-9}).zeta, 3.0 + 1e-9, 1e-14);       // wall, free side
  // Sweeping round the convex lip (1, 0) from the top face, over the wedge and down the wall,
  // zeta never jumps.
  double previous = groove->project({1.3, 0.0}).zeta;
  for (double angle = 0; angle <= 1.5 * kPi; angle += 0.01) {
    const double zeta = groove->project(Vec2(1, 0) + 0.3 * Vec2(std::cos(angle), std::sin(angle))).zeta;
    EXPECT_NEAR(zeta, previous, 0.004);
    previous = zeta;
  }
}

TEST(ProfileDerivatives, MatchFiniteDifferences) {
  const auto die = make_profile(die_pieces());
  const Vec2 c(59.18, -6.85);
  for (const Vec2& q : {Vec2(80, 3),                                         // segment, outside
                        Vec2(75, -4),                                        // segment, inside
                        Vec2(c + 8.0 * Vec2(std::cos(2.0), std::sin(2.0))),  // convex arc, outside
                        Vec2(c + 4.0 * Vec2(std::cos(2.5), std::sin(2.5))),  // convex arc, inside
                        Vec2(120, 2), Vec2(49, -70)})                        // extensions
    expect_derivatives_match(*die, q);

  const auto bowl = make_profile(bowl_pieces());
  for (const Vec2& q : {Vec2(0.3, -1.2), Vec2(-0.8, -0.4),   // concave arc, free side
                        Vec2(0.9, -2.7), Vec2(-2.5, -1.0)})  // concave arc, in the solid
    expect_derivatives_match(*bowl, q);
  // Concave: dnormal = (I - n n^T) / (gap - R), zeta_rate = R / (R - gap).
  const Projection p = bowl->project({0, -0.5});
  EXPECT_NEAR(p.gap, 1.5, 1e-15);
  EXPECT_NEAR(p.zeta_rate, 2.0 / 0.5, 1e-13);
  EXPECT_NEAR(p.dnormal_dx(0, 0), 1.0 / (1.5 - 2.0), 1e-13);

  const auto punch = make_profile(punch_pieces());
  expect_derivatives_match(*punch, {2.7, 0.4});   // convex corner wedge
  expect_derivatives_match(*punch, {-2.2, 1.3});  // the other corner
  const auto groove = make_profile(groove_pieces());
  expect_derivatives_match(*groove, {1.6, -2.8});  // concave corner, from inside the solid
  expect_derivatives_match(*groove, {0.7, -1.5});  // wall of the groove
}

TEST(ProfileValidation, RejectsBadPieces) {
  const auto message_of = [](const std::vector<ProfilePiece>& pieces) -> std::string {
    try {
      make_profile(pieces);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no exception";
  };
  // A gap between pieces 1 and 2 names piece 2.
  const std::string gap =
      message_of({SegmentPiece{{0, 0}, {1, 0}}, SegmentPiece{{1, 0}, {1, 1}}, SegmentPiece{{1, 1.001}, {0, 1}}});
  EXPECT_NE(gap.find("piece 2"), std::string::npos) << gap;
  EXPECT_NE(message_of({SegmentPiece{{0, 0}, {0, 0}}}).find("piece 0"), std::string::npos);
  EXPECT_NE(message_of({SegmentPiece{{0, 0}, {1, 0}}, ArcPiece{{1, 1}, 0.0, -kPi / 2, 0}}).find("piece 1"),
            std::string::npos);
  EXPECT_THROW(make_profile({ArcPiece{{0, 0}, -1.0, 0, 1}}), std::invalid_argument);
  EXPECT_THROW(make_profile({ArcPiece{{0, 0}, 1.0, 0.5, 0.5}}), std::invalid_argument);
  EXPECT_THROW(make_profile({ArcPiece{{0, 0}, 1.0, 0, 7}}), std::invalid_argument);
  EXPECT_THROW(make_profile({}), std::invalid_argument);
  EXPECT_THROW(make_profile({SegmentPiece{{0, 0}, {std::nan(""), 0}}}), std::invalid_argument);
  // Joints closer than the tolerance (1e-9 of the size) are accepted.
  EXPECT_NO_THROW(make_profile({SegmentPiece{{0, 0}, {100, 0}}, SegmentPiece{{100, 1e-8}, {100, 50}}}));
  EXPECT_THROW(make_profile({SegmentPiece{{0, 0}, {100, 0}}, SegmentPiece{{100, 1e-6}, {100, 50}}}),
               std::invalid_argument);
  EXPECT_NO_THROW(make_profile(die_pieces()));
}

}  // namespace
}  // namespace grip
