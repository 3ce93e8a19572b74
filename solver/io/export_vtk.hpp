#pragma once
// ParaView files from a result document (the JSON of result_json): one file per step and a
// .pvd collection with the load factor as time. Generic over body models: the geometry is
// the deformed node positions (`x`, `y` of steps[].nodes[]) and the cells of `mesh.cells`
// (2 sites: line, 3: triangle, 4: quadrilateral, more: polygon); every other numeric node
// field is a point array, every numeric element field a cell array (when there is one row per
// cell), and the contact points' p_n, p_t, sigma_n, sigma_t, gap, slip and state (-1 none,
// 0 open, 1 stick, 2 slip) are point arrays at their node (named `<obstacle>.<field>` when
// the scene has several obstacles). Several bodies: the .vtu holds one <Piece> per body (its
// points, cells and array rows; result.bodies[] gives the rows), and both formats carry a cell
// array `body` (the index in bodies[]); the legacy .vtk is one grid. Bodies meshed from gmsh
// files carry point and cell arrays `gmsh_tag` (result mesh.gmsh; -1 elsewhere). Steps without node fields
// (a failed step) are skipped. An axisymmetric result (effects.axisymmetric) puts the section
// in the x-z plane, points (r, 0, z), so that ParaView's Rotational Extrusion (about z) revolves it.
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace grip {

struct VtkFile {
  std::string name;
  std::string content;
};

// Legacy VTK, ASCII UNSTRUCTURED_GRID, of steps[k]. Throws std::invalid_argument when the
// step has no node fields.
std::string step_legacy_vtk(const nlohmann::json& result, std::size_t k);
// XML VTK UnstructuredGrid (.vtu, ASCII) of steps[k]: what a .pvd collection can reference.
std::string step_vtu(const nlohmann::json& result, std::size_t k);
// A .pvd collection: (time, file name) per data set.
std::string pvd_collection(const std::vector<std::pair<double, std::string>>& datasets);

// Every file for ParaView: <stem>_NNNN.vtu and <stem>_NNNN.vtk per step (NNNN = the step
// number), and <stem>.pvd over the .vtu files. Open the .pvd; the .vtk series opens as well.
std::vector<VtkFile> result_vtk_files(const nlohmann::json& result, const std::string& stem);

}  // namespace grip
