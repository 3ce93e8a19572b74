#pragma once
// The locking table (tests/verification/locking_test.cpp, tests/hard/locking_slow_test.cpp):
// the reference tip deflection of a panel (tests/support/locking_panels.hpp) from q9 on three
// meshes, each twice as fine, by Richardson's extrapolation at the order they show.
#include <cmath>
#include <cstdio>

#include "tests/support/locking_panels.hpp"

namespace grip::testing {

struct Extrapolated {
  double coarse = 0, middle = 0, fine = 0;  // q9 on n, 2 n, 4 n
  double order = 0, value = 0;
};

inline Extrapolated q9_reference(Panel panel, ContinuumKinematics kinematics, int n) {
  Extrapolated e;
  const PanelRun q9{panel, ContinuumElement::q9, Incompressibility::none, kinematics};
  e.coarse = panel_tip(q9, n);
  e.middle = panel_tip(q9, 2 * n);
  e.fine = panel_tip(q9, 4 * n);
  e.order = std::log2((e.middle - e.coarse) / (e.fine - e.middle));
  e.value = e.fine + (e.fine - e.middle) / (std::pow(2.0, e.order) - 1);
  std::printf("%s, %s: q9 on %d, %d, %d: %.7f %.7f %.7f; order %.2f; extrapolated %.7f (the finest %+.2f %%)\n",
              panel == Panel::cook ? "Cook" : "cantilever",
              kinematics == ContinuumKinematics::finite ? "finite" : "linear", n, 2 * n, 4 * n, e.coarse, e.middle,
              e.fine, e.order, e.value, 100 * (e.fine / e.value - 1));
  return e;
}

}  // namespace grip::testing
