// The shipped deploy/haproxy.cfg, run for real in front of a local `grip serve` (its addresses
// come from the environment; the compose defaults otherwise): a request cut by a replica is
// retried on another when it is safe to replay, HAProxy's own 503 is grip's problem document
// with Retry-After, every request is logged, and SIGTERM stops it at once.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "grip_process.hpp"

namespace grip::testing {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

int listen_loopback(int& port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  int yes = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  ::listen(fd, 64);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  port = ntohs(a.sin_port);
  return fd;
}

int free_port() {
  int port = 0;
  ::close(listen_loopback(port));
  return port;
}

// A replica that passes HAProxy's readiness check but cuts every other request: it reads the
// request and closes without a byte (what a replica killed mid-request does).
class CuttingReplica {
 public:
  CuttingReplica() : fd_(listen_loopback(port_)) {
    thread_ = std::thread([this] {
      while (!stop_) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, 100) <= 0) continue;
        const int c = ::accept(fd_, nullptr, nullptr);
        if (c < 0) continue;
        std::string head;
        char buf[4096];
        while (head.find("\r\n\r\n") == std::string::npos) {
          pollfd q{c, POLLIN, 0};
          if (::poll(&q, 1, 2000) <= 0) break;
          const ssize_t n = ::recv(c, buf, sizeof buf, 0);
          if (n <= 0) break;
          head.append(buf, static_cast<size_t>(n));
        }
        if (head.rfind("GET /v1/ready ", 0) == 0) {
          const std::string ok =
              ready_ ? "HTTP/1.1 200 OK\r\nContent-Length: 0\r\nConnection: close\r\n\r\n"
                     : "HTTP/1.1 503 Service Unavailable\r\nContent-Length: 0\r\nConnection: close\r\n\r\n";
          ::send(c, ok.data(), ok.size(), MSG_NOSIGNAL);
        } else if (!head.empty()) {
          ++cuts_;
        }
        ::close(c);
      }
    });
  }
  ~CuttingReplica() {
    stop_ = true;
    thread_.join();
    ::close(fd_);
  }
  int port() const { return port_; }
  int cuts() const { return cuts_; }
  void set_ready(bool r) { ready_ = r; }

 private:
  int port_ = 0;
  int fd_;
  std::atomic<bool> stop_{false}, ready_{true};
  std::atomic<int> cuts_{0};
  std::thread thread_;
};

class HaproxyProcess {
 public:
  HaproxyProcess(const fs::path& log, int front, const std::vector<int>& replicas) : port_(front) {
    const std::string cfg = std::string(GRIP_SOURCE_DIR) + "/deploy/haproxy.cfg";
    const std::string errors = std::string(GRIP_SOURCE_DIR) + "/deploy/errors";
    ::setenv("GRIP_ERRORS", errors.c_str(), 1);
    ::setenv("GRIP_FRONT", ("127.0.0.1:" + std::to_string(front)).c_str(), 1);
    for (size_t i = 0; i < 3; ++i)
      ::setenv(("GRIP" + std::to_string(i + 1)).c_str(), ("127.0.0.1:" + std::to_string(replicas.at(i))).c_str(), 1);
    check_rc_ = std::system(("/usr/sbin/haproxy -q -c -f " + cfg + " > " + log.string() + ".check 2>&1").c_str());
    pid_ = fork();
    if (pid_ == 0) {
      const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      dup2(fd, 1);
      dup2(fd, 2);
      execl("/usr/sbin/haproxy", "haproxy", "-W", "-db", "-f", cfg.c_str(), nullptr);
      _exit(127);
    }
  }
  ~HaproxyProcess() { stop(); }
  // SIGTERM; the seconds until it exited (SIGKILL after 10 s: -1).
  double stop() {
    if (pid_ <= 0) return 0;
    const auto t = Clock::now();
    ::kill(pid_, SIGTERM);
    int status = 0;
    while (waitpid(pid_, &status, WNOHANG) == 0) {
      if (Clock::now() - t > 10s) {
        ::kill(pid_, SIGKILL);
        waitpid(pid_, &status, 0);
        pid_ = -1;
        return -1;
      }
      std::this_thread::sleep_for(10ms);
    }
    pid_ = -1;
    return std::chrono::duration<double>(Clock::now() - t).count();
  }
  int check_rc() const { return check_rc_; }
  int port() const { return port_; }

 private:
  int port_;
  int check_rc_ = -1;
  pid_t pid_ = -1;
};

TEST(HaproxyFront, RetriesSafeRequestsAnswersProblemJson503LogsAndStopsAtOnce) {
  if (!fs::exists("/usr/sbin/haproxy")) GTEST_SKIP() << "haproxy is not installed (scripts/setup.sh installs it)";
  TempDir dir;
  ServerProcess grip(dir.path() / "grip.sqlite", {}, dir.path() / "server.log");
  CuttingReplica cutting;
  const int dead = free_port();  // a replica that is down: connection refused
  HaproxyProcess proxy(dir.path() / "haproxy.log", free_port(), {grip.port(), cutting.port(), dead});
  ASSERT_EQ(proxy.check_rc(), 0) << read_text(dir.path() / "haproxy.log.check");
  const Api api(proxy.port());
  bool up = false;
  for (int i = 0; i < 200 && !up; ++i) {
    const auto r = api.client(2).Get("/v1/ready");
    up = r && r->status == 200;
    if (!up) std::this_thread::sleep_for(50ms);
  }
  ASSERT_TRUE(up) << read_text(dir.path() / "haproxy.log");
  // The down replica out of the rotation first (two failed checks a second apart).
  for (int i = 0; i < 200 && read_text(dir.path() / "haproxy.log").find("grip3 is DOWN") == std::string::npos; ++i)
    std::this_thread::sleep_for(50ms);

  // Safe requests that meet the cutting replica are sent again to grip: all answered.
  int ok = 0;
  for (int i = 0; i < 20; ++i) {
    const auto r = api.get("/v1/health");
    ok += r && r->status == 200;
  }
  EXPECT_EQ(ok, 20);
  EXPECT_GT(cutting.cuts(), 0) << "round robin never chose the cutting replica";
  // A POST with an Idempotency-Key is safe to replay too; one without is not: a cut one is a
  // 502 problem document, never a second job.
  const std::string scene = beam_scene(10, 2).dump();
  int created = 0, bad_gateway = 0, other = 0;
  for (int i = 0; i < 6; ++i) {
    const auto r = api.post_json("/v1/jobs", scene, {{"Idempotency-Key", "drill-" + std::to_string(i)}});
    created += r && r->status == 201;
  }
  EXPECT_EQ(created, 6);
  const int cuts_before = cutting.cuts();
  for (int i = 0; i < 6; ++i) {
    const auto r = api.post_json("/v1/jobs", scene);
    if (r && r->status == 201) ++created;
    else if (r && r->status == 502 && r->get_header_value("Content-Type") == "application/problem+json") ++bad_gateway;
    else ++other;
  }
  EXPECT_EQ(other, 0);
  EXPECT_EQ(bad_gateway, cutting.cuts() - cuts_before)  // each cut POST: one 502, not retried
      << "created " << created << "; haproxy's log:\n"
      << read_text(dir.path() / "haproxy.log");
  const json jobs = json::parse(Api(grip.port()).get("/v1/jobs?limit=100")->body)["jobs"];
  EXPECT_EQ(static_cast<int>(jobs.size()), created);

  // No replica ready: HAProxy's own 503 is grip's problem document with Retry-After.
  cutting.set_ready(false);
  grip.terminate(std::chrono::seconds(30));
  int status = 0;
  std::string body, type, retry_after;
  for (int i = 0; i < 200; ++i) {
    if (const auto r = api.client(2).Get("/v1/jobs")) {
      status = r->status;
      body = r->body;
      type = r->get_header_value("Content-Type");
      retry_after = r->get_header_value("Retry-After");
      if (status == 503 && body.find("no-replica-ready") != std::string::npos) break;
    }
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_EQ(status, 503);
  EXPECT_EQ(type, "application/problem+json");
  EXPECT_EQ(retry_after, "5");
  EXPECT_EQ(json::parse(body, nullptr, false).value("type", std::string()), "urn:grip:problem:no-replica-ready");

  // Logged: one line per request, with its method, path and status. HAProxy writes its log
  // line after the response has gone out, so the last one may land a moment later.
  std::string log = read_text(dir.path() / "haproxy.log");
  for (int i = 0; i < 100 && log.find(" 503 ") == std::string::npos; ++i) {
    std::this_thread::sleep_for(50ms);
    log = read_text(dir.path() / "haproxy.log");
  }
  EXPECT_NE(log.find("\"GET /v1/health HTTP/1.1\""), std::string::npos) << log.substr(0, 2000);
  EXPECT_NE(log.find(" 503 "), std::string::npos) << log;

  // SIGTERM with a client connection open: gone at once (not after `timeout client`).
  httplib::Client held("127.0.0.1", proxy.port());
  held.set_keep_alive(true);
  held.Get("/v1/health");
  const double seconds = proxy.stop();
  std::printf("[ info ] haproxy stopped %.3f s after SIGTERM\n", seconds);
  EXPECT_GE(seconds, 0.0);
  EXPECT_LT(seconds, 5.0);
}

}  // namespace
}  // namespace grip::testing
