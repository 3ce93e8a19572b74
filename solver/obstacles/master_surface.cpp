#include "solver/obstacles/master_surface.hpp"

#include <algorithm>
#include <cmath>

#include "solver/obstacles/dual.hpp"

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

// The outward normal of the side a -> b (the body on its left: to the right of the travel).
template <class S>
P2<S> side_normal(const P2<S>& a, const P2<S>& b) {
  const P2<S> e = unit(b - a);
  return {e.y, -e.x};
}

// The outward normal at site k of a chain of n sites (`at(k)` its position): the mean of its
// sides' normals; at the seam of a closed chain (site 0 = site n - 1) both sides' too.
template <class S, class At>
P2<S> site_normal(const At& at, int n, int k, bool closed) {
  P2<S> sum{S(0.0), S(0.0)};
  if (k > 0) sum = sum + side_normal<S>(at(k - 1), at(k));
  else if (closed) sum = sum + side_normal<S>(at(n - 2), at(n - 1));
  if (k + 1 < n) sum = sum + side_normal<S>(at(k), at(k + 1));
  else if (closed) sum = sum + side_normal<S>(at(0), at(1));
  return unit(sum);
}

// The normal at `along` (in [0, 1]) of segment k: interpolated between its sites' normals.
template <class S, class At>
P2<S> smoothed_normal(const At& at, int n, int k, const S& along, bool closed) {
  return unit((S(1.0) - along) * site_normal<S>(at, n, k, closed) + along * site_normal<S>(at, n, k + 1, closed));
}

// The mortar integrals of the slave segment a -> b against the master segments k_first..k_last
// of a chain (`at(k)` the master sites): add(end, k, int psi_end N_k) for end 0 (a) and 1 (b).
// Each master segment is cut to the part of the slave segment its ends project onto (along
// the slave's normal); on each piece the integrand is quadratic, and two Gauss points make it
// exact.
template <class S, class At, class Add>
void segment_mortar(const P2<S>& a, const P2<S>& b, const At& at, int k_first, int k_last, const Add& add) {
  const double gauss = 1.0 / std::sqrt(3.0);
  const S length = grip::length(b - a);
  const P2<S> along = (S(1.0) / length) * (b - a);
  for (int k = k_first; k <= k_last; ++k) {
    const S xp = dot(at(k) - a, along) / length, xq = dot(at(k + 1) - a, along) / length;
    const S& low = value(xp) <= value(xq) ? xp : xq;
    const S& high = value(xp) <= value(xq) ? xq : xp;
    const S lo = value(low) > 0.0 ? low : S(0.0), hi = value(high) < 1.0 ? high : S(1.0);
    if (!(value(hi) > value(lo)) || std::abs(value(xq) - value(xp)) < 1e-12) continue;
    for (double g : {-gauss, gauss}) {
      const S xi = S(0.5) * (lo + hi) + S(0.5 * g) * (hi - lo), weight = S(0.5) * (hi - lo) * length;
      const S t = (xi - xp) / (xq - xp);
      const S psi_a = S(2.0) - S(3.0) * xi, psi_b = S(3.0) * xi - S(1.0);  // the dual basis on the segment
      add(0, k, psi_a * (S(1.0) - t) * weight);
      add(0, k + 1, psi_a * t * weight);
      add(1, k, psi_b * (S(1.0) - t) * weight);
      add(1, k + 1, psi_b * t * weight);
    }
  }
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
    m.closed.push_back(chain.size() > 3 && chain.front() == chain.back());
    std::vector<double> z{zeta};
    for (size_t i = 1; i < chain.size(); ++i)
      z.push_back(zeta += (body.site_reference(chain[i]) - body.site_reference(chain[i - 1])).norm());
    m.reference_zeta.push_back(z);
  }
  return m;
}

double master_zeta_difference(const MasterSurface& surface, double zeta1, double zeta0) {
  double d = zeta1 - zeta0;
  for (size_t c = 0; c < surface.chains.size(); ++c) {
    const std::vector<double>& z = surface.reference_zeta[c];
    if (!surface.closed[c] || zeta0 < z.front() || zeta0 > z.back()) continue;
    const double length = z.back() - z.front();
    d -= length * std::round(d / length);
    if (d <= -0.5 * length) d += length;
  }
  return d;
}

double DeformedMaster::Chain::reference_near(int k, double near) const {
  double r = (*reference)[k];
  if (!closed) return r;
  const double length = reference->back() - reference->front();
  return r + length * std::round((near - r) / length);
}

DeformedMaster::DeformedMaster(const Body& body, const Vector& q, const MasterSurface& surface) {
  for (size_t c = 0; c < surface.chains.size(); ++c) {
    Chain chain;
    chain.reference = &surface.reference_zeta[c];
    chain.closed = surface.closed[c];
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
    chain.profile = make_profile(std::move(pieces), chain.closed);
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
  surface_ = &surface;
  std::map<int, double> tributary;                        // D_j
  std::map<int, std::map<std::array<int, 2>, double>> m;  // M_jk, k as (chain, index)
  for (const std::vector<int>& slave : surface.slave_chains)
    for (int site : slave) slave_points_[site] = body.surface_point(q, site, surface.slave_side);
  for (const std::vector<int>& slave : surface.slave_chains) {
    for (size_t e = 0; e + 1 < slave.size(); ++e) {
      const Vec2 a = slave_points_[slave[e]].x, b = slave_points_[slave[e + 1]].x;
      const double length = (b - a).norm();
      if (!(length > 0)) continue;
      tributary[slave[e]] += 0.5 * length;
      tributary[slave[e + 1]] += 0.5 * length;
      for (const auto& range : mortar_ranges(a, b)) {
        const int chain = range[0];
        const auto at = [&](int k) { return p2(chains_[chain].points[k].x); };
        const std::array<int, 2> ends{slave[e], slave[e + 1]};
        segment_mortar(p2(a), p2(b), at, range[1], range[2], [&](int end, int k, double v) {
          m[ends[end]][{chain, k}] += v;
        });
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

std::vector<std::array<int, 3>> DeformedMaster::mortar_ranges(const Vec2& a, const Vec2& b) const {
  const Closest from = closest(a), to = closest(b);
  if (from.chain != to.chain) return {};
  // The master segments between the ends' closest points, and one more on either side.
  const int chain = from.chain, count = static_cast<int>(chains_[chain].points.size()) - 1;
  int lo = std::min(from.segment, to.segment), hi = std::max(from.segment, to.segment);
  if (!chains_[chain].closed) return {{chain, std::max(0, lo - 1), std::min(count - 1, hi + 1)}};
  // A closed chain: the short way round, which may cross the seam (segment count - 1 to 0).
  if (hi - lo > count / 2) {  // from hi forward across the seam to lo
    const int first = hi;
    hi = lo + count;
    lo = first;
  }
  --lo, ++hi;
  if (hi - lo + 1 >= count) return {{chain, 0, count - 1}};
  const int start = (lo % count + count) % count, end = start + (hi - lo);
  if (end < count) return {{chain, start, end}};
  return {{chain, start, count - 1}, {chain, 0, end - count}};
}

MasterPoint DeformedMaster::project(const Vec2& x, int slave_site) const {
  const Closest c = closest(x);
  const Chain& on = chains_[c.chain];
  const int k = c.segment, n = static_cast<int>(on.points.size());
  const double t = c.t, along = std::clamp(t, 0.0, 1.0), length = on.zeta[k + 1] - on.zeta[k];
  const std::vector<double>& ref = *on.reference;
  MasterPoint best;
  Projection& p = best.projection;
  p = c.projection;
  p.normal = vec2(smoothed_normal<double>([&](int i) { return p2(on.points[i].x); }, n, k, along, on.closed));
  p.tangent = rot90(p.normal);
  p.dnormal_dx = Mat2::Zero();  // the normal's turn is in force_derivative()
  p.zeta_rate *= (ref[k + 1] - ref[k]) / length;
  const auto mortar = mortar_.find(slave_site);
  if (mortar != mortar_.end()) {  // the mortar point sum_k w_k x_k
    p.point = Vec2::Zero();
    p.zeta = 0.0;
    const double near = ref[k] + t * (ref[k + 1] - ref[k]);
    for (const auto& [at, w] : mortar->second) {
      const SurfacePoint& sp = chains_[at[0]].points[at[1]];
      p.point += w * sp.x;
      p.zeta += w * chains_[at[0]].reference_near(at[1], near);
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

// The pairing of a slave point with its derivatives: `vars` the points whose positions it reads
// (two coordinates each, in this order: the slave point, then the master sites and the slave
// surface's sites), the smoothed normal, the gap (x - x_m) . n, zeta, and each point's share of
// the pair's force f (1 on the slave, -w_k on master site k).
struct DeformedMaster::DualPairing {
  std::vector<const SurfacePoint*> vars;
  P2<Dual> normal;
  Dual gap, zeta;
  std::vector<std::pair<const SurfacePoint*, Dual>> shares;

  // The gradient of s over the dofs: d s / d x_var times d x_var / d q (the points' Jacobians
  // are constant: continuum sites, a beam's offset surface).
  void add_gradient(const Dual& s, double scale, std::vector<std::pair<int, double>>& out) const {
    if (!s.d.size()) return;
    for (size_t v = 0; v < vars.size(); ++v)
      for (const auto& col : vars[v]->jacobian)
        out.emplace_back(col.dof, scale * (s.d[2 * v] * col.dx.x() + s.d[2 * v + 1] * col.dx.y()));
  }
};

DeformedMaster::DualPairing DeformedMaster::dual_pairing(const SurfacePoint& slave, int slave_site) const {
  DualPairing out;
  std::vector<const SurfacePoint*>& vars = out.vars;
  vars.push_back(&slave);
  std::map<std::array<int, 2>, int> master_slot;  // (chain, index) -> variable
  std::map<int, int> slave_slot;                  // slave site -> variable
  const auto use_master = [&](int chain, int k) {
    if (master_slot.emplace(std::array<int, 2>{chain, k}, static_cast<int>(vars.size())).second)
      vars.push_back(&chains_[chain].points[k]);
  };
  const Closest c = closest(slave.x);
  const int n = static_cast<int>(chains_[c.chain].points.size());
  const bool closed = chains_[c.chain].closed;
  for (int k = c.segment - 1; k <= c.segment + 2; ++k) {
    if (closed) {  // across the seam: site 0 is site n - 1, both read
      const int wrapped = ((k % (n - 1)) + (n - 1)) % (n - 1);
      use_master(c.chain, wrapped);
      if (wrapped == 0) use_master(c.chain, n - 1);
    } else if (k >= 0 && k < n) {
      use_master(c.chain, k);
    }
  }
  if (closed && c.segment <= 1) use_master(c.chain, n - 2);  // site 0's other side
  if (closed && c.segment >= n - 3) use_master(c.chain, 1);
  struct Piece {
    int a, b;
    std::array<int, 3> range;
  };
  std::vector<Piece> pieces;  // the slave segments at the site, where it has mortar weights
  const bool mortar = mortar_.count(slave_site) > 0;
  if (mortar)
    for (const std::vector<int>& chain : surface_->slave_chains)
      for (size_t e = 0; e + 1 < chain.size(); ++e) {
        if (chain[e] != slave_site && chain[e + 1] != slave_site) continue;
        const Vec2 a = slave_points_.at(chain[e]).x, b = slave_points_.at(chain[e + 1]).x;
        if (!((b - a).norm() > 0)) continue;
        const auto ranges = mortar_ranges(a, b);
        for (const auto& range : ranges) {
          pieces.push_back({chain[e], chain[e + 1], range});
          for (int k = range[1]; k <= range[2] + 1; ++k) use_master(range[0], k);
        }
        if (!ranges.empty())
          for (int site : {chain[e], chain[e + 1]})
            if (slave_slot.emplace(site, static_cast<int>(vars.size())).second) vars.push_back(&slave_points_.at(site));
      }
  const int count = 2 * static_cast<int>(vars.size());
  const auto seeded = [&](int slot) {
    const Vec2& x = vars[slot]->x;
    return P2<Dual>{Dual(x.x(), Vector::Unit(count, 2 * slot)), Dual(x.y(), Vector::Unit(count, 2 * slot + 1))};
  };
  const auto master_at = [&](int chain) {
    return [&, chain](int k) {
      const auto it = master_slot.find({chain, k});
      if (it != master_slot.end()) return seeded(it->second);
      const Vec2& x = chains_[chain].points[k].x;
      return P2<Dual>{Dual(x.x()), Dual(x.y())};
    };
  };
  const P2<Dual> x = seeded(0);
  // t along the segment: on the segment's line (inside it, or on the extension beyond a chain's
  // end) it moves with x and the segment; at a corner's vertex (t = 0) it stays.
  const auto on = master_at(c.chain);
  const P2<Dual> from = on(c.segment), segment = on(c.segment + 1) - from;
  const Dual t = c.t != 0.0 ? dot(x - from, segment) / dot(segment, segment) : Dual(0.0);
  const Dual along = c.t > 0.0 && c.t < 1.0 ? t : Dual(std::clamp(c.t, 0.0, 1.0));
  out.normal = smoothed_normal<Dual>(on, n, c.segment, along, closed);
  out.shares.push_back({&slave, Dual(1.0)});
  const std::vector<double>& ref = *chains_[c.chain].reference;
  P2<Dual> x_m{Dual(0.0), Dual(0.0)};
  if (mortar) {
    std::map<std::array<int, 2>, Dual> m;  // M_jk as in integrate_mortar, with derivatives
    for (const Piece& piece : pieces) {
      const int chain = piece.range[0];
      const int end = piece.a == slave_site ? 0 : 1;
      segment_mortar(seeded(slave_slot.at(piece.a)), seeded(slave_slot.at(piece.b)), master_at(chain), piece.range[1],
                     piece.range[2], [&](int e, int k, const Dual& v) {
                       if (e == end) m[{chain, k}] += v;
                     });
    }
    Dual covered(0.0);
    for (const auto& entry : m) covered += entry.second;
    const double near = ref[c.segment] + c.t * (ref[c.segment + 1] - ref[c.segment]);
    for (const auto& [k, value] : m) {
      const Dual w = value / covered;
      out.shares.push_back({&chains_[k[0]].points[k[1]], -w});
      x_m = x_m + w * master_at(k[0])(k[1]);
      out.zeta += w * Dual(chains_[k[0]].reference_near(k[1], near));
    }
  } else {
    out.shares.push_back({&chains_[c.chain].points[c.segment], t - Dual(1.0)});
    out.shares.push_back({&chains_[c.chain].points[c.segment + 1], -t});
    x_m = from + t * segment;
    out.zeta = Dual(ref[c.segment]) + t * Dual(ref[c.segment + 1] - ref[c.segment]);
  }
  out.gap = dot(x - x_m, out.normal);
  return out;
}

void DeformedMaster::force_derivative(const SurfacePoint& slave, int slave_site, double p_eta, double p_xi,
                                      Triplets& out) const {
  const DualPairing pairing = dual_pairing(slave, slave_site);
  const P2<Dual> f = Dual(-p_eta) * pairing.normal + Dual(p_xi) * rot90(pairing.normal);
  // d(J_row . share f)/dq_col = sum over variables of d(share f)/dx_var dx_var/dq_col.
  std::vector<std::pair<int, double>> column;
  for (const auto& [point, share] : pairing.shares) {
    const P2<Dual> force = share * f;
    for (const auto& row : point->jacobian) {
      column.clear();
      pairing.add_gradient(Dual(row.dx.x()) * force.x + Dual(row.dx.y()) * force.y, 1.0, column);
      for (const auto& [dof, value] : column) {
        out.emplace_back(row.dof, dof, value);
        out.emplace_back(dof, row.dof, 0.0);  // a tangent's pattern is symmetric
      }
    }
  }
}

void DeformedMaster::gradients(const SurfacePoint& slave, int slave_site, std::vector<std::pair<int, double>>& gap,
                               std::vector<std::pair<int, double>>& zeta) const {
  const DualPairing pairing = dual_pairing(slave, slave_site);
  pairing.add_gradient(pairing.gap, 1.0, gap);
  pairing.add_gradient(pairing.zeta, 1.0, zeta);
}

}  // namespace grip
