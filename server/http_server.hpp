#pragma once
// The HTTP/JSON API (docs/design.md#the-api) over JobService: thin handlers, problem+json (RFC
// 9457) for every error, OGC API - Processes aliases. cpp-httplib stays inside http_server.cpp.
//
// Connections: a thread each for the connection's life, with deadlines and limits per
// connection and client (FrontLimits, server/http_front.hpp). Event streams are counted and
// refused with 503 beyond `max_streams`; a stream's content provider looks at its socket
// every 500 ms (a closed one frees its slot, stop() finishes promptly) while a heartbeat
// comment keeps idle streams alive.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "server/job_service.hpp"

namespace grip::server {

// What one connection may take (server/http_front.hpp).
struct FrontLimits {
  std::chrono::milliseconds head{5000};   // a whole request head, from its first byte
  std::chrono::milliseconds body{10000};  // a whole request body, from the end of the head
  int max_connections = 1024;             // connections served at once (a thread each)
  int per_client = 64;                    // open connections from one client address
  int max_idle = 64;                      // keep-alive connections waiting for their next request
  int keep_alive_seconds = 2;             // how long an idle keep-alive connection is kept
  int io_seconds = 10;                    // one read or write that makes no progress
};

struct HttpOptions {
  std::string host = "127.0.0.1";
  int port = 8080;  // 0: any free port (see bound_port())
  FrontLimits front;
  int max_streams = 32;  // open event streams
  std::size_t max_body_bytes = 8u << 20;
  std::size_t max_mesh_bytes = 64u << 20;  // an uploaded mesh file (POST /v1/meshes)
  std::size_t parse_budget_bytes = 0;      // bodies read and checked at once; 0: max_body_bytes
  std::optional<std::string> token;        // bearer token required on every route but health
  std::chrono::milliseconds heartbeat{15000};
  std::string schemas_dir;  // schemas/*.schema.json and schemas/examples/*.json
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
