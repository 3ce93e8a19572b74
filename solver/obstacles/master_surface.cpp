#include "solver/obstacles/master_surface.hpp"

#include <algorithm>
#include <cmath>

namespace grip {

namespace {

// The runs through the given segments ([a, b], body on the left of a -> b), each followed from
// a segment that no other segment ends at, then the closed loops.
std::vector<std::vector<int>> chains_of(const std::vector<std::array<int, 2>>& segments) {
  std::map<int, int> next;  // site -> the segment starting there
  std::map<int, int> ends;  // site -> how many segments end there
  for (size_t k = 0; k < segments.size(); ++k) {
    next[segments[k][0]] = static_cast<int>(k);
    ++ends[segments[k][1]];
  }
  std::vector<std::vector<int>> chains;
  std::vector<char> used(segments.size(), 0);
  auto follow = [&](size_t first) {
    std::vector<int> chain{segments[first][0]};
    for (size_t k = first; k < segments.size() && !used[k];) {
      used[k] = 1;
      chain.push_back(segments[k][1]);
      const auto it = next.find(segments[k][1]);
      k = it == next.end() ? segments.size() : static_cast<size_t>(it->second);
    }
    chains.push_back(chain);
  };
  for (size_t k = 0; k < segments.size(); ++k)
    if (!used[k] && !ends.count(segments[k][0])) follow(k);
  for (size_t k = 0; k < segments.size(); ++k)
    if (!used[k]) follow(k);
  return chains;
}

}  // namespace

MasterSurface make_master_surface(const Body& body, int body_index, const std::vector<std::array<int, 2>>& segments,
                                  const std::vector<std::array<int, 2>>& slave_segments, int side, int slave_side) {
  MasterSurface m;
  m.body = body_index;
  m.side = side;
  m.slave_side = slave_side;
  m.chains = chains_of(segments);
  m.slave_chains = chains_of(slave_segments);
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
      chain.points.push_back(body.surface_point(q, site, surface.side));
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
  integrate_mortar(body, q, surface);
}

DeformedMaster::Closest DeformedMaster::closest(const Vec2& x) const {
  Closest best;
  for (size_t c = 0; c < chains_.size(); ++c) {
    const Projection p = chains_[c].profile->project(x);
    if (c == 0 || std::abs(p.gap) < std::abs(best.projection.gap)) {
      best.projection = p;
      best.chain = static_cast<int>(c);
    }
  }
  // The segment the point lies on (the end segments for the extensions beyond the ends), and
  // its parameter t along it, unclamped there: the extension moves with the end segment.
  const std::vector<double>& z = chains_[best.chain].zeta;
  const double zeta = best.projection.zeta;
  const size_t k = std::clamp<size_t>(std::upper_bound(z.begin(), z.end(), zeta) - z.begin(), 1, z.size() - 1) - 1;
  best.segment = static_cast<int>(k);
  best.t = (zeta - z[k]) / (z[k + 1] - z[k]);
  return best;
}

void DeformedMaster::integrate_mortar(const Body& body, const Vector& q, const MasterSurface& surface) {
  std::map<int, double> tributary;                          // D_j
  std::map<int, std::map<std::array<int, 2>, double>> m;  // M_jk, k as (chain, index)
  const double gauss = 1.0 / std::sqrt(3.0);
  for (const std::vector<int>& slave : surface.slave_chains) {
    std::vector<Vec2> x;
    for (int site : slave) x.push_back(body.surface_point(q, site, surface.slave_side).x);
    for (size_t e = 0; e + 1 < slave.size(); ++e) {
      const Vec2 a = x[e], b = x[e + 1];
      const double length = (b - a).norm();
      if (!(length > 0)) continue;
      const Vec2 along = (b - a) / length;
      tributary[slave[e]] += 0.5 * length;
      tributary[slave[e + 1]] += 0.5 * length;
      const Closest from = closest(a), to = closest(b);
      if (from.chain != to.chain) continue;
      const Chain& chain = chains_[from.chain];
      const int last = static_cast<int>(chain.points.size()) - 2;
      // The master segments between the ends' closest points, and one more on either side:
      // each is cut to the part of the slave segment its ends project onto (along its normal).
      for (int k = std::max(0, std::min(from.segment, to.segment) - 1);
           k <= std::min(last, std::max(from.segment, to.segment) + 1); ++k) {
        const double xp = (chain.points[k].x - a).dot(along) / length;
        const double xq = (chain.points[k + 1].x - a).dot(along) / length;
        const double lo = std::max(0.0, std::min(xp, xq)), hi = std::min(1.0, std::max(xp, xq));
        if (!(hi > lo) || std::abs(xq - xp) < 1e-12) continue;
        for (double g : {-gauss, gauss}) {
          const double xi = 0.5 * (lo + hi) + 0.5 * g * (hi - lo), weight = 0.5 * (hi - lo) * length;
          const double t = (xi - xp) / (xq - xp);
          const double psi_a = 2 - 3 * xi, psi_b = 3 * xi - 1;  // the dual basis on the segment
          m[slave[e]][{from.chain, k}] += psi_a * (1 - t) * weight;
          m[slave[e]][{from.chain, k + 1}] += psi_a * t * weight;
          m[slave[e + 1]][{from.chain, k}] += psi_b * (1 - t) * weight;
          m[slave[e + 1]][{from.chain, k + 1}] += psi_b * t * weight;
        }
      }
    }
  }
  for (const auto& [site, row] : m) {
    double covered = 0.0;  // int psi_j over the part of its slave segments that the master covers
    for (const auto& entry : row) covered += entry.second;
    if (covered < 0.5 * tributary[site]) continue;
    auto& weights = mortar_[site];
    for (const auto& [k, value] : row) weights.push_back({k, value / covered});
  }
}

MasterPoint DeformedMaster::project(const Vec2& x, int slave_site) const {
  const Closest c = closest(x);
  const Chain& on = chains_[c.chain];
  const size_t k = c.segment;
  const double t = c.t, along = std::clamp(t, 0.0, 1.0), length = on.zeta[k + 1] - on.zeta[k];
  const std::vector<double>& ref = *on.reference;
  MasterPoint best;
  Projection& p = best.projection;
  p = c.projection;
  p.normal = ((1 - along) * on.normal[k] + along * on.normal[k + 1]).normalized();
  p.tangent = rot90(p.normal);
  p.dnormal_dx = Mat2::Zero();
  p.zeta_rate *= (ref[k + 1] - ref[k]) / length;
  const auto mortar = mortar_.find(slave_site);
  if (mortar != mortar_.end()) {  // the mortar point sum_k w_k x_k
    p.point = Vec2::Zero();
    p.zeta = 0.0;
    for (const auto& [at, w] : mortar->second) {
      const SurfacePoint& sp = chains_[at[0]].points[at[1]];
      p.point += w * sp.x;
      p.zeta += w * (*chains_[at[0]].reference)[at[1]];
      for (const auto& j : sp.jacobian) best.jacobian.push_back({j.dof, -w * j.dx});
    }
  } else {
    p.zeta = ref[k] + t * (ref[k + 1] - ref[k]);
    for (const auto& j : on.points[k].jacobian) best.jacobian.push_back({j.dof, -(1 - t) * j.dx});
    for (const auto& j : on.points[k + 1].jacobian) best.jacobian.push_back({j.dof, -t * j.dx});
  }
  p.gap = (x - p.point).dot(p.normal);
  return best;
}

}  // namespace grip
