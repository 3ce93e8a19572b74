#pragma once
// The HTTP/JSON API (DESIGN.md) over JobService: thin handlers, problem+json (RFC 9457) for
// every error, OGC API - Processes aliases. cpp-httplib stays inside http_server.cpp.
//
// Threads: cpp-httplib serves one connection per pool thread for the connection's life, so
// event streams are counted and refused with 503 beyond `max_streams`, the pool is sized
// above that cap, and every stream's content provider returns within about a second (so
// that stop() finishes) while a heartbeat comment keeps idle streams alive.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "server/job_service.hpp"

namespace grip::server {

struct HttpOptions {
  std::string host = "127.0.0.1";
  int port = 8080;                  // 0: any free port (see bound_port())
  int threads = 0;                  // HTTP pool; 0: max_streams + 32
  int max_streams = 32;             // open event streams
  std::size_t max_body_bytes = 8u << 20;
  std::size_t parse_budget_bytes = 0;  // bodies read and checked at once; 0: 2 x max_body_bytes
  std::optional<std::string> token;  // bearer token required on every route but health
  std::chrono::milliseconds heartbeat{15000};
  std::string schemas_dir;          // schemas/*.schema.json and schemas/examples/*.json
};

class HttpServer {
 public:
  HttpServer(JobService& service, HttpOptions options);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Binds the listening socket; returns the port. Throws std::runtime_error on failure.
  int bind();
  // Serves until stop(); returns once every connection has ended.
  void listen();
  // Stops accepting, ends the event streams; listen() then returns.
  void stop();
  int bound_port() const { return port_; }
  int open_streams() const { return open_streams_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int port_ = 0;
  std::atomic<int> open_streams_{0};
};

}  // namespace grip::server
