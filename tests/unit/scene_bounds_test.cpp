// A scene's problems cost at most kMaxSceneIssues, however large the scene (issue 34.2): the
// reader stops at the next problem, the validator stops collecting at a bound, and both
// report more() when they stopped. The validator's memory beyond the document is measured in
// a child process (VmHWM after the validation minus VmRSS before it) for documents of 10,000
// and 80,000 bad entries: it must be small and must not grow with the document.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>

#include "solver/io/scene.hpp"
#include "solver/io/schema_validation.hpp"
#include "tests/support/scenes.hpp"

namespace grip {
namespace {

using nlohmann::json;
using testing::example_scene;

// The sliding block with `n` copies of `entry` as body[key] (or scene[key] when `top`).
json with_copies(const std::string& key, const json& entry, size_t n, bool top = false) {
  json s = example_scene("sliding-block");
  json& where = top ? s : s["body"];
  where[key] = json::array();
  for (size_t i = 0; i < n; ++i) where[key].push_back(entry);
  return s;
}

SceneErrors read_errors(const json& scene) {
  try {
    read_scene(scene);
  } catch (const SceneErrors& e) {
    return e;
  }
  throw std::logic_error("the scene was read without errors");
}

TEST(SceneBounds, ARepeatedSupportStopsTheReaderAtTheLimit) {
  // Each copy prescribes y of the block's 21 top nodes again: 80,000 copies were 1.7 million
  // problems.
  const json support = example_scene("sliding-block")["body"]["supports"][0];
  const SceneErrors e = read_errors(with_copies("supports", support, 80000));
  ASSERT_EQ(e.issues().size(), kMaxSceneIssues);
  EXPECT_TRUE(e.more());
  EXPECT_EQ(e.issues()[0].pointer, "/body/supports/1/fix/1");
  EXPECT_NE(e.issues()[0].detail.find("which /body/supports/0 fixes already"), std::string::npos)
      << e.issues()[0].detail;
}

TEST(SceneBounds, AFewProblemsAreAllListedWithoutMore) {
  const json support = example_scene("sliding-block")["body"]["supports"][0];
  const SceneErrors e = read_errors(with_copies("supports", support, 2));
  EXPECT_EQ(e.issues().size(), 21u);  // the 21 top nodes' y, once
  EXPECT_FALSE(e.more());
}

TEST(SceneBounds, ObstaclesOfOneNameStopAtTheLimit) {
  const json obstacle = example_scene("sliding-block")["obstacles"][0];
  const SceneErrors e = read_errors(with_copies("obstacles", obstacle, 40000, true));
  ASSERT_EQ(e.issues().size(), kMaxSceneIssues);
  EXPECT_TRUE(e.more());
  EXPECT_EQ(e.issues()[0].pointer, "/obstacles/1/name");
  EXPECT_EQ(e.issues()[0].detail, "\"flat\" names another obstacle already");
}

TEST(SceneBounds, TheValidatorListsTheFirstProblemsByPointerAndSaysThereAreMore) {
  const json load = {{"node", 3}, {"force", {1, 0}}, {"bogus", 1}};
  bool more = false;
  const auto issues = validate_against(with_copies("loads", load, 40000), SchemaName::scene, &more);
  ASSERT_EQ(issues.size(), kMaxSceneIssues);
  EXPECT_TRUE(more);
  for (size_t i = 0; i < issues.size(); ++i)
    EXPECT_EQ(issues[i].pointer, "/body/loads/" + std::to_string(i) + "/bogus") << issues[i].detail;
  // Three bad loads: all three, and no more.
  const auto few = validate_against(with_copies("loads", load, 3), SchemaName::scene, &more);
  EXPECT_EQ(few.size(), 3u);
  EXPECT_FALSE(more);
}

double status_kb(const std::string& field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1));
  return -1;
}

// In a child process: the MB the validation of `doc` adds to the peak resident memory.
double validation_peak_mb(const json& doc) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const double before = status_kb("VmRSS");
    // The peak so far (the parent's) must not hide the validation's: reset it.
    std::ofstream("/proc/self/clear_refs") << "5";
    validate_against(doc, SchemaName::scene);
    const double added = (status_kb("VmHWM") - before) / 1024.0;
    if (write(fds[1], &added, sizeof added) != sizeof added) _exit(2);
    _exit(0);
  }
  close(fds[1]);
  double added = -1;
  const bool got = read(fds[0], &added, sizeof added) == sizeof added;
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!got) throw std::runtime_error("the child did not report");
  return added;
}

TEST(SceneBounds, TheValidatorsMemoryDoesNotGrowWithTheDocument) {
  const json load = {{"node", 3}, {"force", {1, 0}}, {"bogus", 1}};
  validate_against(with_copies("loads", load, 2), SchemaName::scene);  // builds the validator here
  const json small = with_copies("loads", load, 10000), large = with_copies("loads", load, 80000);
  const double small_mb = validation_peak_mb(small), large_mb = validation_peak_mb(large);
  std::printf("validation adds %.1f MB at 10,000 bad loads, %.1f MB at 80,000\n", small_mb, large_mb);
  // Collecting every error took 34 MB at 20,000 and 230 MB (and 375 s) at 150,000.
  EXPECT_LT(small_mb, 16.0);
  EXPECT_LT(large_mb, 16.0);
  EXPECT_LT(large_mb, small_mb + 4.0);
}

}  // namespace
}  // namespace grip
