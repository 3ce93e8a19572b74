// Inputs the scene fuzzer (tests/fuzz) once broke the reader with, kept in
// tests/fuzz/regressions: each is read as the service reads a body, and must either be
// malformed JSON, a valid scene, or a SceneErrors whose every issue has a JSON pointer.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "solver/io/json_depth.hpp"
#include "solver/io/scene.hpp"

namespace grip {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kRegressions = fs::path(GRIP_SOURCE_DIR) / "tests" / "fuzz" / "regressions";

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// A well-formed JSON pointer: empty or "/" tokens, '~' only as "~0" or "~1".
bool is_json_pointer(const std::string& p) {
  if (p.empty() || p.front() != '/') return false;
  for (size_t i = 0; i < p.size(); ++i)
    if (p[i] == '~' && (i + 1 == p.size() || (p[i + 1] != '0' && p[i + 1] != '1'))) return false;
  return true;
}

TEST(FuzzRegressions, EveryInputIsReadOrRejectedWithPointers) {
  ASSERT_TRUE(fs::is_directory(kRegressions));
  int inputs = 0;
  for (const auto& entry : fs::directory_iterator(kRegressions)) {
    SCOPED_TRACE(entry.path().filename().string());
    ++inputs;
    json scene;
    try {
      scene = json::parse(read_bytes(entry.path()));
    } catch (const json::parse_error&) {
      continue;  // the service's 400
    }
    try {
      const Scene s = read_scene(scene);
      EXPECT_TRUE(s.problem.body);
    } catch (const SceneErrors& e) {
      ASSERT_FALSE(e.issues().empty());
      for (const SceneIssue& issue : e.issues())
        EXPECT_TRUE(is_json_pointer(issue.pointer)) << issue.pointer << ": " << issue.detail;
    }
  }
  EXPECT_GT(inputs, 0);
}

// A few MB of '[' parse, but dumping or copying them overflowed the stack of `grip solve`
// (and of an HTTP thread): the file is refused before parsing.
TEST(FuzzRegressions, DeepNestingIsRefusedBeforeParsing) {
  const int levels = 1000000;
  const fs::path path = fs::temp_directory_path() / "grip_deep_nesting_test.json";
  {
    std::ofstream out(path, std::ios::binary);
    out << "{\"units\": " << std::string(levels, '[') << std::string(levels, ']') << "}";
  }
  try {
    read_scene_file(path.string());
    ADD_FAILURE() << "a scene nested a million levels deep was read";
  } catch (const SceneErrors& e) {
    ASSERT_EQ(e.issues().size(), 1u);
    EXPECT_EQ(e.issues()[0].pointer, "/");
    EXPECT_NE(e.issues()[0].detail.find("nested deeper than"), std::string::npos);
  }
  fs::remove(path);
  // A number beyond double: nlohmann throws out_of_range.406, not a parse_error.
  {
    std::ofstream out(path, std::ios::binary);
    out << "{\"steps\": 1e400}";
  }
  EXPECT_THROW(read_scene_file(path.string()), SceneErrors);
  fs::remove(path);
  EXPECT_FALSE(nested_deeper_than("{\"a\": [[1], {\"b\": \"[[[[\"}]}", 3));
  EXPECT_TRUE(nested_deeper_than("[[[[]]]]", 3));
}

}  // namespace
}  // namespace grip
