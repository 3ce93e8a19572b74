#pragma once
// Meshes of plane bodies: nodes, quadrilateral elements and named node sets; the checks a
// mesh must pass, its boundary, and two generators (a graded rectangle and a graded
// half-disc). Lengths in the scene's units. Errors are std::invalid_argument with a plain
// sentence; the scene reader adds the JSON pointer.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "solver/elements/quad_element.hpp"

namespace grip {

struct PlaneMesh {
  std::vector<Vec2> nodes;
  // Node ids per element: 4 (q4) or 9 (q9), in the order of quad_element.hpp.
  std::vector<std::vector<int>> elements;
  std::map<std::string, std::vector<int>> sets;  // named node sets
};

// What is wrong with one element (node count, ids, repeated nodes, inverted or zero area),
// or with one node (in no element; element = -1 then).
struct MeshIssue {
  int element;
  int node;
  std::string detail;
};
std::vector<MeshIssue> check_mesh(const PlaneMesh& mesh, QuadShape shape);

// Element sides on the boundary (used by exactly one element), each with its 2 (q4) or 3
// (q9, corner - mid - corner) nodes in the element's counter-clockwise order: the body lies
// to the left of each side.
std::vector<std::vector<int>> boundary_sides(const PlaneMesh& mesh, QuadShape shape);

// The part of the boundary spanned by a node set: the boundary sides whose nodes all belong
// to the set, the set's nodes in order along them (counter-clockwise round the body; several
// runs one after another), and per node the integral of its shape function over those sides
// (half the adjacent side lengths for q4; 1/6, 2/3, 1/6 of a straight side for q9).
struct BoundaryPart {
  std::vector<std::vector<int>> sides;
  std::vector<int> nodes;
  std::vector<double> lengths;  // per entry of `nodes`
};
// Throws if a node of the set lies on no such side.
BoundaryPart boundary_part(const PlaneMesh& mesh, QuadShape shape, const std::vector<int>& set);

// The rigid motions (translation along x and y, rotation) of each connected part of the mesh
// that the fixed dofs (2 per node: x, y) leave free, in words ("translate along x", "rotate
// about (0, -1)"); empty when none is free.
std::string free_rigid_motion(const PlaneMesh& mesh, const std::vector<char>& fixed_dof);

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
PlaneMesh rectangle_mesh(const RectangleSpec& spec, QuadShape shape);

// A half-disc: the arc below the diameter (facing down; `facing_up` mirrors it). A blended
// (transfinite) map of a ns x nt grid: ns divisions along the middle quarter-circle of the arc
// and along the diameter, nt from the arc to the diameter (each end quarter of the arc has
// nt). ns must be even, so that a node sits at the pole (the middle of the arc). Refinement
// is toward the pole, along the arc and in depth. Sets: "arc" (counter-clockwise),
// "diameter", "pole" (one node), "centre" (the middle of the diameter, one node), and with a
// refinement "arc_refined" (the arc nodes within its extent of the pole, along the arc).
struct HalfDiscSpec {
  Vec2 centre = Vec2::Zero();
  double radius = 1.0;
  int ns = 2, nt = 1;
  bool facing_up = false;
  std::optional<Refinement> refine;
};
PlaneMesh half_disc_mesh(const HalfDiscSpec& spec, QuadShape shape);

// Node coordinates of n divisions of [lo, hi]: uniform, or refined toward `focus` (a point of
// [lo, hi]) with elements of about refine.size within refine.extent of it, growing
// geometrically outside. Throws if the divisions cannot hold the refinement.
std::vector<double> graded_divisions(double lo, double hi, int n, std::optional<double> focus,
                                     const std::optional<Refinement>& refine);

}  // namespace grip
