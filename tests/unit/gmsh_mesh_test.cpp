// The gmsh .msh reader (solver/io/gmsh_mesh.hpp): the same small meshes in the four variants
// of the format (tests/data/gmsh/write_meshes.py writes them) read to the same mesh; each
// refusal names the line or the tag; damaged files end in a GmshError or a valid mesh.
#include "solver/io/gmsh_mesh.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>

namespace grip {
namespace {

const std::string kData = std::string(GRIP_SOURCE_DIR) + "/tests/data/gmsh/";
const std::vector<std::string> kVariants = {"v22_ascii", "v22_binary", "v41_ascii", "v41_binary"};

std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<int> nodes_of(const GmshMesh& m, int e) {
  const auto span = m.element(e);
  return {span.begin(), span.end()};
}

// The message of the GmshError that reading `text` throws ("" if it reads).
std::string refusal(const std::string& text) {
  try {
    read_gmsh_mesh(text, "part.msh");
  } catch (const GmshError& e) {
    return e.what();
  }
  return "";
}

std::string kPlate22ForBranch() { return file_text(kData + "plate_v22_ascii.msh"); }

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

// The plate: a q4 and two t3 (the second written clockwise), a tool line off the body, an
// unused node; its groups. Node indices: tags 10..60 -> 0..5, the tool's 70, 80 -> 6, 7.
void expect_plate(const GmshMesh& m) {
  EXPECT_EQ(m.body_nodes, 6);
  EXPECT_EQ(m.node_tags, (std::vector<std::size_t>{10, 20, 30, 40, 50, 60, 70, 80}));
  ASSERT_EQ(m.nodes.size(), 8u);
  EXPECT_EQ(m.nodes[3], Vec2(2, 1));
  EXPECT_EQ(m.nodes[7], Vec2(2, 1.5));
  ASSERT_EQ(m.element_count(), 3);
  EXPECT_EQ(m.element_tags, (std::vector<std::size_t>{1, 2, 3}));
  EXPECT_EQ(m.element_kinds, (std::vector<ElementShape>{ElementShape::q4, ElementShape::t3, ElementShape::t3}));
  EXPECT_EQ(nodes_of(m, 0), (std::vector<int>{0, 1, 4, 5}));
  EXPECT_EQ(nodes_of(m, 1), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(nodes_of(m, 2), (std::vector<int>{1, 3, 4}));  // written 20 50 40: clockwise
  EXPECT_EQ(m.reoriented, 1);

  ASSERT_EQ(m.surfaces.size(), 3u);
  EXPECT_EQ(m.surfaces.at("left").tag, 1);
  EXPECT_EQ(m.surfaces.at("left").elements, (std::vector<int>{0}));
  EXPECT_EQ(m.surfaces.at("surface_7").elements, (std::vector<int>{1, 2}));  // unnamed group 7
  EXPECT_EQ(m.surfaces.at("all").elements, (std::vector<int>{0, 1, 2}));     // 2.2: the elements written twice

  ASSERT_EQ(m.curves.size(), 3u);
  const auto& bottom = m.curves.at("bottom");
  EXPECT_EQ(bottom.tag, 11);
  EXPECT_EQ(bottom.edges, (std::vector<std::vector<int>>{{0, 1}, {1, 2}}));
  EXPECT_EQ(bottom.nodes, (std::vector<int>{0, 1, 2}));
  EXPECT_TRUE(bottom.chain);
  EXPECT_FALSE(bottom.closed);
  EXPECT_EQ(m.curves.at("right").edges, (std::vector<std::vector<int>>{{2, 3}}));
  const auto& tool = m.curves.at("tool");  // 80 -> 70: ordered as gmsh wrote it
  EXPECT_EQ(tool.edges, (std::vector<std::vector<int>>{{7, 6}}));
  EXPECT_EQ(tool.nodes, (std::vector<int>{7, 6}));
  ASSERT_EQ(m.points.size(), 1u);
  EXPECT_EQ(m.points.at("corner").nodes, (std::vector<int>{0}));
  EXPECT_EQ(m.points.at("corner").tag, 21);
}

TEST(GmshMesh, PlateReadsTheSameInAllFourVariants) {
  for (const auto& v : kVariants) {
    SCOPED_TRACE(v);
    expect_plate(read_gmsh_file(kData + "plate_" + v + ".msh"));
  }
}

TEST(GmshMesh, WindowsLineEndsRead) {
  std::string text = file_text(kData + "plate_v41_ascii.msh");
  std::string crlf;
  for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  expect_plate(read_gmsh_mesh(crlf, "crlf.msh"));
}

// Second order: a q9, a q8, two t6 (the second clockwise) on a 0.5 grid of tags
// 1 + 2x + 14y; the bottom as 3-node lines (one backwards), the q9's boundary as a loop.
TEST(GmshMesh, QuadraticElementsKeepGmshNodeOrderCounterClockwise) {
  for (const auto& v : kVariants) {
    SCOPED_TRACE(v);
    const auto m = read_gmsh_file(kData + "quadratic_" + v + ".msh");
    EXPECT_EQ(m.body_nodes, 20);  // 21 grid nodes less the q8's centre
    EXPECT_EQ(m.nodes.size(), 20u);
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
      EXPECT_EQ(m.node_tags[i], 1 + std::lround(2 * m.nodes[i].x()) + 7 * std::lround(2 * m.nodes[i].y()));
    ASSERT_EQ(m.element_count(), 4);
    EXPECT_EQ(m.element_kinds,
              (std::vector<ElementShape>{ElementShape::q9, ElementShape::q8, ElementShape::t6, ElementShape::t6}));
    EXPECT_EQ(m.reoriented, 1);
    // Every element: corners counter-clockwise; each mid-side node halfway between the
    // corners the documented order gives; a q9's centre at the mean of its corners.
    for (int e = 0; e < m.element_count(); ++e) {
      const auto n = nodes_of(m, e);
      const int corners = n.size() == 6 ? 3 : 4;
      double area = 0;
      for (int k = 0; k < corners; ++k) {
        const Vec2 a = m.nodes[n[k]], b = m.nodes[n[(k + 1) % corners]];
        area += a.x() * b.y() - a.y() * b.x();
        EXPECT_EQ(m.nodes[n[corners + k]], (a + b) / 2) << "element " << e << " side " << k;
      }
      EXPECT_GT(area, 0);
      if (n.size() == 9) EXPECT_EQ(m.nodes[n[8]], (m.nodes[n[0]] + m.nodes[n[1]] + m.nodes[n[2]] + m.nodes[n[3]]) / 4);
    }
    EXPECT_EQ(m.surfaces.at("quads").elements, (std::vector<int>{0, 1}));
    EXPECT_EQ(m.surfaces.at("triangles").elements, (std::vector<int>{2, 3}));

    const auto& bottom = m.curves.at("bottom");
    ASSERT_TRUE(bottom.chain);
    EXPECT_FALSE(bottom.closed);
    ASSERT_EQ(bottom.nodes.size(), 7u);  // ends and mid nodes, along x
    for (int k = 0; k < 7; ++k) EXPECT_EQ(m.nodes[bottom.nodes[k]], Vec2(0.5 * k, 0));
    ASSERT_EQ(bottom.edges.size(), 3u);
    EXPECT_EQ(m.nodes[bottom.edges[1][0]], Vec2(2, 0));    // written backwards, kept so
    EXPECT_EQ(m.nodes[bottom.edges[1][2]], Vec2(1.5, 0));  // the mid node last

    const auto& loop = m.curves.at("square_edge");
    ASSERT_TRUE(loop.chain);
    EXPECT_TRUE(loop.closed);
    ASSERT_EQ(loop.nodes.size(), 8u);
    for (int k = 0; k < 8; ++k)
      EXPECT_DOUBLE_EQ((m.nodes[loop.nodes[k]] - m.nodes[loop.nodes[(k + 1) % 8]]).norm(), 0.5);
  }
}

TEST(GmshMesh, SummaryCountsKindsGroupsAndBox) {
  const auto s = gmsh_mesh_summary(read_gmsh_file(kData + "plate_v41_binary.msh"));
  EXPECT_EQ(s["nodes"], 8);
  EXPECT_EQ(s["body_nodes"], 6);
  EXPECT_EQ(s["elements"], (nlohmann::json{{"q4", 1}, {"t3", 2}}));
  EXPECT_EQ(s["reoriented"], 1);
  EXPECT_EQ(s["bounding_box"]["min"], (nlohmann::json{0.0, 0.0}));
  EXPECT_EQ(s["bounding_box"]["max"], (nlohmann::json{2.0, 1.0}));  // the tool above it is no body
  std::map<std::string, nlohmann::json> groups;
  for (const auto& g : s["physical_groups"]) groups[g["name"]] = g;
  ASSERT_EQ(groups.size(), 7u);
  EXPECT_EQ(groups["all"]["elements"], 3);
  EXPECT_EQ(groups["all"]["nodes"], 6);
  EXPECT_EQ(groups["surface_7"]["nodes"], 4);
  EXPECT_EQ(groups["bottom"]["edges"], 2);
  EXPECT_EQ(groups["bottom"]["nodes"], 3);
  EXPECT_EQ(groups["corner"]["dimension"], 0);
}

TEST(GmshMesh, BranchedCurvesKeepTheirNodesInOrderOfAppearance) {
  // The right side's line moved into the bottom as a branch at node 20: no chain; "right" stays, empty.
  const auto m = read_gmsh_mesh(replaced(kPlate22ForBranch(), "6 1 2 13 2 30 40", "6 1 2 11 2 20 50"), "t.msh");
  const auto& bottom = m.curves.at("bottom");
  EXPECT_FALSE(bottom.chain);
  EXPECT_EQ(bottom.edges, (std::vector<std::vector<int>>{{0, 1}, {1, 2}, {1, 4}}));
  EXPECT_EQ(bottom.nodes, (std::vector<int>{0, 1, 2, 4}));
  EXPECT_TRUE(m.curves.at("right").edges.empty());
  EXPECT_TRUE(m.curves.at("right").nodes.empty());
}

// ---- refusals: each names the file's line (ASCII) or the tag at fault.

const std::string kPlate22 = file_text(kData + "plate_v22_ascii.msh");
const std::string kPlate41 = file_text(kData + "plate_v41_ascii.msh");

TEST(GmshMeshRefuses, UnknownFormatVersions) {
  for (const std::string version : {"3.0", "1.0", "4.0"}) {
    EXPECT_EQ(
        refusal(replaced(kPlate22, "2.2 0 8", version + " 0 8")),
        "part.msh:2: format version " + version + " is not read: grip reads 4.1 and 2.2 (gmsh -format msh41 or msh22)");
  }
  EXPECT_NE(refusal("$NOD\n1\n1 0 0 0\n$ENDNOD\n").find("part.msh:1: expected $MeshFormat"), std::string::npos);
}

TEST(GmshMeshRefuses, TruncatedFiles) {
  // Inside the element list: the line where the next number should be.
  const auto cut = kPlate22.substr(0, kPlate22.find("1002 2"));
  EXPECT_EQ(refusal(cut), "part.msh:38: the file ends (truncated?) where an element tag should be");
  EXPECT_EQ(refusal(kPlate22.substr(0, kPlate22.find("$Elements"))), "part.msh: no $Elements section (truncated?)");
  EXPECT_NE(refusal(kPlate41.substr(0, kPlate41.find("$EndNodes") - 3)).find("truncated?"), std::string::npos);
  for (const std::string v : {"v22_binary", "v41_binary"}) {
    const auto binary = file_text(kData + "plate_" + v + ".msh");
    const auto message = refusal(binary.substr(0, binary.find("$EndElements") - 5));
    EXPECT_NE(message.find("part.msh: byte "), std::string::npos) << message;
    EXPECT_NE(message.find("elements cannot fit in the rest of the file (truncated?)"), std::string::npos) << message;
  }
  EXPECT_EQ(refusal(""), "part.msh: the file is empty");
  // Counts no file could hold.
  EXPECT_EQ(refusal(replaced(kPlate41, "$Nodes\n1 9 10 90\n2 1 0 9", "$Nodes\n1 9 10 90\n2 1 0 99999999999999")),
            "part.msh:43: expected a node tag, read '1.5'");
  EXPECT_EQ(refusal(replaced(kPlate22, "$Elements\n11", "$Elements\n18446744073709551615")),
            "part.msh:41: expected an element tag, read '$EndElements'");
  auto binary = file_text(kData + "plate_v41_binary.msh");
  const auto nodes = binary.find("$Nodes\n") + 7;
  binary.replace(nodes, 16, std::string("\x01\0\0\0\0\0\0\0\xff\xff\xff\xff\xff\xff\xff\x7f", 16));
  EXPECT_EQ(refusal(binary), "part.msh: byte " + std::to_string(nodes) +
                                 ": $Nodes declares 9223372036854775807 nodes, its blocks hold 9");
  EXPECT_THROW(
      {
        try {
          read_gmsh_file(kData + "no_such.msh");
        } catch (const GmshError& e) {
          EXPECT_NE(std::string(e.what()).find("no_such.msh: cannot open: "), std::string::npos);
          throw;
        }
      },
      GmshError);
}

TEST(GmshMeshRefuses, SolidElementsWithTheirTag) {
  EXPECT_EQ(refusal(replaced(kPlate22, "11\n8 15", "12\n99 4 2 0 1 10 20 50 60\n8 15")),
            "part.msh:30: element 99 is a 3D element (4-node tetrahedron, gmsh type 4): grip's bodies are plane; grip "
            "reads t3, t6, q4, q8, q9 (gmsh types 2, 9, 3, 16, 10) and lines and points for groups");
  EXPECT_NE(refusal(replaced(kPlate22, "11\n8 15", "12\n99 5 2 0 1 10 20 50 60 10 20 50 60\n8 15"))
                .find("element 99 is a 3D element (8-node hexahedron"),
            std::string::npos);
  for (const std::string v : {"v22_binary", "v41_binary"}) {
    const auto message = refusal(file_text(kData + "tetrahedron_" + v + ".msh"));
    EXPECT_NE(message.find("element 9 is a 3D element (4-node tetrahedron, gmsh type 4)"), std::string::npos)
        << message;
  }
}

TEST(GmshMeshRefuses, ElementsOfOtherOrders) {
  EXPECT_NE(refusal(replaced(kPlate22, "11\n8 15", "12\n99 21 2 0 1 10 20 30 40 50 60 70 80 90 10\n8 15"))
                .find("part.msh:30: element 99 is a 10-node triangle (gmsh type 21), an order grip does not read"),
            std::string::npos);
  EXPECT_NE(
      refusal(replaced(kPlate41, "2 1 3 1\n1 10", "2 1 26 1\n1 10")).find("element 1 is a 4-node line (gmsh type 26)"),
      std::string::npos);
}

TEST(GmshMeshRefuses, DuplicateAndMissingNodes) {
  EXPECT_EQ(refusal(replaced(kPlate22, "30 2 0 0", "20 2 0 0")), "part.msh: node tag 20 appears twice in $Nodes");
  EXPECT_EQ(refusal(replaced(kPlate41, "\n50\n", "\n20\n")), "part.msh: node tag 20 appears twice in $Nodes");
  EXPECT_EQ(refusal(replaced(kPlate22, "1 3 2 1 1 10 20 50 60", "1 3 2 1 1 10 20 50 77")),
            "part.msh:35: element 1 refers to node 77, which is not in $Nodes");
  EXPECT_NE(refusal(replaced(kPlate41, "1 10 20 50 60", "1 10 20 50 77")).find(":59: element 1 refers to node 77"),
            std::string::npos);
}

TEST(GmshMeshRefuses, CoordinatesThatAreNoFiniteNumbers) {
  EXPECT_EQ(refusal(replaced(kPlate22, "50 1 1 0", "50 nan 1 0")),
            "part.msh:22: node 50 has a coordinate that is not a finite number");
  EXPECT_EQ(refusal(replaced(kPlate22, "50 1 1 0", "50 1 inf 0")),
            "part.msh:22: node 50 has a coordinate that is not a finite number");
  EXPECT_EQ(refusal(replaced(kPlate22, "50 1 1 0", "50 1 1e999 0")), "part.msh:22: expected a node's y, read '1e999'");
}

TEST(GmshMeshRefuses, MeshesOffThePlane) {
  EXPECT_EQ(refusal(replaced(kPlate22, "50 1 1 0", "50 1 1 0.5")),
            "part.msh: node 50 has z = 0.500000 where others have z = 0.000000: grip reads plane meshes, in one "
            "plane z = const");
  // A plane z = 3 reads; the unused node 90 may lie anywhere.
  std::string raised = kPlate22;
  for (const std::string n : {"10 0 0", "20 1 0", "30 2 0", "40 2 1", "50 1 1", "60 0 1", "70 0 1.5", "80 2 1.5"})
    raised = replaced(raised, n + " 0\n", n + " 3\n");
  expect_plate(read_gmsh_mesh(replaced(raised, "90 5 5 0", "90 5 5 -7"), "raised.msh"));
}

TEST(GmshMeshRefuses, ElementsOfZeroArea) {
  EXPECT_EQ(refusal(replaced(kPlate22, "2 2 2 7 2 20 30 40", "2 2 2 7 2 20 30 10")),
            "part.msh: element 2 has zero area (its corners lie on one line)");
  EXPECT_EQ(refusal(replaced(kPlate22, "2 2 2 7 2 20 30 40", "2 2 2 7 2 20 30 20")),
            "part.msh: element 2 uses node 20 twice");
}

TEST(GmshMeshRefuses, PartitionedMeshesAndClashingNames) {
  EXPECT_NE(refusal(replaced(kPlate41, "\n$Nodes\n", "\n$PartitionedEntities\n$EndPartitionedEntities\n$Nodes\n"))
                .find("a partitioned mesh"),
            std::string::npos);
  EXPECT_EQ(refusal(replaced(kPlate22, "\"tool\"", "\"corner\"")),
            "part.msh: physical groups 12 (dimension 1) and 21 (dimension 0) are both named 'corner'");
}

// ---- damaged files: every truncation and a few hundred byte changes of each variant end in
// a GmshError or a mesh whose indices are all in range, never a crash, a hang or another
// exception.
void expect_valid(const GmshMesh& m) {
  const int n = static_cast<int>(m.nodes.size());
  ASSERT_EQ(m.node_tags.size(), m.nodes.size());
  ASSERT_LE(m.body_nodes, n);
  ASSERT_EQ(m.element_offsets.size(), m.element_tags.size() + 1);
  for (int v : m.element_nodes) ASSERT_TRUE(v >= 0 && v < m.body_nodes);
  for (const auto& [name, s] : m.surfaces)
    for (int e : s.elements) ASSERT_TRUE(e >= 0 && e < m.element_count());
  for (const auto& [name, c] : m.curves) {
    for (const auto& edge : c.edges)
      for (int v : edge) ASSERT_TRUE(v >= 0 && v < n);
    for (int v : c.nodes) ASSERT_TRUE(v >= 0 && v < n);
  }
  for (const auto& [name, p] : m.points)
    for (int v : p.nodes) ASSERT_TRUE(v >= 0 && v < n);
}

void expect_error_or_valid(const std::string& bytes, const std::string& what) {
  try {
    expect_valid(read_gmsh_mesh(bytes, "fuzz.msh"));
  } catch (const GmshError&) {
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": " << e.what();
  }
}

TEST(GmshMeshDamaged, EveryTruncationAndByteChangeEndsInAnErrorOrAValidMesh) {
  std::mt19937 random(35);
  const std::string interesting = "0123456789 \n-.e$\"\xff";
  int cases = 0;
  for (const std::string name : {"plate", "quadratic"})
    for (const auto& v : kVariants) {
      const auto text = file_text(kData + name + "_" + v + ".msh");
      for (std::size_t n = 0; n < text.size(); ++n, ++cases) expect_error_or_valid(text.substr(0, n), "prefix");
      for (int k = 0; k < 300; ++k, ++cases) {
        std::string damaged = text;
        const auto at = random() % damaged.size();
        damaged[at] = k % 2 ? interesting[random() % interesting.size()] : static_cast<char>(random() % 256);
        expect_error_or_valid(damaged, v + " byte " + std::to_string(at));
      }
    }
  EXPECT_GT(cases, 10000);
}

}  // namespace
}  // namespace grip
