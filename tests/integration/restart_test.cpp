// Durability: kill -9 and SIGTERM of the real server, then a restart on the same database.
#include <gtest/gtest.h>

#include <thread>

#include "grip_process.hpp"

namespace grip::testing {
namespace {

TEST(Restart, KillNineLosesNoAcceptedJobAndResultsEqualAnUninterruptedRun) {
  TempDir dir;
  const fs::path db = dir.path() / "grip.sqlite", log = dir.path() / "server.log";
  const std::vector<json> scenes = {beam_scene(10, 3), beam_scene(40, 60), beam_scene(20, 8),
                                    json::parse(read_text(examples_dir() / "beam-on-cylinder.json"))};
  std::vector<std::string> ids;
  std::string finished_before_kill;
  std::int64_t last_seen_id = 0;
  {
    ServerProcess server(db, {"--workers", "1"}, log);
    const Api api(server.port());
    ids.push_back(api.submit(scenes[0]));
    api.wait_status(ids[0], {"successful"});
    finished_before_kill = api.get("/v1/jobs/" + ids[0] + "/result")->body;
    for (size_t i = 1; i < scenes.size(); ++i) ids.push_back(api.submit(scenes[i]));
    // The long job runs (events seen), the two after it are accepted and queued.
    const Stream seen = follow(api, ids[1], std::nullopt, 20);
    ASSERT_EQ(seen.events.size(), 20u);
    last_seen_id = seen.events.back().id;
    EXPECT_EQ(api.job(ids[1])["status"], "running");
    EXPECT_EQ(api.job(ids[2])["status"], "accepted");
    server.kill9();
  }
  ServerProcess server(db, {"--workers", "2"}, log);
  const Api api(server.port());
  for (const auto& id : ids)
    EXPECT_EQ(api.wait_status(id, {"successful", "failed", "dismissed"})["status"], "successful") << id;
  // A result finished before the crash is intact, byte for byte.
  EXPECT_EQ(api.get("/v1/jobs/" + ids[0] + "/result")->body, finished_before_kill);
  // Every result equals an uninterrupted run's.
  for (size_t i = 0; i < ids.size(); ++i) {
    const json got = json::parse(api.get("/v1/jobs/" + ids[i] + "/result")->body);
    EXPECT_EQ(without_timings(got),
              without_timings(reference_result(scenes[i], dir.path(), "scene" + std::to_string(i))))
        << "job " << i;
  }
  // The interrupted job ran again: its events are the new run's, numbered above every id a
  // client saw before the crash, without gaps or repeats.
  EXPECT_EQ(api.job(ids[1])["attempts"], 2);
  const Stream replay = follow(api, ids[1]);
  ASSERT_TRUE(replay.ended);
  ASSERT_GT(replay.events.front().id, last_seen_id);
  for (size_t i = 1; i < replay.events.size(); ++i) ASSERT_EQ(replay.events[i].id, replay.events[i - 1].id + 1);
  EXPECT_EQ(replay.events.front().type, "step_started");
  EXPECT_EQ(replay.events.front().object()["step"], 1);
  EXPECT_EQ(replay.events.back().type, "job_finished");
  // Resuming from an id of the lost run continues with the new run from its start.
  const Stream resumed = follow(api, ids[1], last_seen_id);
  ASSERT_EQ(resumed.events.size(), replay.events.size());
  EXPECT_EQ(resumed.events.front().id, replay.events.front().id);
}

TEST(Restart, SigtermLetsRunningJobsFinishWithinGraceAndRequeuesTheRest) {
  TempDir dir;
  const fs::path db = dir.path() / "grip.sqlite", log = dir.path() / "server.log";
  std::string long_job, queued, quick;
  {
    // A job longer than the grace period: stopped and accepted again; the queued one too.
    ServerProcess server(db, {"--workers", "1", "--grace", "0.2"}, log);
    const Api api(server.port());
    long_job = api.submit(beam_scene(40, 4000));  // about 1.7 s; 400 steps now take 0.17 s
    queued = api.submit(beam_scene(10, 3));
    ASSERT_EQ(follow(api, long_job, std::nullopt, 5).events.size(), 5u);
    ASSERT_TRUE(wait_open_streams(api, 0));  // the stream above is gone
    Stream open_stream;
    std::thread follower([&] { open_stream = follow(api, long_job); });
    EXPECT_TRUE(wait_open_streams(api, 1));
    EXPECT_EQ(server.terminate(std::chrono::seconds(30)), 0);
    follower.join();  // SIGTERM closed the stream
    EXPECT_EQ(open_stream.status, 200);
    EXPECT_FALSE(open_stream.ended);
  }
  {
    // A job shorter than the grace period finishes before the server exits.
    ServerProcess server(db, {"--workers", "1", "--grace", "60"}, log);
    const Api api(server.port());
    // Taken again first (creation order), with its attempt counted; dismissed to save time.
    EXPECT_EQ(api.wait_status(long_job, {"running"})["attempts"], 2);
    api.del("/v1/jobs/" + long_job);
    api.wait_status(queued, {"successful"});
    quick = api.submit(json::parse(read_text(examples_dir() / "beam-on-cylinder.json")));
    api.wait_status(quick, {"running", "successful"});  // 0.08 s: it may finish before we look
    EXPECT_EQ(server.terminate(std::chrono::seconds(60)), 0);
  }
  ServerProcess server(db, {}, log);
  const Api api(server.port());
  EXPECT_EQ(api.job(long_job)["status"], "dismissed");
  EXPECT_EQ(api.job(queued)["status"], "successful");
  const json doc = api.job(quick);
  EXPECT_EQ(doc["status"], "successful");
  EXPECT_EQ(doc["attempts"], 1);
  const Stream s = follow(api, quick);
  ASSERT_TRUE(s.ended);
  EXPECT_EQ(s.events.front().id, 1);
  EXPECT_EQ(s.events.back().id, static_cast<std::int64_t>(s.events.size()));
}

}  // namespace
}  // namespace grip::testing
