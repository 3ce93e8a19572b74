#include "solver/contact/master_reading.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <map>

#include "solver/contact/contact_error.hpp"

namespace grip {

std::vector<MasterReading> master_readings(const Problem& problem, const Vector& q, const Vector& p, const Vector& tau,
                                           int obstacle) {
  const Body& all = *problem.body;
  const ObstacleInstance& pair = problem.obstacles.at(obstacle);
  std::map<int, std::array<double, 3>> slave;  // site -> sigma_n, sigma_t, pressing
  for (size_t i = 0; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    if (c.obstacle != obstacle) continue;
    const double area = all.tributary_area(c.site);
    slave[c.site] = {p[c.eta] / area, c.xi >= 0 ? p[c.xi] / area : 0.0,
                     contact_state(problem, i, p, tau) != ContactState::open ? 1.0 : 0.0};
  }
  // A slave site that sweeps no area (the axis corner of a quadratic side in axisymmetry) has
  // no stress of its own: it reads its neighbour's along the slave surface, as the result does.
  for (const std::vector<int>& chain : pair.master->slave_chains)
    for (size_t e = 0; e < chain.size(); ++e)
      if (chain.size() > 1 && slave.count(chain[e]) && !(all.tributary_area(chain[e]) > 0)) {
        const int next = chain[e + 1 < chain.size() ? e + 1 : e - 1];
        slave[chain[e]] = slave.count(next) ? slave[next] : std::array<double, 3>{0, 0, 0};
      }
  const auto at = [&](int site) { return all.surface_point(q, site, 0).x; };
  const auto of = [&](int site) { return slave.count(site) ? slave[site] : std::array<double, 3>{0, 0, 0}; };
  std::vector<MasterReading> readings;
  const int b = pair.master->body;
  for (int s = all.site_offset(b); s < all.site_offset(b + 1); ++s) {
    const Vec2 y = at(s);
    double best = std::numeric_limits<double>::infinity();
    MasterReading r;
    r.site = s;
    for (const std::vector<int>& chain : pair.master->slave_chains)
      for (size_t e = 0; e + 1 < chain.size(); ++e) {
        const Vec2 a = at(chain[e]), d = at(chain[e + 1]) - a;
        const double t = std::clamp((y - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
        const double distance = (a + t * d - y).norm();
        if (distance >= best) continue;
        best = distance;
        const auto sa = of(chain[e]), sb = of(chain[e + 1]);
        r.pressing = (t > 1 - 1e-6 || sa[2] > 0) && (t < 1e-6 || sb[2] > 0);
        r.sigma_n = r.pressing ? (1 - t) * sa[0] + t * sb[0] : 0.0;
        r.sigma_t = r.pressing ? (1 - t) * sa[1] + t * sb[1] : 0.0;
      }
    readings.push_back(r);
  }
  return readings;
}

}  // namespace grip
