// Element checks of the Timoshenko beam (Appendix B): rigid motions, consistent tangent,
// and the Timoshenko cantilever closed form.
#include <gtest/gtest.h>

#include <Eigen/SparseCore>
#include <random>

#include "solver/elements/timoshenko_beam.hpp"
#include "solver/equilibrium/equilibrium.hpp"
#include "tests/support/beam_section.hpp"
#include "tests/support/tangent_check.hpp"

namespace grip {
namespace {

using testing::assembled_tangent;
using testing::internal_force;
using testing::rectangular_section;
using testing::uniform_abscissae;

class TimoshenkoBeamKinematics : public ::testing::TestWithParam<Kinematics> {};

TEST_P(TimoshenkoBeamKinematics, RigidTranslationGivesNoForce) {
  const TimoshenkoBeam beam(uniform_abscissae(10, 5), 0.0, rectangular_section(2e5, 0.3, 1, 0.5), GetParam());
  Vector q = Vector::Zero(beam.dof_count());
  for (int k = 0; k < beam.node_count(); ++k) {
    q[TimoshenkoBeam::node_dof(k, 0)] = 0.7;
    q[TimoshenkoBeam::node_dof(k, 1)] = -1.3;
  }
  EXPECT_LT(internal_force(beam, q).norm(), 1e-9);
  // The same translation with a bending state added changes nothing.
  Vector bent = Vector::Zero(beam.dof_count());
  for (int k = 0; k < beam.node_count(); ++k) bent[TimoshenkoBeam::node_dof(k, 1)] = 0.01 * k * k;
  EXPECT_LT((internal_force(beam, bent + q) - internal_force(beam, bent)).norm(),
            1e-8 * internal_force(beam, bent).norm());
}

TEST_P(TimoshenkoBeamKinematics, TangentEqualsFiniteDifferenceOfForce) {
  const TimoshenkoBeam beam(uniform_abscissae(10, 4), 0.0, rectangular_section(2e5, 0.3, 1, 0.5), GetParam());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> dist(-0.05, 0.05);
  Vector q(beam.dof_count());
  for (int i = 0; i < q.size(); ++i) q[i] = dist(rng);
  const testing::TangentCheck c = testing::check_tangent(beam, q, 1e-6);
  EXPECT_LT(c.error(), 1e-7);
  EXPECT_LT(c.asymmetry(), 1e-12);  // a potential: symmetric
}

INSTANTIATE_TEST_SUITE_P(BothKinematics, TimoshenkoBeamKinematics,
                         ::testing::Values(Kinematics::linear, Kinematics::von_karman));

TEST(TimoshenkoBeam, LinearRigidRotationGivesNoForce) {
  const TimoshenkoBeam beam(uniform_abscissae(10, 5), 0.0, rectangular_section(2e5, 0.3, 1, 0.5), Kinematics::linear);
  const double a = 1e-3;
  Vector q = Vector::Zero(beam.dof_count());
  for (int k = 0; k < beam.node_count(); ++k) {
    q[TimoshenkoBeam::node_dof(k, 1)] = a * 10.0 * k / 5;  // w = a x
    q[TimoshenkoBeam::node_dof(k, 2)] = -a;                // theta = -dw/dx
  }
  // Compare with the force of a pure bending state of the same size.
  Vector bend = Vector::Zero(beam.dof_count());
  for (int k = 0; k < beam.node_count(); ++k) bend[TimoshenkoBeam::node_dof(k, 2)] = a * k;
  EXPECT_LT(internal_force(beam, q).norm(), 1e-12 * internal_force(beam, bend).norm());
}

// Linear cantilever under a tip load: delta = P L^3 / (3 EI) + P L / (k'GA).
TEST(TimoshenkoBeam, CantileverTipDeflectionMatchesClosedForm) {
  for (const double depth : {0.2, 4.0}) {  // slender (bending) and stubby (shear matters)
    const double L = 10;
    Problem problem;
    auto beam = std::make_unique<TimoshenkoBeam>(uniform_abscissae(L, 10), 0.0, rectangular_section(1e4, 0.3, 1, depth),
                                                 Kinematics::linear);
    const BeamSection s = beam->section();
    const double P = 0.03 * s.EI / (L * L);  // a bending deflection of L / 100
    problem.loads = {Vector::Zero(beam->dof_count())};
    problem.loads[0][TimoshenkoBeam::node_dof(10, 1)] = -P;
    for (int c = 0; c < 3; ++c) problem.constraints.push_back({TimoshenkoBeam::node_dof(0, c), 0.0});
    problem.body = std::move(beam);
    Equilibrium eq(problem, NewtonParams{});
    eq.set_step({1.0}, {});
    const EquilibriumState st = eq.solve(Vector::Zero(problem.body->dof_count()), Vector());
    ASSERT_TRUE(st.converged) << st.reason;
    const double expected = P * L * L * L / (3 * s.EI) + P * L / s.kGA;
    const double tip = -st.q[TimoshenkoBeam::node_dof(10, 1)];
    EXPECT_NEAR(tip, expected, 0.005 * expected) << "depth " << depth;
    const double shear_part = P * L / s.kGA / expected;
    if (depth > 1) EXPECT_GT(shear_part, 0.05);  // the stubby case does test the shear term
  }
}

}  // namespace
}  // namespace grip
