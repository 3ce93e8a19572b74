// CSV and VTK exports from a result document, generic over body models: a made-up result of
// two quadrilaterals with two obstacles stands in for a continuum body.
#include <gtest/gtest.h>

#include "solver/io/export_csv.hpp"
#include "solver/io/export_vtk.hpp"

namespace grip {
namespace {

using nlohmann::json;

json two_quads() {
  json step = {{"step", 1}, {"load_factor", 0.5}, {"converged", true}, {"seconds", 0.1}};
  step["nodes"] = json::array();
  for (int i = 0; i < 6; ++i)
    step["nodes"].push_back({{"node", i}, {"x", i % 3}, {"y", i / 3}, {"ux", 0.1 * i}, {"uy", -0.2 * i}});
  step["elements"] = {{{"element", 0}, {"sxx", 1.5}}, {{"element", 1}, {"sxx", 2.5}}};
  step["contact_points"] = {{{"node", 0},
                             {"obstacle", "punch"},
                             {"p_n", -2.0},
                             {"p_t", 0.5},
                             {"gap", 0.0},
                             {"state", "stick"},
                             {"pair", {0.0, -0.1}}},
                            {{"node", 1},
                             {"obstacle", "die, upper"},
                             {"p_n", 0.0},
                             {"p_t", 0.0},
                             {"gap", 0.3},
                             {"state", "open"},
                             {"pair", {1.0, -0.4}}}};
  step["history"] = {{{"pass", 1}, {"m", 0}, {"v2", 1e-3}}, {{"pass", 1}, {"m", 1}, {"v2", 1e-9}}};
  step["obstacles"] = {{{"name", "punch"}, {"offset", {0.0, -1.0}}}};
  return {{"mesh", {{"cells", {{0, 1, 4, 3}, {1, 2, 5, 4}}}}}, {"steps", {step}}};
}

TEST(ExportCsv, LongTablesWithIdentifyingColumnsFirst) {
  const json r = two_quads();
  const std::string nodes = result_csv(r, "nodes");
  EXPECT_EQ(nodes.substr(0, nodes.find('\n')), "step,load_factor,node,ux,uy,x,y");
  EXPECT_EQ(std::count(nodes.begin(), nodes.end(), '\n'), 7);
  const std::string points = result_csv(r, "contact_points");
  EXPECT_EQ(points.substr(0, points.find('\n')), "step,load_factor,node,obstacle,gap,p_n,p_t,pair_x,pair_y,state");
  EXPECT_NE(points.find("\"die, upper\""), std::string::npos);  // quoted: it has a comma
  const std::string steps = result_csv(r, "steps");
  EXPECT_NE(steps.find("offset.punch_y"), std::string::npos);
  const std::string history = result_csv(r, "history");
  EXPECT_EQ(std::count(history.begin(), history.end(), '\n'), 3);
  EXPECT_THROW(result_csv(r, "nope"), std::invalid_argument);
}

// Scenes of several bodies: each step's readings on the master bodies are a table of their own;
// a result without them gives an empty one (the client then writes no file).
TEST(ExportCsv, MasterPointsTable) {
  json r = two_quads();
  EXPECT_EQ(result_csv(r, "master_points"), "\n");
  r["steps"][0]["master_points"] = {{{"node", 4},
                                     {"body", "lower"},
                                     {"obstacle", "pair"},
                                     {"x", 1.0},
                                     {"y", 0.0},
                                     {"p_n", -1.5},
                                     {"p_t", 0.0},
                                     {"sigma_n", -3.0},
                                     {"sigma_t", 0.25}},
                                    {{"node", 5},
                                     {"body", "lower"},
                                     {"obstacle", "pair"},
                                     {"x", 2.0},
                                     {"y", 0.0},
                                     {"p_n", 0.0},
                                     {"p_t", 0.0},
                                     {"sigma_n", 0.0},
                                     {"sigma_t", 0.0}}};
  const std::string points = result_csv(r, "master_points");
  const std::string header = points.substr(0, points.find('\n'));
  EXPECT_EQ(header.substr(0, std::string("step,load_factor,body,node").size()), "step,load_factor,body,node");
  for (const char* column : {"body", "obstacle", "sigma_n", "sigma_t"})
    EXPECT_NE(header.find(column), std::string::npos);
  EXPECT_EQ(std::count(points.begin(), points.end(), '\n'), 3);
  EXPECT_NE(points.find("-3"), std::string::npos);
}

TEST(ExportVtk, QuadrilateralsWithPointAndCellArrays) {
  const json r = two_quads();
  const std::string vtk = step_legacy_vtk(r, 0);
  EXPECT_NE(vtk.find("POINTS 6 double"), std::string::npos);
  EXPECT_NE(vtk.find("CELLS 2 10\n4 0 1 4 3\n4 1 2 5 4\n"), std::string::npos);
  EXPECT_NE(vtk.find("CELL_TYPES 2\n9\n9\n"), std::string::npos);
  EXPECT_NE(vtk.find("SCALARS ux double 1"), std::string::npos);
  EXPECT_NE(vtk.find("SCALARS sxx double 1"), std::string::npos);
  // Two obstacles: contact arrays named by obstacle, white space replaced.
  EXPECT_NE(vtk.find("SCALARS punch.p_n double 1"), std::string::npos);
  EXPECT_NE(vtk.find("SCALARS die,_upper.state double 1"), std::string::npos);
  const std::string vtu = step_vtu(r, 0);
  EXPECT_NE(vtu.find("NumberOfPoints=\"6\" NumberOfCells=\"2\""), std::string::npos);
  EXPECT_NE(vtu.find("Name=\"offsets\" format=\"ascii\">\n4 8 \n"), std::string::npos);
  const auto files = result_vtk_files(r, "run");
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(files[0].name, "run_0001.vtu");
  EXPECT_EQ(files[1].name, "run_0001.vtk");
  EXPECT_EQ(files[2].name, "run.pvd");
  EXPECT_NE(files[2].content.find("timestep=\"0.5\" group=\"\" part=\"0\" file=\"run_0001.vtu\""), std::string::npos);
}

// Axisymmetric: the section (r, z) goes to the x-z plane, (r, 0, z), which ParaView's Rotational
// Extrusion revolves about z; a plane result stays in x-y.
TEST(ExportVtk, AxisymmetricSectionLiesInTheXZPlane) {
  json r = two_quads();
  const std::string plane = step_legacy_vtk(r, 0);
  EXPECT_NE(plane.find("POINTS 6 double\n0 0 0\n1 0 0\n2 0 0\n0 1 0\n"), std::string::npos) << plane;
  r["effects"] = {{"axisymmetric", json::array()}};
  const std::string revolved = step_legacy_vtk(r, 0);
  EXPECT_NE(revolved.find("POINTS 6 double\n0 0 0\n1 0 0\n2 0 0\n0 0 1\n1 0 1\n"), std::string::npos) << revolved;
  EXPECT_NE(step_vtu(r, 0).find("\n2 0 1\n"), std::string::npos);
}

TEST(ExportVtk, StepsWithoutNodeFieldsAreSkipped) {
  json r = two_quads();
  r["steps"].push_back({{"step", 2}, {"load_factor", 1.0}, {"converged", false}});
  EXPECT_THROW(step_legacy_vtk(r, 1), std::invalid_argument);
  EXPECT_EQ(result_vtk_files(r, "run").size(), 3u);
}

}  // namespace
}  // namespace grip
