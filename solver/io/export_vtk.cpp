#include "solver/io/export_vtk.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace grip {

using nlohmann::json;

namespace {

struct Array {
  std::string name;
  std::vector<double> values;
};

// The geometry and fields of one step, independent of the file format.
struct Grid {
  std::vector<std::array<double, 2>> points;
  std::vector<std::vector<int>> cells;
  std::vector<Array> point_data;
  std::vector<Array> cell_data;
  double load_factor = 0.0;
  int step = 0;
  // The bodies' rows: first point, points, first cell, cells (one piece over all for one body).
  std::vector<std::array<size_t, 4>> pieces;
  // Axisymmetric: the section in the x-z plane, (r, 0, z), so that ParaView's Rotational
  // Extrusion (about z) revolves it into the body.
  bool section_in_xz = false;
  std::string point_text(const std::array<double, 2>& p) const;
};

std::string number(double v);

std::string Grid::point_text(const std::array<double, 2>& p) const {
  return section_in_xz ? number(p[0]) + " 0 " + number(p[1]) : number(p[0]) + ' ' + number(p[1]) + " 0";
}

int cell_type(size_t sites) {
  switch (sites) {
    case 1:
      return 1;  // VTK_VERTEX
    case 2:
      return 3;  // VTK_LINE
    case 3:
      return 5;  // VTK_TRIANGLE
    case 4:
      return 9;  // VTK_QUAD
    default:
      return 7;  // VTK_POLYGON
  }
}

// Numeric fields of a table (rows of objects) as arrays, skipping `skip` names.
std::vector<Array> numeric_arrays(const json& rows, const std::set<std::string>& skip) {
  std::vector<Array> arrays;
  std::map<std::string, size_t> index;
  for (size_t i = 0; i < rows.size(); ++i)
    for (auto it = rows[i].begin(); it != rows[i].end(); ++it) {
      if (skip.count(it.key()) || !(it.value().is_number() || it.value().is_boolean())) continue;
      auto [pos, fresh] = index.emplace(it.key(), arrays.size());
      if (fresh) arrays.push_back({it.key(), std::vector<double>(rows.size(), 0.0)});
      arrays[pos->second].values[i] =
          it.value().is_boolean() ? (it.value().get<bool>() ? 1.0 : 0.0) : it.value().get<double>();
    }
  return arrays;
}

double state_code(const std::string& s) {
  if (s == "open") return 0;
  if (s == "stick") return 1;
  if (s == "slip") return 2;
  return -1;
}

Grid grid_of(const json& result, size_t k) {
  const json& steps = result.at("steps");
  if (k >= steps.size()) throw std::invalid_argument("no step " + std::to_string(k + 1));
  const json& step = steps[k];
  if (!step.contains("nodes") || step["nodes"].empty())
    throw std::invalid_argument("step " + std::to_string(step.value("step", 0)) + " has no node fields");
  Grid g;
  g.step = step.value("step", static_cast<int>(k) + 1);
  g.load_factor = step.value("load_factor", 0.0);
  g.section_in_xz = result.contains("effects") && result["effects"].contains("axisymmetric");
  const json& nodes = step["nodes"];
  for (const json& n : nodes) g.points.push_back({n.value("x", 0.0), n.value("y", 0.0)});
  if (result.contains("mesh") && result["mesh"].contains("cells"))
    for (const json& c : result["mesh"]["cells"]) {
      std::vector<int> cell = c.get<std::vector<int>>();
      bool valid = !cell.empty();
      for (int s : cell) valid = valid && s >= 0 && s < static_cast<int>(g.points.size());
      if (valid) g.cells.push_back(std::move(cell));
    }
  g.point_data = numeric_arrays(nodes, {"node", "x", "y"});

  if (step.contains("contact_points") && !step["contact_points"].empty()) {
    std::set<std::string> obstacles;
    for (const json& p : step["contact_points"]) obstacles.insert(p.value("obstacle", std::string()));
    const bool prefix = obstacles.size() > 1;
    static const char* fields[] = {"p_n", "p_t", "sigma_n", "sigma_t", "gap", "slip"};
    std::map<std::string, size_t> index;
    auto array = [&](const std::string& name, double fill) -> Array& {
      auto [pos, fresh] = index.emplace(name, g.point_data.size());
      if (fresh) g.point_data.push_back({name, std::vector<double>(g.points.size(), fill)});
      return g.point_data[pos->second];
    };
    for (const json& p : step["contact_points"]) {
      const int node = p.value("node", -1);
      if (node < 0 || node >= static_cast<int>(g.points.size())) continue;
      const std::string pre = prefix ? p.value("obstacle", std::string()) + "." : "";
      for (const char* f : fields)
        if (p.contains(f) && p[f].is_number()) array(pre + f, 0.0).values[node] = p[f].get<double>();
      if (p.contains("state")) array(pre + "state", -1.0).values[node] = state_code(p.value("state", std::string()));
    }
  }
  if (step.contains("elements") && step["elements"].size() == g.cells.size())
    g.cell_data = numeric_arrays(step["elements"], {"element"});
  // Several bodies: each cell's body (its index in the result's bodies[]), to split or colour by.
  if (result.contains("bodies") && result["bodies"].is_array()) {
    Array body{"body", std::vector<double>(g.cells.size(), 0.0)};
    for (size_t b = 0; b < result["bodies"].size(); ++b) {
      const json& entry = result["bodies"][b];
      const size_t first = entry.value("first_element", 0), count = entry.value("elements", 0);
      for (size_t c = first; c < first + count && c < g.cells.size(); ++c) body.values[c] = static_cast<double>(b);
    }
    g.cell_data.push_back(std::move(body));
    for (const json& entry : result["bodies"])
      g.pieces.push_back({entry.value("first_node", size_t{0}), entry.value("nodes", size_t{0}),
                          entry.value("first_element", size_t{0}), entry.value("elements", size_t{0})});
  }
  // gmsh's tags of the bodies meshed from files (result mesh.gmsh), -1 elsewhere: a user finds
  // their node and element by the tag gmsh gave it.
  if (result.contains("mesh") && result["mesh"].contains("gmsh")) {
    Array node_tag{"gmsh_tag", std::vector<double>(g.points.size(), -1.0)};
    Array cell_tag{"gmsh_tag", std::vector<double>(g.cells.size(), -1.0)};
    for (const json& tags : result["mesh"]["gmsh"]) {
      const size_t b = tags.value("body", size_t{0});
      const bool several = result.contains("bodies") && b < result["bodies"].size();
      const size_t first_node = several ? result["bodies"][b].value("first_node", size_t{0}) : 0;
      const size_t first_cell = several ? result["bodies"][b].value("first_element", size_t{0}) : 0;
      const json& nodes = tags["node_tags"];
      const json& cells = tags["element_tags"];
      for (size_t i = 0; i < nodes.size() && first_node + i < g.points.size(); ++i)
        node_tag.values[first_node + i] = nodes[i].get<double>();
      for (size_t i = 0; i < cells.size() && first_cell + i < g.cells.size(); ++i)
        cell_tag.values[first_cell + i] = cells[i].get<double>();
    }
    g.point_data.push_back(std::move(node_tag));
    g.cell_data.push_back(std::move(cell_tag));
  }
  // A piece must hold its rows and its cells' points.
  bool whole = true;
  for (const auto& [first_point, points, first_cell, cells] : g.pieces) {
    whole = whole && first_point + points <= g.points.size() && first_cell + cells <= g.cells.size();
    for (size_t c = first_cell; whole && c < first_cell + cells; ++c)
      for (int s : g.cells[c])
        whole = whole && s >= static_cast<int>(first_point) && s < static_cast<int>(first_point + points);
  }
  if (g.pieces.empty() || !whole) g.pieces = {{0, g.points.size(), 0, g.cells.size()}};
  return g;
}

std::string number(double v) {
  if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// Names in VTK files: no white space.
std::string vtk_name(std::string s) {
  for (char& c : s)
    if (c == ' ' || c == '\t') c = '_';
  return s;
}

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

std::string step_legacy_vtk(const json& result, std::size_t k) {
  const Grid g = grid_of(result, k);
  std::ostringstream os;
  os << "# vtk DataFile Version 3.0\n"
     << "grip result step " << g.step << " load_factor " << number(g.load_factor) << "\n"
     << "ASCII\nDATASET UNSTRUCTURED_GRID\n";
  os << "FIELD FieldData 1\nTimeValue 1 1 double\n" << number(g.load_factor) << "\n";
  os << "POINTS " << g.points.size() << " double\n";
  for (const auto& p : g.points) os << g.point_text(p) << '\n';
  size_t size = 0;
  for (const auto& c : g.cells) size += c.size() + 1;
  os << "CELLS " << g.cells.size() << ' ' << size << "\n";
  for (const auto& c : g.cells) {
    os << c.size();
    for (int s : c) os << ' ' << s;
    os << '\n';
  }
  os << "CELL_TYPES " << g.cells.size() << "\n";
  for (const auto& c : g.cells) os << cell_type(c.size()) << '\n';
  auto write = [&](const std::vector<Array>& arrays) {
    for (const Array& a : arrays) {
      os << "SCALARS " << vtk_name(a.name) << " double 1\nLOOKUP_TABLE default\n";
      for (double v : a.values) os << number(v) << '\n';
    }
  };
  if (!g.point_data.empty()) {
    os << "POINT_DATA " << g.points.size() << "\n";
    write(g.point_data);
  }
  if (!g.cell_data.empty()) {
    os << "CELL_DATA " << g.cells.size() << "\n";
    write(g.cell_data);
  }
  return os.str();
}

std::string step_vtu(const json& result, std::size_t k) {
  const Grid g = grid_of(result, k);
  std::ostringstream os;
  os << "<?xml version=\"1.0\"?>\n"
     << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
     << "<UnstructuredGrid>\n"
     << "<FieldData><DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" "
        "format=\"ascii\">"
     << number(g.load_factor) << "</DataArray></FieldData>\n";
  // One piece per body: its points, its cells (numbered within the piece) and its rows of the
  // arrays.
  for (const auto& [first_point, points, first_cell, cells] : g.pieces) {
    os << "<Piece NumberOfPoints=\"" << points << "\" NumberOfCells=\"" << cells << "\">\n";
    auto arrays = [&](const char* tag, const std::vector<Array>& list, size_t first, size_t count) {
      os << '<' << tag << ">\n";
      for (const Array& a : list) {
        os << "<DataArray type=\"Float64\" Name=\"" << xml_escape(vtk_name(a.name)) << "\" format=\"ascii\">\n";
        for (size_t i = first; i < first + count; ++i) os << number(a.values[i]) << ' ';
        os << "\n</DataArray>\n";
      }
      os << "</" << tag << ">\n";
    };
    arrays("PointData", g.point_data, first_point, points);
    arrays("CellData", g.cell_data, first_cell, cells);
    os << "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (size_t i = first_point; i < first_point + points; ++i) os << g.point_text(g.points[i]) << '\n';
    os << "</DataArray>\n</Points>\n<Cells>\n"
       << "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (size_t c = first_cell; c < first_cell + cells; ++c)
      for (int s : g.cells[c]) os << s - static_cast<int>(first_point) << ' ';
    os << "\n</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    size_t offset = 0;
    for (size_t c = first_cell; c < first_cell + cells; ++c) os << (offset += g.cells[c].size()) << ' ';
    os << "\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (size_t c = first_cell; c < first_cell + cells; ++c) os << cell_type(g.cells[c].size()) << ' ';
    os << "\n</DataArray>\n</Cells>\n</Piece>\n";
  }
  os << "</UnstructuredGrid>\n</VTKFile>\n";
  return os.str();
}

std::string pvd_collection(const std::vector<std::pair<double, std::string>>& datasets) {
  std::ostringstream os;
  os << "<?xml version=\"1.0\"?>\n"
     << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
     << "<Collection>\n";
  for (const auto& [time, file] : datasets)
    os << "<DataSet timestep=\"" << number(time) << "\" group=\"\" part=\"0\" file=\"" << xml_escape(file) << "\"/>\n";
  os << "</Collection>\n</VTKFile>\n";
  return os.str();
}

std::vector<VtkFile> result_vtk_files(const json& result, const std::string& stem) {
  std::vector<VtkFile> files;
  std::vector<std::pair<double, std::string>> datasets;
  const json& steps = result.at("steps");
  for (size_t k = 0; k < steps.size(); ++k) {
    if (!steps[k].contains("nodes") || steps[k]["nodes"].empty()) continue;
    char num[16];
    std::snprintf(num, sizeof num, "%04d", steps[k].value("step", static_cast<int>(k) + 1));
    const std::string base = stem + "_" + num;
    files.push_back({base + ".vtu", step_vtu(result, k)});
    files.push_back({base + ".vtk", step_legacy_vtk(result, k)});
    datasets.emplace_back(steps[k].value("load_factor", 0.0), base + ".vtu");
  }
  files.push_back({stem + ".pvd", pvd_collection(datasets)});
  return files;
}

}  // namespace grip
