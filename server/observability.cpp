#include "server/observability.hpp"

#include <spdlog/pattern_formatter.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <regex>

namespace grip::server {

Histogram::Histogram(std::vector<double> bounds) : bounds_(std::move(bounds)), counts_(bounds_.size() + 1, 0) {}

Histogram::Histogram(const Histogram& other) {
  std::lock_guard lock(other.mutex_);
  bounds_ = other.bounds_;
  counts_ = other.counts_;
  sum_ = other.sum_;
  count_ = other.count_;
}

void Histogram::observe(double value) {
  std::lock_guard lock(mutex_);
  size_t b = 0;
  while (b < bounds_.size() && value > bounds_[b]) ++b;
  ++counts_[b];
  sum_ += value;
  ++count_;
}

std::int64_t Histogram::count() const {
  std::lock_guard lock(mutex_);
  return count_;
}

void Histogram::write(std::ostream& os, const std::string& name, const std::string& labels) const {
  std::lock_guard lock(mutex_);
  const std::string sep = labels.empty() ? "" : ",";
  std::int64_t below = 0;
  for (size_t b = 0; b <= bounds_.size(); ++b) {
    below += counts_[b];
    os << name << "_bucket{" << labels << sep << "le=\"";
    if (b == bounds_.size()) os << "+Inf";
    else os << bounds_[b];
    os << "\"} " << below << "\n";
  }
  const std::string braces = labels.empty() ? "" : "{" + labels + "}";
  os << name << "_sum" << braces << " " << sum_ << "\n" << name << "_count" << braces << " " << count_ << "\n";
}

const std::vector<double>& seconds_buckets() {
  static const std::vector<double> b = {0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25,
                                        0.5,   1,      2.5,   5,    10,    30,   60,  300};
  return b;
}

std::string route_template(const std::string& path) {
  static const std::vector<std::pair<std::regex, std::string>> routes = {
      {std::regex(R"(/(v1/)?jobs)"), "/v1/jobs"},
      {std::regex(R"(/(v1/)?jobs/[^/]+)"), "/v1/jobs/{id}"},
      {std::regex(R"(/(v1/)?jobs/[^/]+/events)"), "/v1/jobs/{id}/events"},
      {std::regex(R"(/(v1/)?jobs/[^/]+/convergence)"), "/v1/jobs/{id}/convergence"},
      {std::regex(R"(/(v1/)?jobs/[^/]+/results?)"), "/v1/jobs/{id}/result"},
      {std::regex(R"(/(v1/)?processes/contact2d/execution)"), "/processes/contact2d/execution"},
      {std::regex(R"(/(v1/)?processes(/contact2d)?)"), "/processes"},
      {std::regex(R"(/v1/(health|ready|metrics))"), ""},  // the path itself
      {std::regex(R"(/|/conformance)"), ""},
      {std::regex(R"(/v1/(schemas|examples))"), ""},
      {std::regex(R"(/v1/(schemas|examples)/[^/]+)"), "/v1/{folder}/{name}"},
      {std::regex(R"(/ui(/[^/]+)?)"), "/ui"},
      {std::regex(R"(/v1/meshes)"), ""},
      {std::regex(R"(/v1/meshes/[^/]+)"), "/v1/meshes/{id}"},
      {std::regex(R"(/v1/studies)"), ""},
      {std::regex(R"(/v1/studies/[^/]+)"), "/v1/studies/{id}"},
      {std::regex(R"(/v1/studies/[^/]+/events)"), "/v1/studies/{id}/events"},
  };
  for (const auto& [pattern, name] : routes)
    if (std::regex_match(path, pattern)) return name.empty() ? path : name;
  return "other";
}

void RequestMetrics::record(const std::string& method, const std::string& route, int status, double seconds) {
  static const std::vector<std::string> methods = {"GET", "POST", "DELETE", "HEAD", "PUT", "PATCH", "OPTIONS"};
  const bool known = std::find(methods.begin(), methods.end(), method) != methods.end();
  std::lock_guard lock(mutex_);
  ++counts_[{known ? method : "other", route, status}];
  latency_.try_emplace(route, seconds_buckets()).first->second.observe(seconds);
}

void RequestMetrics::write(std::ostream& os) const {
  std::lock_guard lock(mutex_);
  os << "# HELP grip_http_requests_total HTTP requests answered by this process, by method, route and status.\n"
     << "# TYPE grip_http_requests_total counter\n";
  for (const auto& [key, n] : counts_)
    os << "grip_http_requests_total{method=\"" << std::get<0>(key) << "\",route=\"" << std::get<1>(key)
       << "\",status=\"" << std::get<2>(key) << "\"} " << n << "\n";
  os << "# HELP grip_http_request_duration_seconds Time from a request's routing to its answer, by route.\n"
     << "# TYPE grip_http_request_duration_seconds histogram\n";
  for (const auto& [route, h] : latency_) h.write(os, "grip_http_request_duration_seconds", "route=\"" + route + "\"");
}

std::string request_id_for(const std::string& header) {
  const bool usable = !header.empty() && header.size() <= 128 &&
                      std::all_of(header.begin(), header.end(), [](unsigned char c) { return c > 32 && c < 127; });
  if (usable) return header;
  thread_local std::mt19937_64 rng{std::random_device{}()};
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(rng()));
  return buf;
}

namespace {

// %* : the message as a JSON string's content (quotes, backslashes, control characters escaped).
class JsonMessage : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& msg, const std::tm&, spdlog::memory_buf_t& dest) override {
    for (char c : std::string_view(msg.payload.data(), msg.payload.size())) {
      switch (c) {
        case '"':
          dest.append(std::string_view("\\\""));
          break;
        case '\\':
          dest.append(std::string_view("\\\\"));
          break;
        case '\n':
          dest.append(std::string_view("\\n"));
          break;
        case '\r':
          dest.append(std::string_view("\\r"));
          break;
        case '\t':
          dest.append(std::string_view("\\t"));
          break;
        default:
          if (static_cast<unsigned char>(c) < 0x20) {
            char u[8];
            std::snprintf(u, sizeof u, "\\u%04x", c);
            dest.append(std::string_view(u));
          } else {
            dest.push_back(c);
          }
      }
    }
  }
  std::unique_ptr<custom_flag_formatter> clone() const override { return std::make_unique<JsonMessage>(); }
};

}  // namespace

void setup_logging(const std::string& format, const std::string& level) {
  auto formatter = std::make_unique<spdlog::pattern_formatter>(spdlog::pattern_time_type::utc);
  if (format == "json") {
    formatter->add_flag<JsonMessage>('*').set_pattern(
        R"({"time":"%Y-%m-%dT%H:%M:%S.%eZ","level":"%l","message":"%*"})");
  } else {
    formatter->set_pattern("%Y-%m-%dT%H:%M:%S.%eZ %^%l%$ %v");
  }
  spdlog::set_formatter(std::move(formatter));
  spdlog::set_level(spdlog::level::from_str(level));
  spdlog::flush_on(spdlog::level::info);
}

}  // namespace grip::server
