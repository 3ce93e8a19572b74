#include "solver/core/problem.hpp"

namespace grip {

void add_candidates(Problem& problem) {
  problem.candidates.clear();
  int next = 0;
  const Body& body = *problem.body;
  for (int o = 0; o < static_cast<int>(problem.obstacles.size()); ++o) {
    const ObstacleInstance& obstacle = problem.obstacles[o];
    for (int site = 0; site < body.site_count(); ++site) {
      const Vec2 x = body.site_reference(site);
      const Projection proj = obstacle.shape->project(x);
      // The side whose outward surface normal (+y or -y) points toward the obstacle.
      const int side = (proj.point - x).y() >= 0 ? +1 : -1;
      Candidate c{site, side, o, next++};
      if (obstacle.frictional || obstacle.friction > 0) c.xi = next++;
      problem.candidates.push_back(c);
    }
  }
  problem.component_count = next;
}

}  // namespace grip
