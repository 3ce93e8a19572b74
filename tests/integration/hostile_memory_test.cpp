// Memory against hostile scenes (issue 34.2): 8 clients submit 6 MB scenes at once (under the
// 8 MiB body limit), each built to make the reader or the validator find problems in every
// entry. The real `grip serve` must keep its peak resident memory (VmHWM) under 500 MB and
// come back within 20 % of its idle size (VmRSS) afterwards. The measured numbers are printed
// for bench/results/hostile-clients.md.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <thread>

#include "grip_process.hpp"

namespace grip::testing {
namespace {

// VmHWM or VmRSS of a process, in MB.
double status_value(pid_t pid, const std::string& field) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1));
  throw std::runtime_error("no " + field + " in /proc/" + std::to_string(pid) + "/status");
}

double status_mb(pid_t pid, const std::string& field) { return status_value(pid, field) / 1024.0; }

// The sliding block with `key` of `where` replaced by `entry` repeated to about `target` bytes.
std::string padded(const json& scene, json& where, const std::string& key, const json& entry, size_t target) {
  where[key] = json::array();
  const size_t base = scene.dump().size();
  const size_t n = (target - base) / (entry.dump().size() + 1);
  for (size_t i = 0; i < n; ++i) where[key].push_back(entry);
  return scene.dump();
}

json sliding_block() { return json::parse(read_text(examples_dir() / "sliding-block.json")); }

// Its one valid support repeated: each copy prescribes y of the 21 top nodes again (the reader
// found 1.7 million problems in 80,000 copies).
std::string repeated_support(size_t target) {
  json s = sliding_block();
  const json support = s["body"]["supports"][0];
  return padded(s, s["body"], "supports", support, target);
}

// Loads with a key no load has: a schema error in every entry.
std::string unknown_key_loads(size_t target) {
  json s = sliding_block();
  return padded(s, s["body"], "loads", {{"node", 3}, {"force", {1, 0}}, {"bogus", 1}}, target);
}

// Obstacles that all have the same name: each names another one already (a search over the
// earlier ones made reading quadratic).
std::string same_name_obstacles(size_t target) {
  json s = sliding_block();
  const json obstacle = s["obstacles"][0];
  return padded(s, s, "obstacles", obstacle, target);
}

TEST(HostileMemory, EightLargeAdversarialScenesAtOnceStayUnder500MbAndMemoryComesBack) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {"--workers", "1"}, dir.path() / "serve.log");
  const Api api(server.port());
  // Warm up on small copies of the attacks (64 KB): the schema's validator is built, the
  // code that answers them is paged in; the server's idle size is measured after.
  for (const std::string& small :
       {repeated_support(64 << 10), unknown_key_loads(64 << 10), same_name_obstacles(64 << 10)}) {
    auto warm = api.post_json("/v1/jobs", small);
    ASSERT_TRUE(warm);
    ASSERT_EQ(warm->status, 422) << warm->body;
  }
  // The server starts its 1,024 connection threads in the background: idle means all there.
  for (int i = 0; i < 100 && status_value(server.pid(), "Threads") < 1024; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const double idle = status_mb(server.pid(), "VmRSS");

  constexpr size_t kSize = 6u << 20;  // bytes of each scene
  const std::vector<std::pair<std::string, std::string>> attacks = {
      {"repeated support", repeated_support(kSize)},
      {"unknown key in every load", unknown_key_loads(kSize)},
      {"obstacles of one name", same_name_obstacles(kSize)},
  };
  for (const auto& [name, body] : attacks) ASSERT_LT(body.size(), 8u << 20) << name;

  std::atomic<int> answered{0};
  std::vector<std::string> failures(8);
  std::vector<std::thread> clients;
  const auto start = std::chrono::steady_clock::now();
  for (int c = 0; c < 8; ++c)
    clients.emplace_back([&, c] {
      const auto& [name, body] = attacks[c % attacks.size()];
      auto cli = api.client(300);
      cli.set_write_timeout(300);  // the server reads one large body at a time: the others wait
      auto r = cli.Post("/v1/jobs", body, "application/json");
      if (!r) {
        failures[c] = name + ": no answer (" + httplib::to_string(r.error()) + ")";
        return;
      }
      const json doc = json::parse(r->body, nullptr, false);
      if (r->status != 422 || doc.is_discarded() || doc["errors"].size() != 100 ||
          doc["detail"].get<std::string>().rfind("more than 100 problems", 0) != 0)
        failures[c] = name + ": " + std::to_string(r->status) + " " + r->body.substr(0, 300);
      ++answered;
    });
  for (auto& t : clients) t.join();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const auto& f : failures) EXPECT_TRUE(f.empty()) << f;
  EXPECT_EQ(answered.load(), 8);

  const double peak = status_mb(server.pid(), "VmHWM");
  double after = status_mb(server.pid(), "VmRSS");
  for (int i = 0; i < 50 && after > 1.2 * idle; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    after = status_mb(server.pid(), "VmRSS");
  }
  std::printf(
      "hostile scenes: %zu, %zu, %zu bytes; 8 clients answered in %.1f s; RSS idle %.1f MB, "
      "peak (VmHWM) %.1f MB, after %.1f MB\n",
      attacks[0].second.size(), attacks[1].second.size(), attacks[2].second.size(), seconds, idle, peak, after);
  EXPECT_LT(peak, 500.0);
  // Issue 34: back within 20 % of the idle size. glibc's per-thread caches of freed blocks
  // held pages of the parses' memory that malloc_trim cannot return (26.8 MB against 21.6 MB
  // idle); grip serve runs without them (apps/grip_server.cpp). Before: 823 MB after one such
  // request.
  EXPECT_LE(after, 1.2 * idle);
  // Still serving.
  auto health = api.get("/v1/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
}

}  // namespace
}  // namespace grip::testing
