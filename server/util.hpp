#pragma once
// Small helpers of the service: timestamps and job ids.
#include <chrono>
#include <optional>
#include <string>

namespace grip::server {

// Now as ISO 8601 UTC with milliseconds: 2025-01-31T12:34:56.789Z.
std::string now_iso8601();
std::string iso8601(std::chrono::system_clock::time_point t);
// The time of a now_iso8601() text; nullopt for another form.
std::optional<std::chrono::system_clock::time_point> parse_iso8601(const std::string& text);

// A random UUID v4: job ids are opaque and unguessable.
std::string new_job_id();

// This process's name in job leases: host, pid and a random part (a restarted process is a
// new replica: its predecessor's leases expire rather than being silently inherited).
std::string default_replica_name();

// Constant-time comparison (bearer tokens).
bool equal_constant_time(const std::string& a, const std::string& b);

}  // namespace grip::server
