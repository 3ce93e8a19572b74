#pragma once
// Test support for the service: the real `grip serve` as a child process on a free loopback
// port, an HTTP client for it, event-stream parsing and scene builders.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace grip::testing {

using nlohmann::json;
namespace fs = std::filesystem;

inline std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

inline fs::path source_dir() { return GRIP_SOURCE_DIR; }
inline fs::path examples_dir() { return source_dir() / "schemas" / "examples"; }

// A fresh folder, removed at the end.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "grip-it-XXXXXX").string();
    if (!mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// `grip serve --host 127.0.0.1 --port 0 --db DB ARGS...`, its output in a log file.
class ServerProcess {
 public:
  ServerProcess(const fs::path& db, std::vector<std::string> args, const fs::path& log) : log_(log) {
    std::vector<std::string> argv = {GRIP_BINARY, "serve", "--host",    "127.0.0.1",   "--port",
                                     "0",         "--db",  db.string(), "--heartbeat", "1"};
    argv.insert(argv.end(), args.begin(), args.end());
    const std::streamoff start = fs::exists(log) ? static_cast<std::streamoff>(fs::file_size(log)) : 0;
    pid_ = fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      dup2(fd, 1);
      dup2(fd, 2);
      std::vector<char*> cargs;
      for (auto& a : argv) cargs.push_back(a.data());
      cargs.push_back(nullptr);
      execv(cargs[0], cargs.data());
      _exit(127);
    }
    // Wait for "listening on http://127.0.0.1:PORT" in this run's part of the log.
    const std::regex listening(R"(listening on http://127\.0\.0\.1:(\d+))");
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline) {
      const std::string text = read_text(log).substr(static_cast<size_t>(start));
      std::smatch m;
      if (std::regex_search(text, m, listening)) {
        port_ = std::stoi(m[1]);
        return;
      }
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        throw std::runtime_error("grip serve exited at start:\n" + text);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    kill9();
    throw std::runtime_error("grip serve did not start:\n" + read_text(log));
  }
  ~ServerProcess() {
    if (pid_ > 0) terminate(std::chrono::seconds(30));
  }
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  int port() const { return port_; }
  pid_t pid() const { return pid_; }
  std::string log() const { return read_text(log_); }

  void kill9() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
  }
  // SIGTERM, then the exit code (SIGKILL and -1 after `patience`).
  int terminate(std::chrono::seconds patience) {
    if (pid_ <= 0) return -1;
    ::kill(pid_, SIGTERM);
    const auto deadline = std::chrono::steady_clock::now() + patience;
    int status = 0;
    while (std::chrono::steady_clock::now() < deadline) {
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    kill9();
    return -1;
  }

 private:
  fs::path log_;
  pid_t pid_ = -1;
  int port_ = 0;
};

// A client of one server; every call opens its own connection (thread-safe by copy).
class Api {
 public:
  explicit Api(int port, std::optional<std::string> token = std::nullopt) : port_(port), token_(std::move(token)) {}

  httplib::Client client(int read_timeout_s = 30) const {
    httplib::Client c("127.0.0.1", port_);
    c.set_connection_timeout(10);
    c.set_read_timeout(read_timeout_s);
    c.set_keep_alive(false);
    if (token_) c.set_bearer_token_auth(*token_);
    return c;
  }

  httplib::Result get(const std::string& path, const httplib::Headers& h = {}) const { return client().Get(path, h); }
  httplib::Result post_json(const std::string& path, const std::string& body, const httplib::Headers& h = {}) const {
    return client().Post(path, h, body, "application/json");
  }
  httplib::Result del(const std::string& path) const { return client().Delete(path); }

  // Submits a scene; the job id (throws unless 201).
  std::string submit(const json& scene) const {
    auto r = post_json("/v1/jobs", scene.dump());
    if (!r || r->status != 201)
      throw std::runtime_error("submit failed: " + (r ? std::to_string(r->status) + " " + r->body
                                                      : "no response: " + httplib::to_string(r.error())));
    return json::parse(r->body).at("jobID");
  }
  json job(const std::string& id) const {
    auto r = get("/v1/jobs/" + id);
    if (!r || r->status != 200) throw std::runtime_error("job " + id + " not readable");
    return json::parse(r->body);
  }
  // Polls until the job's status is one of `statuses`; its document.
  json wait_status(const std::string& id, const std::vector<std::string>& statuses,
                   std::chrono::seconds patience = std::chrono::seconds(120)) const {
    const auto deadline = std::chrono::steady_clock::now() + patience;
    json doc;
    while (std::chrono::steady_clock::now() < deadline) {
      doc = job(id);
      for (const auto& s : statuses)
        if (doc["status"] == s) return doc;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    throw std::runtime_error("job " + id + " stayed " + doc.value("status", std::string("?")));
  }

 private:
  int port_;
  std::optional<std::string> token_;
};

// The value of an unlabelled sample in /v1/metrics.
inline double metric(const Api& api, const std::string& name) {
  const auto r = api.get("/v1/metrics");
  if (!r) throw std::runtime_error("no /v1/metrics");
  const size_t at = r->body.find("\n" + name + " ");
  if (at == std::string::npos) throw std::runtime_error("no " + name + " in /v1/metrics");
  return std::stod(r->body.substr(at + name.size() + 2));
}

// Polls /v1/metrics until the server counts `n` open event streams (a stream the client
// dropped counts until the server's next write to it fails).
inline bool wait_open_streams(const Api& api, int n) {
  const std::string line = "grip_open_streams " + std::to_string(n) + "\n";
  for (int tries = 0; tries < 3000; ++tries) {
    auto r = api.get("/v1/metrics");
    if (r && r->body.find(line) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

struct SseEvent {
  std::int64_t id = 0;
  std::string type;
  std::string data;
  json object() const { return json::parse(data); }
};

// Parses text/event-stream frames as they arrive.
class SseParser {
 public:
  // Feeds bytes; returns the complete events among them.
  std::vector<SseEvent> feed(const char* data, size_t n) {
    buffer_.append(data, n);
    std::vector<SseEvent> out;
    size_t end;
    while ((end = buffer_.find("\n\n")) != std::string::npos) {
      const std::string frame = buffer_.substr(0, end);
      buffer_.erase(0, end + 2);
      SseEvent e;
      bool has_data = false;
      std::istringstream lines(frame);
      std::string line;
      while (std::getline(lines, line)) {
        if (line.rfind("id: ", 0) == 0) e.id = std::stoll(line.substr(4));
        else if (line.rfind("event: ", 0) == 0) e.type = line.substr(7);
        else if (line.rfind("data: ", 0) == 0) {
          e.data = line.substr(6);
          has_data = true;
        } else if (line.rfind(":", 0) == 0) ++comments;
      }
      if (has_data) out.push_back(std::move(e));
    }
    return out;
  }
  int comments = 0;  // heartbeats

 private:
  std::string buffer_;
};

struct Stream {
  int status = 0;
  std::vector<SseEvent> events;
  bool ended = false;  // a job_finished or job_failed arrived
};

// Follows /v1/jobs/ID/events (from after `last_event_id` when given) until the terminal
// event, or until `max_events` events have arrived (then disconnects).
inline Stream follow(const Api& api, const std::string& id, std::optional<std::int64_t> last_event_id = {},
                     size_t max_events = SIZE_MAX) {
  Stream s;
  SseParser parser;
  httplib::Headers h;
  if (last_event_id) h.emplace("Last-Event-ID", std::to_string(*last_event_id));
  auto cli = api.client(60);
  auto r = cli.Get(
      "/v1/jobs/" + id + "/events", h,
      [&](const httplib::Response& res) {
        s.status = res.status;
        return true;
      },
      [&](const char* data, size_t n) {
        for (auto& e : parser.feed(data, n)) {
          s.ended = s.ended || e.type == "job_finished" || e.type == "job_failed";
          s.events.push_back(std::move(e));
          if (s.events.size() >= max_events) return false;
        }
        return true;
      });
  if (r) s.status = r->status;
  return s;
}

// The paper's beam example with another mesh and step count.
inline json beam_scene(int elements, int steps) {
  json scene = json::parse(read_text(examples_dir() / "beam-on-cylinder.json"));
  scene["body"]["mesh"]["elements"] = elements;
  for (auto& load : scene["body"]["loads"]) load["node"] = elements;
  scene["steps"] = steps;
  return scene;
}

// The result of an uninterrupted run: `grip solve` (the binary under test), which builds the
// same result document as the service.
inline json reference_result(const json& scene, const fs::path& dir, const std::string& name) {
  const fs::path in = dir / (name + ".scene.json"), out = dir / (name + ".result.json");
  std::ofstream(in) << scene.dump();
  const std::string cmd =
      std::string(GRIP_BINARY) + " solve " + in.string() + " --out " + out.string() + " > /dev/null";
  if (std::system(cmd.c_str()) != 0) throw std::runtime_error("grip solve failed for " + name);
  return json::parse(read_text(out));
}

// Removes wall-clock fields, which differ between runs of the same scene.
inline json without_timings(json j) {
  if (j.is_object()) {
    for (const char* k : {"seconds", "elapsed_ms"}) j.erase(k);
    for (auto& [k, v] : j.items()) v = without_timings(v);
  } else if (j.is_array()) {
    for (auto& v : j) v = without_timings(v);
  }
  return j;
}

}  // namespace grip::testing
