#include "solver/elements/straight_beam.hpp"

#include <stdexcept>

namespace grip {

StraightBeam::StraightBeam(std::vector<double> node_x, double y0, BeamSection section)
    : x_(std::move(node_x)), y0_(y0), section_(section) {
  if (x_.size() < 2) throw std::invalid_argument("a beam needs at least two nodes");
  for (size_t i = 1; i < x_.size(); ++i)
    if (!(x_[i] > x_[i - 1])) throw std::invalid_argument("beam node abscissae must increase");
}

Vector StraightBeam::dof_length_scales() const {
  Vector scale = Vector::Ones(dof_count());
  for (int k = 2; k < dof_count(); k += 3) scale[k] = characteristic_length();
  return scale;
}

double StraightBeam::tributary_area(int site) const {
  double length = 0.0;
  if (site > 0) length += 0.5 * (x_[site] - x_[site - 1]);
  if (site + 1 < node_count()) length += 0.5 * (x_[site + 1] - x_[site]);
  return length * section_.width;
}

std::vector<std::vector<int>> StraightBeam::cells() const {
  std::vector<std::vector<int>> c;
  for (int e = 0; e < element_count(); ++e) c.push_back({e, e + 1});
  return c;
}

FieldTable StraightBeam::site_fields(const Vector& q) const {
  FieldTable t{{"x", "y", "u", "w", "theta"}, {}};
  for (int k = 0; k < node_count(); ++k) {
    const double u = q[node_dof(k, 0)], w = q[node_dof(k, 1)];
    t.rows.push_back({x_[k] + u, y0_ + w, u, w, q[node_dof(k, 2)]});
  }
  return t;
}

void StraightBeam::add_line_load(const Vec2& per_length, double from, double to, Vector& load) const {
  over_span(from, to, [&](int e, double xi, double dx) {
    int slots[3];
    double N[3], dN[3];
    const int n = axis_shape(e, xi, slots, N, dN);
    for (int k = 0; k < n; ++k) {
      load[3 * slots[k]] += N[k] * per_length.x() * dx;
      load[3 * slots[k] + 1] += N[k] * per_length.y() * dx;
    }
  });
}

FieldTable StraightBeam::element_fields(const Vector& q) const {
  FieldTable t{{"N", "Q", "M"}, {}};
  for (int e = 0; e < element_count(); ++e) {
    const SectionForces f = section_forces(q, e);
    t.rows.push_back({f.N, f.Q, f.M});
  }
  return t;
}

}  // namespace grip
