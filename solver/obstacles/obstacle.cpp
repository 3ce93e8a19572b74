#include "solver/obstacles/obstacle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>

namespace grip {

double Obstacle::smallest_radius() const { return std::numeric_limits<double>::infinity(); }

double Obstacle::zeta_difference(double zeta1, double zeta0) const {
  const double diff = zeta1 - zeta0;
  const double p = period();
  if (!(p > 0.0)) return diff;
  double r = std::remainder(diff, p);  // exact, in [-p/2, p/2]
  if (r <= -0.5 * p) r += p;           // a half-turn counts as +p/2
  return r;
}

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
// Below this fraction of the size of the obstacle, a direction x - c is rounding noise.
constexpr double kTiny = 1e-12;
// Consecutive pieces must meet within this fraction of the size of the profile.
constexpr double kJointTolerance = 1e-9;
// Normals turning by less than this (radians) at a joint make a smooth joint, not a corner.
constexpr double kSmoothTurn = 1e-9;

// Overflow-safe length, so that a huge query never produces Inf.
double safe_norm(const Vec2& v) { return std::hypot(v.x(), v.y()); }

Mat2 tangential_projector(const Vec2& n) { return Mat2::Identity() - n * n.transpose(); }

Vec2 unit_at(double angle) { return {std::cos(angle), std::sin(angle)}; }

// Outward normal of a straight piece running along the unit direction t (solid on the left).
Vec2 normal_of_direction(const Vec2& t) { return {t.y(), -t.x()}; }

Projection straight_projection(const Vec2& point, const Vec2& normal, double gap, double zeta) {
  Projection p;
  p.point = point;
  p.normal = normal;
  p.tangent = rot90(normal);
  p.gap = gap;
  p.zeta = zeta;
  p.dnormal_dx = Mat2::Zero();
  p.zeta_rate = 1.0;
  return p;
}

class Circle final : public Obstacle {
 public:
  Circle(Vec2 centre, double radius) : centre_(centre), radius_(radius) {}

  Projection project(const Vec2& x) const override {
    Projection p;
    const Vec2 r = x - centre_;
    const double d = safe_norm(r);
    if (d <= kTiny * radius_) {
      // At the centre every surface point is nearest: take +y; the derivatives do not exist.
      p.normal = Vec2::UnitY();
      p.point = centre_ + radius_ * p.normal;
      p.gap = (x - p.point).dot(p.normal);
      p.dnormal_dx = Mat2::Zero();
      p.zeta_rate = 0.0;
    } else {
      p.normal = r / d;
      p.point = centre_ + radius_ * p.normal;
      p.gap = d - radius_;
      p.dnormal_dx = tangential_projector(p.normal) / d;
      p.zeta_rate = radius_ / d;
    }
    p.tangent = rot90(p.normal);
    p.zeta = radius_ * std::atan2(p.normal.y(), p.normal.x());
    return p;
  }

  double period() const override { return kTwoPi * radius_; }

  double smallest_radius() const override { return radius_; }

 private:
  Vec2 centre_;
  double radius_;
};

// A piece of a profile, segment or arc, with its place along the chain.
struct Piece {
  bool arc = false;
  Vec2 start = Vec2::Zero(), end = Vec2::Zero();
  Vec2 direction = Vec2::UnitX();  // segment: unit direction of travel
  Vec2 centre = Vec2::Zero();      // arc only
  double radius = 0.0;
  double from_angle = 0.0;
  double turn = 1.0;  // +1 counter-clockwise (convex), -1 clockwise (concave)
  double span = 0.0;  // |to_angle - from_angle|
  double length = 0.0;
  double zeta0 = 0.0;

  Vec2 normal_at_start() const { return arc ? Vec2(turn * unit_at(from_angle)) : normal_of_direction(direction); }
  Vec2 normal_at_end() const {
    return arc ? Vec2(turn * unit_at(from_angle + turn * span)) : normal_of_direction(direction);
  }

  // Projection onto this piece if the foot of the perpendicular from x lies on it (within tol).
  std::optional<Projection> project(const Vec2& x, double tol) const {
    if (!arc) {
      const Vec2 r = x - start;
      const double s = r.dot(direction);
      if (s < -tol || s > length + tol) return std::nullopt;
      const Vec2 n = normal_of_direction(direction);
      return straight_projection(start + s * direction, n, r.dot(n), zeta0 + s);
    }
    const Vec2 r = x - centre;
    const double d = safe_norm(r);
    Projection p;
    if (d <= kTiny * radius) {
      // At the centre the whole arc is equally near: take its middle; no derivatives there.
      const Vec2 u = unit_at(from_angle + 0.5 * turn * span);
      p.normal = turn * u;
      p.point = centre + radius * u;
      p.gap = (x - p.point).dot(p.normal);
      p.zeta = zeta0 + 0.5 * length;
      p.dnormal_dx = Mat2::Zero();
      p.zeta_rate = 0.0;
    } else {
      // Angle travelled from the start, in [0, 2 pi), or slightly negative just before the start.
      double phi = turn * (std::atan2(r.y(), r.x()) - from_angle);
      phi -= kTwoPi * std::floor(phi / kTwoPi);
      const double tol_angle = tol / radius;
      if (phi > kTwoPi - tol_angle) phi -= kTwoPi;
      if (phi > span + tol_angle) return std::nullopt;
      const Vec2 u = r / d;
      p.normal = turn * u;
      p.point = centre + radius * u;
      p.gap = turn * (d - radius);
      p.zeta = zeta0 + radius * phi;
      // Concave (turn = -1): -(I - n n^T) / (radius - gap), the centre lies outside the solid.
      p.dnormal_dx = turn * tangential_projector(u) / d;
      p.zeta_rate = radius / d;
    }
    p.tangent = rot90(p.normal);
    return p;
  }
};

// A joint between two pieces (or a piece and an end extension).
struct Vertex {
  Vec2 position = Vec2::Zero();
  Vec2 mean_normal = Vec2::UnitY();  // bisector of the normals on either side
  double zeta = 0.0;
  bool corner = false;
};

// The straight continuation of the surface beyond an open end.
struct Extension {
  Vec2 origin = Vec2::Zero();
  Vec2 outward = Vec2::UnitX();  // direction away from the profile
  Vec2 normal = Vec2::UnitY();
  double zeta0 = 0.0;
  double zeta_sign = 1.0;  // zeta grows along outward at the end, falls at the start

  std::optional<Projection> project(const Vec2& x, double tol) const {
    const Vec2 r = x - origin;
    const double s = r.dot(outward);
    if (s < -tol) return std::nullopt;
    return straight_projection(origin + s * outward, normal, r.dot(normal), zeta0 + zeta_sign * s);
  }
};

std::invalid_argument piece_error(std::size_t index, const std::string& what) {
  return std::invalid_argument("make_profile: piece " + std::to_string(index) + " " + what);
}

Piece make_piece(const ProfilePiece& input, std::size_t index) {
  Piece p;
  if (const auto* s = std::get_if<SegmentPiece>(&input)) {
    if (!s->from.allFinite() || !s->to.allFinite()) throw piece_error(index, "has a non-finite point");
    p.start = s->from;
    p.end = s->to;
    p.length = safe_norm(s->to - s->from);
    if (p.length > 0.0) p.direction = (s->to - s->from) / p.length;
    return p;
  }
  const auto& a = std::get<ArcPiece>(input);
  if (!a.centre.allFinite() || !std::isfinite(a.radius) || !std::isfinite(a.from_angle) || !std::isfinite(a.to_angle))
    throw piece_error(index, "has a non-finite value");
  if (!(a.radius > 0.0)) throw piece_error(index, "has a non-positive radius");
  p.arc = true;
  p.centre = a.centre;
  p.radius = a.radius;
  p.from_angle = a.from_angle;
  p.turn = a.to_angle >= a.from_angle ? 1.0 : -1.0;
  p.span = std::abs(a.to_angle - a.from_angle);
  if (p.span > kTwoPi * (1.0 + kTiny)) throw piece_error(index, "turns through more than a full circle");
  p.length = a.radius * p.span;
  p.start = a.centre + a.radius * unit_at(a.from_angle);
  p.end = a.centre + a.radius * unit_at(a.to_angle);
  return p;
}

class Profile final : public Obstacle {
 public:
  Profile(const std::vector<ProfilePiece>& input, bool closed) : closed_(closed) {
    if (input.empty()) throw std::invalid_argument("make_profile: a profile needs at least one piece");
    for (std::size_t i = 0; i < input.size(); ++i) pieces_.push_back(make_piece(input[i], i));

    // Size scale for the tolerances: coordinates, lengths and radii.
    scale_ = 0.0;
    for (const Piece& p : pieces_) {
      scale_ = std::max({scale_, p.start.cwiseAbs().maxCoeff(), p.end.cwiseAbs().maxCoeff(), p.length, p.radius});
    }
    for (std::size_t i = 0; i < pieces_.size(); ++i) {
      if (!(pieces_[i].length > kTiny * scale_)) throw piece_error(i, "has zero length");
      if (i > 0 && safe_norm(pieces_[i].start - pieces_[i - 1].end) > kJointTolerance * scale_)
        throw piece_error(i, "does not start where piece " + std::to_string(i - 1) + " ends");
    }
    if (closed_ && safe_norm(pieces_.front().start - pieces_.back().end) > kJointTolerance * scale_)
      throw piece_error(pieces_.size() - 1, "does not end where piece 0 starts (a closed profile)");

    double zeta = 0.0;
    for (std::size_t i = 0; i < pieces_.size(); ++i) {
      Piece& p = pieces_[i];
      p.zeta0 = zeta;
      const Vec2 before = i > 0     ? pieces_[i - 1].normal_at_end()
                          : closed_ ? pieces_.back().normal_at_end()
                                    : p.normal_at_start();
      vertices_.push_back(make_vertex(p.start, before, p.normal_at_start(), zeta));
      zeta += p.length;
    }
    const Piece& last = pieces_.back();
    vertices_.push_back(make_vertex(last.end, last.normal_at_end(),
                                    closed_ ? pieces_.front().normal_at_start() : last.normal_at_end(), zeta));
    length_ = zeta;

    const Vec2 n0 = pieces_.front().normal_at_start();
    start_ = Extension{pieces_.front().start, -rot90(n0), n0, 0.0, -1.0};
    const Vec2 n1 = last.normal_at_end();
    end_ = Extension{last.end, rot90(n1), n1, zeta, 1.0};
  }

  double period() const override { return closed_ ? length_ : 0.0; }

  double smallest_radius() const override {
    double r = std::numeric_limits<double>::infinity();
    for (const Piece& p : pieces_)
      if (p.arc) r = std::min(r, p.radius);
    return r;
  }

  Projection project(const Vec2& x) const override {
    // At a corner the nearest direction is undefined: use the bisecting normal.
    for (const Vertex& v : vertices_) {
      if (v.corner && safe_norm(x - v.position) <= kTiny * scale_) {
        Projection p = straight_projection(v.position, v.mean_normal, (x - v.position).dot(v.mean_normal), v.zeta);
        p.zeta_rate = 0.0;
        return p;
      }
    }

    // Nearest feature by unsigned distance. On a tie a piece wins over a vertex (the vertex is
    // then the end of the piece's foot range, and the piece carries the right derivatives).
    const double tol = kTiny * scale_;
    std::optional<Projection> best;
    double best_distance = std::numeric_limits<double>::infinity();
    const auto consider = [&](const std::optional<Projection>& p) {
      if (p && (!best || std::abs(p->gap) < best_distance)) {
        best = p;
        best_distance = std::abs(p->gap);
      }
    };
    if (!closed_) consider(start_.project(x, tol));
    for (const Piece& piece : pieces_) consider(piece.project(x, tol));
    if (!closed_) consider(end_.project(x, tol));
    for (const Vertex& v : vertices_) {
      const double d = safe_norm(x - v.position);
      if (!best || d < best_distance) {
        best = vertex_projection(v, x, d);
        best_distance = d;
      }
    }
    return *best;
  }

 private:
  static Vertex make_vertex(const Vec2& position, const Vec2& before, const Vec2& after, double zeta) {
    Vertex v;
    v.position = position;
    v.zeta = zeta;
    const double turn = std::atan2(before.x() * after.y() - before.y() * after.x(), before.dot(after));
    v.corner = std::abs(turn) > kSmoothTurn;
    const Vec2 sum = before + after;
    // A cusp (the chain doubles back) is a needle tip pointing along the incoming tangent.
    v.mean_normal = safe_norm(sum) > kTiny ? Vec2(sum / safe_norm(sum)) : Vec2(rot90(before));
    return v;
  }

  // The vertex as a zero-radius arc: convex (x outside) or concave (x inside the solid).
  Projection vertex_projection(const Vertex& v, const Vec2& x, double d) const {
    const Vec2 r = x - v.position;
    if (d <= kTiny * scale_) {
      Projection p = straight_projection(v.position, v.mean_normal, r.dot(v.mean_normal), v.zeta);
      p.zeta_rate = v.corner ? 0.0 : 1.0;
      return p;
    }
    const double side = r.dot(v.mean_normal) >= 0.0 ? 1.0 : -1.0;
    Projection p;
    p.point = v.position;
    p.normal = side * r / d;
    p.tangent = rot90(p.normal);
    p.gap = side * d;
    p.zeta = v.zeta;
    p.dnormal_dx = tangential_projector(p.normal) / p.gap;
    p.zeta_rate = 0.0;
    return p;
  }

  std::vector<Piece> pieces_;
  std::vector<Vertex> vertices_;  // pieces_.size() + 1: start, joints, end
  Extension start_, end_;
  double scale_ = 1.0;
  bool closed_ = false;
  double length_ = 0.0;
};

}  // namespace

std::unique_ptr<Obstacle> make_circle(Vec2 centre, double radius) {
  if (!centre.allFinite()) throw std::invalid_argument("make_circle: non-finite centre");
  if (!std::isfinite(radius) || !(radius > 0.0)) throw std::invalid_argument("make_circle: non-positive radius");
  return std::make_unique<Circle>(centre, radius);
}

std::unique_ptr<Obstacle> make_profile(std::vector<ProfilePiece> pieces, bool closed) {
  return std::make_unique<Profile>(pieces, closed);
}

}  // namespace grip
