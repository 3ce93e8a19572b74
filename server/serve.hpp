#pragma once
// `grip serve`: configuration from flags and GRIP_* environment variables (flags win), the
// store, the job service and the HTTP server wired together, and an orderly SIGTERM.
// `grip healthcheck`: the container's health probe (GET /v1/health), so no curl is needed.
#include <string>
#include <vector>

#include "server/http_server.hpp"
#include "server/job_service.hpp"

namespace grip::server {

struct ServeConfig {
  HttpOptions http;
  ServiceOptions service;
  std::string db = "data/grip.sqlite";
  double grace_seconds = 8.0;  // SIGTERM: running jobs may finish this long (docker stop: 10 s)
  std::string log_level = "info";
  std::string log_format = "text";  // or "json"
};

// Reads GRIP_* variables from `environ`, then the flags. Throws std::invalid_argument naming
// the flag or variable that is wrong.
ServeConfig read_serve_config(const std::vector<std::string>& args);
std::string serve_usage();

// Runs until SIGTERM or SIGINT; returns the exit code.
int serve(const ServeConfig& config);

// GET http://HOST:PORT/v1/health; 0 when it answers 200. Args: [--host H] [--port P].
int healthcheck(const std::vector<std::string>& args);

}  // namespace grip::server
