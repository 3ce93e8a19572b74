// The equilibrium oracle: its Newton tangent includes the stiffness of the follower contact
// load d(T(u) p)/du, so it must equal a finite difference of the residual.
#include <gtest/gtest.h>

#include <Eigen/SparseCore>
#include <random>

#include "solver/elements/timoshenko_beam.hpp"
#include "solver/solve/equilibrium.hpp"

namespace grip {
namespace {

Problem beam_over(std::unique_ptr<Obstacle> shape, double friction) {
  Problem problem;
  std::vector<double> x;
  for (int i = 0; i <= 6; ++i) x.push_back(i * 1.0);
  const double E = 1000, b = 1, d = 0.4;
  auto beam = std::make_unique<TimoshenkoBeam>(
      x, 0.0, BeamSection{E * b * d, E * b * d * d * d / 12, 0.8 * E / 2.6 * b * d, d / 2, b},
      Kinematics::von_karman);
  problem.loads = {Vector::Zero(beam->dof_count())};
  problem.constraints.push_back({0, 0.0});
  problem.body = std::move(beam);
  problem.obstacles.push_back({"tool", std::move(shape), friction, true, {Vec2(0.1, -0.05)}});
  add_candidates(problem);
  return problem;
}

Matrix dense_tangent(const Equilibrium& eq, const Vector& q, const Vector& p) {
  Triplets t;
  eq.residual(q, p, &t);
  Eigen::SparseMatrix<double> K(q.size(), q.size());
  K.setFromTriplets(t.begin(), t.end());
  return Matrix(K);
}

TEST(EquilibriumTangent, IncludesTheFollowerContactLoadStiffness) {
  for (const bool circle : {true, false}) {
    Problem problem = circle ? beam_over(make_circle({3, -10.3}, 10), 0.4)
                             : beam_over(make_profile({ArcPiece{{3, -10.3}, 10, 2.0, 1.0}}), 0.4);
    Equilibrium eq(problem, NewtonParams{});
    eq.set_step({0.7}, std::vector<double>(problem.candidates.size(), 0.3));
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-0.02, 0.02), f(-5, 5);
    Vector q(problem.body->dof_count());
    for (int i = 0; i < q.size(); ++i) q[i] = u(rng);
    Vector p(problem.component_count);
    for (const Candidate& c : problem.candidates) {
      p[c.eta] = -std::abs(f(rng));
      p[c.xi] = f(rng);
    }
    const Matrix K = dense_tangent(eq, q, p);
    Matrix K_fd(q.size(), q.size());
    const double h = 1e-7;
    for (int j = 0; j < q.size(); ++j) {
      Vector qp = q, qm = q;
      qp[j] += h;
      qm[j] -= h;
      K_fd.col(j) = (eq.residual(qp, p, nullptr) - eq.residual(qm, p, nullptr)) / (2 * h);
    }
    EXPECT_LT((K - K_fd).norm(), 1e-6 * K.norm()) << (circle ? "circle" : "concave arc");
    // The contact part is not negligible here, so the check has teeth.
    const Matrix K0 = dense_tangent(eq, q, Vector::Zero(p.size()));
    EXPECT_GT((K - K0).norm(), 1e-4 * K.norm());
  }
}

}  // namespace
}  // namespace grip
