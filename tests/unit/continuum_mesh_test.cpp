// Meshes of the plane continuum: the generators (areas, sets, grading), the checks of an
// element, the boundary sides of a node set with their tributary lengths, and the naming of
// free rigid motions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>

#include "solver/elements/corner_angles.hpp"
#include "solver/elements/plane_mesh.hpp"

namespace grip {
namespace {

using std::numbers::pi;

double area(const PlaneMesh& mesh, ElementShape shape) {
  double a = 0.0;
  for (const auto& el : mesh.elements) {
    ShapeGradients X(el.size(), 2);
    for (size_t k = 0; k < el.size(); ++k) X.row(k) = mesh.nodes[el[k]].transpose();
    for (const ElementPoint& p : element_points(shape, X, 1.0)) a += p.dV;
  }
  return a;
}

TEST(GradedDivisions, UniformWithoutRefinement) {
  const auto x = graded_divisions(1.0, 3.0, 4, std::nullopt, std::nullopt);
  ASSERT_EQ(x.size(), 5u);
  for (int k = 0; k <= 4; ++k) EXPECT_DOUBLE_EQ(x[k], 1.0 + 0.5 * k);
}

TEST(GradedDivisions, FineZoneThenGeometricGrowth) {
  const Refinement r{0.05, 0.5};
  const auto x = graded_divisions(-2.0, 3.0, 40, 0.0, r);
  ASSERT_EQ(x.size(), 41u);
  EXPECT_DOUBLE_EQ(x.front(), -2.0);
  EXPECT_DOUBLE_EQ(x.back(), 3.0);
  bool focus_is_node = false;
  for (size_t k = 1; k < x.size(); ++k) {
    const double h = x[k] - x[k - 1], mid = 0.5 * (x[k] + x[k - 1]);
    EXPECT_GT(h, 0);
    if (std::abs(mid) < 0.5) EXPECT_NEAR(h, 0.05, 1e-12);  // the fine zone
    if (std::abs(mid) > 0.5 && k + 1 < x.size()) {
      const double next = x[k + 1] - x[k];  // growth away from the focus
      if (mid > 0) EXPECT_GT(next, h * 0.999);
      else EXPECT_LT(next, h * 1.001);
    }
    focus_is_node |= std::abs(x[k]) < 1e-12;
  }
  EXPECT_TRUE(focus_is_node);
  EXPECT_THROW(graded_divisions(-2.0, 3.0, 20, 0.0, r), std::invalid_argument);  // 20 fine + 2 coarse needed
}

constexpr ElementShape kShapes[] = {ElementShape::t3, ElementShape::t6, ElementShape::q4, ElementShape::q8,
                                    ElementShape::q9};

TEST(RectangleMesh, AreaSetsAndOrientation) {
  for (ElementShape shape : kShapes) {
    SCOPED_TRACE(shape_name(shape));
    const bool linear = !is_quadratic(shape), triangles = element_corner_count(shape) == 3;
    RectangleSpec spec;
    spec.origin = {-1, 2};
    spec.size = {3, 1.5};
    spec.nx = 10;
    spec.ny = 6;
    spec.refine = Refinement{0.1, 0.3};
    spec.towards = {0.5, 3.5};
    const PlaneMesh mesh = rectangle_mesh(spec, shape);
    EXPECT_TRUE(check_mesh(mesh, shape).empty());
    EXPECT_EQ(mesh.elements.size(), triangles ? 120u : 60u);
    // Nodes: the grid's (without q9's 60 centres for q8).
    EXPECT_EQ(mesh.nodes.size(), linear ? 77u : shape == ElementShape::q8 ? 21u * 13 - 60 : 21u * 13);
    EXPECT_NEAR(area(mesh, shape), 4.5, 1e-12);
    for (int k : mesh.sets.at("bottom")) EXPECT_DOUBLE_EQ(mesh.nodes[k].y(), 2.0);
    for (int k : mesh.sets.at("top")) EXPECT_DOUBLE_EQ(mesh.nodes[k].y(), 3.5);
    for (int k : mesh.sets.at("left")) EXPECT_DOUBLE_EQ(mesh.nodes[k].x(), -1.0);
    for (int k : mesh.sets.at("right")) EXPECT_DOUBLE_EQ(mesh.nodes[k].x(), 2.0);
    EXPECT_EQ(mesh.sets.at("bottom").size(), linear ? 11u : 21u);
    // Refined toward (0.5, 3.5): sides of 0.1 next to that point.
    const auto& top = mesh.sets.at("top");
    bool found = false;
    for (size_t k = 1; k < top.size(); ++k) {
      const Vec2 a = mesh.nodes[top[k - 1]], b = mesh.nodes[top[k]];
      if (std::abs(std::max(a.x(), b.x()) - 0.5) < 1e-12)
        found = std::abs(std::abs(a.x() - b.x()) - (linear ? 0.1 : 0.05)) < 1e-12;
    }
    EXPECT_TRUE(found);
  }
}

// t6 from q9: each q9 split along a diagonal through its centre, the two t6 made of the q9's
// nodes; q8: the q9 without its centre. Same corner positions, same boundary sets.
TEST(RectangleMesh, TrianglesAndSerendipityFromTheQuadrilaterals) {
  RectangleSpec spec;
  spec.size = {2, 1};
  spec.nx = 2;
  spec.ny = 1;
  const PlaneMesh q9 = rectangle_mesh(spec, ElementShape::q9), t6 = rectangle_mesh(spec, ElementShape::t6);
  const PlaneMesh q8 = rectangle_mesh(spec, ElementShape::q8);
  ASSERT_EQ(t6.elements.size(), 4u);
  EXPECT_EQ(t6.nodes, q9.nodes);
  for (size_t e = 0; e < q9.elements.size(); ++e) {
    std::vector<int> both = t6.elements[2 * e];
    both.insert(both.end(), t6.elements[2 * e + 1].begin(), t6.elements[2 * e + 1].end());
    std::sort(both.begin(), both.end());
    both.erase(std::unique(both.begin(), both.end()), both.end());
    std::vector<int> nine = q9.elements[e];
    std::sort(nine.begin(), nine.end());
    EXPECT_EQ(both, nine);
  }
  ASSERT_EQ(q8.nodes.size(), q9.nodes.size() - 2);
  for (size_t e = 0; e < q9.elements.size(); ++e)
    for (int a = 0; a < 8; ++a) EXPECT_EQ(q8.nodes[q8.elements[e][a]], q9.nodes[q9.elements[e][a]]);
  for (const auto& [name, set] : q9.sets)
    for (size_t k = 0; k < set.size(); ++k) EXPECT_EQ(q8.nodes[q8.sets.at(name)[k]], q9.nodes[set[k]]) << name;
}

// Reversing an element turns it clockwise (check_mesh: inverted); reversing again restores it.
TEST(ReverseElement, TurnsEveryKindInsideOut) {
  RectangleSpec spec;
  spec.nx = spec.ny = 2;
  for (ElementShape shape : kShapes) {
    SCOPED_TRACE(shape_name(shape));
    const PlaneMesh mesh = rectangle_mesh(spec, shape);
    PlaneMesh reversed = mesh;
    for (auto& el : reversed.elements) reverse_element(el, shape);
    const auto issues = check_mesh(reversed, shape);
    ASSERT_EQ(issues.size(), mesh.elements.size());
    for (size_t e = 0; e < issues.size(); ++e) {
      EXPECT_EQ(issues[e].element, static_cast<int>(e));
      EXPECT_NE(issues[e].detail.find("inverted"), std::string::npos);
    }
    // The reversed sides are the same sides, run the other way.
    auto sides = boundary_sides(mesh, shape), back = boundary_sides(reversed, shape);
    for (auto& side : back) std::reverse(side.begin(), side.end());
    std::sort(sides.begin(), sides.end());
    std::sort(back.begin(), back.end());
    EXPECT_EQ(sides, back);
    for (auto& el : reversed.elements) reverse_element(el, shape);
    EXPECT_EQ(reversed.elements, mesh.elements);
  }
}

// A 2 x 1 rectangle and a parallelogram sheared by 45 degrees touching it at a corner: the worst aspect
// ratio is the rectangle's 2 (the parallelogram's sides are 1 and sqrt 2), the angles 45
// and 135 degrees are the parallelogram's.
TEST(ElementQuality, AspectRatioAndCornerAngles) {
  PlaneMesh mesh;
  mesh.nodes = {{0, 0}, {2, 0}, {2, 1}, {0, 1}, {3, 0}, {4, 1}, {3, 1}};
  mesh.elements = {{0, 1, 2, 3}, {1, 4, 5, 6}};
  ASSERT_TRUE(check_mesh(mesh, ElementShape::q4).empty());
  const ElementQuality q = element_quality(mesh);
  EXPECT_EQ(q.elements, 2);
  EXPECT_NEAR(q.max_aspect_ratio, 2.0, 1e-12);
  EXPECT_NEAR(q.min_angle, 45.0, 1e-12);
  EXPECT_NEAR(q.max_angle, 135.0, 1e-12);
}

// Triangles by the same measures, from their corners (a t6's mid-sides are not looked at): a
// right isosceles triangle (45, 45, 90 degrees, sides 1, 1, sqrt 2) beside an equilateral one.
TEST(ElementQuality, TrianglesOnTheSameScale) {
  PlaneMesh mesh;
  mesh.nodes = {{0, 0}, {1, 0}, {0, 1}, {2, 0}, {1.5, std::sqrt(0.75)}};
  mesh.elements = {{0, 1, 2}, {1, 3, 4}};
  ASSERT_TRUE(check_mesh(mesh, ElementShape::t3).empty());
  ElementQuality q = element_quality(mesh);
  EXPECT_EQ(q.elements, 2);
  EXPECT_NEAR(q.max_aspect_ratio, std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(q.min_angle, 45.0, 1e-12);
  EXPECT_NEAR(q.max_angle, 90.0, 1e-12);
  mesh.elements = {{1, 3, 4}};
  q = element_quality(mesh);
  EXPECT_NEAR(q.max_aspect_ratio, 1.0, 1e-12);  // as a square's
  EXPECT_NEAR(q.min_angle, 60.0, 1e-12);
  EXPECT_NEAR(q.max_angle, 60.0, 1e-12);
  // The same for t6 (mid-sides added, one of them off its side).
  PlaneMesh t6;
  t6.nodes = {{1, 0}, {2, 0}, {1.5, std::sqrt(0.75)}, {1.5, 0.05}, {1.75, 0.4}, {1.25, 0.4}};
  t6.elements = {{0, 1, 2, 3, 4, 5}};
  ASSERT_TRUE(check_mesh(t6, ElementShape::t6).empty());
  EXPECT_NEAR(element_quality(t6).min_angle, 60.0, 1e-12);
  EXPECT_NEAR(element_quality(t6).max_aspect_ratio, 1.0, 1e-12);
}

// corner_angles_within decides by the sign of a cross product, with atan2 only near a limit:
// it must agree with element_quality (the definition) for limits on either side of the
// mesh's extreme angles and exactly at them (ties), on a uniform grid (every corner 90
// degrees), the grid with nodes moved by 1e-3, and a refined half-disc.
TEST(ElementQuality, CornerAnglesWithinAgreesWithTheExtremeAngles) {
  RectangleSpec spec;
  spec.size = {3, 2};
  spec.nx = 30;
  spec.ny = 20;
  const PlaneMesh grid = rectangle_mesh(spec, ElementShape::q4);
  PlaneMesh moved = grid;
  unsigned state = 12345;
  for (Vec2& x : moved.nodes) {
    state = state * 1103515245u + 12345u;
    const double u = (state >> 8) / double(1 << 24) - 0.5;
    state = state * 1103515245u + 12345u;
    x += 1e-3 * Vec2(u, (state >> 8) / double(1 << 24) - 0.5);
  }
  HalfDiscSpec disc;
  disc.radius = 10;
  disc.ns = 60;
  disc.nt = 30;
  disc.refine = Refinement{0.1, 1.0};
  for (const PlaneMesh& mesh : {grid, moved, half_disc_mesh(disc, ElementShape::q4)}) {
    const ElementQuality q = element_quality(mesh);
    for (double lo : {q.min_angle - 1e-6, std::nextafter(q.min_angle, 0.0), q.min_angle,
                      std::nextafter(q.min_angle, 180.0), q.min_angle + 1e-6})
      for (double hi : {q.max_angle - 1e-6, std::nextafter(q.max_angle, 0.0), q.max_angle,
                        std::nextafter(q.max_angle, 180.0), q.max_angle + 1e-6})
        EXPECT_EQ(corner_angles_within(mesh, lo, hi), q.min_angle >= lo && q.max_angle <= hi) << lo << " " << hi;
  }
}

// From the fewest divisions a refinement admits up, weak and strong, every element is valid
// and well shaped: no block corner sits alone on the arc (the single mapped block had corner
// elements of 3-7 and 173-177 degrees there), and the pole block's corners V inside the body,
// where the ring turns round 270 degrees, leave about 135 to each element beside them.
TEST(HalfDiscMesh, EveryElementIsValidAndWellShapedOverARangeOfRefinements) {
  int checked = 0;
  for (const double size : {0.1, 0.02})
    for (const double extent : {0.3, 0.66, 2.0})
      for (const int extra : {0, 8, 24})  // divisions beyond the fewest the generator accepts
        for (const bool up : {false, true}) {
          const int fine = static_cast<int>(std::lround(extent / size));
          HalfDiscSpec spec;
          spec.radius = 10;
          spec.facing_up = up;
          spec.refine = Refinement{size, extent};
          PlaneMesh mesh;
          for (int c = 1;; ++c) {
            spec.ns = 2 * (fine + c);
            spec.nt = fine + c;
            try {
              mesh = half_disc_mesh(spec, ElementShape::q4);
            } catch (const std::invalid_argument& e) {
              ASSERT_NE(std::string(e.what()).find("give at least"), std::string::npos) << e.what();
              continue;
            }
            if (extra == 0) break;
            spec.ns += 2 * extra;
            spec.nt += extra;
            mesh = half_disc_mesh(spec, ElementShape::q4);
            break;
          }
          const auto issues = check_mesh(mesh, ElementShape::q4);
          EXPECT_TRUE(issues.empty()) << "size " << size << " extent " << extent << " extra " << extra << ": "
                                      << (issues.empty() ? "" : issues[0].detail);
          const ElementQuality q = element_quality(mesh);
          EXPECT_GT(q.min_angle, 40.0) << "size " << size << " extent " << extent << " extra " << extra;
          EXPECT_LT(q.max_angle, 140.0) << "size " << size << " extent " << extent << " extra " << extra;
          ++checked;
        }
  EXPECT_EQ(checked, 36);
}

// Without a refinement: [ns, nt] from the smallest the reader accepts ([4, 2]) to far more rows
// than the arc divisions call for (the pole block then half the radius deep).
TEST(HalfDiscMesh, UniformDivisionsAreValidAndWellShaped) {
  for (const auto& [ns, nt] : std::vector<std::pair<int, int>>{{4, 2}, {8, 4}, {24, 12}, {40, 20}, {24, 30}}) {
    HalfDiscSpec spec;
    spec.radius = 3;
    spec.ns = ns;
    spec.nt = nt;
    const PlaneMesh mesh = half_disc_mesh(spec, ElementShape::q4);
    EXPECT_TRUE(check_mesh(mesh, ElementShape::q4).empty()) << ns << " x " << nt;
    EXPECT_EQ(static_cast<int>(mesh.sets.at("arc").size()), ns + 1);
    const ElementQuality q = element_quality(mesh);
    std::printf("[%d, %d]: %d elements, angles %.1f-%.1f, aspect %.2f\n", ns, nt, q.elements, q.min_angle, q.max_angle,
                q.max_aspect_ratio);
    EXPECT_GT(q.min_angle, 40.0) << ns << " x " << nt;
    EXPECT_LT(q.max_angle, 140.0) << ns << " x " << nt;
  }
  // 8 arc divisions and 20 rows: 18 pole block rows under 2 ring rows would make corners of
  // 23 and 162 degrees; refused, naming the arc divisions that shape them well.
  HalfDiscSpec uneven;
  uneven.radius = 3;
  uneven.ns = 8;
  uneven.nt = 20;
  try {
    half_disc_mesh(uneven, ElementShape::q4);
    ADD_FAILURE() << "[8, 20] accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("give at least"), std::string::npos) << e.what();
  }
}

TEST(HalfDiscMesh, AreaArcAndRefinement) {
  const double R = 2.0;
  for (ElementShape shape : kShapes)
    for (bool up : {false, true}) {
      SCOPED_TRACE(shape_name(shape));
      const bool linear = !is_quadratic(shape);
      HalfDiscSpec spec;
      spec.centre = {1, -1};
      spec.radius = R;
      spec.ns = 36;
      spec.nt = 18;
      spec.facing_up = up;
      spec.refine = Refinement{0.03, 0.2};
      const PlaneMesh mesh = half_disc_mesh(spec, shape);
      ASSERT_TRUE(check_mesh(mesh, shape).empty()) << check_mesh(mesh, shape)[0].detail;
      // t3, q4: the half-disc less the segments that the chords of the arc cut off; the
      // quadratic kinds follow the arc to high order.
      double segments = 0.0;
      const auto& arc = mesh.sets.at("arc");
      for (size_t k = 1; k < arc.size(); k += (linear ? 1 : 2)) {
        const Vec2 a = mesh.nodes[arc[k - 1]] - spec.centre;
        const Vec2 b = mesh.nodes[arc[linear ? k : k + 1]] - spec.centre;
        const double theta = std::acos(std::clamp(a.dot(b) / (R * R), -1.0, 1.0));
        segments += 0.5 * R * R * (theta - std::sin(theta));
      }
      if (linear) EXPECT_NEAR(area(mesh, shape), pi * R * R / 2 - segments, 1e-12);
      else EXPECT_LT(std::abs(area(mesh, shape) - pi * R * R / 2), 0.01 * segments);
      for (int k : mesh.sets.at("arc")) EXPECT_NEAR((mesh.nodes[k] - spec.centre).norm(), R, 1e-12);
      for (int k : mesh.sets.at("diameter")) EXPECT_NEAR(mesh.nodes[k].y(), -1.0, 1e-12);
      const Vec2 pole = mesh.nodes[mesh.sets.at("pole")[0]];
      EXPECT_NEAR((pole - Vec2(1, up ? 1 : -3)).norm(), 0.0, 1e-12);
      EXPECT_NEAR((mesh.nodes[mesh.sets.at("centre")[0]] - spec.centre).norm(), 0.0, 1e-12);
      // Near the pole the arc is divided at the requested size.
      const auto& near = mesh.sets.at("arc_refined");
      const int fine = linear ? 1 : 2;
      EXPECT_EQ(static_cast<int>(near.size()), 2 * fine * 7 + 1);  // 0.2 / 0.03 -> 7 each side
      for (int k : near) EXPECT_LE((mesh.nodes[k] - pole).norm(), 0.2 + 1e-9);
      // Every arc node appears once.
      EXPECT_EQ(std::set<int>(mesh.sets.at("arc").begin(), mesh.sets.at("arc").end()).size(),
                mesh.sets.at("arc").size());
    }
  HalfDiscSpec odd;
  odd.ns = 5;
  EXPECT_THROW(half_disc_mesh(odd, ElementShape::q4), std::invalid_argument);
}

PlaneMesh unit_square(int n) {
  RectangleSpec spec;
  spec.nx = spec.ny = n;
  return rectangle_mesh(spec, ElementShape::q4);
}

TEST(CheckMesh, NamesTheFaultyElementOrNode) {
  PlaneMesh mesh = unit_square(2);
  EXPECT_TRUE(check_mesh(mesh, ElementShape::q4).empty());
  PlaneMesh inverted = mesh;
  std::swap(inverted.elements[1][1], inverted.elements[1][3]);  // clockwise
  auto issues = check_mesh(inverted, ElementShape::q4);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].element, 1);
  EXPECT_NE(issues[0].detail.find("inverted"), std::string::npos);
  PlaneMesh flat = mesh;
  flat.nodes[flat.elements[2][2]] = flat.nodes[flat.elements[2][1]];  // collapses element 2 (and 3)
  issues = check_mesh(flat, ElementShape::q4);
  ASSERT_FALSE(issues.empty());
  EXPECT_EQ(issues[0].element, 2);
  PlaneMesh bad = mesh;
  bad.elements[0][2] = 99;
  bad.elements[3][1] = bad.elements[3][0];
  bad.nodes.push_back({5, 5});
  issues = check_mesh(bad, ElementShape::q4);
  ASSERT_EQ(issues.size(), 3u);
  EXPECT_EQ(issues[0].element, 0);
  EXPECT_NE(issues[0].detail.find("node 99"), std::string::npos);
  EXPECT_EQ(issues[1].element, 3);
  EXPECT_EQ(issues[2].node, 9);                              // the extra node belongs to no element
  EXPECT_FALSE(check_mesh(mesh, ElementShape::q9).empty());  // four nodes are not a q9
}

// A clockwise triangle is inverted, one with its corners on a line has zero area, a t6 whose
// mid-side node lies beyond its side's end folds over: each named by its element.
TEST(CheckMesh, RefusesClockwiseAndDegenerateTriangles) {
  RectangleSpec spec;
  spec.nx = spec.ny = 2;
  const PlaneMesh t3 = rectangle_mesh(spec, ElementShape::t3);
  ASSERT_TRUE(check_mesh(t3, ElementShape::t3).empty());
  PlaneMesh clockwise = t3;
  std::swap(clockwise.elements[5][1], clockwise.elements[5][2]);
  auto issues = check_mesh(clockwise, ElementShape::t3);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].element, 5);
  EXPECT_NE(issues[0].detail.find("inverted or its nodes are not counter-clockwise"), std::string::npos);
  PlaneMesh flat;
  flat.nodes = {{0, 0}, {1, 0}, {1, 1}, {2, 2}};
  flat.elements = {{0, 1, 2}, {0, 2, 3}};  // 0, 2, 3 on the line y = x
  issues = check_mesh(flat, ElementShape::t3);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].element, 1);
  EXPECT_NE(issues[0].detail.find("zero area"), std::string::npos) << issues[0].detail;
  EXPECT_EQ(InvalidMesh(issues).what(), "element 1 " + issues[0].detail);
  PlaneMesh t6 = rectangle_mesh(spec, ElementShape::t6);
  ASSERT_TRUE(check_mesh(t6, ElementShape::t6).empty());
  const auto& e = t6.elements[2];
  t6.nodes[e[3]] = t6.nodes[e[0]] + 1.2 * (t6.nodes[e[1]] - t6.nodes[e[0]]);  // mid-side of 0-1 beyond 1
  issues = check_mesh(t6, ElementShape::t6);
  ASSERT_FALSE(issues.empty());
  EXPECT_EQ(issues[0].element, 2);
  EXPECT_FALSE(check_mesh(t6, ElementShape::q8).empty());  // six nodes are not a q8
}

TEST(BoundaryPart, OrderedCounterClockwiseWithTributaryLengths) {
  RectangleSpec spec;
  spec.size = {4, 1};
  spec.nx = 4;
  spec.ny = 1;
  for (ElementShape shape : kShapes) {
    SCOPED_TRACE(shape_name(shape));
    const PlaneMesh mesh = rectangle_mesh(spec, shape);
    // The bottom, given in a scrambled order, comes back left to right.
    std::vector<int> set = mesh.sets.at("bottom");
    std::reverse(set.begin(), set.end());
    std::swap(set[1], set[3]);
    const BoundaryPart part = boundary_part(mesh, shape, set);
    ASSERT_EQ(part.nodes.size(), set.size());
    for (size_t k = 1; k < part.nodes.size(); ++k)
      EXPECT_LT(mesh.nodes[part.nodes[k - 1]].x(), mesh.nodes[part.nodes[k]].x());
    double total = 0.0;
    for (double l : part.lengths) total += l;
    EXPECT_NEAR(total, 4.0, 1e-12);
    if (!is_quadratic(shape)) {
      EXPECT_NEAR(part.lengths.front(), 0.5, 1e-12);
      EXPECT_NEAR(part.lengths[1], 1.0, 1e-12);
    } else {  // Simpson's weights: 1/6, 2/3, 1/6 of each side
      EXPECT_NEAR(part.lengths[0], 1.0 / 6, 1e-12);
      EXPECT_NEAR(part.lengths[1], 2.0 / 3, 1e-12);
      EXPECT_NEAR(part.lengths[2], 1.0 / 3, 1e-12);
    }
    // The top runs right to left (counter-clockwise round the body).
    const BoundaryPart top = boundary_part(mesh, shape, mesh.sets.at("top"));
    EXPECT_GT(mesh.nodes[top.nodes.front()].x(), mesh.nodes[top.nodes.back()].x());
  }
  const PlaneMesh mesh = rectangle_mesh(spec, ElementShape::q4);
  EXPECT_THROW(boundary_part(mesh, ElementShape::q4, {0, 2}), std::invalid_argument);  // no side between them
}

// boundary_part sorts only the sides whose end nodes are in the set: its sides must be those
// of boundary_sides (every side used by one element) whose nodes all belong to the set, in the
// same order, for q4 and q9 half-discs and their arc, refined arc and diameter.
TEST(BoundaryPart, SidesAreTheBoundarySidesWithinTheSet) {
  HalfDiscSpec disc;
  disc.radius = 10;
  disc.ns = 40;
  disc.nt = 20;
  disc.refine = Refinement{0.2, 1.5};
  for (ElementShape shape : kShapes) {
    const PlaneMesh mesh = half_disc_mesh(disc, shape);
    const auto all = boundary_sides(mesh, shape);
    for (const char* name : {"arc", "arc_refined", "diameter"}) {
      const std::vector<int>& set = mesh.sets.at(name);
      std::vector<std::vector<int>> expected;
      for (const auto& side : all)
        if (std::all_of(side.begin(), side.end(), [&](int a) { return std::count(set.begin(), set.end(), a) > 0; }))
          expected.push_back(side);
      EXPECT_FALSE(expected.empty());
      EXPECT_EQ(boundary_part(mesh, shape, set).sides, expected) << name;
    }
  }
}

TEST(FreeRigidMotion, NamesTheMotionsTheSupportsLeave) {
  const PlaneMesh mesh = unit_square(2);  // nodes 0 1 2 / 3 4 5 / 6 7 8, 0 at (0, 0)
  std::vector<char> fixed(18, 0);
  EXPECT_EQ(free_rigid_motion(mesh, fixed), "translate along x, translate along y and rotate about (0.5, 0.5)");
  for (int k : {0, 1, 2}) fixed[2 * k + 1] = 1;  // the bottom held vertically
  EXPECT_EQ(free_rigid_motion(mesh, fixed), "translate along x");
  std::fill(fixed.begin(), fixed.end(), 0);
  fixed[0] = fixed[1] = 1;  // node 0 pinned
  EXPECT_EQ(free_rigid_motion(mesh, fixed), "rotate about (0, 0)");
  fixed[2 * 8 + 1] = 1;  // and node 8 held vertically
  EXPECT_EQ(free_rigid_motion(mesh, fixed), "");
  std::fill(fixed.begin(), fixed.end(), 0);
  fixed[2 * 4] = 1;  // only the centre's x
  EXPECT_EQ(free_rigid_motion(mesh, fixed), "translate along y and rotate about (0.5, 0.5)");
  // Two separate squares: the one without supports is named.
  PlaneMesh two = mesh;
  for (const Vec2& x : mesh.nodes) two.nodes.push_back(x + Vec2(3, 0));
  for (auto el : mesh.elements) {
    for (int& a : el) a += 9;
    two.elements.push_back(el);
  }
  std::vector<char> first(36, 0);
  for (int k = 0; k < 9; ++k) first[2 * k] = first[2 * k + 1] = 1;
  EXPECT_EQ(free_rigid_motion(two, first),
            "the part containing node 9 can translate along x, translate along y and rotate about (3.5, 0.5)");
  // Triangles: the same square as t3 (the same nodes) and t6, its bottom held vertically.
  RectangleSpec spec;
  spec.nx = spec.ny = 2;
  for (ElementShape shape : {ElementShape::t3, ElementShape::t6}) {
    const PlaneMesh tri = rectangle_mesh(spec, shape);
    std::vector<char> held(2 * tri.nodes.size(), 0);
    for (int k : tri.sets.at("bottom")) held[2 * k + 1] = 1;
    EXPECT_EQ(free_rigid_motion(tri, held), "translate along x") << shape_name(shape);
  }
}

}  // namespace
}  // namespace grip
