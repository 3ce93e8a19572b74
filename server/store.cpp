#include "server/store.hpp"

namespace grip::server {

std::string_view to_string(JobStatus status) {
  switch (status) {
    case JobStatus::accepted: return "accepted";
    case JobStatus::running: return "running";
    case JobStatus::successful: return "successful";
    case JobStatus::failed: return "failed";
    case JobStatus::dismissed: return "dismissed";
  }
  return "failed";
}

std::optional<JobStatus> parse_job_status(std::string_view text) {
  for (JobStatus s : {JobStatus::accepted, JobStatus::running, JobStatus::successful,
                      JobStatus::failed, JobStatus::dismissed})
    if (to_string(s) == text) return s;
  return std::nullopt;
}

}  // namespace grip::server
