// grip's .msh reader against gmsh itself: where Debian's gmsh Python module (python3-gmsh) is
// importable by /usr/bin/python3, tests/data/gmsh/gmsh_reference.py meshes a plate (quads
// beside triangles, a tool line, physical surfaces, curves and a point) at order 1, 2 and 2
// incomplete, writes each in the four variants of the format (4.1 also with parametric
// coordinates) and reports what gmsh's API
// holds; every file must read to the same nodes, elements and groups.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "solver/io/gmsh_mesh.hpp"

namespace grip {
namespace {

using Tags = std::vector<std::size_t>;

int gmsh_type(ElementShape kind) {
  switch (kind) {
    case ElementShape::t3:
      return 2;
    case ElementShape::t6:
      return 9;
    case ElementShape::q4:
      return 3;
    case ElementShape::q8:
      return 16;
    case ElementShape::q9:
      return 10;
  }
  return 0;
}

// An element as (gmsh type, node tags): 2.2 files renumber elements (gmsh's writer numbers
// them as it writes), so elements are matched by their nodes; 4.1 keeps the tags.
using Element = std::pair<int, Tags>;

Tags tags_of(const GmshMesh& m, std::span<const int> nodes) {
  Tags t;
  for (int n : nodes) t.push_back(m.node_tags[n]);
  return t;
}

TEST(GmshPython, GripReadsWhatGmshWroteAsGmshReportsIt) {
  const std::string out = testing::TempDir() + "grip_gmsh_reference_" + std::to_string(getpid());
  const std::string command = "/usr/bin/python3 " + std::string(GRIP_SOURCE_DIR) +
                              "/tests/data/gmsh/gmsh_reference.py " + out + " > /dev/null 2>&1";
  const int status = std::system(command.c_str());
  if (WIFEXITED(status) && WEXITSTATUS(status) == 77)
    GTEST_SKIP() << "gmsh's Python module is not importable by /usr/bin/python3 (Debian package python3-gmsh)";
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command;

  for (const std::string c : {"linear", "quadratic", "serendipity"}) {
    std::ifstream report_file(out + "/" + c + ".json");
    const auto report = nlohmann::json::parse(report_file);
    std::map<std::size_t, Vec2> gmsh_nodes;
    for (const auto& [tag, x] : report["nodes"].items()) gmsh_nodes[std::stoul(tag)] = Vec2(x[0], x[1]);
    std::multiset<Element> gmsh_elements;
    std::map<std::size_t, Element> gmsh_by_tag;
    std::set<std::size_t> body;
    for (const auto& e : report["elements"]) {
      const Element element{e[0].get<int>(), e[2].get<Tags>()};
      gmsh_elements.insert(element);
      gmsh_by_tag[e[1].get<std::size_t>()] = element;
      body.insert(element.second.begin(), element.second.end());
    }
    for (const std::string v :
         {"v22_ascii", "v22_binary", "v41_ascii", "v41_binary", "v41_parametric_ascii", "v41_parametric_binary"}) {
      SCOPED_TRACE(c + "_" + v);
      const auto m = read_gmsh_file(out + "/" + c + "_" + v + ".msh");
      // Nodes: the 2D elements' first, with gmsh's coordinates (ASCII keeps 16 digits).
      ASSERT_EQ(m.body_nodes, static_cast<int>(body.size()));
      EXPECT_EQ(std::set<std::size_t>(m.node_tags.begin(), m.node_tags.begin() + m.body_nodes), body);
      for (std::size_t i = 0; i < m.nodes.size(); ++i) {
        ASSERT_TRUE(gmsh_nodes.contains(m.node_tags[i]));
        EXPECT_NEAR((m.nodes[i] - gmsh_nodes[m.node_tags[i]]).norm(), 0.0, 1e-14);
      }
      // Elements: gmsh meshes counter-clockwise, so nothing is reoriented and the node order is gmsh's.
      EXPECT_EQ(m.reoriented, 0);
      std::multiset<Element> ours;
      for (int e = 0; e < m.element_count(); ++e) {
        const Element element{gmsh_type(m.element_kinds[e]), tags_of(m, m.element(e))};
        ours.insert(element);
        if (v.starts_with("v41")) EXPECT_EQ(gmsh_by_tag[m.element_tags[e]], element);
      }
      EXPECT_EQ(ours, gmsh_elements);
      // Groups: the same members and nodes.
      std::size_t groups = 0;
      for (const auto& g : report["groups"]) {
        const int dimension = g["dimension"], tag = g["tag"];
        std::string name = g["name"];
        if (name.empty())
          name = (dimension == 2 ? "surface_" : dimension == 1 ? "curve_" : "point_") + std::to_string(tag);
        SCOPED_TRACE(name);
        std::multiset<Tags> gmsh_members;
        for (const auto& member : g["elements"]) gmsh_members.insert(member[1].get<Tags>());
        const auto gmsh_group_nodes = g["nodes"].get<Tags>();
        std::multiset<Tags> members;
        Tags nodes;
        if (dimension == 2) {
          ASSERT_TRUE(m.surfaces.contains(name));
          EXPECT_EQ(m.surfaces.at(name).tag, tag);
          std::set<std::size_t> all;
          for (int e : m.surfaces.at(name).elements) {
            members.insert(tags_of(m, m.element(e)));
            for (auto t : tags_of(m, m.element(e))) all.insert(t);
          }
          nodes.assign(all.begin(), all.end());
        } else {
          const bool curve = dimension == 1;
          ASSERT_TRUE(curve ? m.curves.contains(name) : m.points.contains(name));
          if (curve)
            for (const auto& edge : m.curves.at(name).edges) members.insert(tags_of(m, edge));
          nodes = tags_of(m, curve ? m.curves.at(name).nodes : m.points.at(name).nodes);
          if (!curve) members.insert(nodes);
          std::sort(nodes.begin(), nodes.end());
        }
        EXPECT_EQ(members, gmsh_members);
        EXPECT_EQ(nodes, gmsh_group_nodes);
        ++groups;
      }
      EXPECT_EQ(groups, m.surfaces.size() + m.curves.size() + m.points.size());
      // The bottom and the tool are single lines: their nodes in order along them.
      for (const std::string curve : {"bottom", "tool"}) {
        const auto& k = m.curves.at(curve);
        ASSERT_TRUE(k.chain);
        for (std::size_t i = 0; i + 2 < k.nodes.size(); ++i) {
          const Vec2 a = m.nodes[k.nodes[i]], b = m.nodes[k.nodes[i + 1]], d = m.nodes[k.nodes[i + 2]];
          EXPECT_GT((b - a).dot(d - b), 0.0);  // no turning back
        }
      }
      EXPECT_EQ(m.nodes[m.curves.at("tool").nodes.front()], Vec2(2, 1.5));  // as gmsh orients it
    }
  }
  std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace grip
