#include "solver/stepping/candidate_growth.hpp"

#include <algorithm>
#include <map>
#include <set>

#include "solver/stepping/load_stepping.hpp"

namespace grip {

CandidateGrowth add_candidates_for(Problem& problem, const std::vector<OutsidePoint>& outside) {
  CandidateGrowth g;
  g.old_first = problem.rigid.first;
  g.old_candidates = static_cast<int>(problem.candidates.size());
  Body& body = *problem.body;
  // Nodes without a site become sites (with the boundary sides through them).
  std::vector<int> nodes;
  for (const OutsidePoint& o : outside)
    if (o.site < 0) nodes.push_back(o.node);
  std::map<int, int> site_of_node;
  if (!nodes.empty())
    for (int site : body.add_sites(nodes)) site_of_node[body.site_node(site)] = site;
  std::set<std::pair<int, int>> pairs;  // (site, obstacle)
  for (const Candidate& c : problem.candidates) pairs.insert({c.site, c.obstacle});
  // A new site pairs with every rigid obstacle (it is on the contact surface now); a site
  // outside reach with the obstacle it came near.
  std::vector<std::pair<int, int>> wanted;
  for (const auto& [node, site] : site_of_node)
    for (int o = 0; o < static_cast<int>(problem.obstacles.size()); ++o)
      if (problem.obstacles[o].shape) wanted.push_back({site, o});
  for (const OutsidePoint& o : outside)
    if (o.site >= 0) wanted.push_back({o.site, o.obstacle});
  std::vector<Candidate> added;
  int next = g.old_first;
  const Vector q0 = Vector::Zero(body.dof_count());
  for (const auto& [site, o] : wanted) {
    if (!pairs.insert({site, o}).second) continue;
    const ObstacleInstance& obstacle = problem.obstacles[o];
    const Vec2 x = body.site_reference(site);
    const int side = (obstacle.shape->project(x).point - x).y() >= 0 ? +1 : -1;
    Candidate c{site, side, o, next++};
    if (obstacle.frictional || obstacle.friction > 0) c.xi = next++;
    added.push_back(c);
  }
  g.added_components = next - g.old_first;
  if (!g.grew()) return g;
  problem.candidates.insert(problem.candidates.end(), added.begin(), added.end());
  problem.rigid.first = next;
  problem.component_count = next + problem.rigid.count();
  // The note: which nodes, which obstacles, why.
  std::map<int, std::pair<std::vector<int>, std::vector<int>>> by_obstacle;  // entered, near
  for (const OutsidePoint& o : outside) {
    auto& lists = by_obstacle[o.obstacle];
    (o.entered ? lists.first : lists.second).push_back(o.node);
  }
  std::string note;
  auto list = [](std::vector<int> v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    std::string s;
    for (size_t k = 0; k < v.size() && k < 20; ++k) s += (k ? ", " : "") + std::to_string(v[k]);
    if (v.size() > 20) s += " and " + std::to_string(v.size() - 20) + " more";
    return s;
  };
  for (const auto& [o, lists] : by_obstacle) {
    const std::string& name = problem.obstacles[o].name;
    if (!lists.first.empty())
      note += (note.empty() ? "" : "; ") + std::string("nodes ") + list(lists.first) + " entered the obstacle '" +
              name + "' outside the contact candidates";
    if (!lists.second.empty())
      note += (note.empty() ? "" : "; ") + std::string("nodes ") + list(lists.second) +
              " came within reach of the obstacle '" + name + "'";
  }
  g.note = note + ": contact candidates from this step on (" + std::to_string(added.size()) + " added)";
  return g;
}

Vector grown_components(const Vector& v, const CandidateGrowth& g, const Problem& problem) {
  // Only a vector of the old layout (a record of a failed step may have none).
  if (!g.grew() || v.size() != g.old_first + problem.rigid.count()) return v;
  Vector out = Vector::Zero(problem.component_count);
  out.head(g.old_first) = v.head(g.old_first);
  const int amplitudes = static_cast<int>(v.size()) - g.old_first;
  if (amplitudes > 0) out.segment(problem.rigid.first, amplitudes) = v.tail(amplitudes);
  return out;
}

void grow_record(StepRecord& rec, const CandidateGrowth& g, const Problem& problem) {
  if (!g.grew()) return;
  rec.p = grown_components(rec.p, g, problem);
  if (rec.tau.size()) {
    Vector tau = Vector::Zero(problem.candidates.size());
    tau.head(rec.tau.size()) = rec.tau;
    rec.tau = tau;
  }
  EquilibriumState& s = rec.state;
  s.p = grown_components(s.p, g, problem);
  s.s = grown_components(s.s, g, problem);
  if (s.enabled.size() == static_cast<size_t>(g.old_first + problem.rigid.count())) {
    std::vector<char> e(problem.component_count, 0);
    std::copy(s.enabled.begin(), s.enabled.begin() + g.old_first, e.begin());
    std::copy(s.enabled.begin() + g.old_first, s.enabled.end(), e.begin() + problem.rigid.first);
    s.enabled = std::move(e);
  }
  if (s.q.size() == 0 || s.points.size() != static_cast<size_t>(g.old_candidates)) return;
  // The new candidates at this record's state: open (p = 0), their gap where they were.
  for (size_t i = g.old_candidates; i < problem.candidates.size(); ++i) {
    const Candidate& c = problem.candidates[i];
    const ObstacleInstance& o = problem.obstacles[c.obstacle];
    PairedPoint pp;
    pp.point = problem.body->surface_point(s.q, c.site, c.side);
    const Vec2 offset = o.offset(rec.factors);
    pp.projection = o.shape->project(pp.point.x - offset);
    pp.projection.point += offset;
    pp.projection.gap -= pp.point.clearance;
    pp.eta = -pp.projection.normal;
    pp.xi = pp.projection.tangent;
    if (s.s.size()) s.s[c.eta] = -pp.projection.gap;
    s.points.push_back(std::move(pp));
  }
}

}  // namespace grip
