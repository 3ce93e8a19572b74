// grip mesh PART.geo: the gmsh executable meshes a geometry on the user's machine (never in the
// service); the file it writes reads as the scene reader reads it. Skipped where gmsh is not
// installed (it is not a dependency of grip: Debian's gmsh, on PATH).
#include <gtest/gtest.h>

#include <cmath>

// Eigen's headers (through gmsh_mesh.hpp) before httplib.h (through grip_process.hpp).
#include "solver/io/gmsh_mesh.hpp"
// (kept apart so that clang-format does not sort them)
#include "grip_process.hpp"

namespace grip::testing {
namespace {

bool gmsh_installed() { return std::system("command -v gmsh > /dev/null 2>&1") == 0; }

// `grip ARGS` with stdout and stderr into files of `dir`; the exit code.
int run_grip(const TempDir& dir, const std::string& args, const std::string& env = "") {
  const std::string command = env + " " + std::string(GRIP_BINARY) + " " + args + " > " +
                              (dir.path() / "out.txt").string() + " 2> " + (dir.path() / "err.txt").string();
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(GripMesh, MeshesTheHertzGeometryIntoT6WithItsPhysicalGroups) {
  if (!gmsh_installed()) GTEST_SKIP() << "gmsh is not installed (Debian's gmsh): grip mesh has nothing to run";
  TempDir dir;
  const fs::path geo = examples_dir() / "hertz-t6.geo", msh = dir.path() / "hertz.msh";
  ASSERT_EQ(run_grip(dir, "mesh " + geo.string() + " -o " + msh.string() + " --order 2"), 0)
      << read_text(dir.path() / "err.txt");
  // stdout is the summary of what was written; gmsh's messages went to stderr.
  const json summary = json::parse(read_text(dir.path() / "out.txt"));
  const GmshMesh mesh = read_gmsh_file(msh.string());
  EXPECT_EQ(summary, gmsh_mesh_summary(mesh));
  ASSERT_GT(mesh.element_count(), 100);
  for (int e = 0; e < mesh.element_count(); ++e) ASSERT_EQ(mesh.element_kinds[e], ElementShape::t6) << e;
  EXPECT_EQ(mesh.reoriented, 0);
  ASSERT_EQ(mesh.surfaces.count("disc"), 1u);
  EXPECT_EQ(mesh.surfaces.at("disc").elements.size(), static_cast<size_t>(mesh.element_count()));
  for (const char* name : {"contact", "arc", "diameter"}) ASSERT_EQ(mesh.curves.count(name), 1u) << name;
  // The contact curve: one chain of 3-node lines along the arc within 1 mm of the pole, its mid
  // nodes on the circle too (second order on the geometry), refined to 0.05 mm there.
  const GmshCurve& contact = mesh.curves.at("contact");
  EXPECT_TRUE(contact.chain);
  EXPECT_FALSE(contact.closed);
  for (const auto& edge : contact.edges) EXPECT_EQ(edge.size(), 3u);
  EXPECT_GE(contact.edges.size(), 30u);  // 2 mm of arc at 0.05 mm: 40 edges
  for (int n : contact.nodes) {
    EXPECT_NEAR(mesh.nodes[n].norm(), 10.0, 1e-9) << "node tag " << mesh.node_tags[n];
    EXPECT_LE(std::abs(mesh.nodes[n].x()), 1.0 + 1e-9);
  }
  for (int n : mesh.curves.at("diameter").nodes) EXPECT_NEAR(mesh.nodes[n].y(), 0.0, 1e-12);
  // Without -o: beside the .geo, with its stem.
  fs::copy_file(geo, dir.path() / "part.geo");
  ASSERT_EQ(run_grip(dir, "mesh " + (dir.path() / "part.geo").string()), 0) << read_text(dir.path() / "err.txt");
  EXPECT_EQ(read_gmsh_file((dir.path() / "part.msh").string()).surfaces.count("disc"), 1u);
}

TEST(GripMesh, AGeometryGmshCannotMeshIsAnErrorAndNoFile) {
  if (!gmsh_installed()) GTEST_SKIP() << "gmsh is not installed (Debian's gmsh): grip mesh has nothing to run";
  TempDir dir;
  const fs::path geo = dir.path() / "broken.geo", msh = dir.path() / "broken.msh";
  std::ofstream(geo) << "Point(1) = {0, 0, 0};\nLine(1) = {1, 2};  // point 2 does not exist\n";
  std::ofstream(msh) << "an old file";
  EXPECT_EQ(run_grip(dir, "mesh " + geo.string()), 2);
  EXPECT_NE(read_text(dir.path() / "err.txt").find("grip mesh: "), std::string::npos)
      << read_text(dir.path() / "err.txt");
  EXPECT_TRUE(read_text(dir.path() / "out.txt").empty());
}

// Runs everywhere: with no gmsh on PATH the command says what to install.
TEST(GripMesh, WithoutGmshSaysToInstallIt) {
  TempDir dir;
  EXPECT_EQ(
      run_grip(dir, "mesh " + (examples_dir() / "hertz-t6.geo").string() + " -o " + (dir.path() / "x.msh").string(),
               "PATH=" + dir.path().string()),
      2);
  const std::string err = read_text(dir.path() / "err.txt");
  EXPECT_NE(err.find("the gmsh executable is not on PATH; install Debian's gmsh"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir.path() / "x.msh"));
  EXPECT_EQ(run_grip(dir, "mesh"), 2);  // usage
  EXPECT_EQ(run_grip(dir, "mesh a.geo --order 3"), 2);
}

}  // namespace
}  // namespace grip::testing
