// body.mesh.gmsh: a continuum body's mesh from a gmsh file (gmsh_mesh.hpp).
//   {"file": "part.msh"} (grip solve: relative to the scene file) | {"id": "..."} (the
//   service: an upload to POST /v1/meshes), and "surfaces": ["name", ...] (physical surfaces;
//   default: every 2D element of the file).
// The body takes the elements of those surfaces and their nodes; physical curves and points
// whose nodes all lie on the body become its node sets by their names (a curve's nodes in order
// along it), usable as contact_set, supports, loads and contact pairs. A curve that does not lie
// on the body (a tool drawn beside it) is left to obstacles.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "solver/io/gmsh_mesh.hpp"
#include "solver/io/scene_reader.hpp"

namespace grip::scene_io {

namespace {

// The mesh a {"file"} or {"id"} reference names, through the caller's resolver; null after an error.
std::shared_ptr<const GmshMesh> resolve(Reader& r, json& gmsh, const std::string& ptr) {
  const bool by_file = gmsh.contains("file"), by_id = gmsh.contains("id");
  if (by_file == by_id) {
    r.error(ptr, "needs exactly one of \"file\" (a .msh file, relative to the scene) and \"id\" (an uploaded mesh)");
    return nullptr;
  }
  const char* key = by_file ? "file" : "id";
  if (!gmsh[key].is_string() || gmsh[key].get<std::string>().empty()) {
    r.error(ptr + "/" + key, show(gmsh[key]) + " is not a non-empty string");
    return nullptr;
  }
  if (!r.meshes) {
    r.error(ptr, "a mesh from a file is read by grip solve (\"file\") or the service (\"id\" of POST /v1/meshes)");
    return nullptr;
  }
  try {
    return (*r.meshes)(gmsh);
  } catch (const std::exception& e) {
    r.error(ptr + "/" + key, e.what());
    return nullptr;
  }
}

// The arc from a through m to b, or the segment a-b where the three are (nearly) in line.
ProfilePiece arc_through(const Vec2& a, const Vec2& m, const Vec2& b) {
  const Vec2 u = m - a, v = b - m;
  const double turn = u.x() * v.y() - u.y() * v.x();
  if (std::abs(turn) <= 1e-12 * u.norm() * v.norm()) return SegmentPiece{a, b};
  // The circumcentre of a, m, b.
  const Vec2 ab = b - a, am = m - a;
  const double d = 2 * (am.x() * ab.y() - am.y() * ab.x());
  const Vec2 c = a + Vec2(ab.y() * am.squaredNorm() - am.y() * ab.squaredNorm(),
                          am.x() * ab.squaredNorm() - ab.x() * am.squaredNorm()) /
                         d;
  const double from = std::atan2(a.y() - c.y(), a.x() - c.x());
  double to = std::atan2(b.y() - c.y(), b.x() - c.x());
  // Counter-clockwise (a left turn): to above from; clockwise: below.
  const double two_pi = 2 * std::numbers::pi;
  if (turn > 0)
    while (to <= from) to += two_pi;
  else
    while (to >= from) to -= two_pi;
  return ArcPiece{c, (a - c).norm(), from, to};
}

}  // namespace

std::optional<std::vector<ProfilePiece>> read_curve_pieces(Reader& r, json& shape, const std::string& ptr) {
  json* gmsh = r.object(shape, ptr, "gmsh", true);
  if (!gmsh) return std::nullopt;
  const std::shared_ptr<const GmshMesh> file = resolve(r, *gmsh, ptr + "/gmsh");
  if (!file) return std::nullopt;
  if (!shape.contains("curve") || !shape["curve"].is_string()) {
    r.error(ptr + "/curve", "is required: the name of a physical curve of the mesh");
    return std::nullopt;
  }
  const std::string name = shape["curve"].get<std::string>();
  const auto it = file->curves.find(name);
  if (it == file->curves.end()) {
    std::vector<std::string> names;
    for (const auto& [n, c] : file->curves) names.push_back(n);
    r.error(ptr + "/curve",
            show(shape["curve"]) + " names no physical curve of the mesh (curves: " + Reader::list(names) + ")");
    return std::nullopt;
  }
  const GmshCurve& curve = it->second;
  if (curve.edges.empty() || !curve.chain || curve.closed) {
    r.error(ptr + "/curve", "\"" + name + "\" must be one open chain of lines (a rigid profile; " +
                                (curve.closed ? "it is a closed loop: split it, or use a circle)" : "it branches)"));
    return std::nullopt;
  }
  // Along the chain: 2-node lines are segments, 3-node lines arcs through their mid node.
  std::vector<int> nodes = curve.nodes;
  if (!shape.contains("reverse")) shape["reverse"] = false;
  if (!shape["reverse"].is_boolean()) r.error(ptr + "/reverse", show(shape["reverse"]) + " is not true or false");
  else if (shape["reverse"].get<bool>()) std::reverse(nodes.begin(), nodes.end());
  const int stride = curve.edges.front().size() == 3 ? 2 : 1;
  std::vector<ProfilePiece> pieces;
  for (size_t k = 0; k + stride < nodes.size(); k += stride) {
    const Vec2& a = file->nodes[nodes[k]];
    const Vec2& b = file->nodes[nodes[k + stride]];
    pieces.push_back(stride == 1 ? ProfilePiece(SegmentPiece{a, b}) : arc_through(a, file->nodes[nodes[k + 1]], b));
  }
  return pieces;
}

std::optional<FileMesh> read_file_mesh(Reader& r, json& gmsh, const std::string& ptr) {
  const std::shared_ptr<const GmshMesh> file = resolve(r, gmsh, ptr);
  if (!file) return std::nullopt;

  // The elements: those of the named surfaces, each once, in the file's order.
  std::vector<char> chosen(file->element_count(), 0);
  if (json* surfaces = r.array(gmsh, ptr, "surfaces", false); surfaces && !surfaces->empty()) {
    std::vector<std::string> names;
    for (const auto& [name, s] : file->surfaces) names.push_back(name);
    for (size_t k = 0; k < surfaces->size(); ++k) {
      const json& name = (*surfaces)[k];
      const auto it = name.is_string() ? file->surfaces.find(name.get<std::string>()) : file->surfaces.end();
      if (it == file->surfaces.end()) {
        r.error(ptr + "/surfaces/" + std::to_string(k),
                show(name) + " names no physical surface of the mesh (surfaces: " + Reader::list(names) + ")");
        continue;
      }
      for (int e : it->second.elements) chosen[e] = 1;
    }
  } else {
    std::fill(chosen.begin(), chosen.end(), 1);
  }
  if (!r.issues.empty()) return std::nullopt;

  FileMesh out;
  std::vector<int> index(file->nodes.size(), -1);  // the file's node -> the body's
  std::vector<int> element_index(file->element_count(), -1);
  int first = -1;
  for (int e = 0; e < file->element_count(); ++e) {
    if (!chosen[e]) continue;
    if (first < 0) first = e;
    if (file->element_kinds[e] != file->element_kinds[first]) {
      r.error(ptr, std::string("mixes ") + shape_name(file->element_kinds[first]) + " (element tag " +
                       std::to_string(file->element_tags[first]) + ") and " + shape_name(file->element_kinds[e]) +
                       " (element tag " + std::to_string(file->element_tags[e]) +
                       ") elements: one body takes one element kind (mesh the part with one, or name its surfaces "
                       "as bodies)");
      return std::nullopt;
    }
    std::vector<int> element;
    for (int n : file->element(e)) {
      if (index[n] < 0) {
        index[n] = static_cast<int>(out.mesh.nodes.size());
        out.mesh.nodes.push_back(file->nodes[n]);
        out.tags.nodes.push_back(file->node_tags[n]);
      }
      element.push_back(index[n]);
    }
    element_index[e] = static_cast<int>(out.mesh.elements.size());
    out.mesh.elements.push_back(std::move(element));
    out.tags.elements.push_back(file->element_tags[e]);
  }
  if (first < 0) {
    r.error(ptr, "the mesh has no 2D element" + std::string(gmsh.contains("surfaces") ? " in those surfaces" : "") +
                     ": a body needs triangles or quadrilaterals");
    return std::nullopt;
  }
  out.element = shape_name(file->element_kinds[first]);

  for (const auto& [name, surface] : file->surfaces)
    for (int e : surface.elements)
      if (element_index[e] >= 0) out.surfaces[name].push_back(element_index[e]);

  // Node sets: the curves and points that lie wholly on the body.
  const auto on_body = [&](const std::vector<int>& nodes, std::vector<int>& set) {
    set.clear();
    for (int n : nodes) {
      if (index[n] < 0) return false;
      set.push_back(index[n]);
    }
    return !set.empty();
  };
  std::vector<int> set;
  for (const auto& [name, curve] : file->curves)
    if (on_body(curve.nodes, set)) out.mesh.sets[name] = set;
  for (const auto& [name, points] : file->points)
    if (on_body(points.nodes, set)) out.mesh.sets[name] = set;
  return out;
}

}  // namespace grip::scene_io
