// Element checks of the geometrically exact beam (solver/elements/reissner_beam.hpp): its
// tangent against finite differences of its force at large rotations, finite rigid motions
// that leave it unstrained, and no shear locking at L/t = 1000.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <cmath>
#include <random>

#include "solver/elements/reissner_beam.hpp"
#include "tests/support/beam_section.hpp"
#include "tests/support/tangent_check.hpp"

namespace grip {
namespace {

using testing::assembled_tangent;
using testing::internal_force;
using testing::rectangular_section;
using testing::uniform_abscissae;

class ReissnerBeamElements : public ::testing::TestWithParam<BeamElement> {};

// At a state with rotations up to 1.5 rad and strains of a few per cent, the tangent (material
// and geometric) is the central difference of the force to the difference's own error.
TEST_P(ReissnerBeamElements, TangentEqualsFiniteDifferenceOfForce) {
  const ReissnerBeam beam(uniform_abscissae(10, 4), 0.3, rectangular_section(2e5, 0.3, 1, 0.5), GetParam());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> small(-0.3, 0.3), angle(-1.5, 1.5);
  Vector q(beam.dof_count());
  for (int i = 0; i < q.size(); ++i) q[i] = i % 3 == 2 ? angle(rng) : small(rng);
  const double h = 1e-6;
  const testing::TangentCheck c = testing::check_tangent(beam, q, h);
  EXPECT_LT(c.error(), 1e-8);
  EXPECT_LT(c.asymmetry(), 1e-12);  // a potential: symmetric
  const Matrix& K = c.K;
  // And the force is the gradient of the strain energy: a directional difference of the force
  // along a random direction is K times that direction, however far q is from the reference.
  Vector d(q.size());
  for (int i = 0; i < d.size(); ++i) d[i] = small(rng);
  const Vector df = (internal_force(beam, q + h * d) - internal_force(beam, q - h * d)) / (2 * h);
  EXPECT_LT((df - K * d).norm(), 1e-8 * (K * d).norm());
}

// A finite rigid motion (turn by 2.5 rad about a point off the axis, then a translation) of a
// bent state leaves its strains, so its force turned along with it; of the straight beam no force.
TEST_P(ReissnerBeamElements, FiniteRigidMotionLeavesTheStrains) {
  const double y0 = 0.4;
  const ReissnerBeam beam(uniform_abscissae(10, 5), y0, rectangular_section(2e5, 0.3, 1, 0.5), GetParam());
  const int nodes = beam.dof_count() / 3;
  // Reference positions of every node (ends, then mid nodes).
  std::vector<double> X(nodes);
  for (int k = 0; k < nodes; ++k) X[k] = k < beam.node_count() ? 2.0 * k : 2.0 * (k - beam.node_count()) + 1.0;
  const double c = 2.5, cs = std::cos(c), sn = std::sin(c);
  const Vec2 centre(1.0, -2.0), shift(0.3, -0.7);
  auto moved = [&](const Vector& q) {
    Vector m(q.size());
    for (int k = 0; k < nodes; ++k) {
      const Vec2 x(X[k] + q[3 * k], y0 + q[3 * k + 1]);
      const Vec2 r = x - centre, turned = centre + Vec2(cs * r.x() - sn * r.y(), sn * r.x() + cs * r.y()) + shift;
      m[3 * k] = turned.x() - X[k];
      m[3 * k + 1] = turned.y() - y0;
      m[3 * k + 2] = q[3 * k + 2] - c;  // theta is clockwise
    }
    return m;
  };
  const Vector zero = Vector::Zero(beam.dof_count());
  EXPECT_LT(internal_force(beam, moved(zero)).norm(), 1e-9);
  Vector bent = zero;
  for (int k = 0; k < nodes; ++k) {
    bent[3 * k + 1] = 0.02 * X[k] * X[k];
    bent[3 * k + 2] = -0.03 * X[k];
  }
  const Vector f = internal_force(beam, bent), g = internal_force(beam, moved(bent));
  // The nodal forces turn with the beam; the moments stay.
  for (int k = 0; k < nodes; ++k) {
    const Vec2 fk(f[3 * k], f[3 * k + 1]), gk(g[3 * k], g[3 * k + 1]);
    EXPECT_LT((gk - Vec2(cs * fk.x() - sn * fk.y(), sn * fk.x() + cs * fk.y())).norm(), 1e-9 * f.norm()) << k;
    EXPECT_NEAR(g[3 * k + 2], f[3 * k + 2], 1e-9 * f.norm()) << k;
  }
  // Along the turn's rate at the state, the force only turns: (-f_y, f_x) at each node.
  const Vector rate = beam.own_rotation_at(bent);
  const double h = 1e-6;
  const Vector df = (internal_force(beam, bent + h * rate) - internal_force(beam, bent - h * rate)) / (2 * h);
  Vector turned = Vector::Zero(f.size());
  for (int k = 0; k < nodes; ++k) {
    turned[3 * k] = -f[3 * k + 1];
    turned[3 * k + 1] = f[3 * k];
  }
  EXPECT_LT((df - turned).norm(), 1e-7 * f.norm());
}

INSTANTIATE_TEST_SUITE_P(BothElements, ReissnerBeamElements, ::testing::Values(BeamElement::b2, BeamElement::b3));

// Linear response of a cantilever under a tip load: the tangent at the straight state solved
// for the tip deflection, 10 elements, L/t = 1000.
double tip_deflection(BeamElement element, int elements, double L, double t, double F) {
  const ReissnerBeam beam(uniform_abscissae(L, elements), 0.0, rectangular_section(1e7, 0.3, 1, t), element);
  const Matrix K = assembled_tangent(beam, Vector::Zero(beam.dof_count()));
  Vector f = Vector::Zero(beam.dof_count());
  f[ReissnerBeam::node_dof(elements, 1)] = F;
  std::vector<int> free;
  for (int i = 3; i < beam.dof_count(); ++i) free.push_back(i);  // node 0 clamped
  Matrix Kf(free.size(), free.size());
  Vector ff(free.size());
  for (size_t i = 0; i < free.size(); ++i) {
    ff[i] = f[free[i]];
    for (size_t j = 0; j < free.size(); ++j) Kf(i, j) = K(free[i], free[j]);
  }
  const Vector u = Kf.ldlt().solve(ff);
  return u[ReissnerBeam::node_dof(elements, 1) - 3];
}

// No shear locking: at L/t = 1000 the quadratic element's tip deflection is the Euler-Bernoulli
// F L^3 / 3EI (plus the shear term F L / kGA, 3e-7 of it) to 1e-3 with 10 elements; the
// linear element's, with its one Gauss point, is the same less its known discretisation error
// F L^3 / (12 EI n^2) (2.5e-3 relative at n = 10: it needs 16 elements for 1e-3).
TEST(ReissnerBeam, NoShearLockingAtLengthOverThickness1000) {
  const double L = 1.0, t = 1e-3, F = 1e-6, E = 1e7;
  const double EI = E * t * t * t / 12, kGA = 5.0 / 6.0 * E / 2.6 * t;
  const double bernoulli = F * L * L * L / (3 * EI), shear = F * L / kGA;
  const double b3 = tip_deflection(BeamElement::b3, 10, L, t, F);
  EXPECT_NEAR(b3, bernoulli, 1e-3 * bernoulli);
  EXPECT_NEAR(b3, bernoulli + shear, 1e-8 * bernoulli);  // nodally exact for a linear moment
  const double b2 = tip_deflection(BeamElement::b2, 10, L, t, F);
  EXPECT_NEAR(b2, bernoulli * (1 - 0.25 / 100) + shear, 1e-8 * bernoulli);
  EXPECT_NEAR(tip_deflection(BeamElement::b2, 16, L, t, F), bernoulli, 1e-3 * bernoulli);
}

}  // namespace
}  // namespace grip
