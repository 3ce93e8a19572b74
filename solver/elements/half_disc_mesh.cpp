// The half-disc generator: four mapped blocks, so that no block corner sits alone on the arc
// (a lone corner on a smooth arc makes an element of nearly 180 degrees there).
//
//   pole block  the arc within the refinement's extent of the pole (without a refinement, the
//               middle half of the arc), nf x np elements in polar rows down to depth D;
//   two sides   the rest of the arc on each side, from the pole block's corner S to the end of
//               the diameter, m x np elements;
//   core        from the pole block's inner arc up to the middle of the diameter, nf x m.
//
// The three outer blocks form a ring of m rows round the pole block: its rows grow away from
// the pole as the arc's divisions and the depth's do, and its np + nf + np columns end evenly
// spaced on the diameter. The ring meets the pole block's inner corners V along curves that
// leave V on the bisector of the ring's 270 degrees there, so that each side of it has about
// 135. ns = nf + 2 m divisions along the arc, nt = np + m from the pole to the centre.
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include "solver/elements/corner_angles.hpp"

namespace grip {
namespace {

// The ring's elements grow at most this much from one to the next. The load of the shipped
// Hertz scene at its prescribed displacement, against a refined mesh (q9, 4701 N/mm), at the
// fewest divisions each growth admits: 1.5-fold 0.85-0.95 % stiff at a/h 10, 20 and 40 (one
// element row fewer), 1.4-fold 0.63-0.65 %, 1.3-fold 0.48 % (a/h 10); 4-fold (the rectangle's
// limit) 8 %. The far field's coarse rows set it, not the contact zone (a and p0 move < 0.1 %).
constexpr double kRingGrowth = 1.4;

using Curve = std::function<Vec2(double)>;  // a point for each parameter in [0, 1]

Curve segment(const Vec2& a, const Vec2& b) {
  return [=](double t) { return Vec2(a + t * (b - a)); };
}

Curve circle_arc(const Vec2& centre, double radius, double from, double to) {
  return [=](double t) {
    const double angle = from + t * (to - from);
    return Vec2(centre + radius * Vec2(std::cos(angle), std::sin(angle)));
  };
}

// The curve with its parameter the fraction of its length (a table of chords).
Curve by_length(const Curve& f) {
  constexpr int n = 256;
  auto length = std::make_shared<std::vector<double>>(1, 0.0);
  for (int k = 0; k < n; ++k) length->push_back(length->back() + (f((k + 1.0) / n) - f(double(k) / n)).norm());
  return [f, length](double s) {
    const std::vector<double>& L = *length;
    const double target = std::clamp(s, 0.0, 1.0) * L.back();
    const int k = std::clamp(static_cast<int>(std::upper_bound(L.begin(), L.end(), target) - L.begin()) - 1, 0, n - 1);
    return f((k + (target - L[k]) / (L[k + 1] - L[k])) / n);
  };
}

// Nodes of a patch bounded by four curves that meet at its corners (bottom and top run from
// the left side to the right one, left and right from the bottom to the top), with the nodes
// of each side at the given parameters: the grid of lines joining matching nodes of opposite
// sides, mapped by the transfinite (Coons) blend of the four curves. Node [i][j]: i along the
// bottom, j along the left side.
std::vector<std::vector<Vec2>> patch_nodes(const Curve& bottom, const Curve& top, const Curve& left, const Curve& right,
                                           const std::vector<double>& b, const std::vector<double>& c,
                                           const std::vector<double>& l, const std::vector<double>& r) {
  const Vec2 c00 = bottom(0), c10 = bottom(1), c01 = top(0), c11 = top(1);
  std::vector<std::vector<Vec2>> out(b.size(), std::vector<Vec2>(l.size()));
  for (size_t i = 0; i < b.size(); ++i)
    for (size_t j = 0; j < l.size(); ++j) {
      // xi = (1 - eta) b + eta c and eta = (1 - xi) l + xi r: where the two lines cross.
      const double xi = (b[i] + l[j] * (c[i] - b[i])) / (1 - (c[i] - b[i]) * (r[j] - l[j]));
      const double eta = l[j] + xi * (r[j] - l[j]);
      out[i][j] = (1 - eta) * bottom(xi) + eta * top(xi) + (1 - xi) * left(eta) + xi * right(eta) -
                  ((1 - xi) * (1 - eta) * c00 + xi * (1 - eta) * c10 + (1 - xi) * eta * c01 + xi * eta * c11);
    }
  return out;
}

std::vector<double> fractions(const std::vector<double>& v) {
  std::vector<double> out;
  for (double x : v) out.push_back((x - v.front()) / (v.back() - v.front()));
  return out;
}

std::vector<double> even(int n) {
  std::vector<double> out;
  for (int k = 0; k <= n; ++k) out.push_back(static_cast<double>(k) / n);
  return out;
}

// The q4 or q9 elements of a block of node ids [i][j] (every node for q4; corners at even i, j
// for q9), counter-clockwise whichever way the block's i and j turn.
void add_block_elements(PlaneMesh& mesh, ElementShape shape, const std::vector<std::vector<int>>& ids) {
  const int step = shape == ElementShape::q4 ? 1 : 2;
  const int ni = static_cast<int>(ids.size()) - 1, nj = static_cast<int>(ids[0].size()) - 1;
  const size_t first = mesh.elements.size();
  for (int i = 0; i < ni; i += step)
    for (int j = 0; j < nj; j += step) {
      const int I = i + step, J = j + step;
      if (shape == ElementShape::q4) mesh.elements.push_back({ids[i][j], ids[I][j], ids[I][J], ids[i][J]});
      else
        mesh.elements.push_back({ids[i][j], ids[I][j], ids[I][J], ids[i][J], ids[i + 1][j], ids[I][j + 1],
                                 ids[i + 1][J], ids[i][j + 1], ids[i + 1][j + 1]});
    }
  const auto& e = mesh.elements[first];
  const Vec2 d1 = mesh.nodes[e[2]] - mesh.nodes[e[0]], d2 = mesh.nodes[e[3]] - mesh.nodes[e[1]];
  if (d1.x() * d2.y() - d1.y() * d2.x() < 0)
    for (size_t k = first; k < mesh.elements.size(); ++k) reverse_element(mesh.elements[k], shape);
}

// The half-disc of q4 or q9 elements.
PlaneMesh build_half_disc(const HalfDiscSpec& spec, ElementShape shape) {
  using std::numbers::pi;
  if (spec.ns < 4 || spec.ns % 2)
    throw std::invalid_argument("ns must be even (a node sits at the pole) and at least 4");
  const double R = spec.radius;
  const Vec2 c = spec.centre;
  // Node positions along the arc (length from the pole) and down the axis (depth below the
  // pole), graded toward the pole.
  const std::vector<double> s = graded_divisions(-pi * R / 2, pi * R / 2, spec.ns, 0.0, spec.refine, kRingGrowth);
  const std::vector<double> t = graded_divisions(0, R, spec.nt, 0.0, spec.refine, kRingGrowth);
  int half = (spec.ns / 2 + 1) / 2;
  if (spec.refine) {
    const double reach = std::min(spec.refine->extent, pi * R / 4) * (1 + 1e-9);
    half = static_cast<int>(std::count_if(s.begin(), s.end(), [&](double v) { return v > 0 && v <= reach; }));
  }
  half = std::clamp(half, 1, spec.ns / 2 - 1);
  const int nf = 2 * half, m = (spec.ns - nf) / 2, np = spec.nt - m;
  if (np < 1)
    throw std::invalid_argument("nt = " + std::to_string(spec.nt) + " leaves no row under the " + std::to_string(m) +
                                " that ring the pole block (ns - " + std::to_string(nf) +
                                " arc divisions at the pole, halved): give at least " + std::to_string(m + 1));
  // The pole block: at most half the radius deep.
  const double depth = std::min(t[np], R / 2), row_scale = depth / t[np];
  const double beta = -s[m] / R, a0 = 1.5 * pi - beta, a1 = 1.5 * pi + beta;
  const double w = R - np * 2 * R / (nf + 2 * np);  // where the ring's side blocks meet the core on the diameter
  std::vector<double> angles, rows, ring;
  for (int k = m; k <= spec.ns - m; ++k) angles.push_back(1.5 * pi + s[k] / R);
  for (int k = 0; k <= np; ++k) rows.push_back(t[k] * row_scale);
  for (int k = np; k <= spec.nt; ++k) ring.push_back(t[k]);
  const std::vector<double> rows_f = refine_for(shape, fractions(rows)), ring_f = refine_for(shape, fractions(ring));
  angles = refine_for(shape, angles);
  rows = refine_for(shape, rows);

  PlaneMesh mesh;
  auto add = [&](const Vec2& p) {
    mesh.nodes.push_back(p);
    return static_cast<int>(mesh.nodes.size()) - 1;
  };
  auto polar = [&](double radius, double angle) { return Vec2(c + radius * Vec2(std::cos(angle), std::sin(angle))); };
  const int NF = static_cast<int>(angles.size()) - 1, NP = static_cast<int>(rows.size()) - 1;
  const int M = static_cast<int>(ring_f.size()) - 1;
  std::vector<std::vector<int>> pole(NF + 1, std::vector<int>(NP + 1));
  for (int i = 0; i <= NF; ++i)
    for (int j = 0; j <= NP; ++j) pole[i][j] = add(polar(R - rows[j], angles[i]));
  add_block_elements(mesh, shape, pole);

  // The side blocks: i along the arc away from the pole block, j from the arc to the core.
  std::vector<std::vector<int>> sides[2];
  Curve interface[2];
  for (int k = 0; k < 2; ++k) {
    const double sign = k == 0 ? -1.0 : 1.0, at = 1.5 * pi + sign * beta;
    const Vec2 S = polar(R, at), V = polar(R - depth, at), W = c + Vec2(sign * w, 0);
    const Vec2 radial(std::cos(at), std::sin(at)), toward_other = -sign * Vec2(-std::sin(at), std::cos(at));
    const Vec2 bisector = -(radial + toward_other).normalized();
    const Vec2 control = V + 0.5 * (W - V).norm() * bisector;
    interface[k] =
        by_length([=](double u) { return Vec2((1 - u) * (1 - u) * V + 2 * u * (1 - u) * control + u * u * W); });
    std::vector<double> along;  // the side's arc divisions, from S to the end of the arc
    for (int q = 0; q <= m; ++q) along.push_back(std::abs(s[k == 0 ? m - q : spec.ns - m + q]));
    const auto nodes = patch_nodes(circle_arc(c, R, at, 1.5 * pi + sign * pi / 2), interface[k], segment(S, V),
                                   segment(c + Vec2(sign * R, 0), W), refine_for(shape, fractions(along)), ring_f,
                                   rows_f, refine_for(shape, even(np)));
    auto& ids = sides[k];
    ids.assign(M + 1, std::vector<int>(NP + 1));
    for (int i = 0; i <= M; ++i)
      for (int j = 0; j <= NP; ++j) ids[i][j] = i == 0 ? pole[k == 0 ? 0 : NF][j] : add(nodes[i][j]);
    add_block_elements(mesh, shape, ids);
  }

  // The core: i across, j from the pole block up to the diameter.
  const auto nodes =
      patch_nodes(circle_arc(c, R - depth, a0, a1), segment(c - Vec2(w, 0), c + Vec2(w, 0)), interface[0], interface[1],
                  fractions(angles), refine_for(shape, even(nf)), ring_f, ring_f);
  std::vector<std::vector<int>> core(NF + 1, std::vector<int>(M + 1));
  for (int i = 0; i <= NF; ++i)
    for (int j = 0; j <= M; ++j)
      core[i][j] = j == 0 ? pole[i][NP] : i == 0 ? sides[0][j][NP] : i == NF ? sides[1][j][NP] : add(nodes[i][j]);
  add_block_elements(mesh, shape, core);

  // Sets. The arc counter-clockwise (facing down): from the diameter's left end through the pole.
  std::vector<int> arc, diameter;
  for (int i = M; i >= 1; --i) arc.push_back(sides[0][i][0]);
  for (int i = 0; i <= NF; ++i) arc.push_back(pole[i][0]);
  for (int i = 1; i <= M; ++i) arc.push_back(sides[1][i][0]);
  for (int j = 0; j <= NP; ++j) diameter.push_back(sides[0][M][j]);
  for (int i = 1; i < NF; ++i) diameter.push_back(core[i][M]);
  for (int j = NP; j >= 0; --j) diameter.push_back(sides[1][M][j]);
  mesh.sets["diameter"] = diameter;
  mesh.sets["pole"] = {pole[NF / 2][0]};
  mesh.sets["centre"] = {core[NF / 2][M]};
  if (spec.facing_up) {
    // Mirror; that turns the elements clockwise: reverse them (and the arc's direction).
    for (Vec2& x : mesh.nodes) x.y() = 2 * c.y() - x.y();
    for (auto& el : mesh.elements) reverse_element(el, shape);
    std::reverse(arc.begin(), arc.end());
  }
  mesh.sets["arc"] = arc;
  if (spec.refine) {
    // The arc nodes within the refinement's extent of the pole (measured along the arc).
    const Vec2 pole_at = mesh.nodes[mesh.sets["pole"][0]] - c;
    std::vector<int>& near = mesh.sets["arc_refined"];
    for (int id : arc)
      if (R * std::acos(std::clamp((mesh.nodes[id] - c).dot(pole_at) / (R * R), -1.0, 1.0)) <=
          spec.refine->extent * (1 + 1e-9))
        near.push_back(id);
  }
  return mesh;
}

// Corner angles within this of 90 degrees. The blocks keep 45-135 at every count that holds a
// refinement; uneven counts without one can fall outside ([8, 20]: 18 rows under 2 ring rows,
// 23-162 degrees).
constexpr double kAngleSlack = 60.0;

bool well_shaped(const PlaneMesh& mesh) { return corner_angles_within(mesh, 90 - kAngleSlack, 90 + kAngleSlack); }

// The half at x >= the centre's: the blocks are symmetric about the line through the pole and
// the centre (an even number of columns on each side of it), so no element crosses it. Its
// nodes are put exactly on it, the others dropped and the sets renumbered; "axis" is added.
PlaneMesh right_half(PlaneMesh whole, const Vec2& centre, double radius) {
  const double x0 = centre.x(), slack = 1e-9 * radius;
  for (Vec2& x : whole.nodes)
    if (std::abs(x.x() - x0) <= slack) x.x() = x0;
  PlaneMesh half;
  std::vector<int> id(whole.nodes.size(), -1);
  for (const auto& el : whole.elements) {
    const bool right = std::all_of(el.begin(), el.end(), [&](int n) { return whole.nodes[n].x() >= x0; });
    if (!right) {
      if (std::any_of(el.begin(), el.end(), [&](int n) { return whole.nodes[n].x() > x0; }))
        throw std::logic_error("half_disc: an element crosses the line through the pole and the centre");
      continue;
    }
    std::vector<int> kept;
    for (int n : el) {
      if (id[n] < 0) {
        id[n] = static_cast<int>(half.nodes.size());
        half.nodes.push_back(whole.nodes[n]);
      }
      kept.push_back(id[n]);
    }
    half.elements.push_back(std::move(kept));
  }
  for (const auto& [name, set] : whole.sets) {
    std::vector<int>& renumbered = half.sets[name];
    for (int n : set)
      if (id[n] >= 0) renumbered.push_back(id[n]);
  }
  std::vector<int>& axis = half.sets["axis"];
  for (size_t n = 0; n < half.nodes.size(); ++n)
    if (half.nodes[n].x() == x0) axis.push_back(static_cast<int>(n));
  std::sort(axis.begin(), axis.end(), [&](int a, int b) { return half.nodes[a].y() < half.nodes[b].y(); });
  return half;
}

}  // namespace

PlaneMesh half_disc_mesh(const HalfDiscSpec& spec, ElementShape shape) {
  PlaneMesh mesh = build_half_disc(spec, grid_shape(shape));
  if (well_shaped(mesh))
    return quads_as(spec.right_half ? right_half(std::move(mesh), spec.centre, spec.radius) : std::move(mesh), shape);
  // Name the fewest arc divisions that shape the elements well (more arc divisions, more ring
  // rows, fewer pole block rows).
  std::string hint = "give fewer divisions from the pole to the centre";
  HalfDiscSpec more = spec;
  for (more.ns = spec.ns + 2; more.ns <= 2000; more.ns += 2) {
    try {
      if (!well_shaped(build_half_disc(more, ElementShape::q4))) continue;
    } catch (const std::invalid_argument&) {
      continue;
    }
    hint = "give at least " + std::to_string(more.ns) + " along the arc";
    break;
  }
  const ElementQuality q = element_quality(mesh);
  std::ostringstream os;
  os.precision(3);
  os << "[" << spec.ns << ", " << spec.nt << "] divisions make corner angles of " << q.min_angle << " to "
     << q.max_angle << " degrees (well shaped: " << 90 - kAngleSlack << " to " << 90 + kAngleSlack << "): " << hint;
  throw std::invalid_argument(os.str());
}

}  // namespace grip
