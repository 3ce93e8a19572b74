#include "solver/io/quantities.hpp"

#include <algorithm>
#include <cmath>

#include "solver/contact/contact_error.hpp"

namespace grip {
namespace {

// A candidate of one obstacle as a zone measure sees it.
struct ZonePoint {
  double zeta = 0.0;  // along the obstacle: the order of the points
  Vec2 X;             // reference position: lengths are measured on the undeformed surface
  double f = 0.0;     // vanishes like a square root at the zone's end
  bool in = false;
};

// Beyond the last node `last` of a zone (prev: the node before it inside, -1 if none), toward
// `beyond` outside: where f^2, linear through prev and last, vanishes, at most at `beyond`;
// halfway where f does not fall toward the end.
double zone_end(const std::vector<ZonePoint>& pts, int last, int prev, int beyond) {
  const double gap = (pts[beyond].X - pts[last].X).norm();
  const double fl = pts[last].f * pts[last].f;
  if (prev < 0) return 0.5 * gap;
  const double fp = pts[prev].f * pts[prev].f;
  if (!(fp > fl)) return 0.5 * gap;
  return std::clamp(fl * (pts[last].X - pts[prev].X).norm() / (fp - fl), 0.0, gap);
}

// The total length of the zones (ZonePoint::in) along the points; a closed obstacle's list
// wraps around.
double zone_length(std::vector<ZonePoint> pts, bool closed) {
  std::sort(pts.begin(), pts.end(), [](const ZonePoint& a, const ZonePoint& b) { return a.zeta < b.zeta; });
  const int n = static_cast<int>(pts.size());
  if (n == 0) return 0.0;
  if (closed) {
    const auto out = std::find_if(pts.begin(), pts.end(), [](const ZonePoint& p) { return !p.in; });
    if (out == pts.end()) {  // in contact all around
      double length = 0.0;
      for (int k = 0; k < n; ++k) length += (pts[(k + 1) % n].X - pts[k].X).norm();
      return length;
    }
    std::rotate(pts.begin(), out, pts.end());  // a zone across the seam becomes one run
  }
  double length = 0.0;
  for (int lo = 0; lo < n;) {
    if (!pts[lo].in) {
      ++lo;
      continue;
    }
    int hi = lo;
    while (hi + 1 < n && pts[hi + 1].in) ++hi;
    for (int k = lo + 1; k <= hi; ++k) length += (pts[k].X - pts[k - 1].X).norm();
    const int after = hi + 1 < n ? hi + 1 : (closed ? 0 : -1);
    if (after >= 0) length += zone_end(pts, hi, hi > lo ? hi - 1 : -1, after);
    if (lo > 0) length += zone_end(pts, lo, hi > lo ? lo + 1 : -1, lo - 1);
    lo = hi + 1;
  }
  return length;
}

double zone_width(const Problem& problem, const StepRecord& rec, int obstacle, bool stick) {
  const Body& body = *problem.body;
  const ObstacleInstance& o = problem.obstacles[obstacle];
  std::vector<ZonePoint> pts;
  const size_t count = std::min(problem.candidates.size(), rec.state.points.size());
  for (size_t i = 0; i < count; ++i) {
    const Candidate& c = problem.candidates[i];
    if (c.obstacle != obstacle) continue;
    const double area = body.tributary_area(c.site);
    const double p_n = rec.p[c.eta], p_t = c.xi >= 0 ? rec.p[c.xi] : 0.0;
    ZonePoint z{rec.state.points[i].projection.zeta, body.site_reference(c.site), 0.0, false};
    if (stick) {
      z.in = contact_state(problem, i, rec.p, rec.tau) == ContactState::stick;
      z.f = (o.friction * std::abs(p_n) - std::abs(p_t)) / area;
    } else {
      z.in = p_n < 0;
      z.f = p_n / area;
    }
    pts.push_back(z);
  }
  return zone_length(std::move(pts), o.shape && o.shape->period() > 0);
}

}  // namespace

double quantity_value(const Problem& problem, const StepRecord& rec, const Quantity& q) {
  const Body& body = *problem.body;
  const size_t count = std::min(problem.candidates.size(), rec.state.points.size());
  switch (q.kind) {
    case QuantityKind::reaction:
    case QuantityKind::displacement: {
      const Vector& v = q.kind == QuantityKind::reaction ? rec.reactions : rec.state.q;
      double sum = 0.0;
      for (const auto& [dof, weight] : q.dofs)
        if (dof < v.size()) sum += weight * v[dof];
      return sum;
    }
    case QuantityKind::resultant: {
      double sum = 0.0;
      for (size_t i = 0; i < count; ++i) {
        const Candidate& c = problem.candidates[i];
        if (q.obstacle >= 0 && c.obstacle != q.obstacle) continue;
        const PairedPoint& pp = rec.state.points[i];
        sum += rec.p[c.eta] * pp.eta[q.component] + (c.xi >= 0 ? rec.p[c.xi] * pp.xi[q.component] : 0.0);
      }
      return sum;
    }
    case QuantityKind::peak_pressure: {
      double peak = 0.0;
      for (size_t i = 0; i < count; ++i) {
        const Candidate& c = problem.candidates[i];
        if (q.obstacle >= 0 && c.obstacle != q.obstacle) continue;
        peak = std::max(peak, -rec.p[c.eta] / body.tributary_area(c.site));
      }
      return peak;
    }
    case QuantityKind::contact_width:
      return zone_width(problem, rec, q.obstacle, false);
    case QuantityKind::stick_width:
      return zone_width(problem, rec, q.obstacle, true);
    case QuantityKind::field: {
      const FieldTable& t = rec.element_fields;
      if (q.element < static_cast<int>(t.rows.size()) && q.column < static_cast<int>(t.rows[q.element].size()))
        return t.rows[q.element][q.column];
      return 0.0;  // not recorded: the reader asks for every step's fields
    }
  }
  return 0.0;
}

nlohmann::json quantity_values(const Problem& problem, const StepRecord& rec, const std::vector<Quantity>& quantities) {
  if (!rec.converged) return nullptr;
  nlohmann::json values = nlohmann::json::object();
  for (const Quantity& q : quantities) values[q.name] = quantity_value(problem, rec, q);
  return values;
}

}  // namespace grip
