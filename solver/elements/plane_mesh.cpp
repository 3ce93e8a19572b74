#include "solver/elements/plane_mesh.hpp"

#include "solver/elements/corner_angles.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace grip {
namespace {

// The corners of an element of `nodes` nodes: 3 for t3 and t6, 4 for q4, q8 and q9.
int corners_of(size_t nodes) { return nodes == 3 || nodes == 6 ? 3 : 4; }

std::string point_text(const Vec2& p) {
  std::ostringstream os;
  os << "(" << p.x() << ", " << p.y() << ")";
  return os.str();
}

// Integral of each node's shape function along a side (2 or 3 nodes), by 3-point Gauss.
// Per node of a side: the integral of its shape function along the side, and the same weighted
// by 2 pi r (r = x: the area it sweeps revolved about the axis x = 0). 3-point Gauss: exact on
// straight sides, where r is linear along the side.
std::array<std::array<double, 3>, 2> side_weights(const PlaneMesh& mesh, const std::vector<int>& side) {
  static const double g[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, w[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  const bool quadratic = side.size() == 3;
  std::array<std::array<double, 3>, 2> out{};
  for (int k = 0; k < 3; ++k) {
    const double s = g[k];
    const double N[3] = {quadratic ? 0.5 * s * (s - 1) : 0.5 * (1 - s), quadratic ? 1 - s * s : 0.5 * (1 + s),
                         quadratic ? 0.5 * s * (s + 1) : 0.0};
    const double dN[3] = {quadratic ? s - 0.5 : -0.5, quadratic ? -2 * s : 0.5, quadratic ? s + 0.5 : 0.0};
    Vec2 x = Vec2::Zero(), dx = Vec2::Zero();
    for (size_t a = 0; a < side.size(); ++a) {
      x += N[a] * mesh.nodes[side[a]];
      dx += dN[a] * mesh.nodes[side[a]];
    }
    for (size_t a = 0; a < side.size(); ++a) {
      out[0][a] += w[k] * N[a] * dx.norm();
      out[1][a] += w[k] * N[a] * dx.norm() * 2 * std::numbers::pi * x.x();
    }
  }
  // A quadratic side's corner on the axis: 2 pi r N_a integrates to 0 on a straight side, and on
  // a curved one to a sliver set by the side's curvature, not by what the node carries: no share.
  if (quadratic)
    for (int a : {0, 2})
      if (mesh.nodes[side[a]].x() == 0.0) out[1][a] = 0.0;
  return out;
}

// Connected parts of the mesh (elements sharing a node): the part of each node, -1 if none;
// parts numbered in the order of their first node.
std::vector<int> node_parts(const PlaneMesh& mesh, int& count) {
  std::vector<int> parent(mesh.nodes.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];  // path halving
    return i;
  };
  std::vector<char> used(mesh.nodes.size(), 0);
  for (const auto& e : mesh.elements)
    for (int a : e) {
      used[a] = 1;
      parent[root(a)] = root(e.front());
    }
  std::vector<int> part(mesh.nodes.size(), -1), index(mesh.nodes.size(), -1);  // index: of a root
  count = 0;
  for (size_t i = 0; i < part.size(); ++i)
    if (used[i]) {
      int& k = index[root(static_cast<int>(i))];
      if (k < 0) k = count++;
      part[i] = k;
    }
  return part;
}

// Coordinates from `focus` outward over `length`: n_fine divisions of the fine zone, then n_coarse
// growing geometrically with the first matching the fine spacing.
std::vector<double> one_sided(double length, double fine_length, int n_fine, int n_coarse) {
  std::vector<double> x{0.0};
  const double h = n_fine > 0 ? fine_length / n_fine : 0.0;
  for (int k = 1; k <= n_fine; ++k) x.push_back(fine_length * k / n_fine);
  const double rest = length - fine_length;
  if (n_coarse == 0) return x;
  // Growth r with h (r + r^2 + ... + r^n) = rest; h = 0 (no fine zone): uniform.
  double r = 1.0;
  if (h > 0) {
    auto sum = [&](double g) {
      double s = 0.0, p = 1.0;
      for (int k = 0; k < n_coarse; ++k) s += (p *= g);
      return h * s;
    };
    double lo = 1e-6, hi = 2.0;
    while (sum(hi) < rest) hi *= 2;
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi);
      (sum(mid) < rest ? lo : hi) = mid;
    }
    r = 0.5 * (lo + hi);
  }
  double step = h > 0 ? h : rest / n_coarse, pos = fine_length;
  for (int k = 1; k <= n_coarse; ++k) {
    if (h > 0) step *= r;
    pos = k == n_coarse ? length : pos + step;
    x.push_back(pos);
  }
  return x;
}

// A structured mesh of ni x nj q4 or q9 elements on a grid of (m ni + 1) x (m nj + 1) nodes
// (m = 1 for q4, 2 for q9), node (I, J) at `at(I, J)`, I along the first and J along the
// second direction (a right-handed pair gives counter-clockwise elements).
PlaneMesh grid_mesh(int ni, int nj, ElementShape shape, const std::function<Vec2(int, int)>& at) {
  const int m = shape == ElementShape::q4 ? 1 : 2, NI = m * ni + 1, NJ = m * nj + 1;
  PlaneMesh mesh;
  for (int J = 0; J < NJ; ++J)
    for (int I = 0; I < NI; ++I) mesh.nodes.push_back(at(I, J));
  auto id = [&](int I, int J) { return J * NI + I; };
  for (int j = 0; j < nj; ++j)
    for (int i = 0; i < ni; ++i) {
      const int I = m * i, J = m * j;
      if (shape == ElementShape::q4) mesh.elements.push_back({id(I, J), id(I + 1, J), id(I + 1, J + 1), id(I, J + 1)});
      else
        mesh.elements.push_back({id(I, J), id(I + 2, J), id(I + 2, J + 2), id(I, J + 2), id(I + 1, J), id(I + 2, J + 1),
                                 id(I + 1, J + 2), id(I, J + 1), id(I + 1, J + 1)});
    }
  return mesh;
}

// Grid node ids along an edge of the grid, from (I0, J0) in steps (dI, dJ), `count` nodes.
std::vector<int> grid_line(int NI, int I0, int J0, int dI, int dJ, int count) {
  std::vector<int> ids;
  for (int k = 0; k < count; ++k) ids.push_back((J0 + k * dJ) * NI + I0 + k * dI);
  return ids;
}

std::string growth_text(double growth) {
  std::ostringstream os;
  os << growth;
  return os.str();
}

// The fewest elements that cover `rest` beyond a fine zone of elements h, growing at most
// `growth`-fold from one to the next: h (r + ... + r^n) >= rest at r = growth.
int coarse_needed(double h, double rest, double growth) {
  const double r = growth;
  return std::max(1, static_cast<int>(std::ceil(std::log(1 + rest * (r - 1) / (h * r)) / std::log(r) - 1e-9)));
}

}  // namespace

std::vector<double> refine_for(ElementShape shape, const std::vector<double>& v) {
  if (!is_quadratic(shape)) return v;
  std::vector<double> out;
  for (size_t i = 0; i + 1 < v.size(); ++i) {
    out.push_back(v[i]);
    out.push_back(0.5 * (v[i] + v[i + 1]));
  }
  out.push_back(v.back());
  return out;
}

void reverse_element(std::vector<int>& element, ElementShape shape) {
  if (element_corner_count(shape) == 3) {  // 0, 2, 1 and the mid-sides of 0-2, 2-1, 1-0
    std::swap(element[1], element[2]);
    if (shape == ElementShape::t6) std::swap(element[3], element[5]);
    return;
  }
  std::swap(element[1], element[3]);  // 0, 3, 2, 1 and the mid-sides of 0-3, 3-2, 2-1, 1-0
  if (is_quadratic(shape)) {
    std::swap(element[4], element[7]);
    std::swap(element[5], element[6]);
  }
}

ElementShape grid_shape(ElementShape shape) { return is_quadratic(shape) ? ElementShape::q9 : ElementShape::q4; }

PlaneMesh quads_as(PlaneMesh quads, ElementShape shape) {
  if (shape == ElementShape::q4 || shape == ElementShape::q9) return quads;
  PlaneMesh out;
  if (shape == ElementShape::q8) {
    // Drop the centre nodes: number the others in their order.
    std::vector<int> id(quads.nodes.size(), 0);
    for (const auto& el : quads.elements) id[el[8]] = -1;
    for (size_t i = 0; i < id.size(); ++i)
      if (id[i] == 0) {
        id[i] = static_cast<int>(out.nodes.size());
        out.nodes.push_back(quads.nodes[i]);
      }
    for (const auto& el : quads.elements) {
      std::vector<int> q8;
      for (int a = 0; a < 8; ++a) q8.push_back(id[el[a]]);
      out.elements.push_back(std::move(q8));
    }
    for (const auto& [name, set] : quads.sets) {
      std::vector<int>& renumbered = out.sets[name];
      for (int i : set)
        if (id[i] >= 0) renumbered.push_back(id[i]);
    }
    return out;
  }
  out.nodes = std::move(quads.nodes);
  out.sets = std::move(quads.sets);
  for (const auto& e : quads.elements) {
    const double d02 = (out.nodes[e[2]] - out.nodes[e[0]]).norm(), d13 = (out.nodes[e[3]] - out.nodes[e[1]]).norm();
    const bool along_13 = d13 < (1 - 1e-9) * d02;
    if (shape == ElementShape::t3) {
      if (along_13) out.elements.insert(out.elements.end(), {{e[0], e[1], e[3]}, {e[1], e[2], e[3]}});
      else out.elements.insert(out.elements.end(), {{e[0], e[1], e[2]}, {e[0], e[2], e[3]}});
    } else if (along_13) {  // t6: corners, then the mid-sides (q9 node 8 on the diagonal)
      out.elements.insert(out.elements.end(),
                          {{e[0], e[1], e[3], e[4], e[8], e[7]}, {e[1], e[2], e[3], e[5], e[6], e[8]}});
    } else {
      out.elements.insert(out.elements.end(),
                          {{e[0], e[1], e[2], e[4], e[5], e[8]}, {e[0], e[2], e[3], e[8], e[6], e[7]}});
    }
  }
  return out;
}

namespace {

// det of J = X^T dN (as element_point's detJ) for an element of N nodes x with the natural
// derivatives dN at one point, summed node by node in plain doubles (check_mesh for the 11,520
// elements of Hertz a/h 40: 10.8 M instructions with Eigen's dynamic-size rows and a sort of
// each element's ids, 8.6 M so).
template <int N>
double det_j(const Vec2* x, const Vec2* dN) {
  double j00 = 0.0, j01 = 0.0, j10 = 0.0, j11 = 0.0;
  for (int a = 0; a < N; ++a) {
    j00 += x[a].x() * dN[a].x();
    j01 += x[a].x() * dN[a].y();
    j10 += x[a].y() * dN[a].x();
    j11 += x[a].y() * dN[a].y();
  }
  return j00 * j11 - j10 * j01;
}

double det_j(int n, const Vec2* x, const Vec2* dN) {
  switch (n) {
    case 3:
      return det_j<3>(x, dN);
    case 4:
      return det_j<4>(x, dN);
    case 6:
      return det_j<6>(x, dN);
    case 8:
      return det_j<8>(x, dN);
    default:
      return det_j<9>(x, dN);
  }
}

}  // namespace

std::vector<MeshIssue> check_mesh(const PlaneMesh& mesh, ElementShape shape) {
  std::vector<MeshIssue> issues;
  const int n = element_node_count(shape), nodes = static_cast<int>(mesh.nodes.size());
  // det J at the element's nodes and Gauss points, from the shape functions' natural
  // derivatives there (the same for every element: computed once, not per element).
  std::vector<Vec2> checks;
  for (int a = 0; a < n; ++a) checks.push_back(node_natural(shape, a));
  for (const GaussPoint& g : gauss_rule(shape)) checks.push_back({g.xi, g.eta});
  // dN[c * n + a]: node a's natural derivatives at check point c.
  std::vector<Vec2> dN(checks.size() * n);
  Vector N;
  ShapeGradients dN_c;
  for (size_t c = 0; c < checks.size(); ++c) {
    shape_functions(shape, checks[c].x(), checks[c].y(), N, dN_c);
    for (int a = 0; a < n; ++a) dN[c * n + a] = dN_c.row(a).transpose();
  }
  std::vector<char> used(mesh.nodes.size(), 0);
  Vec2 x[9];  // the element's nodes
  for (int e = 0; e < static_cast<int>(mesh.elements.size()); ++e) {
    const auto& el = mesh.elements[e];
    if (static_cast<int>(el.size()) != n) {
      issues.push_back({e, -1,
                        "has " + std::to_string(el.size()) + " nodes; a " + shape_name(shape) + " element has " +
                            std::to_string(n)});
      continue;
    }
    bool ids_ok = true;
    for (int a : el)
      if (a < 0 || a >= nodes) {
        issues.push_back({e, -1, "names node " + std::to_string(a) + ", which does not exist"});
        ids_ok = false;
      } else {
        used[a] = 1;  // even in a faulty element: one fault, one message
      }
    if (!ids_ok) continue;
    bool repeated = false;  // at most 9 ids: pairs, not a sort
    for (int a = 1; a < n; ++a)
      for (int b = 0; b < a; ++b) repeated |= el[a] == el[b];
    if (repeated) {
      issues.push_back({e, -1, "names a node twice"});
      continue;
    }
    for (int a = 0; a < n; ++a) x[a] = mesh.nodes[el[a]];
    Vec2 lo = x[0], hi = lo;
    for (int a = 1; a < n; ++a) {
      lo = lo.cwiseMin(x[a]);
      hi = hi.cwiseMax(x[a]);
    }
    const double size2 = (hi - lo).squaredNorm();
    for (size_t c = 0; c < checks.size(); ++c) {
      const double det = det_j(n, x, &dN[c * n]);
      if (!(det > 1e-12 * size2)) {
        issues.push_back(
            {e, -1,
             std::string(det < 0 ? "is inverted or its nodes are not counter-clockwise" : "has zero area") +
                 " (det J = " + std::to_string(det) + " at xi, eta = " + point_text(checks[c]) + ")"});
        break;
      }
    }
  }
  for (int i = 0; i < nodes; ++i)
    if (!used[i]) issues.push_back({-1, i, "belongs to no element"});
  return issues;
}

InvalidMesh::InvalidMesh(std::vector<MeshIssue> all)
    : std::invalid_argument((all.at(0).element >= 0 ? "element " + std::to_string(all[0].element)
                                                    : "node " + std::to_string(all[0].node)) +
                            " " + all[0].detail),
      issues(std::move(all)) {}

namespace {

// The boundary sides (boundary_sides) whose end nodes both have (*in)[node] set (all sides
// without `in`), in the order of their sorted end nodes.
std::vector<std::vector<int>> boundary_sides_within(const PlaneMesh& mesh, ElementShape shape,
                                                    const std::vector<char>* in) {
  // Every element side by its end nodes, sorted (a vector, not a map); the sides that appear
  // once. Whether a side is on the boundary depends on its end nodes only, so the sides outside
  // `in` are left out before the sort (a contact set's: 200 of the 46,000 sides of Hertz a/h 40,
  // whose full sort took 11 M instructions at every scene read).
  struct Side {
    std::pair<int, int> key;
    int element, local;
  };
  const auto& locals = element_sides(shape);
  std::vector<Side> all;
  if (!in) all.reserve(mesh.elements.size() * locals.size());
  for (int e = 0; e < static_cast<int>(mesh.elements.size()); ++e)
    for (int l = 0; l < static_cast<int>(locals.size()); ++l) {
      const auto& el = mesh.elements[e];
      const int a = el[locals[l].front()], b = el[locals[l].back()];
      if (!in || ((*in)[a] && (*in)[b])) all.push_back({std::minmax(a, b), e, l});
    }
  std::sort(all.begin(), all.end(), [](const Side& a, const Side& b) { return a.key < b.key; });
  std::vector<std::vector<int>> sides;
  for (size_t k = 0; k < all.size();) {
    size_t end = k + 1;
    while (end < all.size() && all[end].key == all[k].key) ++end;
    if (end == k + 1) {
      std::vector<int> side;
      for (int a : locals[all[k].local]) side.push_back(mesh.elements[all[k].element][a]);
      sides.push_back(side);
    }
    k = end;
  }
  return sides;
}

}  // namespace

std::vector<std::vector<int>> boundary_sides(const PlaneMesh& mesh, ElementShape shape) {
  return boundary_sides_within(mesh, shape, nullptr);
}

BoundaryPart boundary_part(const PlaneMesh& mesh, ElementShape shape, const std::vector<int>& set) {
  const size_t nodes = mesh.nodes.size();
  std::vector<char> in(nodes, 0);
  for (int i : set) in.at(i) = 1;
  BoundaryPart part;
  // Per node (vectors, not maps and sets: 15 M instructions for the 2000-node contact set of a
  // flat): the next node along the boundary (body on the left), whether a side leads in,
  // whether a side holds it, and its tributary length.
  std::vector<int> next(nodes, -1);
  std::vector<char> has_previous(nodes, 0), on_side(nodes, 0);
  std::vector<double> length(nodes, 0.0), revolved(nodes, 0.0);
  for (auto& side : boundary_sides_within(mesh, shape, &in)) {
    if (!std::all_of(side.begin(), side.end(), [&](int a) { return in[a] != 0; }))
      continue;  // a quadratic side's middle
    const auto w = side_weights(mesh, side);
    for (size_t a = 0; a < side.size(); ++a) {
      length[side[a]] += w[0][a];
      revolved[side[a]] += w[1][a];
      on_side[side[a]] = 1;
    }
    for (size_t a = 0; a + 1 < side.size(); ++a) {
      if (next[side[a]] < 0) next[side[a]] = side[a + 1];
      has_previous[side[a + 1]] = 1;
    }
    part.sides.push_back(std::move(side));
  }
  for (int i : set)
    if (!on_side[i])
      throw std::invalid_argument("node " + std::to_string(i) +
                                  " lies on no boundary side whose nodes all belong to the set");
  // Runs start where no side leads in (then closed loops, at their smallest node).
  std::vector<int> starts;
  for (size_t i = 0; i < nodes; ++i)
    if (on_side[i] && !has_previous[i]) starts.push_back(static_cast<int>(i));
  for (size_t i = 0; i < nodes; ++i)
    if (on_side[i]) starts.push_back(static_cast<int>(i));
  std::vector<char> visited(nodes, 0);
  for (int s : starts)
    for (int i = s; !visited[i]; i = next[i]) {
      visited[i] = 1;
      part.nodes.push_back(i);
      part.lengths.push_back(length[i]);
      part.revolved_areas.push_back(revolved[i]);
      if (next[i] < 0) break;
    }
  return part;
}

ElementQuality element_quality(const PlaneMesh& mesh) {
  ElementQuality q{.elements = static_cast<int>(mesh.elements.size()),
                   .max_aspect_ratio = 0.0,
                   .min_angle = 180.0,
                   .max_angle = 0.0};
  if (mesh.elements.empty()) return {};
  const double degrees = 180.0 / std::acos(-1.0);
  for (const auto& el : mesh.elements) {
    double shortest = std::numeric_limits<double>::infinity(), longest = 0.0;
    const int n = corners_of(el.size());
    for (int a = 0; a < n; ++a) {
      const Vec2& here = mesh.nodes[el[a]];
      const Vec2 next = mesh.nodes[el[(a + 1) % n]] - here, previous = mesh.nodes[el[(a + n - 1) % n]] - here;
      shortest = std::min(shortest, next.norm());
      longest = std::max(longest, next.norm());
      const double angle = std::atan2(std::abs(next.x() * previous.y() - next.y() * previous.x()), next.dot(previous));
      q.min_angle = std::min(q.min_angle, angle * degrees);
      q.max_angle = std::max(q.max_angle, angle * degrees);
    }
    q.max_aspect_ratio = std::max(q.max_aspect_ratio, longest / shortest);
  }
  return q;
}

bool corner_angles_within(const PlaneMesh& mesh, double lo, double hi) {
  // A corner's angle is atan2(cross, dot) of its sides (element_quality); it lies above the
  // angle a when the corner (dot, cross) turns counter-clockwise from (cos a, sin a). That sign
  // decides where the corner is more than 1e-12 radians from the limit, far beyond the
  // rounding of either, and atan2 in degrees, element_quality's value, decides the rest.
  const double degrees = 180.0 / std::acos(-1.0);
  const Vec2 lo_dir(std::cos(lo / degrees), std::sin(lo / degrees)),
      hi_dir(std::cos(hi / degrees), std::sin(hi / degrees));
  for (const auto& el : mesh.elements)
    for (int a = 0, n = corners_of(el.size()); a < n; ++a) {
      const Vec2& here = mesh.nodes[el[a]];
      const Vec2 next = mesh.nodes[el[(a + 1) % n]] - here, previous = mesh.nodes[el[(a + n - 1) % n]] - here;
      const Vec2 corner(next.dot(previous), std::abs(next.x() * previous.y() - next.y() * previous.x()));
      const double above_lo = lo_dir.x() * corner.y() - lo_dir.y() * corner.x();
      const double above_hi = hi_dir.x() * corner.y() - hi_dir.y() * corner.x();
      const double margin2 = 1e-24 * corner.squaredNorm();
      if (above_lo * above_lo > margin2 && above_hi * above_hi > margin2) {
        if (above_lo < 0 || above_hi > 0) return false;
        continue;
      }
      const double angle = std::atan2(corner.y(), corner.x()) * degrees;
      if (!(angle >= lo && angle <= hi)) return false;
    }
  return true;
}

std::string free_rigid_motion(const PlaneMesh& mesh, const std::vector<char>& fixed_dof) {
  int parts = 0;
  const std::vector<int> part = node_parts(mesh, parts);
  std::vector<std::string> found;
  for (int k = 0; k < parts; ++k) {
    // The part's centre and size scale the rotation mode.
    Vec2 lo = Vec2::Constant(1e300), hi = -lo;
    for (size_t i = 0; i < part.size(); ++i)
      if (part[i] == k) {
        lo = lo.cwiseMin(mesh.nodes[i]);
        hi = hi.cwiseMax(mesh.nodes[i]);
      }
    const Vec2 c = 0.5 * (lo + hi);
    const double L = std::max((hi - lo).norm(), 1e-300);
    // Rows: the fixed dofs; columns: translation x, translation y, rotation about c.
    Eigen::Matrix3d G = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < part.size(); ++i) {
      if (part[i] != k) continue;
      const Vec2 r = (mesh.nodes[i] - c) / L;
      for (int d = 0; d < 2; ++d) {
        if (!fixed_dof[2 * i + d]) continue;
        const Eigen::Vector3d row = d == 0 ? Eigen::Vector3d(1, 0, -r.y()) : Eigen::Vector3d(0, 1, r.x());
        G += row * row.transpose();
      }
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(G);
    const double scale = std::max(1.0, eig.eigenvalues().maxCoeff());
    std::vector<Eigen::Vector3d> null;
    for (int m = 0; m < 3; ++m)
      if (eig.eigenvalues()[m] <= 1e-10 * scale) null.push_back(eig.eigenvectors().col(m));
    if (null.empty()) continue;
    auto in_null = [&](const Eigen::Vector3d& v) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (const auto& nv : null) p += nv.dot(v) * nv;
      return p;
    };
    std::vector<std::string> motions;
    bool tx = false, ty = false;
    if ((in_null(Eigen::Vector3d::UnitX()) - Eigen::Vector3d::UnitX()).norm() < 1e-6) {
      motions.push_back("translate along x");
      tx = true;
    }
    if ((in_null(Eigen::Vector3d::UnitY()) - Eigen::Vector3d::UnitY()).norm() < 1e-6) {
      motions.push_back("translate along y");
      ty = true;
    }
    if (static_cast<int>(null.size()) > static_cast<int>(tx) + static_cast<int>(ty)) {
      Eigen::Vector3d v = in_null(Eigen::Vector3d::UnitZ());
      if (v.norm() < 1e-6) v = null.front();
      if (tx) v.x() = 0;
      if (ty) v.y() = 0;
      if (std::abs(v.z()) > 1e-6 * v.norm()) {
        // a ex + b ey + w (rotation about c) is a rotation about c + L (-b, a) / w.
        const Vec2 pivot = c + L * Vec2(-v.y(), v.x()) / v.z();
        motions.push_back("rotate about " + point_text(pivot));
      } else {
        motions.push_back("translate along " + point_text(v.head<2>().normalized()));
      }
    }
    std::string text;
    for (size_t m = 0; m < motions.size(); ++m)
      text += (m ? m + 1 == motions.size() ? " and " : ", " : "") + motions[m];
    if (parts > 1)
      text = "the part containing node " + std::to_string(std::find(part.begin(), part.end(), k) - part.begin()) +
             " can " + text;
    found.push_back(text);
  }
  std::string all;
  for (size_t m = 0; m < found.size(); ++m) all += (m ? "; " : "") + found[m];
  return all;
}

std::vector<double> graded_divisions(double lo, double hi, int n, std::optional<double> focus,
                                     const std::optional<Refinement>& refine, double max_growth) {
  std::vector<double> x;
  if (!refine || !focus) {
    for (int k = 0; k <= n; ++k) x.push_back(lo + (hi - lo) * k / n);
    return x;
  }
  const double f = std::clamp(*focus, lo, hi);
  const double len[2] = {f - lo, hi - f};  // below and above the focus
  int fine[2], coarse[2] = {0, 0};
  double fine_len[2], coarse_len[2];
  int coarse_total = n, sides_needing = 0, needed[2] = {0, 0};
  for (int s = 0; s < 2; ++s) {
    fine_len[s] = std::min(refine->extent, len[s]);
    fine[s] = fine_len[s] > 0 ? std::max(1, static_cast<int>(std::lround(fine_len[s] / refine->size))) : 0;
    coarse_len[s] = len[s] - fine_len[s];
    coarse_total -= fine[s];
    if (coarse_len[s] > 1e-12 * (hi - lo)) {
      ++sides_needing;
      needed[s] = fine[s] > 0 ? coarse_needed(fine_len[s] / fine[s], coarse_len[s], max_growth) : 1;
    }
  }
  if (coarse_total < needed[0] + needed[1])
    throw std::invalid_argument(std::to_string(n) + " divisions cannot hold the refinement: it takes " +
                                std::to_string(n - coarse_total) + " within the extent and " +
                                std::to_string(needed[0] + needed[1]) + " more outside it (elements growing at most " +
                                growth_text(max_growth) + "-fold): give at least " +
                                std::to_string(n - coarse_total + needed[0] + needed[1]));
  const double total_coarse_len = coarse_len[0] + coarse_len[1];
  if (sides_needing == 2) {
    coarse[0] = std::clamp(static_cast<int>(std::lround(coarse_total * coarse_len[0] / total_coarse_len)), needed[0],
                           coarse_total - needed[1]);
    coarse[1] = coarse_total - coarse[0];
  } else if (sides_needing == 1) {
    coarse[coarse_len[0] > coarse_len[1] ? 0 : 1] = coarse_total;
  } else if (coarse_total > 0) {
    throw std::invalid_argument("the refinement extent covers the whole length: give fewer divisions (" +
                                std::to_string(n - coarse_total) + ")");
  }
  const std::vector<double> below = one_sided(len[0], fine_len[0], fine[0], coarse[0]);
  const std::vector<double> above = one_sided(len[1], fine_len[1], fine[1], coarse[1]);
  for (auto it = below.rbegin(); it != below.rend(); ++it) x.push_back(f - *it);
  for (size_t k = 1; k < above.size(); ++k) x.push_back(f + above[k]);
  x.front() = lo;
  x.back() = hi;
  return x;
}

PlaneMesh rectangle_mesh(const RectangleSpec& spec, ElementShape shape) {
  const Vec2 o = spec.origin, s = spec.size;
  const std::vector<double> x =
      refine_for(shape, graded_divisions(o.x(), o.x() + s.x(), spec.nx, spec.towards.x(), spec.refine));
  const std::vector<double> y =
      refine_for(shape, graded_divisions(o.y(), o.y() + s.y(), spec.ny, spec.towards.y(), spec.refine));
  PlaneMesh mesh = grid_mesh(spec.nx, spec.ny, grid_shape(shape), [&](int I, int J) { return Vec2(x[I], y[J]); });
  const int NI = static_cast<int>(x.size()), NJ = static_cast<int>(y.size());
  mesh.sets["bottom"] = grid_line(NI, 0, 0, 1, 0, NI);
  mesh.sets["right"] = grid_line(NI, NI - 1, 0, 0, 1, NJ);
  mesh.sets["top"] = grid_line(NI, NI - 1, NJ - 1, -1, 0, NI);
  mesh.sets["left"] = grid_line(NI, 0, NJ - 1, 0, -1, NJ);
  return quads_as(std::move(mesh), shape);
}

}  // namespace grip
