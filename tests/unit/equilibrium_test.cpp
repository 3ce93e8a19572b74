// The equilibrium oracle: its Newton tangent includes the stiffness of the follower contact
// load d(T(u) p)/du, so it must equal a finite difference of the residual.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <random>

#include "solver/elements/timoshenko_beam.hpp"
#include "solver/equilibrium/equilibrium.hpp"
#include "solver/io/scene.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

Problem beam_over(std::unique_ptr<Obstacle> shape, double friction) {
  Problem problem;
  std::vector<double> x;
  for (int i = 0; i <= 6; ++i) x.push_back(i * 1.0);
  const double E = 1000, b = 1, d = 0.4;
  auto beam = std::make_unique<TimoshenkoBeam>(
      x, 0.0, BeamSection{E * b * d, E * b * d * d * d / 12, 0.8 * E / 2.6 * b * d, d / 2, b}, Kinematics::von_karman);
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

// C = T^T K^-1 T formed densely over every free dof: the reference for the compliance from G.
// With contact forces p, the tangent is Newton's, with their stiffness: C = T^T K_t^-1 T.
Matrix dense_compliance(const Problem& problem, const Equilibrium& eq, const EquilibriumState& state,
                        const std::vector<int>& components, const Vector* p = nullptr) {
  const int n = problem.body->dof_count();
  std::vector<int> free_index(n, -1);
  int free_count = 0;
  for (int i = 0; i < n; ++i)
    if (eq.is_free(i)) free_index[i] = free_count++;
  Triplets t;
  Vector force = Vector::Zero(n);
  TripletSink sink(t);
  if (p) eq.residual(state.q, *p, &t);
  else problem.body->internal_force(state.q, force, &sink);
  Matrix K = Matrix::Zero(free_count, free_count);
  for (const auto& e : t)
    if (free_index[e.row()] >= 0 && free_index[e.col()] >= 0) K(free_index[e.row()], free_index[e.col()]) += e.value();
  Matrix T = Matrix::Zero(free_count, components.size());
  for (size_t k = 0; k < components.size(); ++k)
    for (size_t i = 0; i < problem.candidates.size(); ++i) {
      const Candidate& c = problem.candidates[i];
      if (c.eta != components[k] && c.xi != components[k]) continue;
      const PairedPoint& pp = state.points[i];
      const Vec2 direction = c.eta == components[k] ? pp.eta : pp.xi;
      for (const auto& j : pp.point.jacobian)
        if (free_index[j.dof] >= 0) T(free_index[j.dof], k) += j.dx.dot(direction);
    }
  return T.transpose() * K.partialPivLu().solve(T);
}

// The compliance from G on the components asked for, first on every other enabled component
// (G covers their surface dofs), then on all (G grows by the rest, with reuse on): both equal
// the dense one, from one factorization.
void expect_compliance_from_g_is_dense(const Problem& problem, const Vector& q, const std::string& what) {
  Equilibrium eq(problem, NewtonParams{});
  eq.set_compliance_reuse(true);  // a changing tangent too keeps its G while it grows
  eq.set_step({0.7}, std::vector<double>(problem.candidates.size(), 0.0));
  const EquilibriumState state = eq.evaluate(q);
  std::vector<int> all, half;
  for (int a = 0; a < problem.component_count; ++a)
    if (state.enabled[a]) all.push_back(a);
  for (size_t k = 0; k < all.size(); k += 2) half.push_back(all[k]);
  ASSERT_GT(all.size(), 6u) << what;
  for (const auto* components : {&half, &all}) {
    const Matrix reference = dense_compliance(problem, eq, state, *components);
    const Matrix C = eq.compliance(state, *components).block;
    const double error = (C - reference).norm() / reference.norm();
    std::printf("%s, %zu components: |C_G - C_dense| / |C_dense| = %.3g\n", what.c_str(), components->size(), error);
    EXPECT_LT(error, 1e-12) << what << ", " << components->size() << " components";
  }
  EXPECT_EQ(eq.counters().compliance_forms, 1) << what;
  EXPECT_EQ(eq.counters().factorizations, 1) << what;
}

Vector small_random_displacement(const Problem& problem, double size) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-size, size);
  Vector q(problem.body->dof_count());
  for (int i = 0; i < q.size(); ++i) q[i] = u(rng);
  return q;
}

TEST(Compliance, FromGEqualsTheDenseOneOnABeam) {
  // von Karman kinematics: the tangent depends on q; candidates carry rotation dofs too.
  Problem problem = beam_over(make_circle({3, -10.3}, 10), 0.4);
  for (int d : {1, 2}) problem.constraints.push_back({TimoshenkoBeam::node_dof(0, d), 0.0});  // clamped
  expect_compliance_from_g_is_dense(problem, small_random_displacement(problem, 0.02), "von Karman beam");
}

// The shipped Hertz half-disc, coarse (8 x 4 elements), all of its arc a contact set.
Scene coarse_half_disc(const char* kinematics) {
  nlohmann::json j = testing::example_scene("hertz");
  nlohmann::json& disc = j["body"]["mesh"]["half_disc"];
  disc.erase("refine");
  disc["divisions"] = {8, 4};
  j["body"]["contact_set"] = "arc";
  j["body"]["kinematics"] = kinematics;
  j["obstacles"][0]["friction"] = 0.3;
  return read_scene(j);
}

TEST(Compliance, FromGEqualsTheDenseOneOnAContinuum) {
  for (const char* kinematics : {"linear", "finite"}) {
    const Scene scene = coarse_half_disc(kinematics);
    expect_compliance_from_g_is_dense(scene.problem, small_random_displacement(scene.problem, 0.05),
                                      std::string("half-disc, ") + kinematics);
  }
}

// A thin strip on a flat, 101 contact nodes on its bottom and 4 element rows: the body's
// fill-reducing ordering is nearly banded there (long elimination-tree paths from the surface
// rows), so G comes from a second factorization in nested-dissection order.
TEST(Compliance, FromGEqualsTheDenseOneOnAThinStrip) {
  const Scene scene = read_scene(nlohmann::json::parse(R"({
    "units": {"force": "N", "length": "mm"},
    "body": {"model": "continuum", "kinematics": "linear", "analysis": "plane_strain", "element": "q4",
             "thickness": 1, "material": {"young": 200000, "poisson": 0.3},
             "mesh": {"rectangle": {"size": [1, 0.04], "divisions": [100, 4]}},
             "supports": [{"set": "top", "fix": ["x", "y"], "values": {"y": -1e-6}}]},
    "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [2, 0], "to": [-1, 0]}, "friction": 0.3}],
    "steps": 1})"));
  expect_compliance_from_g_is_dense(scene.problem, small_random_displacement(scene.problem, 1e-5), "thin strip");
}

// A body stiff in its reference state pressed by given forces onto a circle (frictionless): its
// compliance holds the stiffness of the contact forces that turn with the circle's normal, so
// it is T^T K_t^-1 T with Newton's whole tangent K_t (the finite difference of the residual,
// above), and a real solve's change of s under a force change matches C dp to the third order
// (a central difference), where the body's own T^T K^-1 T errs to the first.
TEST(Compliance, WithTheTurningContactForcesIsTheExactLinearization) {
  Problem problem = beam_over(make_circle({3, -1.3}, 1), 0.0);
  for (int d : {1, 2}) problem.constraints.push_back({TimoshenkoBeam::node_dof(0, d), 0.0});  // clamped
  Equilibrium eq(problem, NewtonParams{});
  eq.set_step({0.7}, std::vector<double>(problem.candidates.size(), 0.0));
  const EquilibriumState start = eq.evaluate(Vector::Zero(problem.body->dof_count()));
  Vector p = Vector::Zero(problem.component_count);
  std::vector<int> pressed;
  for (const Candidate& c : problem.candidates)
    if (start.enabled[c.eta]) {
      p[c.eta] = -0.01;
      pressed.push_back(c.eta);
    }
  ASSERT_GE(pressed.size(), 4u);
  const EquilibriumState state = eq.solve(start.q, p);
  ASSERT_TRUE(state.converged) << state.reason;
  const Matrix C = eq.compliance(state, pressed).block;
  EXPECT_TRUE(eq.compliance_turns());
  const Matrix exact = dense_compliance(problem, eq, state, pressed, &p);
  const Matrix body_only = dense_compliance(problem, eq, state, pressed);
  const double off_exact = (C - exact).norm() / exact.norm(), turning = (exact - body_only).norm() / exact.norm();
  // s(p + dp) - s(p - dp) = 2 C dp + O(dp^3): the mispredictions of C and of the body's own.
  const Vector dp = 0.05 * p;
  const EquilibriumState plus = eq.solve(state.q, p + dp), minus = eq.solve(state.q, p - dp);
  ASSERT_TRUE(plus.converged && minus.converged);
  Vector ds(pressed.size()), dp_pressed(pressed.size());
  for (size_t a = 0; a < pressed.size(); ++a) {
    ds[a] = 0.5 * (plus.s[pressed[a]] - minus.s[pressed[a]]);
    dp_pressed[a] = dp[pressed[a]];
  }
  const double miss = (ds - C * dp_pressed).norm() / ds.norm(),
               miss_body = (ds - body_only * dp_pressed).norm() / ds.norm();
  std::printf(
      "|C - T^T K_t^-1 T| = %.3g, the turning terms' share %.3g; misprediction of a 5 %% force change: %.3g (body's "
      "own "
      "K: %.3g)\n",
      off_exact, turning, miss, miss_body);
  EXPECT_LT(off_exact, 1e-10);
  EXPECT_GT(turning, 1e-3);  // the check has teeth
  EXPECT_LT(miss, 0.01 * miss_body);
}

// Pressing forces large beside the beam's bending stiffness: the turning terms make the sum
// with the body's tangent indefinite (a pressed point on a convex obstacle whose body gives way
// along it: the filleted punch on the plastic block, bench/results/prandtl-fillet.md). For
// cev's default loop (set_indefinite_turning) the compliance still carries them, from an LU
// factorization: T^T K_t^-1 T, indefinite; otherwise the body's own T^T K^-1 T.
TEST(Compliance, WithAnIndefiniteTurningSumIsStillTheExactLinearizationForCev) {
  Problem problem = beam_over(make_circle({3, -1.3}, 1), 0.0);
  for (int d : {1, 2}) problem.constraints.push_back({TimoshenkoBeam::node_dof(0, d), 0.0});  // clamped
  Equilibrium eq(problem, NewtonParams{});
  eq.set_step({0.7}, std::vector<double>(problem.candidates.size(), 0.0));
  EquilibriumState state = eq.evaluate(Vector::Zero(problem.body->dof_count()));
  state.p = Vector::Zero(problem.component_count);
  std::vector<int> pressed;
  for (const Candidate& c : problem.candidates)
    if (state.enabled[c.eta]) {
      state.p[c.eta] = -2.0;
      pressed.push_back(c.eta);
    }
  ASSERT_GE(pressed.size(), 4u);
  const Matrix exact = dense_compliance(problem, eq, state, pressed, &state.p);
  const Matrix body_only = dense_compliance(problem, eq, state, pressed);
  const Eigen::SelfAdjointEigenSolver<Matrix> modes(exact);
  EXPECT_LT(modes.eigenvalues().minCoeff(), 0.0);                    // indefinite: no Cholesky of K_t
  const Matrix definite_only = eq.compliance(state, pressed).block;  // the default: not indefinite
  EXPECT_FALSE(eq.compliance_turns());
  EXPECT_LT((definite_only - body_only).norm(), 1e-10 * body_only.norm());
  eq.set_indefinite_turning(true);
  const Matrix C = eq.compliance(state, pressed).block;
  EXPECT_TRUE(eq.compliance_turns());
  const double off_exact = (C - exact).norm() / exact.norm(), turning = (exact - body_only).norm() / exact.norm();
  std::printf("indefinite: |C - T^T K_t^-1 T| = %.3g, the turning terms' share %.3g, smallest eigenvalue %.3g\n",
              off_exact, turning, modes.eigenvalues().minCoeff());
  EXPECT_LT(off_exact, 1e-10);
  EXPECT_GT(turning, 1e-3);
}

// A constant tangent: one factorization and one G serve every call, whatever the state.
TEST(Compliance, ConstantTangentFormsGOnce) {
  const Scene scene = coarse_half_disc("linear");
  Equilibrium eq(scene.problem, NewtonParams{});
  std::vector<int> all;
  for (int a = 0; a < scene.problem.component_count; ++a) all.push_back(a);
  for (const double size : {0.0, 0.01, 0.02}) {
    eq.set_step({1.0}, std::vector<double>(scene.problem.candidates.size(), 0.0));
    const EquilibriumState state = eq.evaluate(small_random_displacement(scene.problem, size));
    std::vector<int> enabled;
    for (int a : all)
      if (state.enabled[a]) enabled.push_back(a);
    const Matrix reference = dense_compliance(scene.problem, eq, state, enabled);
    EXPECT_LT((eq.compliance(state, enabled).block - reference).norm(), 1e-12 * reference.norm());
  }
  EXPECT_EQ(eq.counters().compliance_forms, 1);
  EXPECT_EQ(eq.counters().factorizations, 1);
}

}  // namespace
}  // namespace grip
