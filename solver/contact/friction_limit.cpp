#include "solver/contact/friction_limit.hpp"

#include <Eigen/QR>
#include <cmath>
#include <cstdio>
#include <vector>

#include "solver/contact/contact_error.hpp"
#include "solver/contact/held_by_contact.hpp"
#include "solver/problem/rigid_modes.hpp"

namespace grip {
namespace {

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", x);
  return text;
}

std::string point_text(const Vec2& x) { return "(" + number(x.x()) + ", " + number(x.y()) + ")"; }

// A pressed point with friction: where it is, how it moves and slips along the held motions.
struct Rubbing {
  int candidate = 0;
  Vec2 x = Vec2::Zero();
  Matrix velocity;  // 2 x modes: the point's velocity along each free motion
  Vector slip_rate;
};

}  // namespace

std::string friction_limit_exceeded(const Problem& problem, const EquilibriumState& state, const Vector& p,
                                    const Vector& tau, const LoadFactors& factors) {
  const RigidModes& rigid = problem.rigid;
  const int n = static_cast<int>(problem.candidates.size());
  if (rigid.count() == 0 || static_cast<int>(state.points.size()) != n || state.q.size() != problem.body->dof_count() ||
      p.size() != problem.component_count || state.s.size() != problem.component_count)
    return "";
  const Matrix R = rigid_modes_at(problem, state.q);
  // The generalized force of the load and of the normal forces on the free motions.
  Vector w = R.transpose() * problem.load(factors);
  Vector normal_rates = Vector::Zero(R.cols());  // the normal forces' work along each free motion
  std::vector<Rubbing> rubbing;
  for (int i = 0; i < n; ++i) {
    const Candidate& c = problem.candidates[i];
    if (!(p[c.eta] < 0)) continue;
    const PairedPoint& pp = state.points[i];
    Rubbing r{i, pp.point.x, Matrix::Zero(2, R.cols()), Vector()};
    for (const auto& j : pp.point.jacobian) r.velocity += j.dx * R.row(j.dof);
    normal_rates += p[c.eta] * (pp.eta.transpose() * r.velocity).transpose();
    if (c.xi < 0 || problem.obstacles[c.obstacle].friction <= 0) continue;
    r.slip_rate = (pp.xi.transpose() * r.velocity).transpose();
    rubbing.push_back(std::move(r));
  }
  if (rubbing.empty()) return "";
  // The held motion c: the rigid motion that fits the slips (the least-norm one, so that a
  // motion that no slip sees, across a flat, stays out of it).
  const int m = static_cast<int>(rubbing.size());
  Matrix G(m, R.cols());
  Vector slips(m);
  for (int r = 0; r < m; ++r) {
    G.row(r) = rubbing[r].slip_rate.transpose();
    slips[r] = state.s[problem.candidates[rubbing[r].candidate].xi];
  }
  w += normal_rates;
  const Vector c = G.completeOrthogonalDecomposition().solve(slips);
  const Vector rates = G * c;
  const double largest_rate = rates.lpNorm<Eigen::Infinity>();
  if (!(largest_rate > 0)) return "";
  // W: the work of the load and the normal forces along c; D: the most that friction at these
  // normal forces can oppose. Every point that slips along c must already give it all: on its
  // bound (the pass's tau or Coulomb's mu |p_eta|), against c.
  const double work = w.dot(c);
  double capacity = 0.0;
  for (int r = 0; r < m; ++r) {
    const int i = rubbing[r].candidate;
    const Candidate& cand = problem.candidates[i];
    const double coulomb = problem.obstacles[cand.obstacle].friction * std::abs(p[cand.eta]);
    capacity += coulomb * std::abs(rates[r]);
    if (std::abs(rates[r]) <= 1e-9 * largest_rate) continue;  // at the centre of the turn
    const double bound = tau.size() == n ? std::min(coulomb, tau[i]) : coulomb;
    if (std::abs(p[cand.xi]) < bound * (1 - kBoundTolerance) || p[cand.xi] * rates[r] >= 0) return "";
  }
  if (!(capacity > 0) || work <= capacity) return "";
  // Where c presses the points more than it slides them (the normal forces do more work along it
  // than friction can oppose: a gear turned against its mate's flank), the normal forces change
  // along c and balance the load there: W > D shows nothing.
  if (std::abs(normal_rates.dot(c)) > capacity) return "";
  // Worded as a turn about its centre (moments) or as a slide (forces): the fit of a rigid
  // velocity t + omega (x - centre)^perp to the points' velocities along c.
  Vec2 mean = Vec2::Zero();
  for (const Rubbing& r : rubbing) mean += r.x / m;
  Matrix A(2 * m, 3);
  Vector v(2 * m);
  for (int r = 0; r < m; ++r) {
    const Vec2 d = rubbing[r].x - mean;
    A.row(2 * r) << 1, 0, -d.y();
    A.row(2 * r + 1) << 0, 1, d.x();
    v.segment<2>(2 * r) = rubbing[r].velocity * c;
  }
  const Vector fit = A.completeOrthogonalDecomposition().solve(v);
  const Vec2 t = fit.head<2>();
  const double omega = fit[2];
  const std::string ratio = number(work / capacity), at = load_factors_text(problem, factors);
  const Vec2 centre = omega != 0 ? Vec2(mean.x() - t.y() / omega, mean.y() + t.x() / omega) : mean;
  if (m > 1 && omega != 0 && (centre - mean).norm() <= 10 * problem.body->characteristic_length())
    return "the couple exceeds what friction can hold: M / (mu sum N r) = " + ratio + " " + at +
           " (the body turns about " + point_text(centre) + "; M = " + number(work / std::abs(omega)) +
           ", the moment of the load and the normal contact forces N about it; mu sum N r = " +
           number(capacity / std::abs(omega)) +
           ", the largest moment friction opposes at those normal forces, r the levers of the slips); no static "
           "equilibrium exists";
  const double speed = t.norm() > 0 ? t.norm() : 1.0;
  return "the shear load exceeds what friction can hold: Q / (mu N) = " + ratio + " " + at + " (along " +
         point_text(t / speed) + "; Q = " + number(work / speed) +
         ", the load and the normal contact forces N along that slide; mu N = " + number(capacity / speed) +
         ", the most friction opposes at those normal forces); no static equilibrium exists";
}

}  // namespace grip
