#pragma once
// Meshes of plane bodies: nodes, elements (plane_element.hpp) and named node sets; the checks a
// mesh must pass, its boundary, and two generators (a graded rectangle and a graded
// half-disc). Lengths in the scene's units. Errors are std::invalid_argument with a plain
// sentence; the scene reader adds the JSON pointer.
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "solver/elements/plane_element.hpp"

namespace grip {

struct PlaneMesh {
  std::vector<Vec2> nodes;
  // Node ids per element: 3 (t3), 6 (t6), 4 (q4), 8 (q8) or 9 (q9), in the order of
  // plane_element.hpp; one kind per mesh.
  std::vector<std::vector<int>> elements;
  std::map<std::string, std::vector<int>> sets;  // named node sets
};

// What is wrong with one element (node count, ids, repeated nodes, inverted (a clockwise
// triangle or quadrilateral) or zero area), or with one node (in no element; element = -1 then).
struct MeshIssue {
  int element;
  int node;
  std::string detail;
};
std::vector<MeshIssue> check_mesh(const PlaneMesh& mesh, ElementShape shape);
// What a body that takes a mesh (ContinuumBody) throws when check_mesh finds issues: all of
// them (the scene reader names each one's JSON pointer); what() is the first in words.
struct InvalidMesh : std::invalid_argument {
  explicit InvalidMesh(std::vector<MeshIssue> issues);
  std::vector<MeshIssue> issues;
};

// Element sides on the boundary (used by exactly one element), each with its 2 (t3, q4) or 3
// (t6, q8, q9: corner - mid - corner) nodes in the element's counter-clockwise order: the body
// lies to the left of each side.
std::vector<std::vector<int>> boundary_sides(const PlaneMesh& mesh, ElementShape shape);

// The part of the boundary spanned by a node set: the boundary sides whose nodes all belong
// to the set, the set's nodes in order along them (counter-clockwise round the body; several
// runs one after another), and per node the integral of its shape function over those sides
// (half the adjacent side lengths for t3 and q4; 1/6, 2/3, 1/6 of a straight side for t6, q8
// and q9), and that integral weighted by 2 pi r (r = x: the area the node's share sweeps
// revolved about the axis, for axisymmetry).
struct BoundaryPart {
  std::vector<std::vector<int>> sides;
  std::vector<int> nodes;
  std::vector<double> lengths;         // per entry of `nodes`
  std::vector<double> revolved_areas;  // per entry of `nodes`
};
// Throws if a node of the set lies on no such side.
BoundaryPart boundary_part(const PlaneMesh& mesh, ElementShape shape, const std::vector<int>& set);

// The rigid motions (translation along x and y, rotation) of each connected part of the mesh
// that the fixed dofs (2 per node: x, y) leave free, in words ("translate along x", "rotate
// about (0, -1)"); empty when none is free.
std::string free_rigid_motion(const PlaneMesh& mesh, const std::vector<char>& fixed_dof);

// The shape of the elements from their corners (types.hpp): corner angles in degrees (90 at best
// for a quadrilateral, 60 for a triangle) and the longest over the shortest side between
// corners (1 at best for both: a square, an equilateral triangle). Mid-side nodes are not
// looked at (check_mesh finds those that invert an element).
ElementQuality element_quality(const PlaneMesh& mesh);

// Local refinement of a generated mesh: elements of about `size` within `extent` of a point,
// growing geometrically beyond it so that the given divisions fill the body.
struct Refinement {
  double size = 0.0;
  double extent = 0.0;
};

// A rectangle [origin, origin + size] of nx by ny elements; refinement toward `towards`
// (each direction separately). Sets: "bottom", "right", "top", "left" (counter-clockwise).
struct RectangleSpec {
  Vec2 origin = Vec2::Zero();
  Vec2 size = Vec2::Ones();
  int nx = 1, ny = 1;
  std::optional<Refinement> refine;
  Vec2 towards = Vec2::Zero();
};
// Every kind: a grid of q4 or q9 (grid_shape) turned into `shape` by quads_as.
PlaneMesh rectangle_mesh(const RectangleSpec& spec, ElementShape shape);

// A half-disc: the arc below the diameter (facing down; `facing_up` mirrors it). Four mapped
// blocks (half_disc_mesh.cpp): a pole block under the pole, ringed by two side blocks and a
// core. ns divisions along the arc (even, so that a node sits at the pole), graded toward the
// pole with a refinement; the pole block takes those within the refinement's extent (at most
// the middle half of the arc; without a refinement, the middle half) and each side the rest.
// nt divisions from the pole to the centre: the ring's rows (ns less the pole block's, halved)
// and the pole block's below them. Sets: "arc" (counter-clockwise), "diameter", "pole" (one
// node), "centre" (the middle of the diameter, one node), and with a refinement "arc_refined"
// (the arc nodes within its extent of the pole, along the arc). `right_half`: only the half
// at x >= the centre's (the section of a hemisphere about the axis through the pole and the
// centre, for axisymmetry), with the set "axis" (its nodes on that line, upward).
struct HalfDiscSpec {
  Vec2 centre = Vec2::Zero();
  double radius = 1.0;
  int ns = 4, nt = 2;
  bool facing_up = false;
  bool right_half = false;
  std::optional<Refinement> refine;
};
PlaneMesh half_disc_mesh(const HalfDiscSpec& spec, ElementShape shape);

// The quadrilaterals a generator builds for `shape`: q4 for t3 and q4, q9 for the quadratic kinds.
ElementShape grid_shape(ElementShape shape);
// A mesh of grid_shape(shape) elements as `shape`: each q4 split along its shorter diagonal
// (0-2 on a tie) into two t3; each q9 along the same diagonal, through its centre node, into
// two t6 whose mid-sides are the q9's nodes; a q9 without its centre node as a q8 (the centre
// nodes dropped, the others and the sets renumbered in order). q4 and q9: unchanged.
PlaneMesh quads_as(PlaneMesh quads, ElementShape shape);

// The values of a grid's lines: for a quadratic shape the midpoints inserted between
// consecutive values (t3, q4: as given).
std::vector<double> refine_for(ElementShape shape, const std::vector<double>& v);

// An element's nodes in the opposite turning sense (clockwise <-> counter-clockwise).
void reverse_element(std::vector<int>& element, ElementShape shape);

// Node coordinates of n divisions of [lo, hi]: uniform, or refined toward `focus` (a point of
// [lo, hi]) with elements of about refine.size within refine.extent of it, growing
// geometrically outside. Throws if the divisions cannot hold the refinement with elements
// growing at most `max_growth`-fold from one to the next (faster than 4-fold spoils the
// answer: Hertz with one coarse element a side put a and p0 5 % off).
std::vector<double> graded_divisions(double lo, double hi, int n, std::optional<double> focus,
                                     const std::optional<Refinement>& refine, double max_growth = 4.0);

}  // namespace grip
