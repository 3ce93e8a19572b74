#pragma once
// What the service tells operators about itself (docs/limits.md#metrics, #logs): Prometheus
// histograms, request counts by method, route template and status, request ids, and the log
// format (UTC timestamps with Z; plain text or one JSON object a line).
#include <cstdint>
#include <map>
#include <mutex>
#include <ostream>
#include <string>
#include <tuple>
#include <vector>

namespace grip::server {

// A Prometheus histogram with fixed upper bounds (+Inf added). Thread-safe.
class Histogram {
 public:
  explicit Histogram(std::vector<double> bounds);
  Histogram(const Histogram& other);
  void observe(double value);
  // `name`_bucket{`labels`,le="..."}, `name`_sum{`labels`} and `name`_count{`labels`} lines.
  void write(std::ostream& os, const std::string& name, const std::string& labels) const;
  std::int64_t count() const;

 private:
  mutable std::mutex mutex_;
  std::vector<double> bounds_;
  std::vector<std::int64_t> counts_;  // per bound, not cumulative
  double sum_ = 0;
  std::int64_t count_ = 0;
};

// Seconds: 1 ms to 5 min.
const std::vector<double>& seconds_buckets();

// The route a path belongs to, with its variable parts named ("/v1/jobs/{id}/events"); "other"
// for a path of no route (label values stay few whatever clients send).
std::string route_template(const std::string& path);

// HTTP requests by method, route template and status, and their latency per route.
class RequestMetrics {
 public:
  void record(const std::string& method, const std::string& route, int status, double seconds);
  void write(std::ostream& os) const;

 private:
  mutable std::mutex mutex_;
  std::map<std::tuple<std::string, std::string, int>, std::int64_t> counts_;
  std::map<std::string, Histogram> latency_;
};

// The request's id: its X-Request-Id when that is 1 to 128 visible ASCII characters, else a
// new random one (16 hex digits).
std::string request_id_for(const std::string& header);

// spdlog's default logger: timestamps in UTC with a Z, at `level`; `format` "text" (the
// default) or "json" (one object a line: time, level, message; for log shippers).
void setup_logging(const std::string& format, const std::string& level);

}  // namespace grip::server
