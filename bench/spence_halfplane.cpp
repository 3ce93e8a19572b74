// Issue 15, the frictional Hertz check: the same problem on an elastic half-plane by the
// boundary-element model of tests/support/spence_halfplane.hpp, to tell the coupling and a
// finite cylinder's effect from the relation's. Prints c/a by the stick set and by the
// 0.99 mu p rule.
//   build/tests/bench/spence_halfplane mu per_a increments coupled Rc   (built with the project)
//   e.g. build/tests/bench/spence_halfplane 0.3 80 100 1 20
// Measured (nu = 0.3, mu = 0.3, a/h = 80, 100 increments; a/h = 40 and 50 increments the same,
// a/h 120 and 160 the same):
//   uncoupled, half-plane:  stick set 0.750 (a/h 160: 0.744 = K'/K relation), 0.99 rule 0.713
//   coupled, half-plane:    stick set 0.692, 0.99 rule 0.667; a 2.5 % below Hertz, peak +8 %
//   coupled, Rc = 20 (the half-disc scene's R / a): stick set 0.744, 0.99 rule 0.718
//   coupled, Rc = 10: stick set 0.795, 0.99 rule 0.769
#include <cstdio>
#include <cstdlib>

#include "tests/support/spence_halfplane.hpp"

int main(int argc, char** argv) {
  const double mu = argc > 1 ? atof(argv[1]) : 0.3;
  const int per_a = argc > 2 ? atoi(argv[2]) : 40, increments = argc > 3 ? atoi(argv[3]) : 50;
  const bool coupled = argc > 4 ? atoi(argv[4]) : 1;
  const double Rc = argc > 5 ? atof(argv[5]) : 0.0;
  const grip::testing::HalfPlaneSpence r = grip::testing::spence_half_plane(mu, 0.3, per_a, increments, coupled, Rc);
  std::printf("  stick set: c/a %.4f\n", r.c_stick / r.a);
  std::printf("active-set iterations %d (200: not settled): a %.4f (Hertz 1), c %.4f, c/a %.4f by the 0.99 rule; "
              "peak %.4f of Hertz's p0\n",
              r.iterations, r.a, r.c_rule, r.c_rule / r.a, r.peak);
}
