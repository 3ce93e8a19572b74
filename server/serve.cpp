#include "server/serve.hpp"

#include <httplib.h>
#include <malloc.h>
#include <pthread.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <thread>

#include "server/observability.hpp"
#include "server/postgres_store.hpp"
#include "server/sqlite_store.hpp"

namespace grip::server {
namespace {

namespace fs = std::filesystem;

struct Flag {
  const char* name;  // --name
  const char* env;   // GRIP_NAME
  const char* arg;
  const char* help;
  std::function<void(ServeConfig&, const std::string&)> set;
};

long long integer(const std::string& v, const std::string& what, long long lo, long long hi) {
  size_t used = 0;
  long long n = 0;
  try {
    n = std::stoll(v, &used);
  } catch (...) {
    used = 0;
  }
  if (used != v.size() || v.empty() || n < lo || n > hi)
    throw std::invalid_argument(what + ": '" + v + "' is not an integer from " + std::to_string(lo) + " to " +
                                std::to_string(hi));
  return n;
}

double real(const std::string& v, const std::string& what, double lo) {
  size_t used = 0;
  double x = 0;
  try {
    x = std::stod(v, &used);
  } catch (...) {
    used = 0;
  }
  if (used != v.size() || v.empty() || !(x >= lo))
    throw std::invalid_argument(what + ": '" + v + "' is not a number >= " + std::to_string(lo));
  return x;
}

const std::vector<Flag>& flags() {
  static const std::vector<Flag> list = {
      {"host", "GRIP_HOST", "HOST", "address to listen on (default 127.0.0.1)",
       [](ServeConfig& c, const std::string& v) { c.http.host = v; }},
      {"port", "GRIP_PORT", "PORT", "port (default 8080; 0: any free port)",
       [](ServeConfig& c, const std::string& v) { c.http.port = static_cast<int>(integer(v, "--port", 0, 65535)); }},
      {"db", "GRIP_DB", "PATH|URL", "SQLite file (default data/grip.sqlite) or postgresql:// URL",
       [](ServeConfig& c, const std::string& v) { c.db = v; }},
      {"workers", "GRIP_WORKERS", "N", "solver threads (default: one per core)",
       [](ServeConfig& c, const std::string& v) {
         c.service.workers = static_cast<int>(integer(v, "--workers", 1, 1024));
       }},
      {"queue", "GRIP_QUEUE", "N", "accepted jobs that may wait for a worker (default 256)",
       [](ServeConfig& c, const std::string& v) {
         c.service.queue_capacity = static_cast<int>(integer(v, "--queue", 1, 1000000));
       }},
      {"streams", "GRIP_STREAMS", "N", "open event streams (default 32)",
       [](ServeConfig& c, const std::string& v) {
         c.http.max_streams = static_cast<int>(integer(v, "--streams", 1, 10000));
       }},
      {"http-threads", "GRIP_HTTP_THREADS", "N",
       "connections served at once, a thread each, all started with the server (default 1024)",
       [](ServeConfig& c, const std::string& v) {
         c.http.front.max_connections = static_cast<int>(integer(v, "--http-threads", 2, 20000));
       }},
      {"per-client", "GRIP_PER_CLIENT", "N", "open connections from one client address (default 64)",
       [](ServeConfig& c, const std::string& v) {
         c.http.front.per_client = static_cast<int>(integer(v, "--per-client", 1, 100000));
       }},
      {"idle-connections", "GRIP_IDLE_CONNECTIONS", "N", "keep-alive connections kept waiting (default 64)",
       [](ServeConfig& c, const std::string& v) {
         c.http.front.max_idle = static_cast<int>(integer(v, "--idle-connections", 0, 100000));
       }},
      {"head-timeout", "GRIP_HEAD_TIMEOUT", "S", "seconds for a whole request head (default 5)",
       [](ServeConfig& c, const std::string& v) {
         c.http.front.head = std::chrono::milliseconds(static_cast<long long>(1000 * real(v, "--head-timeout", 0.1)));
       }},
      {"body-timeout", "GRIP_BODY_TIMEOUT", "S", "seconds for a whole request body (default 10)",
       [](ServeConfig& c, const std::string& v) {
         c.http.front.body = std::chrono::milliseconds(static_cast<long long>(1000 * real(v, "--body-timeout", 0.1)));
       }},
      {"max-body", "GRIP_MAX_BODY", "BYTES", "largest request body (default 8388608)",
       [](ServeConfig& c, const std::string& v) {
         c.http.max_body_bytes = static_cast<size_t>(integer(v, "--max-body", 1024, 1LL << 34));
       }},
      {"max-mesh", "GRIP_MAX_MESH", "BYTES", "largest uploaded mesh file, POST /v1/meshes (default 67108864)",
       [](ServeConfig& c, const std::string& v) {
         c.http.max_mesh_bytes = static_cast<size_t>(integer(v, "--max-mesh", 1024, 1LL << 34));
       }},
      {"parse-budget", "GRIP_PARSE_BUDGET", "BYTES",
       "submitted bodies read and checked at once; more wait (default: max-body)",
       [](ServeConfig& c, const std::string& v) {
         c.http.parse_budget_bytes = static_cast<size_t>(integer(v, "--parse-budget", 1024, 1LL << 36));
       }},
      {"max-nodes", "GRIP_MAX_NODES", "N", "nodes per job (default 100000)",
       [](ServeConfig& c, const std::string& v) {
         c.service.limits.max_nodes = static_cast<int>(integer(v, "--max-nodes", 1, 1LL << 30));
       }},
      {"max-steps", "GRIP_MAX_STEPS", "N", "load steps per job (default 10000)",
       [](ServeConfig& c, const std::string& v) {
         c.service.limits.max_steps = static_cast<int>(integer(v, "--max-steps", 1, 1LL << 30));
       }},
      {"max-iterations", "GRIP_MAX_ITERATIONS", "N", "contact iterations per job (default 1000000)",
       [](ServeConfig& c, const std::string& v) {
         c.service.limits.max_iterations = integer(v, "--max-iterations", 1, 1LL << 50);
       }},
      {"max-seconds", "GRIP_MAX_SECONDS", "S", "wall seconds per job run (default 3600)",
       [](ServeConfig& c, const std::string& v) { c.service.limits.max_seconds = real(v, "--max-seconds", 0.001); }},
      {"retain-jobs", "GRIP_RETAIN_JOBS", "N",
       "finished jobs kept; older ones are removed, dismissed first (default 10000; 0: all)",
       [](ServeConfig& c, const std::string& v) {
         c.service.retention.max_jobs = integer(v, "--retain-jobs", 0, 1LL << 40);
       }},
      {"retain-age", "GRIP_RETAIN_AGE", "S", "seconds a finished job is kept (default 0: no age bound)",
       [](ServeConfig& c, const std::string& v) { c.service.retention.max_age_seconds = real(v, "--retain-age", 0); }},
      {"retain-bytes", "GRIP_RETAIN_BYTES", "BYTES", "stored bytes of finished jobs kept (default 0: no size bound)",
       [](ServeConfig& c, const std::string& v) {
         c.service.retention.max_bytes = integer(v, "--retain-bytes", 0, 1LL << 50);
       }},
      {"prune-interval", "GRIP_PRUNE_INTERVAL", "S", "seconds between retention passes (default 60)",
       [](ServeConfig& c, const std::string& v) {
         c.service.prune_interval =
             std::chrono::milliseconds(static_cast<long long>(1000 * real(v, "--prune-interval", 0.05)));
       }},
      {"replica", "GRIP_REPLICA", "NAME", "this process's name in job leases (default host-pid-random)",
       [](ServeConfig& c, const std::string& v) { c.service.replica = v; }},
      {"lease", "GRIP_LEASE", "S", "a run unrenewed this long is taken over by another replica (default 10)",
       [](ServeConfig& c, const std::string& v) { c.service.lease_seconds = real(v, "--lease", 0.3); }},
      {"token", "GRIP_TOKEN", "TOKEN", "bearer token required on every route but /v1/health",
       [](ServeConfig& c, const std::string& v) {
         if (!v.empty()) c.http.token = v;
       }},
      {"grace", "GRIP_GRACE", "S", "SIGTERM: seconds running jobs may still finish (default 8)",
       [](ServeConfig& c, const std::string& v) { c.grace_seconds = real(v, "--grace", 0); }},
      {"heartbeat", "GRIP_HEARTBEAT", "S", "seconds between event-stream pings (default 15)",
       [](ServeConfig& c, const std::string& v) {
         c.http.heartbeat = std::chrono::milliseconds(static_cast<long long>(1000 * real(v, "--heartbeat", 0.1)));
       }},
      {"schemas", "GRIP_SCHEMAS", "DIR", "schemas and examples folder (default: found beside the binary)",
       [](ServeConfig& c, const std::string& v) { c.http.schemas_dir = v; }},
      {"log-format", "GRIP_LOG_FORMAT", "FORMAT", "text or json (one object a line, for log shippers; default text)",
       [](ServeConfig& c, const std::string& v) {
         if (v != "text" && v != "json") throw std::invalid_argument("--log-format: '" + v + "' is not text or json");
         c.log_format = v;
       }},
      {"log-level", "GRIP_LOG_LEVEL", "LEVEL", "trace, debug, info, warn, error (default info)",
       [](ServeConfig& c, const std::string& v) {
         if (spdlog::level::from_str(v) == spdlog::level::off && v != "off")
           throw std::invalid_argument("--log-level: '" + v + "' is not a level");
         c.log_level = v;
       }},
  };
  return list;
}

std::string find_schemas_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  std::vector<fs::path> candidates;
  if (!ec) {
    candidates.push_back(exe.parent_path() / "../../schemas");          // build/apps/grip
    candidates.push_back(exe.parent_path() / "../share/grip/schemas");  // installed
  }
  candidates.push_back("schemas");
  for (const auto& c : candidates)
    if (fs::is_directory(c / "examples", ec)) return fs::weakly_canonical(c, ec).string();
  return "schemas";
}

}  // namespace

std::string serve_usage() {
  std::string s = "usage: grip serve [options]   (each option also as its GRIP_* variable)\n";
  for (const Flag& f : flags()) {
    std::string left = std::string("  --") + f.name + " " + f.arg;
    left.resize(std::max<size_t>(left.size() + 1, 26), ' ');
    s += left + f.help + "  [" + f.env + "]\n";
  }
  return s;
}

ServeConfig read_serve_config(const std::vector<std::string>& args) {
  ServeConfig c;
  c.service.retention.max_jobs = 10000;  // the disk stays bounded unless asked otherwise
  for (const Flag& f : flags())
    if (const char* v = std::getenv(f.env)) f.set(c, v);
  for (size_t i = 0; i < args.size(); ++i) {
    std::string a = args[i], value;
    if (a.rfind("--", 0) != 0) throw std::invalid_argument("unexpected argument '" + a + "'");
    a = a.substr(2);
    const auto eq = a.find('=');
    bool has_value = false;
    if (eq != std::string::npos) {
      value = a.substr(eq + 1);
      a = a.substr(0, eq);
      has_value = true;
    }
    const Flag* flag = nullptr;
    for (const Flag& f : flags())
      if (a == f.name) flag = &f;
    if (!flag) throw std::invalid_argument("unknown option --" + a);
    if (!has_value) {
      if (i + 1 >= args.size()) throw std::invalid_argument("--" + a + " needs a value");
      value = args[++i];
    }
    flag->set(c, value);
  }
  if (c.http.schemas_dir.empty()) c.http.schemas_dir = find_schemas_dir();
  return c;
}

int serve(const ServeConfig& config) {
  setup_logging(config.log_format, config.log_level);
  // Two malloc arenas, not glibc's 8 per core: a thread per connection otherwise spreads what
  // large requests freed over arenas that keep it (8 hostile 6 MB scenes left 44 MB resident
  // against 25 MB with two; docs/limits.md#memory).
  mallopt(M_ARENA_MAX, 2);

  // Signals go to one thread only: block them before any thread starts.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);

  const ServeConfig& c = config;
  const FrontLimits& f = c.http.front;
  spdlog::info("grip serve: host {} port {} db {} workers {} queue {} streams {} http-threads {}", c.http.host,
               c.http.port, is_postgresql_url(c.db) ? redacted_url(c.db) : c.db,
               c.service.workers > 0 ? c.service.workers : static_cast<int>(std::thread::hardware_concurrency()),
               c.service.queue_capacity, c.http.max_streams, f.max_connections);
  spdlog::info("connections: {} per client, {} kept idle, head within {} s, body within {} s", f.per_client, f.max_idle,
               f.head.count() / 1000.0, f.body.count() / 1000.0);
  spdlog::info("limits: body {} bytes, mesh {} bytes, {} nodes, {} steps, {} contact iterations, {} s per job",
               c.http.max_body_bytes, c.http.max_mesh_bytes, c.service.limits.max_nodes, c.service.limits.max_steps,
               c.service.limits.max_iterations, c.service.limits.max_seconds);
  const Retention& keep = c.service.retention;
  spdlog::info("retention: {} finished jobs, {} s, {} bytes (0: no bound), every {} s; parse budget {} bytes",
               keep.max_jobs, keep.max_age_seconds, keep.max_bytes, c.service.prune_interval.count() / 1000.0,
               c.http.parse_budget_bytes ? c.http.parse_budget_bytes : c.http.max_body_bytes);
  spdlog::info("token {}, grace {} s, heartbeat {} s, schemas {}, log level {}",
               c.http.token ? "required" : "not required", c.grace_seconds, c.http.heartbeat.count() / 1000.0,
               c.http.schemas_dir, c.log_level);

  std::unique_ptr<Store> store;
  try {
    if (is_postgresql_url(c.db)) store = std::make_unique<PostgresStore>(c.db);
    else store = std::make_unique<SqliteStore>(c.db);
  } catch (const std::exception& e) {
    spdlog::critical("cannot open the job store: {}", e.what());
    return 1;
  }
  JobService service(*store, c.service);
  service.start();
  HttpServer http(service, c.http);
  int port = 0;
  try {
    port = http.bind();
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    service.shutdown(std::chrono::milliseconds(0));
    return 1;
  }
  spdlog::info("listening on http://{}:{}", c.http.host, port);

  std::atomic<bool> signalled{false};
  std::thread signal_thread([&] {
    int sig = 0;
    sigwait(&signals, &sig);
    signalled = true;
    spdlog::info("{}: stopping: no new jobs, closing streams", sig == SIGTERM ? "SIGTERM" : "SIGINT");
    // Jobs stay readable while the running ones use their grace period; HTTP stops after.
    service.shutdown(std::chrono::milliseconds(static_cast<long long>(c.grace_seconds * 1000)));
    http.stop();
  });
  http.listen();
  if (!signalled) {
    spdlog::error("the HTTP server stopped by itself");
    pthread_kill(signal_thread.native_handle(), SIGTERM);
  }
  signal_thread.join();
  spdlog::info("stopped");
  return signalled ? 0 : 1;
}

int healthcheck(const std::vector<std::string>& args) {
  std::string host = "127.0.0.1";
  int port = 8080;
  if (const char* p = std::getenv("GRIP_PORT")) port = std::atoi(p);
  for (size_t i = 0; i + 1 < args.size(); i += 2) {
    if (args[i] == "--host") host = args[i + 1];
    else if (args[i] == "--port") port = std::atoi(args[i + 1].c_str());
  }
  if (host == "0.0.0.0") host = "127.0.0.1";
  httplib::Client cli(host, port);
  cli.set_connection_timeout(3);
  cli.set_read_timeout(3);
  const auto res = cli.Get("/v1/health");
  if (res && res->status == 200) return 0;
  std::fprintf(stderr, "unhealthy: %s\n",
               res ? ("status " + std::to_string(res->status)).c_str() : httplib::to_string(res.error()).c_str());
  return 1;
}

}  // namespace grip::server
