#pragma once
// Plane meshes from gmsh's .msh files: format 4.1 and 2.2, ASCII and binary (little-endian,
// as gmsh writes them). Our own reader rather than gmsh's library: docs/design.md#reading-gmsh-meshes.
//
// What is read: $MeshFormat, $PhysicalNames, $Entities (4.1: each entity's physical groups),
// $Nodes, $Elements; other sections ($NodeData, $Periodic, ...) are skipped. The mesh must lie
// in a plane z = const (x and y are kept). Elements: 3- and 6-node triangles, 4-, 8- and
// 9-node quadrilaterals (gmsh types 2, 9, 3, 16, 10) make the body; 2- and 3-node lines
// (types 1, 8) and points (type 15) only carry physical curves and points. Anything else (a 3D
// element, a 10-node triangle, a partitioned mesh) is refused, as are a truncated file, an
// unknown version, duplicate node tags, an element on a missing node, a NaN or infinite
// coordinate and an element of zero area.
#include <cstddef>
#include <map>
#include <nlohmann/json.hpp>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "solver/elements/plane_element.hpp"
#include "solver/model/types.hpp"

namespace grip {

// Bad file: what() is "<source>:<line>: <sentence>" for the ASCII parts of a file,
// "<source>: byte <offset>: ..." for binary data, "<source>: ..." for what concerns the whole
// mesh; the sentence names the element or node by its gmsh tag where one is at fault.
struct GmshError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A physical surface: an element set (indices into GmshMesh's elements).
struct GmshSurface {
  int tag = 0;
  std::vector<int> elements;
};

// A physical curve: its 1D elements (edges) and their nodes. Each edge lists 2 node indices
// (a 2-node line) or 3 (a 3-node line: its two ends, then its mid node, gmsh's order), oriented
// as gmsh wrote it. `nodes` are the curve's distinct nodes: in order along the curve, mid nodes
// in between, when its edges make one chain (`chain`; `closed` for a loop, whose first node is
// not repeated), else in order of first appearance.
struct GmshCurve {
  int tag = 0;
  std::vector<std::vector<int>> edges;
  std::vector<int> nodes;
  bool chain = false;
  bool closed = false;
};

// A physical point: a node set.
struct GmshPoints {
  int tag = 0;
  std::vector<int> nodes;
};

// The mesh, plain data. Nodes are numbered 0..n-1: first the `body_nodes` nodes of the 2D
// elements (the body), then the nodes that only physical curves or points use (a rigid tool's
// curve drawn beside the body); nodes used by neither are dropped. Each keeps its gmsh tag.
// Elements are in gmsh's node order (corners counter-clockwise; t6: then the mid-sides of
// 0-1, 1-2, 2-0; q8: then the mid-sides of 0-1, 1-2, 2-3, 3-0; q9: those and the centre); an
// element gmsh wrote clockwise is reoriented (counted in `reoriented`).
// Groups are keyed by their physical name; a group without one is "surface_<tag>",
// "curve_<tag>" or "point_<tag>". A curve and a point never share a name (both are node sets).
struct GmshMesh {
  std::vector<Vec2> nodes;
  std::vector<std::size_t> node_tags;
  int body_nodes = 0;

  std::vector<std::size_t> element_tags;
  std::vector<ElementShape> element_kinds;
  std::vector<int> element_offsets{0};  // element e's nodes: element_nodes[offsets[e], offsets[e + 1])
  std::vector<int> element_nodes;
  int reoriented = 0;

  std::map<std::string, GmshSurface> surfaces;
  std::map<std::string, GmshCurve> curves;
  std::map<std::string, GmshPoints> points;

  int element_count() const { return static_cast<int>(element_tags.size()); }
  std::span<const int> element(int e) const {
    return {element_nodes.data() + element_offsets[e], element_nodes.data() + element_offsets[e + 1]};
  }
};

// `source` names the file in messages. Throws GmshError.
GmshMesh read_gmsh_mesh(std::string_view bytes, const std::string& source);
// Reads the whole file first; throws GmshError also when it cannot be opened.
GmshMesh read_gmsh_file(const std::string& path);

// What was read, as the service answers an upload and `grip mesh-info` prints it:
//   {"nodes": n, "body_nodes": n, "elements": {"t3": n, ...}, "reoriented": n,
//    "physical_groups": [{"name", "dimension": 2|1|0, "tag", "elements"|"edges", "nodes"}],
//    "bounding_box": {"min": [x, y], "max": [x, y]}}   (of the body's nodes; of all with no body)
nlohmann::json gmsh_mesh_summary(const GmshMesh& mesh);

}  // namespace grip
