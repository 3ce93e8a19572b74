// Scale-out (label `scaleout`): one throwaway PostgreSQL cluster, three `grip serve` replicas
// on it behind HAProxy (Debian's package; health checks on /v1/ready), 500 small jobs from 20
// concurrent clients. During the run one replica is killed with -9 and restarted, and the
// database is stopped and started again. Afterwards every acknowledged job is successful
// exactly once, with a result equal to `grip solve`'s and one complete event stream; event
// streams opened on one replica and resumed (Last-Event-ID) on another miss and repeat
// nothing; a job running on one replica is dismissed through another.
#include <gtest/gtest.h>

#include <atomic>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "tests/integration/grip_process.hpp"
#include "tests/support/postgres_cluster.hpp"

namespace grip::testing {
namespace {

using namespace std::chrono_literals;

int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

// HAProxy in front of the replicas: round robin, a replica whose /v1/ready fails leaves the
// rotation; a connection refused (a killed replica) is retried on another.
class LoadBalancer {
 public:
  LoadBalancer(const fs::path& dir, const std::vector<int>& backends) : port_(free_port()) {
    const fs::path cfg = dir / "haproxy.cfg";
    std::ofstream out(cfg);
    out << "global\n  maxconn 4000\n"
        << "defaults\n  mode http\n  timeout connect 2s\n  timeout client 120s\n"
        << "  timeout server 120s\n  retries 3\n  option redispatch\n"
        << "listen grip\n  bind 127.0.0.1:" << port_ << "\n  balance roundrobin\n"
        << "  option httpchk GET /v1/ready\n  default-server inter 300ms fall 1 rise 1\n";
    for (size_t i = 0; i < backends.size(); ++i) out << "  server r" << i << " 127.0.0.1:" << backends[i] << " check\n";
    out.close();
    const fs::path log = dir / "haproxy.log";
    pid_ = fork();
    if (pid_ == 0) {
      const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      dup2(fd, 1);
      dup2(fd, 2);
      execl("/usr/sbin/haproxy", "haproxy", "-db", "-f", cfg.c_str(), nullptr);
      _exit(127);
    }
    // Ready when /v1/health answers through it.
    for (int i = 0; i < 200; ++i) {
      if (auto r = Api(port_).client(2).Get("/v1/health"); r && r->status == 200) return;
      std::this_thread::sleep_for(50ms);
    }
    throw std::runtime_error("haproxy did not start:\n" + read_text(log));
  }
  ~LoadBalancer() {
    ::kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
  }
  int port() const { return port_; }

 private:
  int port_;
  pid_t pid_ = -1;
};

// Ids strictly contiguous, no repeats, the terminal event last and only there.
void expect_complete(const std::vector<SseEvent>& events, const std::string& id) {
  ASSERT_FALSE(events.empty()) << id;
  for (size_t i = 1; i < events.size(); ++i) ASSERT_EQ(events[i].id, events[i - 1].id + 1) << id;
  int terminal = 0;
  for (const auto& e : events) terminal += e.type == "job_finished" || e.type == "job_failed";
  EXPECT_EQ(terminal, 1) << id;
  EXPECT_TRUE(events.back().type == "job_finished" || events.back().type == "job_failed") << id;
  EXPECT_EQ(events.front().type, "step_started") << id;
}

TEST(Scaleout, ThreeReplicasOnePostgresNothingLostNothingRunTwice) {
  if (!fs::exists("/usr/sbin/haproxy")) GTEST_SKIP() << "haproxy is not installed (scripts/setup.sh installs it)";
  std::unique_ptr<PostgresCluster> cluster;
  try {
    cluster = std::make_unique<PostgresCluster>();
  } catch (const std::exception& e) {
    GTEST_SKIP() << "no PostgreSQL cluster could be started: " << e.what();
  }
  TempDir dir;
  const std::string url = cluster->new_database();
  const std::vector<int> ports = {free_port(), free_port(), free_port()};
  auto start_replica = [&](int i) {
    return std::make_unique<ServerProcess>(
        url,
        std::vector<std::string>{"--port", std::to_string(ports[i]), "--workers", "1", "--lease", "8", "--replica",
                                 "r" + std::to_string(i), "--streams", "64"},
        dir.path() / ("replica" + std::to_string(i) + ".log"));
  };
  std::vector<std::unique_ptr<ServerProcess>> replicas;
  for (int i = 0; i < 3; ++i) replicas.push_back(start_replica(i));
  LoadBalancer lb(dir.path(), ports);
  struct LogsOnFailure {
    const fs::path& dir;
    ~LogsOnFailure() {
      if (!::testing::Test::HasFailure()) return;
      for (int i = 0; i < 3; ++i) {
        const std::string text = read_text(dir / ("replica" + std::to_string(i) + ".log"));
        std::printf("---- replica%d.log (end)\n%s\n", i,
                    text.substr(text.size() > 6000 ? text.size() - 6000 : 0).c_str());
      }
    }
  } logs_on_failure{dir.path()};
  const Api api(lb.port());

  const std::vector<json> variants = {beam_scene(8, 3), beam_scene(10, 3), beam_scene(12, 3), beam_scene(10, 4),
                                      beam_scene(14, 2)};
  std::vector<std::string> references;
  for (size_t v = 0; v < variants.size(); ++v)
    references.push_back(without_timings(reference_result(variants[v], dir.path(), "v" + std::to_string(v))).dump());

  constexpr int kJobs = 500, kClients = 20;
  const auto t0 = std::chrono::steady_clock::now();
  auto note = [&](const std::string& what) {
    std::printf("[ info ] %6.1f s  %s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                what.c_str());
    std::fflush(stdout);
  };
  std::atomic<bool> abort_all{false};
  std::mutex m;
  std::map<std::string, int> acknowledged;  // job id -> variant
  std::atomic<int> next{0}, acks{0}, refused_503{0}, connection_errors{0};
  auto client = [&] {
    for (int k; !abort_all && (k = next++) < kJobs;) {
      const std::string key = "scaleout-" + std::to_string(k);
      const int variant = k % static_cast<int>(variants.size());
      while (!abort_all) {
        auto r =
            api.client(30).Post("/v1/jobs", {{"Idempotency-Key", key}}, variants[variant].dump(), "application/json");
        if (r && r->status == 201) {
          std::lock_guard lock(m);
          acknowledged[json::parse(r->body).at("jobID")] = variant;
          ++acks;
          break;
        }
        if (r && r->status == 503) {
          ++refused_503;
          std::this_thread::sleep_for(std::chrono::milliseconds(
              std::min(1000, 1000 * std::max(1, std::atoi(r->get_header_value("Retry-After").c_str())))));
        } else {
          if (r && r->status < 500) {
            ADD_FAILURE() << r->status << " " << r->body;
            return;
          }
          ++connection_errors;  // a replica killed under the request: retried with the same key
          std::this_thread::sleep_for(100ms);
        }
      }
    }
  };
  // Streams opened on one replica, resumed with Last-Event-ID on the next one.
  std::atomic<bool> load_done{false};
  std::atomic<int> streams_checked{0};
  auto streamer = [&](int s) {
    while (!load_done && !abort_all) {
      std::string id;
      {
        std::lock_guard lock(m);
        if (acknowledged.size() > static_cast<size_t>(s))
          id = std::next(acknowledged.begin(), s * 7 % acknowledged.size())->first;
      }
      if (id.empty()) {
        std::this_thread::sleep_for(50ms);
        continue;
      }
      const int first = s % 3;
      Stream head = follow(Api(ports[first]), id, std::nullopt, 3);
      if (head.status != 200) continue;  // that replica is down right now
      std::vector<SseEvent> all = head.events;
      if (!head.ended) {
        const Stream tail =
            follow(Api(ports[(first + 1) % 3]), id, all.empty() ? std::nullopt : std::optional(all.back().id));
        if (tail.status != 200 || !tail.ended) continue;
        // A takeover between the two parts starts a new run above every id given out: the
        // tail is then that run's stream, complete by itself.
        if (!all.empty() && !tail.events.empty() && tail.events.front().id != all.back().id + 1) all.clear();
        all.insert(all.end(), tail.events.begin(), tail.events.end());
      }
      expect_complete(all, id);
      ++streams_checked;
    }
  };

  std::vector<std::thread> threads, streamers;
  // Whatever happens below, the threads end before the test does.
  struct Joiner {
    std::vector<std::thread>& a;
    std::vector<std::thread>& b;
    std::atomic<bool>& abort;
    ~Joiner() {
      abort = true;
      for (auto* v : {&a, &b})
        for (auto& t : *v)
          if (t.joinable()) t.join();
    }
  } joiner{threads, streamers, abort_all};
  auto wait_acks = [&](int n) {
    const auto deadline = std::chrono::steady_clock::now() + 120s;
    while (acks < n && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(10ms);
    return acks >= n;
  };
  for (int c = 0; c < kClients; ++c) threads.emplace_back(client);
  for (int s = 0; s < 6; ++s) streamers.emplace_back(streamer, s);

  // Drill 1: kill -9 a replica mid-run, restart it.
  ASSERT_TRUE(wait_acks(120)) << acks;
  note("120 acknowledged: kill -9 r1");
  replicas[1]->kill9();
  std::this_thread::sleep_for(500ms);
  replicas[1] = start_replica(1);
  note("r1 restarted");
  // Drill 2: the database goes away for 2.5 s and comes back.
  ASSERT_TRUE(wait_acks(280)) << acks;
  note("280 acknowledged: database stopped");
  cluster->stop();
  std::this_thread::sleep_for(1000ms);
  {
    // While it is away: not ready (503), submissions refused with Retry-After.
    auto ready = Api(ports[0]).get("/v1/ready");
    ASSERT_TRUE(ready);
    EXPECT_EQ(ready->status, 503);
    auto refused = Api(ports[2]).post_json("/v1/jobs", variants[0].dump());
    ASSERT_TRUE(refused);
    EXPECT_EQ(refused->status, 503);
    EXPECT_FALSE(refused->get_header_value("Retry-After").empty());
    auto health = Api(ports[0]).get("/v1/health");  // alive, no hang
    ASSERT_TRUE(health);
    EXPECT_EQ(health->status, 200);
  }
  std::this_thread::sleep_for(1500ms);
  cluster->start();
  note("database started again");
  for (auto& t : threads) t.join();
  note(std::to_string(acks.load()) + " acknowledged");
  ASSERT_EQ(acknowledged.size(), static_cast<size_t>(kJobs));

  // Every acknowledged job: successful, exactly once, its result equal to grip solve's, one
  // complete stream (read through any replica).
  int retried = 0;
  std::map<std::string, int> attempts_by_runner;
  for (const auto& [id, variant] : acknowledged) {
    const json doc = Api(ports[variant % 3]).wait_status(id, {"successful", "failed", "dismissed"}, 180s);
    ASSERT_EQ(doc["status"], "successful") << id << " " << doc.dump();
    retried += doc["attempts"].get<int>() > 1;
    auto r = Api(ports[(variant + 1) % 3]).get("/v1/jobs/" + id + "/result");
    ASSERT_EQ(r->status, 200);
    EXPECT_EQ(without_timings(json::parse(r->body)).dump(), references[variant]) << id;
    const Stream s = follow(Api(ports[(variant + 2) % 3]), id);
    ASSERT_TRUE(s.ended) << id;
    expect_complete(s.events, id);
    EXPECT_EQ(s.events.back().type, "job_finished") << id;
    int iterations = 0;
    for (const auto& e : s.events)
      if (e.type == "iteration") iterations += json::parse(e.data)["trials"].get<int>();  // real solves
    EXPECT_EQ(iterations, doc["iterations"].get<int>()) << id;
  }
  load_done = true;
  for (auto& t : streamers) t.join();
  note("all checked");
  note("dismissals");
  // Dismissal across replicas: a long job, dismissed through a replica that does not run it.
  // Long enough to be still running 300 ms in on a fast machine (a step takes about 0.1 ms).
  constexpr int kLongSteps = 4000;
  const json long_job = beam_scene(40, kLongSteps);
  for (int d = 0; d < 2; ++d) {
    const std::string id = Api(ports[d]).submit(long_job);  // the queue is empty by now
    const json running = Api(ports[d]).wait_status(id, {"running"}, 120s);
    const std::string runner = running.at("replica");
    const int other = runner == "r0" ? 1 : 0;
    std::this_thread::sleep_for(300ms);  // well into its run
    const auto before = Api(ports[other]).get("/v1/jobs/" + id + "/convergence");
    ASSERT_TRUE(before);
    const size_t stored_before = json::parse(before->body)["iterations"].size();
    auto del = Api(ports[other]).del("/v1/jobs/" + id);
    ASSERT_TRUE(del);
    EXPECT_EQ(del->status, 200);
    EXPECT_EQ(json::parse(del->body)["status"], "dismissed");
    EXPECT_EQ(Api(ports[2]).wait_status(id, {"dismissed"}, 60s)["status"], "dismissed");
    const Stream s = follow(Api(ports[2]), id);
    ASSERT_TRUE(s.ended);
    EXPECT_EQ(s.events.back().object()["reason"], "dismissed");
    EXPECT_EQ(Api(ports[2]).get("/v1/jobs/" + id + "/result")->status, 404);
    int iterations = 0, steps = 0;
    for (const auto& e : s.events) {
      iterations += e.type == "iteration";
      steps += e.type == "step_finished";
    }
    EXPECT_LT(steps, kLongSteps);  // stopped early
    // Iterations stored after the snapshot taken just before the DELETE: the ones in flight to
    // the database then, plus those run before the dismissal reached the runner.
    // The runner's own account: the contact iteration at which it heard of the dismissal and
    // the iterations it ran in all.
    // The runner logs its account just after it commits the final status, so the stream can end
    // a moment before the line is written: wait for it.
    const std::regex heard_line("job " + id + ": dismissal heard at contact iteration (\\d+)");
    const std::regex ran_line("job " + id + " dismissed in [0-9.]+ s: (\\d+) contact iterations");
    std::string log;
    std::smatch heard, ran;
    for (auto until = std::chrono::steady_clock::now() + 10s; std::chrono::steady_clock::now() < until;
         std::this_thread::sleep_for(50ms)) {
      log = read_text(dir.path() / ("replica" + runner.substr(1) + ".log"));
      if (std::regex_search(log, ran, ran_line)) break;
    }
    ASSERT_TRUE(std::regex_search(log, heard, heard_line));
    ASSERT_TRUE(std::regex_search(log, ran, ran_line));
    EXPECT_LE(std::stoi(ran[1]) - std::stoi(heard[1]), 1);
    EXPECT_EQ(std::stoi(ran[1]), iterations);
    std::printf(
        "[ info ] dismissed on %s through r%d: heard at iteration %s, stopped after %s; %zu iterations "
        "stored after a snapshot taken just before the DELETE\n",
        runner.c_str(), other, heard[1].str().c_str(), ran[1].str().c_str(),
        static_cast<size_t>(iterations) - stored_before);
  }

  // No job twice: the store holds exactly the acknowledged jobs and the two dismissed ones.
  int listed = 0;
  std::string next_link = "/v1/jobs?limit=1000";
  const json page = json::parse(api.get(next_link)->body);
  listed = static_cast<int>(page["jobs"].size());
  EXPECT_EQ(listed, kJobs + 2);
  std::printf(
      "[ info ] %d jobs acknowledged; %d ran more than once (taken over); %d 503s and %d "
      "connection errors retried; %d streams checked across replicas\n",
      static_cast<int>(acknowledged.size()), retried, refused_503.load(), connection_errors.load(),
      streams_checked.load());
  EXPECT_GT(streams_checked.load(), 0);
}

// A study (a sweep of Hertz's contact tolerance, 6 jobs of 8 steps) submitted to one replica of
// two on one PostgreSQL; that replica is killed with -9 while it runs one of the study's jobs.
// The other replica serves the study's table, takes the lost job over when its lease expires,
// and the study completes with every level successful once: the lost job ran twice (attempts
// 2) and its outputs are the same as a level that ran once with the same scene would give.
TEST(Scaleout, AStudySurvivesTheLossOfAReplica) {
  std::unique_ptr<PostgresCluster> cluster;
  try {
    cluster = std::make_unique<PostgresCluster>();
  } catch (const std::exception& e) {
    GTEST_SKIP() << "no PostgreSQL cluster could be started: " << e.what();
  }
  TempDir dir;
  const std::string url = cluster->new_database();
  std::vector<std::unique_ptr<ServerProcess>> replicas;
  for (int i = 0; i < 2; ++i)
    replicas.push_back(std::make_unique<ServerProcess>(
        url, std::vector<std::string>{"--workers", "1", "--lease", "2", "--replica", "r" + std::to_string(i)},
        dir.path() / ("replica" + std::to_string(i) + ".log")));
  const Api a(replicas[0]->port()), b(replicas[1]->port());
  json scene = json::parse(read_text(examples_dir() / "hertz.json"));
  scene["steps"] = 8;
  scene["outputs"] = {{{"name", "P"}, {"kind", "resultant"}, {"component", "y"}},
                      {{"name", "width"}, {"kind", "contact_width"}}};
  const json request = {
      {"scene", scene},
      {"sweep", {{{"pointer", "/solver/contact/tolerance"}, {"values", {1e-8, 1e-8, 1e-8, 1e-8, 1e-8, 1e-8}}}}}};
  const auto posted = a.post_json("/v1/studies", request.dump());
  ASSERT_TRUE(posted && posted->status == 201) << (posted ? posted->body : "no response");
  const json accepted = json::parse(posted->body);
  const std::string id = accepted["id"];
  // Kill r0 while it runs one of the study's jobs.
  std::string lost;
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (lost.empty() && std::chrono::steady_clock::now() < deadline) {
    for (const json& level : accepted["levels"]) {
      // Asked of r0 itself, whose document has the run's step: killed with half its steps to go.
      const json job = a.job(level["job"]);
      if (job["status"] == "running" && job.value("replica", "") == "r0" && job.value("step", 99) <= 4)
        lost = level["job"];
    }
    if (lost.empty()) std::this_thread::sleep_for(20ms);
  }
  ASSERT_FALSE(lost.empty()) << "r0 ran none of the study's jobs";
  replicas[0]->kill9();
  json study;
  const auto end = std::chrono::steady_clock::now() + 180s;
  do {
    std::this_thread::sleep_for(200ms);
    study = json::parse(b.get("/v1/studies/" + id)->body);
  } while (study["status"] != "successful" && std::chrono::steady_clock::now() < end);
  ASSERT_EQ(study["status"], "successful") << study.dump(2);
  const json reference = study["levels"][0]["outputs"];
  for (const json& level : study["levels"]) {
    const json job = b.job(level["job"]);
    EXPECT_EQ(job["status"], "successful");
    EXPECT_EQ(job["attempts"], level["job"] == lost ? 2 : 1) << level["job"];
    EXPECT_EQ(level["outputs"], reference);  // the same scene: the same numbers, however often run
    EXPECT_EQ(job["steps_completed"], 8);
  }
}

}  // namespace
}  // namespace grip::testing
