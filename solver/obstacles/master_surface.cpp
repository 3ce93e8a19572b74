#include "solver/obstacles/master_surface.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace grip {

MasterSurface make_master_surface(const Body& body, int body_index, const std::vector<std::array<int, 2>>& segments) {
  MasterSurface m;
  m.body = body_index;
  std::map<int, int> next;  // site -> the segment starting there
  std::map<int, int> ends;  // site -> how many segments end there
  for (size_t k = 0; k < segments.size(); ++k) {
    next[segments[k][0]] = static_cast<int>(k);
    ++ends[segments[k][1]];
  }
  std::vector<char> used(segments.size(), 0);
  auto follow = [&](size_t first) {
    std::vector<int> chain{segments[first][0]};
    for (size_t k = first; k < segments.size() && !used[k];) {
      used[k] = 1;
      chain.push_back(segments[k][1]);
      const auto it = next.find(segments[k][1]);
      k = it == next.end() ? segments.size() : static_cast<size_t>(it->second);
    }
    m.chains.push_back(chain);
  };
  for (size_t k = 0; k < segments.size(); ++k)
    if (!used[k] && !ends.count(segments[k][0])) follow(k);
  for (size_t k = 0; k < segments.size(); ++k)
    if (!used[k]) follow(k);  // closed loops
  double zeta = 0.0;
  for (const auto& chain : m.chains) {
    std::vector<double> z{zeta};
    for (size_t i = 1; i < chain.size(); ++i)
      z.push_back(zeta += (body.site_reference(chain[i]) - body.site_reference(chain[i - 1])).norm());
    m.reference_zeta.push_back(z);
  }
  return m;
}

DeformedMaster::DeformedMaster(const Body& body, const Vector& q, const MasterSurface& surface) {
  for (size_t c = 0; c < surface.chains.size(); ++c) {
    Chain chain;
    chain.reference = &surface.reference_zeta[c];
    std::vector<ProfilePiece> pieces;
    chain.zeta.push_back(0.0);
    for (int site : surface.chains[c]) {
      chain.points.push_back(body.surface_point(q, site, 0));
      const size_t n = chain.points.size();
      if (n < 2) continue;
      const Vec2 a = chain.points[n - 2].x, b = chain.points[n - 1].x;
      pieces.push_back(SegmentPiece{a, b});
      chain.zeta.push_back(chain.zeta.back() + (b - a).norm());
    }
    const size_t n = chain.points.size();
    chain.normal.assign(n, Vec2::Zero());
    for (size_t k = 0; k + 1 < n; ++k) {  // outward: to the right of the direction of travel
      const Vec2 side = -rot90((chain.points[k + 1].x - chain.points[k].x).normalized());
      chain.normal[k] += side;
      chain.normal[k + 1] += side;
    }
    for (Vec2& normal : chain.normal) normal.normalize();
    chain.profile = make_profile(std::move(pieces));
    chains_.push_back(std::move(chain));
  }
}

MasterPoint DeformedMaster::project(const Vec2& x) const {
  MasterPoint best;
  const Chain* on = nullptr;
  for (const Chain& chain : chains_) {
    const Projection p = chain.profile->project(x);
    if (!on || std::abs(p.gap) < std::abs(best.projection.gap)) {
      best.projection = p;
      on = &chain;
    }
  }
  // The segment the point lies on (the end segments for the extensions beyond the ends), and
  // its parameter t along it, unclamped there: the extension moves with the end segment.
  const std::vector<double>& z = on->zeta;
  const double zeta = best.projection.zeta;
  const size_t k = std::clamp<size_t>(std::upper_bound(z.begin(), z.end(), zeta) - z.begin(), 1, z.size() - 1) - 1;
  const double length = z[k + 1] - z[k], t = (zeta - z[k]) / length;
  Projection& p = best.projection;
  const double along = std::clamp(t, 0.0, 1.0);
  p.normal = ((1 - along) * on->normal[k] + along * on->normal[k + 1]).normalized();
  p.tangent = rot90(p.normal);
  p.gap = (x - p.point).dot(p.normal);
  p.dnormal_dx = Mat2::Zero();
  const std::vector<double>& ref = *on->reference;
  best.projection.zeta = ref[k] + t * (ref[k + 1] - ref[k]);
  best.projection.zeta_rate *= (ref[k + 1] - ref[k]) / length;
  for (const auto& j : on->points[k].jacobian) best.jacobian.push_back({j.dof, -(1 - t) * j.dx});
  for (const auto& j : on->points[k + 1].jacobian) best.jacobian.push_back({j.dof, -t * j.dx});
  return best;
}

}  // namespace grip
