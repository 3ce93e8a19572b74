#pragma once
// Two bending panels that show volumetric locking (tests/verification/f_bar_test.cpp,
// tests/verification/locking_test.cpp): plane strain, clamped on the left side (x = 0), a
// uniform shear traction on the right side (total force `load`, consistent nodal forces), the
// tip's vertical displacement read at the right side's top corner.
// - Cook's membrane: the trapezoid (0, 0), (48, 44), (48, 60), (0, 44), load 1;
// - a cantilever 10 x 2, load 0.01 (the tip moves about 0.15 % of the length: finite and linear
//   kinematics agree to 1e-3).
// E = 250 and a neo-Hookean law (finite kinematics) or Hooke's (linear).
#include <Eigen/CholmodSupport>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "solver/elements/continuum.hpp"

namespace grip::testing {

enum class Panel { cook, cantilever };

// n divisions along the height (Cook: n along both; the cantilever: 5 n along its length).
inline PlaneMesh panel_mesh(Panel panel, int n, ContinuumElement element) {
  RectangleSpec spec;
  spec.nx = panel == Panel::cook ? n : 5 * n;
  spec.ny = n;
  PlaneMesh mesh = rectangle_mesh(spec, element_shape(element));
  for (Vec2& x : mesh.nodes)
    x = panel == Panel::cook ? Vec2(48 * x.x(), 44 * x.x() + x.y() * (44 - 28 * x.x())) : Vec2(10 * x.x(), 2 * x.y());
  return mesh;
}

struct PanelRun {
  Panel panel = Panel::cook;
  ContinuumElement element = ContinuumElement::q4;
  Incompressibility incompressibility = Incompressibility::none;
  ContinuumKinematics kinematics = ContinuumKinematics::finite;
  double poisson = 0.4999;
};

// The tip's vertical displacement on n divisions (Newton's method to 1e-10 of the residual).
inline double panel_tip(const PanelRun& run, int n) {
  PlaneMesh mesh = panel_mesh(run.panel, n, run.element);
  const double load = run.panel == Panel::cook ? 1.0 : 0.01;
  const Vec2 tip_at = run.panel == Panel::cook ? Vec2(48, 60) : Vec2(10, 2);
  const std::vector<int> left = mesh.sets.at("left");
  std::vector<int> side = mesh.sets.at("right");
  std::sort(side.begin(), side.end(), [&](int a, int b) { return mesh.nodes[a].y() < mesh.nodes[b].y(); });
  const double height = mesh.nodes[side.back()].y() - mesh.nodes[side.front()].y();
  std::shared_ptr<const PlaneMaterial> law;
  if (run.kinematics == ContinuumKinematics::finite)
    law = std::make_shared<NeoHookeMaterial>(250.0, run.poisson, PlaneAnalysis::plane_strain);
  else law = std::make_shared<HookeMaterial>(250.0, run.poisson, PlaneAnalysis::plane_strain);
  const ContinuumBody body(mesh, mesh.sets.at("bottom"), {law},
                           {run.element, run.kinematics, PlaneAnalysis::plane_strain, 1.0, run.incompressibility});
  // Consistent nodal forces of the uniform traction along the right side's straight pieces.
  Vector f_ext = Vector::Zero(body.dof_count());
  const int stride = grid_shape(element_shape(run.element)) == ElementShape::q9 ? 2 : 1;
  for (size_t k = 0; k + stride < side.size(); k += stride) {
    const double f = load * (mesh.nodes[side[k + stride]] - mesh.nodes[side[k]]).norm() / height;
    if (stride == 2) {
      f_ext[2 * side[k] + 1] += f / 6;
      f_ext[2 * side[k + 1] + 1] += 4 * f / 6;
      f_ext[2 * side[k + 2] + 1] += f / 6;
    } else {
      f_ext[2 * side[k] + 1] += f / 2;
      f_ext[2 * side[k + 1] + 1] += f / 2;
    }
  }
  int tip = 0;
  for (size_t k = 0; k < mesh.nodes.size(); ++k)
    if ((mesh.nodes[k] - tip_at).norm() < 1e-9) tip = static_cast<int>(k);
  std::vector<int> free_index(body.dof_count(), 0);
  for (int node : left) free_index[2 * node] = free_index[2 * node + 1] = -1;
  int free = 0;
  for (int& i : free_index)
    if (i == 0) i = free++;
  Vector q = Vector::Zero(body.dof_count());
  for (int it = 0; it < 30; ++it) {
    Triplets t, tf;
    Vector f = -f_ext;
    TripletSink sink(t);
    body.internal_force(q, f, &sink);
    Vector r(free);
    for (int i = 0; i < q.size(); ++i)
      if (free_index[i] >= 0) r[free_index[i]] = f[i];
    if (r.norm() <= 1e-10 * load) break;
    tf.reserve(t.size());
    for (const auto& e : t)
      if (free_index[e.row()] >= 0 && free_index[e.col()] >= 0)
        tf.emplace_back(free_index[e.row()], free_index[e.col()], e.value());
    Eigen::SparseMatrix<double> K(free, free);
    K.setFromTriplets(tf.begin(), tf.end());
    Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> solver(K);  // supernodal: the refined q9 meshes
    const Vector dq = solver.solve(-r);
    for (int i = 0; i < q.size(); ++i)
      if (free_index[i] >= 0) q[i] += dq[free_index[i]];
  }
  return q[2 * tip + 1];
}

}  // namespace grip::testing
