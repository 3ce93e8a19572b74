#pragma once
// A plane beam of rectangular section on a uniform mesh: the setup of the beam element tests.
#include <vector>

#include "solver/elements/straight_beam.hpp"

namespace grip::testing {

// E, nu; width out of plane, depth in plane; shear correction 5/6.
inline BeamSection rectangular_section(double E, double nu, double width, double depth) {
  const double G = E / (2 * (1 + nu));
  return {E * width * depth, E * width * depth * depth * depth / 12, 5.0 / 6.0 * G * width * depth, depth / 2, width};
}

inline std::vector<double> uniform_abscissae(double length, int elements) {
  std::vector<double> x;
  for (int i = 0; i <= elements; ++i) x.push_back(length * i / elements);
  return x;
}

}  // namespace grip::testing
