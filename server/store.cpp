#include "server/store.hpp"

#include "server/util.hpp"

namespace grip::server {

std::string_view to_string(JobStatus status) {
  switch (status) {
    case JobStatus::accepted:
      return "accepted";
    case JobStatus::running:
      return "running";
    case JobStatus::successful:
      return "successful";
    case JobStatus::failed:
      return "failed";
    case JobStatus::dismissed:
      return "dismissed";
  }
  return "failed";
}

std::optional<JobStatus> parse_job_status(std::string_view text) {
  for (JobStatus s :
       {JobStatus::accepted, JobStatus::running, JobStatus::successful, JobStatus::failed, JobStatus::dismissed})
    if (to_string(s) == text) return s;
  return std::nullopt;
}

}  // namespace grip::server

namespace grip::server {

std::string retention_cutoff(const Retention& r, const std::string& now) {
  if (r.max_age_seconds <= 0) return "";
  const auto t = parse_iso8601(now);
  if (!t) return "";
  return iso8601(*t - std::chrono::milliseconds(static_cast<std::int64_t>(r.max_age_seconds * 1000)));
}

std::vector<std::string> beyond_retention(const std::vector<FinishedJob>& jobs, const Retention& r,
                                          const std::string& cutoff) {
  std::vector<std::string> out;
  std::int64_t kept = 0, bytes = 0;
  for (const FinishedJob& j : jobs) {
    const bool too_old = !cutoff.empty() && j.finished < cutoff;  // ISO 8601 UTC sorts as time
    const bool too_many = r.max_jobs > 0 && kept + 1 > r.max_jobs;
    const bool too_large = r.max_bytes > 0 && bytes + j.stored_bytes > r.max_bytes;
    if (too_old || too_many || too_large) {
      out.push_back(j.id);
      continue;
    }
    ++kept;
    bytes += j.stored_bytes;
  }
  return out;
}

}  // namespace grip::server
