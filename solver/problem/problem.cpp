#include "solver/problem/problem.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace grip {

namespace {

// The obstacle positions to test reach at: the start, and along each stretch of the path
// (motions are linear in the factors, so a few samples per stretch follow it closely).
std::vector<LoadFactors> sampled_path(const std::vector<LoadStep>& path) {
  std::vector<LoadFactors> samples;
  if (path.empty()) return samples;
  samples.push_back(LoadFactors(path.front().factors.size(), 0.0));
  const size_t stride = std::max<size_t>(1, path.size() / 256);
  for (size_t k = 0; k < path.size(); ++k)
    if (k % stride == 0 || k + 1 == path.size() || path[k].stage != path[std::min(k + 1, path.size() - 1)].stage)
      samples.push_back(path[k].factors);
  return samples;
}

}  // namespace

void add_candidates(Problem& problem, const std::vector<LoadStep>& path, double reach) {
  problem.candidates.clear();
  int next = 0;
  const Body& body = *problem.body;
  const std::vector<LoadFactors> samples = sampled_path(path);
  const Vector q0 = Vector::Zero(body.dof_count());
  for (int o = 0; o < static_cast<int>(problem.obstacles.size()); ++o) {
    const ObstacleInstance& obstacle = problem.obstacles[o];
    std::vector<int> sites = obstacle.slaves;
    if (sites.empty())
      for (int site = 0; site < body.site_count(); ++site) sites.push_back(site);
    std::optional<DeformedMaster> master;
    if (obstacle.master) master.emplace(body, q0, *obstacle.master);
    for (int site : sites) {
      const Vec2 x = body.site_reference(site);
      const Projection proj = master ? master->project(x).projection : obstacle.shape->project(x);
      if (reach > 0 && master && std::abs(proj.gap) > reach) continue;
      if (reach > 0 && !master && !samples.empty()) {
        double nearest = std::numeric_limits<double>::infinity();
        for (const LoadFactors& f : samples)
          nearest = std::min(nearest, std::abs(obstacle.shape->project(x - obstacle.offset(f)).gap));
        if (nearest > reach) continue;
      }
      // The side whose outward surface normal (+y or -y) points toward the obstacle; a pair's
      // slave surface names its side (a beam's upper or lower surface).
      const int named = master ? obstacle.master->slave_side : 0;
      const int side = named ? named : (proj.point - x).y() >= 0 ? +1 : -1;
      Candidate c{site, side, o, next++};
      if (obstacle.frictional || obstacle.friction > 0) c.xi = next++;
      problem.candidates.push_back(c);
    }
  }
  problem.rigid.first = next;
  problem.component_count = next + problem.rigid.count();
}

}  // namespace grip
