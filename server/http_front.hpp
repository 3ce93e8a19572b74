#pragma once
// The connection side of the HTTP server (docs/connections.md). cpp-httplib 0.11.4,
// as Debian packages it, serves a connection on one thread of a fixed pool for the
// connection's whole life, times reads out per recv (a byte every few seconds keeps a request
// alive for ever), polls idle keep-alive sockets every 10 ms, has no limit per client and no
// limit on a request head's size, and cannot tell that an event stream's client went away.
// HttpFront keeps httplib's parser and routing (Server::process_request) and replaces the
// loop around them (the virtual process_and_close_socket) and the socket stream:
// - a thread per connection, `max_connections` of them started at start-up; beyond them a
//   connection goes to one of two reserved threads, which answer /v1/health and /v1/ready
//   and refuse the rest with 503 and Retry-After;
// - a deadline for a whole request head and for a whole body (408 when missed);
// - a cap on connections per client address (503 + Retry-After, at once) and on idle
//   keep-alive connections (past it, responses carry Connection: close);
// - a head of at most 64 KiB and lines of at most 8 KiB (431 / 414 naming the limit);
// - is_writable() false once the peer closed, so an event stream ends within its next wait.
// This header brings httplib.h: include it after Eigen's headers (httplib's <resolv.h>
// defines `_res`).
#include <httplib.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "server/http_server.hpp"

namespace grip::server {

// What the request on this thread's connection ran into; read by the error handler.
struct ConnectionNote {
  std::string client;            // the peer's address
  bool in_body = false;          // the head has been read
  bool deadline_missed = false;  // in the head or, with in_body, the body
  bool line_too_long = false;    // a line of the head over kMaxLine
  bool head_too_large = false;   // the head over kMaxHead
  bool overflow = false;         // served by a reserved thread: health and readiness only
  bool close = false;            // close the connection after this response
  // Body bytes the client announced and the server answered without reading (an early 413,
  // 401, 503...): read and dropped before the close, within bounds (HttpFront::kMaxLingerBytes,
  // the body deadline), so that the close does not reset the connection before the client has
  // read the answer, and none of them is read as a request.
  std::uint64_t discard = 0;
  // Body bytes httplib has taken from the connection since the end of the head.
  std::uint64_t body_read = 0;
  // A chunked body was read to its end (its length is known only then).
  bool body_complete = false;
  // Starts the body's deadline again: a handler that waited before reading the body (the
  // memory budget of server/body_budget.hpp) gives the client its whole deadline.
  std::function<void()> restart_body_deadline;
};

class HttpFront : public httplib::Server {
 public:
  static constexpr std::size_t kMaxLine = 8192;  // httplib's compiled-in line limit
  static constexpr std::size_t kMaxHead = 65536;
  // At most this much of an unread body is read and dropped before a close (ConnectionNote::discard).
  static constexpr std::uint64_t kMaxLingerBytes = std::uint64_t{1} << 30;

  explicit HttpFront(FrontLimits limits);
  ~HttpFront() override;

  // The note of the connection the calling thread serves; nullptr on any other thread.
  static ConnectionNote* note();
  const FrontLimits& limits() const { return limits_; }
  int open_connections() const { return open_.load(); }

 private:
  bool process_and_close_socket(socket_t sock) override;
  void serve(socket_t sock, ConnectionNote& note);
  bool admit(const std::string& client);
  void leave(const std::string& client);

  FrontLimits limits_;
  std::atomic<int> open_{0};
  std::atomic<int> idle_{0};
  std::mutex clients_mutex_;
  std::map<std::string, int> clients_;  // open connections per address
};

}  // namespace grip::server
