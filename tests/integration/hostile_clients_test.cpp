// Slow, idle and hostile clients against one `grip serve` (issue 34): raw loopback sockets,
// bounded in count and time. The asserts are about the service answering; the latencies are
// printed ([ info ] lines) and recorded in bench/results/hostile-clients.md. The 100 ms
// for /v1/health is not asserted: nine in ten answer within 5 ms, but on 2 shared cores about
// one request in 70 waits 0.4-0.7 s, of which the client's own loopback connect takes up to
// 170 ms (the measuring process was not running), so a bound would fail on the machine's load.
//
// The attackers connect from other loopback addresses (127.0.1.x, 127.0.2.x: Linux routes
// all of 127/8 to lo) than the well-behaved client (127.0.0.1), as they would from other
// hosts; none of them reaches the limit per address, so it is the deadlines and the thread per
// connection that keep the service answering, not that limit.
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

#include "grip_process.hpp"

namespace grip::testing {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// A connection from `source` (a loopback address) to the server; -1 on failure.
int connect_from(const std::string& source, int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  sockaddr_in from{};
  from.sin_family = AF_INET;
  ::inet_pton(AF_INET, source.c_str(), &from.sin_addr);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&from), sizeof from) != 0 ||
      ::connect(fd, reinterpret_cast<sockaddr*>(&to), sizeof to) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

bool send_all(int fd, const std::string& s) {
  return ::send(fd, s.data(), s.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(s.size());
}

// Holds each of a server's `threads` connection threads (--http-threads) with a head that never
// ends, from 127.0.2.1, and lets the server take them; the connections to close afterwards.
std::vector<int> hold_connection_threads(int port, int threads) {
  std::vector<int> held;
  for (int i = 0; i < threads; ++i) {
    held.push_back(connect_from("127.0.2.1", port));
    send_all(held.back(), "GET /v1/health HTTP/1.1\r\nHost: grip\r\n");  // never ends
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  return held;
}

// What the server sent until it closed or `patience` passed; `closed`: it closed in order.
std::string read_answer(int fd, std::chrono::milliseconds patience, bool* closed = nullptr) {
  std::string text;
  const auto until = Clock::now() + patience;
  char buf[4096];
  while (Clock::now() < until) {
    pollfd p{fd, POLLIN, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now()).count();
    if (::poll(&p, 1, static_cast<int>(std::max<long long>(left, 0))) <= 0) break;
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) {
      if (closed) *closed = n == 0;
      break;
    }
    text.append(buf, static_cast<size_t>(n));
  }
  return text;
}

// The status line and headers of the server's answer (up to `patience`).
std::string read_head(int fd, std::chrono::milliseconds patience) {
  std::string text;
  const auto until = Clock::now() + patience;
  char buf[4096];
  while (Clock::now() < until && text.find("\r\n\r\n") == std::string::npos) {
    pollfd p{fd, POLLIN, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now()).count();
    if (::poll(&p, 1, static_cast<int>(std::max<long long>(left, 0))) <= 0) break;
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    text.append(buf, static_cast<size_t>(n));
  }
  return text;
}

// What the server has sent so far, without waiting; `closed` when it closed.
std::string read_now(int fd, bool& closed) {
  std::string text;
  char buf[4096];
  closed = false;
  while (true) {
    const ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT);
    if (n > 0) {
      text.append(buf, static_cast<size_t>(n));
      continue;
    }
    closed = n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK);
    return text;
  }
}

std::string attacker(int i) { return "127.0.1." + std::to_string(1 + i % 200); }

json problem_of(const std::string& answer) {
  const size_t at = answer.find("\r\n\r\n");
  if (at == std::string::npos) return json();
  return json::parse(answer.substr(at + 4), nullptr, false);
}

// 500 slow-loris connections (a byte of the head every 400 ms, reopened when the server
// closes them) and 500 idle keep-alive connections (one request, then silence; reopened when
// closed): /v1/health answers throughout, a small job completes, and the slow heads end with
// a 408 at the head deadline instead of holding their threads.
TEST(HostileClients, SlowAndIdleConnectionsStarveNeitherHealthNorJobs) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {"--head-timeout", "2", "--workers", "1"},
                       dir.path() / "server.log");
  const Api api(server.port());
  const int port = server.port();
  constexpr int kSlow = 500, kIdle = 500;
  const std::string slow_head = "GET /v1/health HTTP/1.1\r\nHost: grip\r\nX-Padding: ";
  std::vector<int> slow(kSlow, -1), idle(kIdle, -1);
  std::vector<size_t> sent(kSlow, 0);
  int reopened = 0, answered_408 = 0, closed_without_408 = 0;
  auto open_slow = [&](int i) {
    slow[i] = connect_from(attacker(i), port);
    sent[i] = 0;
  };
  auto open_idle = [&](int i) {
    idle[i] = connect_from(attacker(kSlow + i), port);
    if (idle[i] >= 0) send_all(idle[i], "GET /v1/health HTTP/1.1\r\nHost: grip\r\n\r\n");
  };
  const auto start = Clock::now();
  for (int i = 0; i < kSlow; ++i) open_slow(i);
  for (int i = 0; i < kIdle; ++i) open_idle(i);
  const int opened = static_cast<int>(std::count_if(slow.begin(), slow.end(), [](int fd) { return fd >= 0; }) +
                                      std::count_if(idle.begin(), idle.end(), [](int fd) { return fd >= 0; }));
  std::printf("[ info ] %d of %d attacking connections open after %.0f ms\n", opened, kSlow + kIdle, ms_since(start));
  ASSERT_GE(opened, (kSlow + kIdle) * 9 / 10);

  // The attack runs on its own thread; the well-behaved client measures meanwhile.
  std::atomic<bool> attacking{true};
  std::thread attack([&] {
    while (attacking) {
      for (int i = 0; i < kSlow; ++i) {
        if (slow[i] < 0) {
          open_slow(i);
          ++reopened;
          continue;
        }
        bool closed = false;
        const std::string got = read_now(slow[i], closed);
        if (!got.empty() || closed) {
          if (got.rfind("HTTP/1.1 408", 0) == 0) ++answered_408;
          else ++closed_without_408;
          ::close(slow[i]);
          slow[i] = -1;
          continue;
        }
        const char byte = sent[i] < slow_head.size() ? slow_head[sent[i]] : 'a';
        ++sent[i];
        ::send(slow[i], &byte, 1, MSG_NOSIGNAL);
      }
      for (int i = 0; i < kIdle; ++i) {
        bool closed = false;
        if (idle[i] >= 0) read_now(idle[i], closed);
        if (idle[i] < 0 || closed) {
          if (idle[i] >= 0) ::close(idle[i]);
          open_idle(i);
          ++reopened;
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(400));
    }
  });

  std::vector<double> health_ms;
  int health_ok = 0;
  std::string job;
  double submitted_ms = 0;
  while (ms_since(start) < 7000) {
    const auto t = Clock::now();
    const auto r = api.client(10).Get("/v1/health");
    health_ms.push_back(ms_since(t));
    health_ok += r && r->status == 200;
    if (job.empty() && ms_since(start) > 1000) {
      submitted_ms = ms_since(start);
      job = api.submit(beam_scene(10, 2));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const json doc = api.wait_status(job, {"successful", "failed"}, std::chrono::seconds(60));
  attacking = false;
  attack.join();
  for (int fd : slow)
    if (fd >= 0) ::close(fd);
  for (int fd : idle)
    if (fd >= 0) ::close(fd);

  std::sort(health_ms.begin(), health_ms.end());
  const auto finished = [&](const json& d) { return d.value("finished", std::string()); };
  std::printf("[ info ] /v1/health under attack: %zu requests, median %.1f ms, max %.1f ms\n", health_ms.size(),
              health_ms[health_ms.size() / 2], health_ms.back());
  std::printf("[ info ] job submitted at %.0f ms: solve %.3f s, created %s, finished %s\n", submitted_ms,
              doc.value("solve_seconds", 0.0), doc.value("created", std::string()).c_str(), finished(doc).c_str());
  std::printf("[ info ] slow heads: %d answered 408, %d closed otherwise; %d connections reopened\n", answered_408,
              closed_without_408, reopened);
  EXPECT_EQ(health_ok, static_cast<int>(health_ms.size()));
  EXPECT_EQ(doc["status"], "successful");
  // 7 s of attack against a 2 s head deadline: the first wave of slow heads was cut, most with
  // a 408 (the rest lose it to the reset that their next byte meets on the closed socket).
  EXPECT_GE(answered_408 + closed_without_408, kSlow * 9 / 10);
  EXPECT_GE(answered_408, kSlow / 4);
  EXPECT_EQ(api.get("/v1/health")->status, 200);
}

// A POST without Content-Length (curl -X POST with no data) is answered 411 at once instead
// of holding a thread until the body deadline.
TEST(HostileClients, APostWithoutALengthIsAnswered411AtOnce) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {}, dir.path() / "server.log");
  const int fd = connect_from("127.0.0.1", server.port());
  ASSERT_GE(fd, 0);
  send_all(fd, "POST /v1/jobs HTTP/1.1\r\nHost: grip\r\nContent-Type: application/json\r\n\r\n");
  // Well below the 10 s body deadline: answered without waiting for a body.
  const std::string answer = read_answer(fd, std::chrono::milliseconds(3000));
  ::close(fd);
  EXPECT_EQ(answer.rfind("HTTP/1.1 411", 0), 0u) << answer;
  const json p = problem_of(answer);
  EXPECT_EQ(p.value("status", 0), 411) << answer;
  EXPECT_NE(p.value("detail", std::string()).find("Content-Length"), std::string::npos) << answer;
}

// A body announced over the limit (200 MB against --max-mesh's 64 MiB) is refused before any
// of it is read: with Expect: 100-continue the 413 comes instead of the 100; without, it comes
// while the client is still sending, before the body deadline (--body-timeout 5 here). Then
// the server drops what the client sends, but only up to that deadline (or 1 GiB): a client
// that keeps the connection open, silent or streaming, has it closed.
TEST(HostileClients, ABodyAnnouncedOverTheLimitIs413BeforeItIsSentAndHoldsNoThread) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {"--body-timeout", "5"}, dir.path() / "server.log");
  auto post = [&](const std::string& length, bool expect) {
    const int fd = connect_from("127.0.0.1", server.port());
    send_all(fd,
             "POST /v1/meshes HTTP/1.1\r\nHost: grip\r\nContent-Type: application/octet-stream\r\n"
             "Content-Length: " +
                 length + "\r\n" + (expect ? "Expect: 100-continue\r\n" : "") + "\r\n");
    return fd;
  };
  // Sends `piece` every `pause` until a send fails (the server has closed: a reset), at most
  // 15 s; the bytes sent.
  struct Cut {
    bool cut = false;
    double bytes = 0, ms = 0;
  };
  auto send_until_cut = [](int fd, const std::string& piece, std::chrono::milliseconds pause) {
    timeval second{1, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &second, sizeof second);
    const auto start = Clock::now();
    Cut c;
    while (!c.cut && ms_since(start) < 15000) {
      const ssize_t n = ::send(fd, piece.data(), piece.size(), MSG_NOSIGNAL);
      c.cut = n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR;
      if (n > 0) c.bytes += static_cast<double>(n);
      std::this_thread::sleep_for(pause);
    }
    c.ms = ms_since(start);
    ::close(fd);
    return c;
  };

  // Asked first: the problem document, and no 100 Continue.
  int fd = post("209715200", true);
  ASSERT_GE(fd, 0);
  ::shutdown(fd, SHUT_WR);  // nothing follows: the server's drain ends at once
  std::string answer = read_answer(fd, std::chrono::milliseconds(3000));
  ::close(fd);
  EXPECT_EQ(answer.rfind("HTTP/1.1 413", 0), 0u) << answer;
  const json p = problem_of(answer);
  ASSERT_TRUE(p.is_object()) << answer;
  EXPECT_EQ(p.value("type", std::string()), "urn:grip:problem:payload-too-large") << answer;
  EXPECT_NE(p.value("detail", std::string()).find("67108864"), std::string::npos) << answer;
  EXPECT_NE(p.value("detail", std::string()).find("209715200"), std::string::npos) << answer;

  // Not asked: answered after the first MiB of the 200, the rest unsent; then a byte every
  // 100 ms, dropped until the body deadline, when the connection is cut.
  fd = post("209715200", false);
  ASSERT_GE(fd, 0);
  send_all(fd, std::string(1u << 20, ' '));
  answer = read_head(fd, std::chrono::milliseconds(3000));
  EXPECT_EQ(answer.rfind("HTTP/1.1 413", 0), 0u) << answer;
  EXPECT_NE(answer.find("Connection: close"), std::string::npos) << answer;
  const Cut slow = send_until_cut(fd, " ", std::chrono::milliseconds(100));
  std::printf("[ info ] a byte every 100 ms after the 413: cut after %.0f bytes, %.0f ms (deadline 5 s)\n", slow.bytes,
              slow.ms);
  EXPECT_TRUE(slow.cut);

  // 10 GB announced and streamed as fast as loopback takes it: dropped up to 1 GiB or the
  // deadline, then cut.
  fd = post("10000000000", false);
  ASSERT_GE(fd, 0);
  const Cut fast = send_until_cut(fd, std::string(1u << 16, ' '), std::chrono::milliseconds(0));
  std::printf("[ info ] a 10 GB body streamed after its 413: cut after %.0f MB, %.0f ms (deadline 5 s, 1 GiB)\n",
              fast.bytes / 1e6, fast.ms);
  EXPECT_TRUE(fast.cut);
  EXPECT_LT(fast.bytes, 2e9);
  const Api api(server.port());
  EXPECT_EQ(api.get("/v1/health")->status, 200);
}

// An answer given before the request's body is read (a 401 for a wrong or missing token, a
// 503 from a reserved thread) or without it ever being read (httplib reads no body on a GET)
// closes the connection, as the 413 does, and drops the body: a body that is itself a request
// is never served as the connection's next one (request smuggling). On a kept-alive
// connection the 401 was followed by a 200 for the GET /v1/health in its body.
TEST(HostileClients, AnAnswerBeforeTheBodyClosesAndNoneOfTheBodyIsServed) {
  const std::string inner = "GET /v1/health HTTP/1.1\r\nHost: grip\r\n\r\n";
  const std::string length = "Content-Length: " + std::to_string(inner.size()) + "\r\n";
  // Everything the server sends on a connection after `request`, until it closes (`closed`,
  // an orderly close) or 3 s pass; `responses`: the status lines among it.
  struct Exchange {
    std::string text;
    bool closed = false;
    int responses = 0;
  };
  auto exchange = [](int port, const std::string& request) {
    Exchange e;
    const int fd = connect_from("127.0.0.1", port);
    if (fd < 0) return e;
    send_all(fd, request);
    e.text = read_answer(fd, std::chrono::milliseconds(3000), &e.closed);
    ::close(fd);
    for (size_t at = e.text.find("HTTP/1.1 "); at != std::string::npos; at = e.text.find("HTTP/1.1 ", at + 1))
      ++e.responses;
    return e;
  };
  auto expect_one_then_close = [](const Exchange& e, const std::string& status) {
    EXPECT_EQ(e.text.rfind("HTTP/1.1 " + status, 0), 0u) << e.text;
    EXPECT_EQ(e.responses, 1) << e.text;
    EXPECT_TRUE(e.closed) << e.text;
    const std::string head = e.text.substr(0, e.text.find("\r\n\r\n"));
    EXPECT_NE(head.find("Connection: close"), std::string::npos) << e.text;
    EXPECT_EQ(head.find("Keep-Alive"), std::string::npos) << e.text;
  };
  // A field of the answer's problem document (or JSON body); "" when it has none.
  auto field = [](const Exchange& e, const char* name) {
    const json p = problem_of(e.text);
    return p.is_object() && p.contains(name) && p[name].is_string() ? p[name].get<std::string>() : std::string();
  };
  {
    TempDir dir;
    ServerProcess server(dir.path() / "grip.sqlite", {"--token", "s3cret"}, dir.path() / "server.log");
    const std::string post = "POST /v1/jobs HTTP/1.1\r\nHost: grip\r\nContent-Type: application/json\r\n";
    // A wrong token, the body sent with the head.
    Exchange e = exchange(server.port(), post + "Authorization: Bearer wrong\r\n" + length + "\r\n" + inner);
    expect_one_then_close(e, "401");
    EXPECT_EQ(field(e, "type"), "urn:grip:problem:unauthorized") << e.text;
    EXPECT_EQ(field(e, "detail"), "the bearer token is not valid") << e.text;
    // No token.
    e = exchange(server.port(), post + length + "\r\n" + inner);
    expect_one_then_close(e, "401");
    EXPECT_EQ(field(e, "type"), "urn:grip:problem:unauthorized") << e.text;
    EXPECT_NE(field(e, "detail").find("requires a bearer token"), std::string::npos) << e.text;
    // A wrong token, the request in a chunked body.
    char size[16];
    std::snprintf(size, sizeof size, "%zx", inner.size());
    e = exchange(server.port(), post + "Authorization: Bearer wrong\r\nTransfer-Encoding: chunked\r\n\r\n" + size +
                                    "\r\n" + inner + "\r\n0\r\n\r\n");
    expect_one_then_close(e, "401");
    EXPECT_EQ(field(e, "type"), "urn:grip:problem:unauthorized") << e.text;
    // A GET with a body (no token needed for health): answered, the body dropped.
    e = exchange(server.port(), "GET /v1/health HTTP/1.1\r\nHost: grip\r\n" + length + "\r\n" + inner);
    expect_one_then_close(e, "200");
    EXPECT_EQ(field(e, "status"), "ok") << e.text;
    // The right token: the body is read, and a request after it on the same connection is
    // served (a 400 for the body that is no scene, then the health check).
    e = exchange(server.port(), post + "Authorization: Bearer s3cret\r\n" + length + "\r\n" + inner + inner);
    EXPECT_EQ(e.text.rfind("HTTP/1.1 400", 0), 0u) << e.text;
    EXPECT_EQ(e.responses, 2) << e.text;
    EXPECT_NE(e.text.find("{\"status\":\"ok\"}"), std::string::npos) << e.text;
  }
  {
    // Both connection threads held by unfinished heads: a reserved thread refuses the POST.
    TempDir dir;
    ServerProcess server(dir.path() / "grip.sqlite", {"--http-threads", "2"}, dir.path() / "server.log");
    const std::vector<int> held = hold_connection_threads(server.port(), 2);
    const Exchange e = exchange(server.port(),
                                "POST /v1/jobs HTTP/1.1\r\nHost: grip\r\nContent-Type: "
                                "application/json\r\n" +
                                    length + "\r\n" + inner);
    expect_one_then_close(e, "503");
    EXPECT_EQ(field(e, "type"), "urn:grip:problem:server-busy") << e.text;
    for (int fd : held) ::close(fd);
  }
}

// Past the limit per client address, a connection is refused at once with a problem
// document and Retry-After; other addresses are served.
TEST(HostileClients, ConnectionsPastTheLimitPerAddressAreRefusedWith503) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {"--per-client", "8"}, dir.path() / "server.log");
  std::vector<int> held;
  for (int i = 0; i < 8; ++i) held.push_back(connect_from("127.0.2.1", server.port()));
  // The server counts a connection once a thread takes it: let them be taken.
  const Api api(server.port());
  ASSERT_EQ(api.get("/v1/health")->status, 200);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const int extra = connect_from("127.0.2.1", server.port());
  ASSERT_GE(extra, 0);
  send_all(extra, "GET /v1/health HTTP/1.1\r\nHost: grip\r\n\r\n");
  const std::string answer = read_answer(extra, std::chrono::milliseconds(3000));
  ::close(extra);
  EXPECT_EQ(answer.rfind("HTTP/1.1 503", 0), 0u) << answer;
  EXPECT_NE(answer.find("Retry-After: "), std::string::npos) << answer;
  EXPECT_EQ(problem_of(answer).value("type", std::string()), "urn:grip:problem:too-many-connections") << answer;
  EXPECT_EQ(api.get("/v1/health")->status, 200);  // 127.0.0.1 is another address
  for (int fd : held) ::close(fd);
  EXPECT_NE(server.log().find("127.0.2.1: connection refused"), std::string::npos);
}

// Every connection thread taken (--http-threads 2, both held by slow heads): the reserved
// threads still answer /v1/health and /v1/ready, and refuse the rest with 503 + Retry-After.
TEST(HostileClients, HealthIsAnsweredWhenEveryConnectionThreadIsTaken) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {"--http-threads", "2"}, dir.path() / "server.log");
  const std::vector<int> held = hold_connection_threads(server.port(), 2);
  const Api api(server.port());
  const auto health = api.client(3).Get("/v1/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
  const auto jobs = api.client(3).Get("/v1/jobs");
  ASSERT_TRUE(jobs);
  EXPECT_EQ(jobs->status, 503);
  EXPECT_FALSE(jobs->get_header_value("Retry-After").empty());
  EXPECT_EQ(json::parse(jobs->body).value("type", std::string()), "urn:grip:problem:server-busy") << jobs->body;
  for (int fd : held) ::close(fd);
}

// Oversize heads say which limit they hit.
TEST(HostileClients, OversizeHeadersAndUrlsNameTheLimitTheyHit) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {}, dir.path() / "server.log");
  struct Case {
    std::string request;
    int status;
    std::string slug;
    std::string limit;  // in the detail
  };
  const std::vector<Case> cases = {
      {"GET /v1/health HTTP/1.1\r\nHost: grip\r\nX-Big: " + std::string(65536, 'a') + "\r\n\r\n", 431,
       "header-too-large", "65536"},
      {"GET /v1/health HTTP/1.1\r\nHost: grip\r\nX-Big: " + std::string(9000, 'a') + "\r\n\r\n", 431,
       "header-too-large", "8192"},
      {"GET /v1/jobs?x=" + std::string(100000, 'a') + " HTTP/1.1\r\nHost: grip\r\n\r\n", 414, "uri-too-long", "8192"},
      {"GET /v1/jobs?x=" + std::string(9000, 'a') + " HTTP/1.1\r\nHost: grip\r\n\r\n", 414, "uri-too-long", "8192"},
  };
  for (const Case& c : cases) {
    const int fd = connect_from("127.0.0.1", server.port());
    ASSERT_GE(fd, 0);
    send_all(fd, c.request);
    const std::string answer = read_answer(fd, std::chrono::milliseconds(5000));
    ::close(fd);
    EXPECT_EQ(answer.rfind("HTTP/1.1 " + std::to_string(c.status), 0), 0u) << answer.substr(0, 300);
    const json p = problem_of(answer);
    EXPECT_EQ(p.value("type", std::string()), "urn:grip:problem:" + c.slug) << answer.substr(0, 300);
    EXPECT_NE(p.value("detail", std::string()).find(c.limit), std::string::npos) << answer.substr(0, 300);
  }
  EXPECT_EQ(Api(server.port()).get("/v1/health")->status, 200);
}

// Browsers ask for /favicon.ico on every page load: no 404 for it.
TEST(HostileClients, FaviconIsNoContentNotNotFound) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {}, dir.path() / "server.log");
  const auto r = Api(server.port()).get("/favicon.ico");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 204);
}

// 32 event streams opened and dropped on a queued job (quiet: no event to write) free their
// slots at once, not at the next heartbeat (15 s here): 32 new streams are then accepted.
// (cpp-httplib alone freed about 20 of the 32 at once, the others at the heartbeat.)
TEST(HostileClients, DroppedStreamsOnAQuietJobFreeTheirSlotsAtOnce) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {"--workers", "1", "--streams", "32", "--heartbeat", "15"},
                       dir.path() / "server.log");
  const Api api(server.port());
  // Some 50 s of solving (10,000 slide steps; dismissed at the end) holds the only worker.
  json long_job = json::parse(read_text(fs::path(GRIP_SOURCE_DIR) / "tests/load/small-job.json"));
  long_job["stages"].back()["steps"] = 9990;
  const std::string busy = api.submit(long_job);
  const std::string queued = api.submit(beam_scene(10, 2));
  const std::string request = "GET /v1/jobs/" + queued + "/events HTTP/1.1\r\nHost: grip\r\n\r\n";
  std::vector<int> streams;
  for (int i = 0; i < 32; ++i) {
    const int fd = connect_from("127.0.0.1", server.port());
    ASSERT_GE(fd, 0);
    send_all(fd, request);
    streams.push_back(fd);
  }
  for (int fd : streams) {
    const std::string head = read_head(fd, std::chrono::milliseconds(5000));
    EXPECT_EQ(head.rfind("HTTP/1.1 200", 0), 0u) << head;
  }
  ASSERT_TRUE(wait_open_streams(api, 32));
  ASSERT_EQ(api.job(queued)["status"], "accepted");
  const auto dropped = Clock::now();
  for (int fd : streams) ::close(fd);
  // 32 new streams, each asked again while refused (503): all are accepted once the dropped
  // ones are freed, long before the next heartbeat would have found them gone.
  streams.clear();
  double all_ms = 0;
  while (streams.size() < 32 && ms_since(dropped) < 10000) {
    const int fd = connect_from("127.0.0.1", server.port());
    send_all(fd, request);
    const std::string head = read_head(fd, std::chrono::milliseconds(2000));
    if (head.rfind("HTTP/1.1 200", 0) == 0) {
      streams.push_back(fd);
      all_ms = ms_since(dropped);
    } else {
      EXPECT_EQ(head.rfind("HTTP/1.1 503", 0), 0u) << head;
      ::close(fd);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  std::printf("[ info ] 32 new streams accepted within %.0f ms after 32 were dropped (heartbeat 15 s)\n", all_ms);
  EXPECT_EQ(streams.size(), 32u);
  EXPECT_EQ(api.job(queued)["status"], "accepted");  // still quiet: no write freed the slots
  for (int fd : streams) ::close(fd);
  api.del("/v1/jobs/" + busy);
  api.del("/v1/jobs/" + queued);
}

}  // namespace
}  // namespace grip::testing
