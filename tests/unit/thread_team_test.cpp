// grip solve's kept threads (apps/thread_team.hpp): every task runs once per call, call after
// call on the same threads; a task's exception reaches the caller and the team stays usable; a
// call from inside a task runs serially instead of waiting for itself; the two cylinders solve
// to the same bits on the team as one after another.
#include "apps/thread_team.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <stdexcept>
#include <vector>

#include "solver/io/scene.hpp"
#include "solver/stepping/load_stepping.hpp"

namespace grip {
namespace {

TEST(ThreadTeam, EveryTaskOnceCallAfterCall) {
  ThreadTeam team(2);
  for (int call = 0; call < 200; ++call) {
    const int count = 1 + call % 5;
    std::vector<int> runs(count, 0);  // each task writes its own entry
    team.run(count, [&](int k) { ++runs[k]; });
    for (int k = 0; k < count; ++k) ASSERT_EQ(runs[k], 1) << "call " << call << " task " << k;
  }
}

TEST(ThreadTeam, AnExceptionReachesTheCallerAndNestedCallsRunSerially) {
  ThreadTeam team(2);
  EXPECT_THROW(team.run(2,
                        [](int k) {
                          if (k == 1) throw std::runtime_error("task 1");
                        }),
               std::runtime_error);
  std::atomic<int> inner{0};
  team.run(2, [&](int) { team.run(3, [&](int) { ++inner; }); });
  EXPECT_EQ(inner.load(), 6);
}

TEST(ThreadTeam, TwoCylindersTheSameAsOneAfterAnother) {
  Scene serial = read_scene_file(GRIP_SOURCE_DIR "/schemas/examples/two-cylinders.json");
  Scene teamed = read_scene_file(GRIP_SOURCE_DIR "/schemas/examples/two-cylinders.json");
  auto team = std::make_shared<ThreadTeam>(2);
  teamed.params.newton.parallel = [team](int count, const std::function<void(int)>& task) { team->run(count, task); };
  const RunResult a = run_load_steps(serial.problem, serial.steps, serial.params);
  const RunResult b = run_load_steps(teamed.problem, teamed.steps, teamed.params);
  ASSERT_TRUE(a.completed);
  ASSERT_TRUE(b.completed);
  ASSERT_EQ(a.steps.size(), b.steps.size());
  for (size_t k = 0; k < a.steps.size(); ++k) {
    EXPECT_EQ((a.steps[k].p - b.steps[k].p).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ((a.steps[k].state.q - b.steps[k].state.q).cwiseAbs().maxCoeff(), 0.0);
  }
}

}  // namespace
}  // namespace grip
