// Issue 35, hard cases of meshes from gmsh files: the same mesh written another way must solve
// to the same numbers. The shipped hertz-t6 mesh (schemas/examples/hertz-t6.msh, 4.1 ASCII,
// 1868 elements) rewritten with every triangle clockwise (gmsh writes them so for a surface
// whose normal points down), and with its node tags scattered (gmsh keeps tags of a mesh that
// was partly removed, renumbered or merged): the reader reorients and renumbers, the solve
// gives the same contact forces, and the result names the file's own tags.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <sstream>

#include "solver/io/gmsh_mesh.hpp"
#include "solver/io/result.hpp"
#include "tests/support/result_checks.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using namespace grip::testing;
using nlohmann::json;

const std::string kExamples = std::string(GRIP_SOURCE_DIR) + "/schemas/examples/";

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// A 4.1 ASCII file with each node tag t written as tag(t) and each 2D element's nodes passed
// through reorder(type, nodes), line by line ($Nodes and $Elements; the rest as it was).
std::string rewrite(const std::string& text, const std::function<long(long)>& tag,
                    const std::function<void(int, std::vector<long>&)>& reorder) {
  std::istringstream in(text);
  std::ostringstream out;
  std::string line;
  const auto ints = [](const std::string& l) {
    std::istringstream s(l);
    std::vector<long> v;
    for (long x; s >> x;) v.push_back(x);
    return v;
  };
  const auto join = [](const std::vector<long>& v) {
    std::string s;
    for (long x : v) s += (s.empty() ? "" : " ") + std::to_string(x);
    return s;
  };
  while (std::getline(in, line)) {
    out << line << '\n';
    if (line == "$Nodes") {
      std::getline(in, line);
      std::vector<long> h = ints(line);  // blocks, nodes, min tag, max tag
      out << h[0] << ' ' << h[1] << ' ' << tag(h[2]) << ' ' << tag(h[3]) << '\n';
      for (long b = 0; b < h[0]; ++b) {
        std::getline(in, line);
        const long n = ints(line).at(3);
        out << line << '\n';
        for (long k = 0; k < n; ++k) {
          std::getline(in, line);
          out << tag(ints(line).at(0)) << '\n';
        }
        for (long k = 0; k < n; ++k) {
          std::getline(in, line);
          out << line << '\n';
        }
      }
    } else if (line == "$Elements") {
      std::getline(in, line);
      out << line << '\n';
      const long blocks = ints(line).at(0);
      for (long b = 0; b < blocks; ++b) {
        std::getline(in, line);
        const std::vector<long> h = ints(line);  // dim, entity, type, count
        out << line << '\n';
        for (long k = 0; k < h[3]; ++k) {
          std::getline(in, line);
          std::vector<long> e = ints(line);
          std::vector<long> nodes(e.begin() + 1, e.end());
          for (long& n : nodes) n = tag(n);
          if (h[0] == 2) reorder(static_cast<int>(h[2]), nodes);
          out << e[0] << ' ' << join(nodes) << '\n';
        }
      }
    }
  }
  return out.str();
}

// hertz-t6 with its mesh from `bytes`.
Solved solve_hertz_t6(const std::string& bytes) {
  const auto mesh = std::make_shared<const GmshMesh>(read_gmsh_mesh(bytes, "hertz-t6.msh"));
  return solve_scene(example_scene("hertz-t6"), [&](const json&) { return mesh; });
}

void expect_same_forces(const Solved& a, const Solved& b) {
  ASSERT_EQ(a.run.steps.size(), b.run.steps.size());
  for (size_t k = 0; k < a.run.steps.size(); ++k) {
    const Vector& p = a.run.steps[k].p;
    ASSERT_EQ(p.size(), b.run.steps[k].p.size());
    EXPECT_LE((p - b.run.steps[k].p).lpNorm<Eigen::Infinity>(), 1e-9 * p.lpNorm<Eigen::Infinity>()) << "step " << k + 1;
  }
}

TEST(GmshScenesHard, AFileWithEveryTriangleClockwiseSolvesAsWrittenCounterClockwise) {
  const std::string original = read_text(kExamples + "hertz-t6.msh");
  // t6 (gmsh type 9) clockwise: corners 0, 2, 1, then the mid-sides of 0-2, 2-1, 1-0.
  const std::string flipped = rewrite(
      original, [](long t) { return t; },
      [](int type, std::vector<long>& n) {
        ASSERT_EQ(type, 9);
        n = {n[0], n[2], n[1], n[5], n[4], n[3]};
      });
  ASSERT_NE(flipped, original);
  const GmshMesh mesh = read_gmsh_mesh(flipped, "flipped");
  EXPECT_EQ(mesh.reoriented, mesh.element_count());
  EXPECT_EQ(read_gmsh_mesh(original, "original").reoriented, 0);
  const Solved a = solve_hertz_t6(original), b = solve_hertz_t6(flipped);
  expect_hard_case_sound(b);
  ASSERT_TRUE(a.run.completed) << a.run.reason;
  ASSERT_TRUE(b.run.completed) << b.run.reason;
  expect_same_forces(a, b);
}

TEST(GmshScenesHard, ScatteredNodeTagsSolveAsTheOriginalAndStayInTheResult) {
  const std::string original = read_text(kExamples + "hertz-t6.msh");
  // Tags 1..3651 become 10^9 + 7 t (wide gaps, none of the small numbers); nothing else changes.
  const auto scatter = [](long t) { return 1000000000L + 7 * t; };
  const std::string scattered = rewrite(original, scatter, [](int, std::vector<long>&) {});
  const Solved a = solve_hertz_t6(original), b = solve_hertz_t6(scattered);
  expect_hard_case_sound(b);
  ASSERT_TRUE(a.run.completed) << a.run.reason;
  ASSERT_TRUE(b.run.completed) << b.run.reason;
  expect_same_forces(a, b);
  const json ra = result_json(a.scene, a.run), rb = result_json(b.scene, b.run);
  const json& tags_a = ra["mesh"]["gmsh"][0]["node_tags"];
  const json& tags_b = rb["mesh"]["gmsh"][0]["node_tags"];
  ASSERT_EQ(tags_a.size(), tags_b.size());
  for (size_t n = 0; n < tags_a.size(); ++n)
    ASSERT_EQ(tags_b[n].get<long>(), scatter(tags_a[n].get<long>())) << "node " << n;
}

}  // namespace
}  // namespace grip
