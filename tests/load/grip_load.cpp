// grip_load: a load client for a running `grip serve` (scripts/load.sh starts the server).
//
// --clients threads submit --jobs copies of one scene (honouring 503 + Retry-After, each
// submission with its own Idempotency-Key so that a retry never doubles a job), while
// --streams threads each hold an event stream open, following the newest accepted job not
// yet followed. Afterwards every accepted job must be `successful` with a complete result
// (summary.completed, as many steps as the scene asks). Prints the figures; --report appends
// them as a markdown table. Exit code 0 only when nothing was lost or failed.
//
// Iteration -> event delay: events carry no wall-clock time, only `elapsed_ms` since their
// step began. The server time of an iteration is estimated as the job's `started` (stamped
// before the scene is read) + the `seconds` of the steps before + `elapsed_ms`: never later
// than the true time, so receive time - estimate is an upper bound of the delay (client and
// server share the machine's clock). Only live events count: those whose estimated time is
// after the stream was opened (replayed ones are not a delay).
#include <httplib.h>
#include <sys/resource.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

using nlohmann::json;
using Steady = std::chrono::steady_clock;
using Wall = std::chrono::system_clock;

struct Options {
  std::string host = "127.0.0.1";
  int port = 8080;
  int jobs = 1000;
  int clients = 50;
  int streams = 100;
  std::string scene_path;
  int server_pid = 0;
  std::string report;
  double timeout_s = 600;  // the whole run
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "grip_load: %s\nusage: grip_load --port P --scene FILE [--host H] [--jobs N] "
               "[--clients N] [--streams N] [--server-pid PID] [--report FILE] [--timeout S]\n",
               why.c_str());
  std::exit(2);
}

Options parse_args(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) usage(a + " needs a value");
    const std::string v = argv[++i];
    try {
      if (a == "--host") o.host = v;
      else if (a == "--port") o.port = std::stoi(v);
      else if (a == "--jobs") o.jobs = std::stoi(v);
      else if (a == "--clients") o.clients = std::stoi(v);
      else if (a == "--streams") o.streams = std::stoi(v);
      else if (a == "--scene") o.scene_path = v;
      else if (a == "--server-pid") o.server_pid = std::stoi(v);
      else if (a == "--report") o.report = v;
      else if (a == "--timeout") o.timeout_s = std::stod(v);
      else usage("unknown option " + a);
    } catch (const std::logic_error&) {
      usage("bad value for " + a + ": " + v);
    }
  }
  if (o.scene_path.empty()) usage("--scene is required");
  if (o.jobs < 1 || o.clients < 1 || o.streams < 0) usage("--jobs and --clients must be >= 1");
  return o;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<size_t>(std::ceil(q * static_cast<double>(v.size())));
  return v[std::clamp<size_t>(rank, 1, v.size()) - 1];
}

// "2026-11-22T05:10:03.123Z" (the server's timestamps) as a wall-clock time.
std::optional<Wall::time_point> parse_iso(const std::string& s) {
  std::tm tm{};
  int ms = 0;
  if (std::sscanf(s.c_str(), "%d-%d-%dT%d:%d:%d.%dZ", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour, &tm.tm_min,
                  &tm.tm_sec, &ms) != 7)
    return std::nullopt;
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return Wall::from_time_t(timegm(&tm)) + std::chrono::milliseconds(ms);
}

// Load steps the scene asks for: a count, a list of factors, or stages.
int expected_steps(const json& scene) {
  if (scene.contains("stages")) {
    int n = 0;
    for (const auto& st : scene["stages"])
      n += st["steps"].is_array() ? static_cast<int>(st["steps"].size()) : st["steps"].get<int>();
    return n;
  }
  const json& s = scene.at("steps");
  return s.is_array() ? static_cast<int>(s.size()) : s.get<int>();
}

std::optional<long> proc_status_kib(int pid, const std::string& field) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(field + ":", 0) == 0) return std::stol(line.substr(field.size() + 1));
  return std::nullopt;
}

// A process's CPU time (user + system) in seconds, from /proc/PID/stat; 0 if it cannot be read.
double proc_cpu_seconds(int pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto close = stat.rfind(')');  // the command name may hold spaces
  if (close == std::string::npos) return 0;
  std::istringstream rest(stat.substr(close + 2));
  std::string field;
  double utime = 0, stime = 0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {  // fields 14 and 15 (1-based): utime, stime
    if (i == 14) utime = std::stod(field);
    if (i == 15) stime = std::stod(field);
  }
  return (utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

double own_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  const auto s = [](timeval t) { return t.tv_sec + t.tv_usec * 1e-6; };
  return s(u.ru_utime) + s(u.ru_stime);
}

int retry_after(const httplib::Response& r) {
  const std::string v = r.get_header_value("Retry-After");
  try {
    return std::clamp(std::stoi(v), 0, 60);
  } catch (...) {
    return 1;
  }
}

// Shared state of one run.
struct Run {
  Options opt;
  std::string scene_body;
  int steps = 0;
  Steady::time_point deadline;

  std::atomic<int> next_job{0};
  std::atomic<int> submitters_left{0};
  std::atomic<long> rejected_503{0};      // queue full: retried after Retry-After
  std::atomic<long> stream_503{0};        // too many streams: retried after Retry-After
  std::atomic<long> transport_errors{0};  // no response; retried (same Idempotency-Key)
  std::atomic<long> other_status{0};      // any other answer to a submission
  std::atomic<long> replays{0};           // Idempotent-Replayed answers

  std::mutex m;
  std::condition_variable cv;
  std::vector<std::string> accepted;   // every job acknowledged with 201
  std::vector<std::string> to_follow;  // accepted, not yet followed (newest at the back)
  std::vector<double> submit_ms;       // latency of the accepted attempt
  std::vector<double> delay_ms;        // live iteration events
  long events_received = 0;
  long live_iterations = 0;
  long streams_followed = 0;
  long streams_incomplete = 0;  // no terminal event, or ids not consecutive
  std::vector<std::string> problems;

  httplib::Client client(int read_timeout_s = 30) const {
    httplib::Client c(opt.host, opt.port);
    c.set_connection_timeout(10);
    c.set_read_timeout(read_timeout_s);
    c.set_write_timeout(30);
    return c;
  }
  void problem(const std::string& what) {
    std::lock_guard lock(m);
    if (problems.size() < 20) problems.push_back(what);
  }
  bool late() const { return Steady::now() > deadline; }
};

void submitter(Run& run) {
  httplib::Client cli = run.client();
  cli.set_keep_alive(true);
  const std::string run_tag = std::to_string(::getpid()) + "-" + std::to_string(Wall::now().time_since_epoch().count());
  for (int i; (i = run.next_job++) < run.opt.jobs && !run.late();) {
    const httplib::Headers headers = {{"Idempotency-Key", "load-" + run_tag + "-" + std::to_string(i)}};
    while (!run.late()) {
      const auto t0 = Steady::now();
      auto r = cli.Post("/v1/jobs", headers, run.scene_body, "application/json");
      const double ms = std::chrono::duration<double, std::milli>(Steady::now() - t0).count();
      if (!r) {
        ++run.transport_errors;
        run.problem("submit: no response (" + httplib::to_string(r.error()) + ")");
        std::this_thread::sleep_for(std::chrono::seconds(1));
        continue;
      }
      if (r->status == 503) {
        ++run.rejected_503;
        std::this_thread::sleep_for(std::chrono::seconds(retry_after(*r)));
        continue;
      }
      if (r->status != 201) {
        ++run.other_status;
        run.problem("submit: " + std::to_string(r->status) + " " + r->body.substr(0, 200));
        break;
      }
      if (r->get_header_value("Idempotent-Replayed") == "true") ++run.replays;
      const std::string id = json::parse(r->body).at("jobID");
      {
        std::lock_guard lock(run.m);
        run.submit_ms.push_back(ms);
        run.accepted.push_back(id);
        run.to_follow.push_back(id);
      }
      run.cv.notify_one();
      break;
    }
  }
  if (--run.submitters_left == 0) run.cv.notify_all();
}

struct Followed {
  Wall::time_point opened;
  struct Iteration {
    int step;
    double elapsed_ms;
    Wall::time_point received;
  };
  std::vector<Iteration> iterations;
  std::map<int, double> step_seconds;
  std::int64_t last_id = 0;
  bool consecutive = true;
  bool ended = false;
  long events = 0;
};

// Follows one job's events to the end (retrying on 503); false when the stream broke off.
bool follow(Run& run, const std::string& id, Followed& f) {
  std::string buffer;
  while (!run.late()) {
    int status = 0, wait = 1;
    httplib::Client cli = run.client(60);
    auto r = cli.Get(
        "/v1/jobs/" + id + "/events", {},
        [&](const httplib::Response& res) {
          status = res.status;
          if (status == 503) wait = retry_after(res);
          f.opened = Wall::now();
          return status == 200;
        },
        [&](const char* data, size_t n) {
          const auto now = Wall::now();
          buffer.append(data, n);
          size_t end;
          while ((end = buffer.find("\n\n")) != std::string::npos) {
            std::istringstream frame(buffer.substr(0, end));
            buffer.erase(0, end + 2);
            std::string line, type, payload;
            std::int64_t eid = -1;
            while (std::getline(frame, line)) {
              if (line.rfind("id: ", 0) == 0) eid = std::stoll(line.substr(4));
              else if (line.rfind("event: ", 0) == 0) type = line.substr(7);
              else if (line.rfind("data: ", 0) == 0) payload = line.substr(6);
            }
            if (eid < 0) continue;  // retry: or a ping
            ++f.events;
            if (eid != f.last_id + 1) f.consecutive = false;
            f.last_id = eid;
            if (type == "iteration") {
              const json e = json::parse(payload);
              f.iterations.push_back({e.at("step").get<int>(), e.at("elapsed_ms").get<double>(), now});
            } else if (type == "step_finished") {
              const json e = json::parse(payload);
              f.step_seconds[e.at("step").get<int>()] = e.at("seconds").get<double>();
            } else if (type == "job_finished" || type == "job_failed") {
              f.ended = true;
            }
          }
          return true;
        });
    if (status == 503) {
      ++run.stream_503;
      std::this_thread::sleep_for(std::chrono::seconds(wait));
      continue;
    }
    if (!r && status == 0) {
      run.problem("events " + id + ": no response (" + httplib::to_string(r.error()) + ")");
      return false;
    }
    if (status != 200) {
      run.problem("events " + id + ": status " + std::to_string(status));
      return false;
    }
    return f.ended;
  }
  return false;
}

void streamer(Run& run) {
  while (true) {
    std::string id;
    {
      std::unique_lock lock(run.m);
      run.cv.wait(lock, [&] { return !run.to_follow.empty() || run.submitters_left == 0; });
      if (run.to_follow.empty()) return;
      // The newest job: the one most likely still waiting, so its events arrive live.
      id = run.to_follow.back();
      run.to_follow.pop_back();
    }
    Followed f;
    const bool ended = follow(run, id, f);
    // The job's start on the server's clock, then the estimated time of each iteration.
    std::optional<Wall::time_point> started;
    if (auto r = run.client().Get("/v1/jobs/" + id); r && r->status == 200)
      started = parse_iso(json::parse(r->body).value("started", ""));
    std::vector<double> delays;
    if (started) {
      std::map<int, Wall::time_point> step_start;
      Wall::time_point t = *started;
      for (int s = 1; s <= run.steps; ++s) {
        step_start[s] = t;
        const auto it = f.step_seconds.find(s);
        if (it == f.step_seconds.end()) break;
        t += std::chrono::duration_cast<Wall::duration>(std::chrono::duration<double>(it->second));
      }
      for (const auto& it : f.iterations) {
        const auto s = step_start.find(it.step);
        if (s == step_start.end()) continue;
        const Wall::time_point produced = s->second + std::chrono::duration_cast<Wall::duration>(
                                                          std::chrono::duration<double, std::milli>(it.elapsed_ms));
        if (produced < f.opened) continue;  // replayed, not live
        delays.push_back(std::chrono::duration<double, std::milli>(it.received - produced).count());
      }
    }
    std::lock_guard lock(run.m);
    ++run.streams_followed;
    run.events_received += f.events;
    run.live_iterations += static_cast<long>(delays.size());
    run.delay_ms.insert(run.delay_ms.end(), delays.begin(), delays.end());
    if (!ended || !f.consecutive) {
      ++run.streams_incomplete;
      if (run.problems.size() < 20)
        run.problems.push_back("events " + id + ": " + (ended ? "ids not consecutive" : "no terminal event"));
    }
  }
}

struct Verified {
  long successful = 0, failed = 0, missing = 0, unfinished = 0, incomplete = 0;
  Wall::time_point first_created = Wall::time_point::max(), last_finished = Wall::time_point::min();
};

// Waits for each job to finish, then checks its status and its stored result.
void verify(Run& run, const std::vector<std::string>& ids, Verified& v, std::mutex& m) {
  httplib::Client cli = run.client(60);
  cli.set_keep_alive(true);
  for (const std::string& id : ids) {
    json doc;
    bool found = false, finished = false;
    while (true) {
      auto r = cli.Get("/v1/jobs/" + id);
      if (r && r->status == 404) break;
      if (r && r->status == 200) {
        found = true;
        doc = json::parse(r->body);
        const std::string s = doc.value("status", "");
        finished = s == "successful" || s == "failed" || s == "dismissed";
        if (finished) break;
      }
      if (run.late()) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    std::string bad;
    if (!found) bad = "missing";
    else if (!finished) bad = "unfinished";
    else if (doc["status"] != "successful") bad = "failed";
    else {
      auto r = cli.Get("/v1/jobs/" + id + "/result");
      json result;
      if (r && r->status == 200) result = json::parse(r->body, nullptr, false);
      if (!result.is_object() || !result.contains("steps") || !result["steps"].is_array() ||
          static_cast<int>(result["steps"].size()) != run.steps ||
          result["summary"].value("completed", false) != true || result["summary"].value("steps", -1) != run.steps)
        bad = "incomplete";
      else
        for (const auto& st : result["steps"]) bad = st.value("converged", false) ? bad : "incomplete";
    }
    std::lock_guard lock(m);
    if (bad.empty()) ++v.successful;
    else if (bad == "missing") ++v.missing;
    else if (bad == "unfinished") ++v.unfinished;
    else if (bad == "failed") ++v.failed;
    else ++v.incomplete;
    if (!bad.empty()) run.problem("job " + id + ": " + bad + (found ? " " + doc.value("message", "") : ""));
    if (found) {
      if (auto t = parse_iso(doc.value("created", ""))) v.first_created = std::min(v.first_created, *t);
      if (auto t = parse_iso(doc.value("finished", ""))) v.last_finished = std::max(v.last_finished, *t);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  Run run;
  run.opt = parse_args(argc, argv);
  const Options& o = run.opt;
  {
    std::ifstream in(o.scene_path);
    if (!in) usage("cannot read " + o.scene_path);
    const json scene = json::parse(in);
    run.scene_body = scene.dump();
    run.steps = expected_steps(scene);
  }
  run.deadline =
      Steady::now() + std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(o.timeout_s));
  if (auto r = run.client().Get("/v1/health"); !r || r->status != 200) {
    std::fprintf(stderr, "grip_load: no healthy server on %s:%d\n", o.host.c_str(), o.port);
    return 2;
  }

  // Peak resident memory of the server, sampled (VmHWM is read at the end as well).
  std::atomic<bool> sampling{true};
  long rss_max_kib = 0;
  std::thread sampler([&] {
    while (sampling && o.server_pid > 0) {
      if (auto kib = proc_status_kib(o.server_pid, "VmRSS")) rss_max_kib = std::max(rss_max_kib, *kib);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });

  const double server_cpu0 = o.server_pid > 0 ? proc_cpu_seconds(o.server_pid) : 0, own_cpu0 = own_cpu_seconds();
  const auto t0 = Steady::now();
  run.submitters_left = o.clients;
  std::vector<std::thread> threads;
  for (int s = 0; s < o.streams; ++s) threads.emplace_back([&] { streamer(run); });
  std::vector<std::thread> submitters;
  for (int c = 0; c < o.clients; ++c) submitters.emplace_back([&] { submitter(run); });
  for (auto& t : submitters) t.join();
  const double submit_s = std::chrono::duration<double>(Steady::now() - t0).count();

  // Every accepted job, checked by as many threads as there were clients.
  Verified v;
  std::mutex vm;
  std::vector<std::vector<std::string>> shares(static_cast<size_t>(o.clients));
  for (size_t i = 0; i < run.accepted.size(); ++i) shares[i % shares.size()].push_back(run.accepted[i]);
  std::vector<std::thread> verifiers;
  for (auto& share : shares) verifiers.emplace_back([&] { verify(run, share, v, vm); });
  for (auto& t : verifiers) t.join();
  const double done_s = std::chrono::duration<double>(Steady::now() - t0).count();
  for (auto& t : threads) t.join();
  sampling = false;
  sampler.join();

  const double server_cpu_ms = o.server_pid > 0 ? 1e3 * (proc_cpu_seconds(o.server_pid) - server_cpu0) /
                                                      std::max(1L, static_cast<long>(run.accepted.size()))
                                                : 0;
  const double own_cpu_ms = 1e3 * (own_cpu_seconds() - own_cpu0) / std::max(1L, static_cast<long>(run.accepted.size()));
  const long hwm_kib = o.server_pid > 0 ? proc_status_kib(o.server_pid, "VmHWM").value_or(0) : 0;
  const long accepted = static_cast<long>(run.accepted.size());
  const double server_span_s =
      v.last_finished > v.first_created ? std::chrono::duration<double>(v.last_finished - v.first_created).count() : 0;
  const bool all_ok =
      accepted == o.jobs && v.successful == accepted && run.other_status == 0 && run.streams_incomplete == 0;

  char buf[4096];
  std::snprintf(buf, sizeof buf,
                "| jobs submitted / accepted / successful with a complete result | %d / %ld / %ld |\n"
                "| failed / unfinished / missing / incomplete result | %ld / %ld / %ld / %ld |\n"
                "| clients, event streams | %d, %d |\n"
                "| steps per job | %d |\n"
                "| throughput (server: first created to last finished) | %.1f jobs/s (%.2f s) |\n"
                "| throughput (client: first submit to last verified) | %.1f jobs/s (%.2f s) |\n"
                "| submit latency p50 / p99 / max (accepted attempts) | %.1f / %.1f / %.1f ms |\n"
                "| 503 answers: queue full / stream cap (each retried after Retry-After) | %ld / %ld |\n"
                "| other submit answers, transport errors, idempotent replays | %ld, %ld, %ld |\n"
                "| streams followed to the end (incomplete) | %ld (%ld) |\n"
                "| events received, live iteration events measured | %ld, %ld |\n"
                "| iteration -> event delay p50 / p99 / max (upper bound, see below) | %.1f / %.1f / %.1f ms |\n"
                "| server peak memory VmHWM (max VmRSS sampled) | %.1f MiB (%.1f MiB) |\n"
                "| CPU time per accepted job: server / this load client | %.1f / %.1f ms |\n",
                o.jobs, accepted, v.successful, v.failed, v.unfinished, v.missing, v.incomplete, o.clients, o.streams,
                run.steps, server_span_s > 0 ? accepted / server_span_s : 0.0, server_span_s, accepted / done_s, done_s,
                percentile(run.submit_ms, 0.5), percentile(run.submit_ms, 0.99), percentile(run.submit_ms, 1.0),
                run.rejected_503.load(), run.stream_503.load(), run.other_status.load(), run.transport_errors.load(),
                run.replays.load(), run.streams_followed, run.streams_incomplete, run.events_received,
                run.live_iterations, percentile(run.delay_ms, 0.5), percentile(run.delay_ms, 0.99),
                percentile(run.delay_ms, 1.0), hwm_kib / 1024.0, rss_max_kib / 1024.0, server_cpu_ms, own_cpu_ms);
  const std::string table = std::string("| | |\n|---|---|\n") + buf;
  std::printf("%s", table.c_str());
  std::printf("submission phase %.2f s; all %s\n", submit_s, all_ok ? "successful" : "NOT successful");
  for (const auto& p : run.problems) std::printf("problem: %s\n", p.c_str());
  if (!o.report.empty()) {
    std::ofstream out(o.report, std::ios::app);
    out << table << "\nAll accepted jobs successful with complete results: " << (all_ok ? "yes" : "NO") << ".\n";
    for (const auto& p : run.problems) out << "- problem: " << p << "\n";
  }
  return all_ok ? 0 : 1;
}
