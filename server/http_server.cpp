#include "server/http_server.hpp"

#include <spdlog/spdlog.h>

#include <sys/socket.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <thread>

#include "server/body_budget.hpp"
#include "server/compression.hpp"
#include "server/observability.hpp"
#include "server/studies.hpp"
#include "server/tar.hpp"
#include "server/ui.hpp"
#include "server/util.hpp"
#include "solver/io/export_csv.hpp"
#include "solver/io/export_vtk.hpp"
#include "solver/io/gmsh_mesh.hpp"
#include "solver/io/json_depth.hpp"
#include "solver/io/scene.hpp"

// After Eigen (through the solver's headers): httplib.h brings <resolv.h>, whose `_res`
// macro breaks Eigen's headers.
#include "server/http_front.hpp"

namespace grip::server {

using nlohmann::json;
using httplib::Request;
using httplib::Response;
namespace fs = std::filesystem;

namespace {

constexpr const char* kProcessId = "contact2d";
constexpr const char* kProblemJson = "application/problem+json";
constexpr const char* kJson = "application/json";
constexpr const char* kResultsRel = "http://www.opengis.net/def/rel/ogc/1.0/results";

thread_local std::chrono::steady_clock::time_point request_start;

// ---- responses

json error_list(std::string detail, std::string pointer = "") {
  return json::array({{{"pointer", std::move(pointer)}, {"detail", std::move(detail)}}});
}

// RFC 9457 problem details with grip's `errors[]` of {pointer, detail}.
constexpr const char* kBusyReadingScenes =
    "this server is reading as many scenes as its memory budget allows; nothing was accepted; retry after 5 s";

void problem(Response& res, const Request& req, int status, const std::string& slug, const std::string& title,
             const std::string& detail, json errors = nullptr) {
  if (errors.is_null() || errors.empty()) errors = error_list(detail);
  const json body = {{"type", "urn:grip:problem:" + slug},
                     {"title", title},
                     {"status", status},
                     {"detail", detail},
                     {"instance", req.path},
                     {"errors", errors}};
  res.status = status;
  // A parse error's message quotes the bytes it stopped at, which may not be UTF-8.
  res.set_content(body.dump(-1, ' ', false, json::error_handler_t::replace), kProblemJson);
}

void send_json(Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(body.dump(), kJson);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// A decimal integer >= 0, or nothing.
std::optional<std::int64_t> parse_count(const std::string& s) {
  if (s.empty() || s.size() > 18 || !std::all_of(s.begin(), s.end(), ::isdigit)) return std::nullopt;
  return std::stoll(s);
}

bool safe_name(const std::string& s) {
  return !s.empty() && s.size() < 100 && s[0] != '.' && std::all_of(s.begin(), s.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '-' || c == '_' || c == '.';
  });
}

std::optional<std::string> read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// Opaque list cursor: the creation order to continue below, hex with a version prefix.
std::string encode_cursor(std::int64_t before) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "c1%llx", static_cast<unsigned long long>(before));
  return buf;
}

std::optional<std::int64_t> decode_cursor(const std::string& c) {
  if (c.size() < 3 || c.size() > 18 || c.compare(0, 2, "c1") != 0) return std::nullopt;
  if (!std::all_of(c.begin() + 2, c.end(), ::isxdigit)) return std::nullopt;
  const unsigned long long v = std::stoull(c.substr(2), nullptr, 16);
  if (v > static_cast<unsigned long long>(std::numeric_limits<std::int64_t>::max())) return std::nullopt;
  return static_cast<std::int64_t>(v);
}

std::string job_path(const std::string& id) { return "/v1/jobs/" + id; }

// Accept-Encoding names `coding` (or *) without q=0.
bool accepts(const Request& req, std::string_view coding) {
  std::stringstream list(lower(req.get_header_value("Accept-Encoding")));
  std::string item;
  while (std::getline(list, item, ',')) {
    const size_t semi = item.find(';');
    std::string c = item.substr(0, semi), params = semi == std::string::npos ? "" : item.substr(semi + 1);
    c.erase(std::remove_if(c.begin(), c.end(), ::isspace), c.end());
    params.erase(std::remove_if(params.begin(), params.end(), ::isspace), params.end());
    const bool refused = params.rfind("q=0", 0) == 0 && params.find_first_of("123456789", 2) == std::string::npos;
    if ((c == coding || c == "*") && !refused) return true;
  }
  return false;
}

// The methods a known route takes (empty: no such route), for 405 + Allow.
std::string allowed_methods(const std::string& path) {
  static const std::vector<std::pair<std::regex, std::string>> routes = {
      {std::regex(R"(/v1/jobs)"), "GET, POST"},
      {std::regex(R"(/jobs)"), "GET"},
      {std::regex(R"(/(v1/)?jobs/[^/]+)"), "GET, DELETE"},
      {std::regex(R"(/(v1/)?jobs/[^/]+/(events|convergence|result|results))"), "GET"},
      {std::regex(R"(/(v1/)?processes/contact2d/execution)"), "POST"},
      {std::regex(R"(/|/conformance|/(v1/)?processes(/contact2d)?|/v1/(health|ready|metrics))"), "GET"},
      {std::regex(R"(/v1/(schemas|examples)(/[^/]+)?)"), "GET"},
      {std::regex(R"(/v1/meshes)"), "POST"},
      {std::regex(R"(/v1/studies)"), "POST"},
      {std::regex(R"(/v1/studies/[^/]+)"), "GET, DELETE"},
      {std::regex(R"(/v1/studies/[^/]+/events)"), "GET"},
      {std::regex(R"(/v1/meshes/[^/]+)"), "GET, DELETE"},
  };
  for (const auto& [pattern, methods] : routes)
    if (std::regex_match(path, pattern)) return methods;
  return "";
}

json job_document(const JobView& v) {
  const JobRecord& r = v.record;
  json doc = {
      {"jobID", r.id},        {"processID", kProcessId}, {"type", "process"},    {"status", to_string(r.status)},
      {"message", r.message}, {"created", r.created},    {"updated", r.updated}, {"nodes", r.nodes},
      {"steps", r.steps},     {"attempts", r.attempts}};
  if (!r.owner.empty()) doc["replica"] = r.owner;  // the process that runs (or last ran) it
  if (!r.started.empty()) doc["started"] = r.started;
  if (!r.finished.empty()) doc["finished"] = r.finished;
  // Converged steps: while running from the run's progress, once finished as stored.
  int completed = r.status == JobStatus::successful ? r.steps : r.steps_completed;
  if (v.progress) completed = v.progress->steps_done;
  doc["steps_completed"] = completed;
  const int percent = r.steps > 0 ? 100 * completed / r.steps : (r.status == JobStatus::successful ? 100 : 0);
  if (r.status == JobStatus::dismissed) doc["failure"] = {{"kind", "dismissed"}, {"message", r.message}, {"step", 0}};
  else if (r.status == JobStatus::failed && !r.failure_kind.empty())  // empty: failed before kinds were kept
    doc["failure"] = {{"kind", r.failure_kind}, {"message", r.message}, {"step", r.failure_step}};
  if (v.progress) {
    const Progress& p = *v.progress;
    doc["step"] = p.step;
    doc["contact_error"] = p.contact_error;
    doc["iterations"] = p.iterations;
    char msg[96];
    std::snprintf(msg, sizeof msg, "step %d of %d, ||v||_2 = %.3e", p.step, r.steps, p.contact_error);
    doc["message"] = msg;
  } else if (is_finished(r.status) && r.status != JobStatus::dismissed) {
    doc["iterations"] = r.iterations;
    doc["solve_seconds"] = r.solve_seconds;
  }
  if (is_finished(r.status) && r.stored_bytes > 0) doc["stored_bytes"] = r.stored_bytes;
  if (!r.request_id.empty()) doc["request_id"] = r.request_id;
  doc["progress"] = percent;
  const std::string self = job_path(r.id);
  json links = json::array({
      {{"href", self}, {"rel", "self"}, {"type", kJson}, {"title", "this job"}},
      {{"href", self + "/events"},
       {"rel", "monitor"},
       {"type", "text/event-stream"},
       {"title", "events: replayed, then live"}},
      {{"href", self + "/convergence"}, {"rel", "related"}, {"type", kJson}, {"title", "contact error history"}},
  });
  if (r.status == JobStatus::successful || r.status == JobStatus::failed)
    links.push_back({{"href", self + "/result"}, {"rel", kResultsRel}, {"type", kJson}, {"title", "result"}});
  doc["links"] = links;
  return doc;
}

// An uploaded mesh as the API answers it: id, sizes, when, and what the reader found.
json mesh_document(const MeshRecord& r, json summary) {
  json doc = {{"id", r.id}, {"bytes", r.bytes}, {"stored_bytes", r.stored}, {"created", r.created}};
  doc.update(summary);
  doc["links"] = json::array({{{"href", "/v1/meshes/" + r.id}, {"rel", "self"}, {"type", kJson}}});
  return doc;
}

}  // namespace

struct HttpServer::Impl {
  Impl(JobService& s, HttpOptions o, std::atomic<int>& streams)
      : service(s), studies(s), options(std::move(o)), open_streams(streams), svr(options.front),
        budget(options.parse_budget_bytes ? options.parse_budget_bytes : options.max_body_bytes) {}

  JobService& service;
  Studies studies;
  HttpOptions options;
  std::atomic<int>& open_streams;
  HttpFront svr;
  std::atomic<bool> stopping{false};
  RequestMetrics request_metrics;
  int listen_fd = -1;  // the listening socket, seen by the socket-options hook
  BodyBudget budget;   // submissions' bodies being read and checked

  // Registers a handler for every path pattern given.
  template <class F>
  void get(std::initializer_list<const char*> patterns, F handler) {
    for (const char* p : patterns) svr.Get(p, handler);
  }

  void routes();
  void hooks();
  // The most a request's body may hold: --max-mesh for an upload, --max-body for the other
  // POSTs, the larger of the two for the rest (httplib's payload limit).
  std::size_t body_limit(const Request& req) const;
  // A declared Content-Length over body_limit: the 413 at once, before any of the body is
  // read (to a client that sent Expect: 100-continue, instead of the 100); the connection
  // then closes after dropping the body (bounded: server/http_front.hpp). True if answered.
  bool refuse_declared_body(const Request& req, Response& res);
  // The request announced a body that has not been read to its end.
  bool body_unread(const Request& req) const;
  // An answer given with the request's body unread (before it, as a 401 or a 413, or without
  // it, as to a GET with a body): it says `Connection: close`, and what the client sends of the
  // body is read and dropped within bounds (server/http_front.hpp) before the connection
  // closes, so that none of it is read as a request.
  void close_with_body_unread(const Request& req, Response& res);

  // ---- handlers
  void submit(const Request& req, Response& res, const httplib::ContentReader& reader, bool ogc);
  // Reads the body, up to `limit` bytes, into `text`; false after answering 413, 408 or 400.
  bool read_body(const Request& req, Response& res, const httplib::ContentReader& reader, std::size_t limit,
                 std::string& text);
  // read_body, then the body as JSON (`what` names it in a 415); false after answering 4xx.
  bool read_json_body(const Request& req, Response& res, const httplib::ContentReader& reader, const char* what,
                      json& body);
  // 422 with every issue's pointer (under `prefix`): an invalid `what` (scene, study).
  void invalid(const Request& req, Response& res, const SceneErrors& e, const std::string& prefix,
               const std::string& what);
  void submit_study(const Request& req, Response& res, const httplib::ContentReader& reader);
  // The body's share of the memory budget (server/body_budget.hpp): its declared length, at most
  // `limit`, waited for up to 2 minutes; else a 503 with Retry-After saying `busy`, and none.
  std::optional<BodyBudget::Hold> take_budget(const Request& req, Response& res, std::size_t limit,
                                              const std::string& busy);
  void get_study(const Request& req, Response& res);
  // The study's table as Server-Sent Events: `study` each time it changes, `study_finished` last.
  void study_events(const Request& req, Response& res);
  void remove_study(const Request& req, Response& res);
  void upload_mesh(const Request& req, Response& res, const httplib::ContentReader& reader);
  void get_mesh(const Request& req, Response& res);
  void remove_mesh(const Request& req, Response& res);
  void list_jobs(const Request& req, Response& res);
  void get_job(const Request& req, Response& res);
  void dismiss(const Request& req, Response& res);
  void events(const Request& req, Response& res);
  void convergence(const Request& req, Response& res);
  void result(const Request& req, Response& res);
  void metrics(const Request& req, Response& res);
  void process_description(const Request& req, Response& res);
  void file_list(const Request& req, Response& res, const fs::path& dir, const std::string& suffix,
                 const std::string& route);
  void file(const Request& req, Response& res, const fs::path& dir, const std::string& suffix);

  void not_found_job(const Request& req, Response& res, const std::string& id) {
    problem(res, req, 404, "job-not-found", "Job not found", "no job with id '" + id + "'");
  }
};

std::size_t HttpServer::Impl::body_limit(const Request& req) const {
  if (req.path == "/v1/meshes") return options.max_mesh_bytes;
  if (req.method == "POST") return options.max_body_bytes;
  return std::max(options.max_body_bytes, options.max_mesh_bytes);
}

bool HttpServer::Impl::refuse_declared_body(const Request& req, Response& res) {
  const std::size_t limit = body_limit(req);
  const auto declared = parse_count(req.get_header_value("Content-Length"));
  if (!declared || static_cast<std::uint64_t>(*declared) <= limit) return false;
  close_with_body_unread(req, res);
  problem(res, req, 413, "payload-too-large", "Payload too large",
          "the request body (Content-Length " + std::to_string(*declared) + ") is over this server's limit of " +
              std::to_string(limit) + " bytes");
  return true;
}

bool HttpServer::Impl::body_unread(const Request& req) const {
  const ConnectionNote* note = HttpFront::note();
  if (!note) return false;
  // Chunked (httplib reads chunks whatever the Content-Length says): unread until read_body
  // saw its end; with a Content-Length as well, never taken as read (RFC 9112 6.3).
  if (req.has_header("Transfer-Encoding")) return !note->body_complete || req.has_header("Content-Length");
  if (!req.has_header("Content-Length")) return false;
  const auto declared = parse_count(req.get_header_value("Content-Length"));
  return !declared || note->body_read < static_cast<std::uint64_t>(*declared);  // unreadable: not read
}

void HttpServer::Impl::close_with_body_unread(const Request& req, Response& res) {
  res.headers.erase("Keep-Alive");  // httplib's, when it meant to keep the connection
  res.headers.erase("Connection");
  res.set_header("Connection", "close");
  ConnectionNote* note = HttpFront::note();
  if (!note) return;
  note->close = true;
  if (note->deadline_missed) return;  // the body had its time: closed without waiting more
  const auto declared = parse_count(req.get_header_value("Content-Length"));
  if (req.has_header("Transfer-Encoding")) note->discard = body_limit(req);  // no length known: up to the route's limit
  else if (declared)
    note->discard = static_cast<std::uint64_t>(*declared) - std::min<std::uint64_t>(*declared, note->body_read);
}

void HttpServer::Impl::hooks() {
  // Threads, deadlines and limits per connection: HttpFront (server/http_front.hpp).
  // The larger of the two: each route holds its own limit (read_body).
  svr.set_payload_max_length(std::max(options.max_body_bytes, options.max_mesh_bytes));
  svr.set_tcp_nodelay(true);  // events are small writes: no Nagle delay
  // Instead of the default options: SO_REUSEADDR only (the default's SO_REUSEPORT would let a
  // second server bind the same port unnoticed), and the socket kept so that bind() can
  // deepen the listen backlog, which httplib 0.11.4 fixes at 5: a burst of connections beyond
  // it loses connections.
  svr.set_socket_options([this](socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    if (listen_fd < 0) listen_fd = sock;
  });

  // A client that asks before it sends its body: 100, or the 413 when it announced too much.
  svr.set_expect_100_continue_handler([this](const Request& req, Response& res) {
    request_start = std::chrono::steady_clock::now();
    res.set_header("X-Request-Id", request_id_for(req.get_header_value("X-Request-Id")));
    return refuse_declared_body(req, res) ? 413 : 100;
  });

  svr.set_pre_routing_handler([this](const Request& req, Response& res) {
    // Set already when the expect handler answered 100.
    if (!res.has_header("X-Request-Id")) {
      request_start = std::chrono::steady_clock::now();
      // Echoed in the answer, logged, and attached to a job it creates.
      res.set_header("X-Request-Id", request_id_for(req.get_header_value("X-Request-Id")));
    }
    ConnectionNote* note = HttpFront::note();
    if (note && note->overflow && req.path != "/v1/health" && req.path != "/v1/ready") {
      res.set_header("Retry-After", "1");
      problem(res, req, 503, "server-busy", "Server busy",
              "every connection this server serves at once (" + std::to_string(options.front.max_connections) +
                  ") is taken; only /v1/health and /v1/ready are answered; retry later");
      return httplib::Server::HandlerResponse::Handled;
    }
    // A body of unknown length would be read until the client closes (curl -X POST without
    // data held a thread for 10 s).
    if ((req.method == "POST" || req.method == "PUT" || req.method == "PATCH") && !req.has_header("Content-Length") &&
        !req.has_header("Transfer-Encoding")) {
      close_with_body_unread(req, res);
      problem(res, req, 411, "length-required", "Length required",
              req.method + " needs a Content-Length (or Transfer-Encoding: chunked)");
      return httplib::Server::HandlerResponse::Handled;
    }
    // Answered before the body is read: a client that reads while it sends (curl, browsers)
    // stops at once, and the body is dropped 64 KiB at a time rather than through httplib's
    // 4 KiB reads.
    if (refuse_declared_body(req, res)) return httplib::Server::HandlerResponse::Handled;
    if (!options.token || req.path == "/v1/health" || is_page_request(req))
      return httplib::Server::HandlerResponse::Unhandled;
    const std::string auth = req.get_header_value("Authorization");
    const std::string prefix = "Bearer ";
    if (auth.size() > prefix.size() && lower(auth.substr(0, prefix.size())) == "bearer " &&
        equal_constant_time(auth.substr(prefix.size()), *options.token))
      return httplib::Server::HandlerResponse::Unhandled;
    res.set_header("WWW-Authenticate", "Bearer realm=\"grip\"");
    problem(res, req, 401, "unauthorized", "Unauthorized",
            auth.empty() ? "this server requires a bearer token (Authorization: Bearer ...)"
                         : "the bearer token is not valid");
    return httplib::Server::HandlerResponse::Handled;
  });

  // Every answer, written after this: one whose request body was not read to its end (a 401 or
  // a 503 answered before it, a body on a GET or HEAD, which httplib never reads, a chunked
  // body that broke off) closes the connection as the 413 does, the rest of the body dropped:
  // else its bytes were read as the connection's next request.
  svr.set_post_routing_handler([this](const Request& req, Response& res) {
    if (body_unread(req)) close_with_body_unread(req, res);
  });

  // Errors that no handler described (unknown route, 413, unreadable request): a problem
  // document. Bodies a handler already set are left alone.
  svr.set_error_handler(httplib::Server::HandlerWithResponse([this](const Request& req, Response& res) {
    if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
    // What the connection ran into says more than httplib's status (400 for all of these).
    if (const ConnectionNote* note = HttpFront::note()) {
      const auto& front = options.front;
      if (res.status == 400 && note->deadline_missed) {
        res.set_header("Connection", "close");
        problem(res, req, 408, "request-timeout", "Request timeout",
                note->in_body ? "the request body did not arrive within " + std::to_string(front.body.count()) + " ms"
                              : "the request head did not arrive within " + std::to_string(front.head.count()) + " ms");
        spdlog::warn("{}: 408: request {} too slow", note->client, note->in_body ? "body" : "head");
        return httplib::Server::HandlerResponse::Handled;
      }
      if (res.status == 400 && (note->head_too_large || note->line_too_long)) {
        res.set_header("Connection", "close");
        problem(
            res, req, 431, "header-too-large", "Request header fields too large",
            note->head_too_large
                ? "the request head is over this server's limit of " + std::to_string(HttpFront::kMaxHead) + " bytes"
                : "a header line is over this server's limit of " + std::to_string(HttpFront::kMaxLine) + " bytes");
        spdlog::warn("{}: 431: request head over its limit", note->client);
        return httplib::Server::HandlerResponse::Handled;
      }
    }
    switch (res.status) {
      case 404: {
        // A known route asked with another method: 405 and the methods it takes.
        const std::string allow = allowed_methods(req.path);
        if (!allow.empty()) {
          res.set_header("Allow", allow);
          problem(res, req, 405, "method-not-allowed", "Method not allowed",
                  req.method + " is not allowed on " + req.path + "; allowed: " + allow);
          break;
        }
        problem(res, req, 404, "not-found", "Not found", "no route " + req.method + " " + req.path);
        break;
      }
      case 413:
        problem(res, req, 413, "payload-too-large", "Payload too large",
                "the request body is over this server's limit");
        break;
      case 414:
        problem(res, req, 414, "uri-too-long", "URI too long",
                "the request line is over this server's limit of " + std::to_string(HttpFront::kMaxLine) + " bytes");
        spdlog::warn("{}: 414: request line over its limit", req.remote_addr);
        break;
      default:
        problem(res, req, res.status, "http-" + std::to_string(res.status),
                res.status < 500 ? "Bad request" : "Server error",
                "the request could not be served (" + std::to_string(res.status) + ")");
    }
    return httplib::Server::HandlerResponse::Handled;
  }));

  svr.set_exception_handler([](const Request& req, Response& res, std::exception_ptr ep) {
    std::string what = "unknown exception";
    struct KeepId {  // the headers are cleared below; the request id stays
      Response& res;
      const std::string id = res.get_header_value("X-Request-Id");
      ~KeepId() {
        if (!id.empty() && !res.has_header("X-Request-Id")) res.set_header("X-Request-Id", id);
      }
    } keep{res};
    try {
      std::rethrow_exception(ep);
    } catch (const StoreUnavailable& e) {
      spdlog::warn("{} {}: {}", req.method, req.path, e.what());
      res.headers.clear();
      res.set_header("Retry-After", "5");
      return problem(res, req, 503, "database-unavailable", "Database unavailable",
                     "the job database does not answer; nothing was changed; retry later");
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    spdlog::error("{} {}: {}", req.method, req.path, what);
    res.headers.clear();
    problem(res, req, 500, "internal-error", "Internal server error",
            "the server failed to answer this request; it has been logged");
  });

  svr.set_logger([this](const Request& req, const Response& res) {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - request_start).count();
    request_metrics.record(req.method, route_template(req.path), res.status, seconds);
    const bool quiet = req.path == "/v1/health" || req.path == "/v1/ready" || req.path == "/v1/metrics";
    const std::string id = res.get_header_value("X-Request-Id");
    spdlog::log(quiet ? spdlog::level::debug : spdlog::level::info, "{} {} {} {:.1f} ms request {} client {}",
                req.method, req.path, res.status, 1000 * seconds, id.empty() ? "-" : id, req.remote_addr);
  });
}

void HttpServer::Impl::routes() {
  // ---- service
  svr.Get("/v1/health", [](const Request&, Response& res) { send_json(res, 200, {{"status", "ok"}}); });
  // Browsers ask for it on every page load; the page names no icon.
  svr.Get("/favicon.ico", [](const Request&, Response& res) {
    res.status = 204;
    res.set_header("Cache-Control", "public, max-age=86400");
  });
  svr.Get("/v1/ready", [this](const Request& req, Response& res) {
    if (!service.ready()) {
      res.set_header("Retry-After", "5");
      return problem(res, req, 503, "not-ready", "Not ready",
                     service.draining() ? "the server is shutting down"
                                        : "the server is starting or its database does not answer");
    }
    send_json(res, 200, {{"status", "ready"}, {"replica", service.replica()}});
  });
  svr.Get("/v1/metrics", [this](const Request& req, Response& res) { metrics(req, res); });

  // ---- landing page and OGC API - Processes
  svr.Get("/", [](const Request& req, Response& res) {
    res.set_header("Vary", "Accept");
    if (wants_page(req) && serve_page_file(req, res, "index.html")) return;
    send_json(res, 200,
              {{"title", "grip"},
               {"description", "2D frictional contact solver service (contact error vector scheme)"},
               {"links",
                json::array({{{"href", "/"}, {"rel", "self"}, {"type", kJson}},
                             {{"href", "/conformance"}, {"rel", "http://www.opengis.net/def/rel/ogc/1.0/conformance"}},
                             {{"href", "/processes"}, {"rel", "http://www.opengis.net/def/rel/ogc/1.0/processes"}},
                             {{"href", "/jobs"}, {"rel", "http://www.opengis.net/def/rel/ogc/1.0/job-list"}}})}});
  });
  // ---- the browser page (server/ui.hpp)
  svr.Get("/ui", [](const Request& req, Response& res) { serve_page_file(req, res, "index.html"); });
  svr.Get(R"(/ui/([^/]+))", [](const Request& req, Response& res) {
    if (!serve_page_file(req, res, req.matches[1]))
      problem(res, req, 404, "not-found", "Not found", "the page has no file '" + req.matches[1].str() + "'");
  });
  svr.Get("/conformance", [](const Request&, Response& res) {
    send_json(res, 200,
              {{"conformsTo",
                {"http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/core",
                 "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/json",
                 "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/job-list",
                 "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/dismiss"}}});
  });
  get({"/processes", "/v1/processes"}, [](const Request&, Response& res) {
    send_json(res, 200,
              {{"processes",
                {{{"id", kProcessId},
                  {"title", "2D frictional contact"},
                  {"version", "0.1.0"},
                  {"jobControlOptions", {"async-execute"}},
                  {"outputTransmission", {"value"}},
                  {"links", {{{"href", "/processes/contact2d"}, {"rel", "self"}, {"type", kJson}}}}}}},
               {"links", {{{"href", "/processes"}, {"rel", "self"}, {"type", kJson}}}}});
  });
  get({"/processes/contact2d", "/v1/processes/contact2d"},
      [this](const Request& req, Response& res) { process_description(req, res); });
  for (const char* p : {"/processes/contact2d/execution", "/v1/processes/contact2d/execution"})
    svr.Post(p, [this](const Request& req, Response& res, const httplib::ContentReader& reader) {
      submit(req, res, reader, true);
    });

  // ---- jobs
  svr.Post("/v1/jobs", [this](const Request& req, Response& res, const httplib::ContentReader& reader) {
    submit(req, res, reader, false);
  });
  get({"/v1/jobs", "/jobs"}, [this](const Request& req, Response& res) { list_jobs(req, res); });
  get({R"(/v1/jobs/([^/]+))", R"(/jobs/([^/]+))"}, [this](const Request& req, Response& res) { get_job(req, res); });
  svr.Delete(R"(/v1/jobs/([^/]+))", [this](const Request& req, Response& res) { dismiss(req, res); });
  svr.Delete(R"(/jobs/([^/]+))", [this](const Request& req, Response& res) { dismiss(req, res); });
  get({R"(/v1/jobs/([^/]+)/events)", R"(/jobs/([^/]+)/events)"},
      [this](const Request& req, Response& res) { events(req, res); });
  get({R"(/v1/jobs/([^/]+)/convergence)", R"(/jobs/([^/]+)/convergence)"},
      [this](const Request& req, Response& res) { convergence(req, res); });
  get({R"(/v1/jobs/([^/]+)/result)", R"(/jobs/([^/]+)/results?)"},
      [this](const Request& req, Response& res) { result(req, res); });

  // ---- studies
  svr.Post("/v1/studies", [this](const Request& req, Response& res, const httplib::ContentReader& reader) {
    submit_study(req, res, reader);
  });
  svr.Get(R"(/v1/studies/([^/]+))", [this](const Request& req, Response& res) { get_study(req, res); });
  svr.Get(R"(/v1/studies/([^/]+)/events)", [this](const Request& req, Response& res) { study_events(req, res); });
  svr.Delete(R"(/v1/studies/([^/]+))", [this](const Request& req, Response& res) { remove_study(req, res); });

  // ---- uploaded meshes
  svr.Post("/v1/meshes", [this](const Request& req, Response& res, const httplib::ContentReader& reader) {
    upload_mesh(req, res, reader);
  });
  svr.Get(R"(/v1/meshes/([^/]+))", [this](const Request& req, Response& res) { get_mesh(req, res); });
  svr.Delete(R"(/v1/meshes/([^/]+))", [this](const Request& req, Response& res) { remove_mesh(req, res); });

  // ---- schemas and examples
  const fs::path schemas = options.schemas_dir;
  svr.Get("/v1/schemas", [this, schemas](const Request& req, Response& res) {
    file_list(req, res, schemas, ".schema.json", "/v1/schemas/");
  });
  svr.Get(R"(/v1/schemas/([^/]+))",
          [this, schemas](const Request& req, Response& res) { file(req, res, schemas, ".schema.json"); });
  svr.Get("/v1/examples", [this, schemas](const Request& req, Response& res) {
    file_list(req, res, schemas / "examples", ".json", "/v1/examples/");
  });
  // An example's mesh file (body.mesh.gmsh {"file"}): what the page and the client upload for it.
  svr.Get(R"(/v1/examples/([^/]+\.msh))",
          [this, schemas](const Request& req, Response& res) { file(req, res, schemas / "examples", ".msh"); });
  svr.Get(R"(/v1/examples/([^/]+))",
          [this, schemas](const Request& req, Response& res) { file(req, res, schemas / "examples", ".json"); });
}

void HttpServer::Impl::submit(const Request& req, Response& res, const httplib::ContentReader& reader, bool ogc) {
  // Held until the answer is built (destroyed last).
  const auto hold = take_budget(req, res, options.max_body_bytes, kBusyReadingScenes);
  if (!hold) return;
  json body;
  if (!read_json_body(req, res, reader, "a scene", body)) return;
  // OGC execute request: {"inputs": {"scene": {...}}} (or the scene's fields as inputs).
  std::string prefix;
  json scene = std::move(body);
  if (ogc && scene.is_object() && scene.contains("inputs") && scene["inputs"].is_object()) {
    json inputs = scene["inputs"];
    if (inputs.contains("scene")) {
      scene = inputs["scene"];
      prefix = "/inputs/scene";
    } else {
      scene = std::move(inputs);
      prefix = "/inputs";
    }
  }
  std::optional<std::string> key;
  if (req.has_header("Idempotency-Key")) {
    key = req.get_header_value("Idempotency-Key");
    if (key->empty() || key->size() > 255)
      return problem(res, req, 400, "bad-idempotency-key", "Bad Idempotency-Key",
                     "Idempotency-Key must have 1 to 255 characters");
  }
  try {
    const SubmitResult r = service.submit(scene, key, res.get_header_value("X-Request-Id"));
    res.set_header("Location", job_path(r.job.record.id));
    if (r.replayed) res.set_header("Idempotent-Replayed", "true");
    send_json(res, 201, job_document(r.job));
  } catch (const SceneErrors& e) {
    invalid(req, res, e, prefix, "scene");
  } catch (const QueueFull& e) {
    res.set_header("Retry-After", std::to_string(e.retry_after_seconds));
    problem(res, req, 503, "queue-full", "Queue full",
            "the job queue is full; nothing was accepted; retry after " + std::to_string(e.retry_after_seconds) + " s");
  } catch (const ShuttingDown&) {
    res.set_header("Retry-After", "10");
    problem(res, req, 503, "shutting-down", "Shutting down", "the server is shutting down; nothing was accepted");
  } catch (const IdempotencyConflict& e) {
    problem(res, req, 422, "idempotency-key-reused", "Idempotency-Key reused", e.what());
  }
}

bool HttpServer::Impl::read_json_body(const Request& req, Response& res, const httplib::ContentReader& reader,
                                      const char* what, json& body) {
  std::string text;
  if (!read_body(req, res, reader, options.max_body_bytes, text)) return false;
  const std::string type = lower(req.get_header_value("Content-Type"));
  const std::string media = type.substr(0, type.find(';'));
  auto trimmed = media;
  trimmed.erase(std::remove_if(trimmed.begin(), trimmed.end(), ::isspace), trimmed.end());
  if (trimmed != "application/json" && !(trimmed.size() > 5 && trimmed.compare(trimmed.size() - 5, 5, "+json") == 0)) {
    res.set_header("Accept-Post", "application/json");
    problem(res, req, 415, "unsupported-media-type", "Unsupported media type",
            std::string(what) + " is submitted as application/json, not '" +
                (media.empty() ? std::string("(none)") : media) + "'");
    return false;
  }
  if (nested_deeper_than(text, kMaxJsonDepth)) {
    problem(res, req, 400, "malformed-json", "Malformed JSON",
            "arrays and objects are nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    return false;
  }
  try {
    body = json::parse(text);
  } catch (const json::parse_error& e) {
    problem(res, req, 400, "malformed-json", "Malformed JSON", "the body is not JSON: " + std::string(e.what()),
            error_list("parse error at byte " + std::to_string(e.byte) + ": " + e.what()));
    return false;
  } catch (const json::exception& e) {  // a number out of range (1e400): out_of_range.406
    problem(res, req, 400, "malformed-json", "Malformed JSON",
            "the body is not JSON that this server can read: " + std::string(e.what()));
    return false;
  }
  return true;
}

bool HttpServer::Impl::read_body(const Request& req, Response& res, const httplib::ContentReader& reader,
                                 std::size_t limit, std::string& text) {
  if (ConnectionNote* note = HttpFront::note(); note && note->restart_body_deadline) note->restart_body_deadline();
  // The body is read here: httplib 0.11.4 holds a body to the payload limit only when it has
  // a Content-Length (a chunked one of 100 MB was buffered whole). Past the limit the rest is
  // read and dropped, as httplib does with a long Content-Length, so the client gets its 413.
  bool too_large = false;
  const bool complete = reader([&](const char* data, size_t n) {
    if (!too_large && text.size() + n > limit) {
      too_large = true;
      std::string().swap(text);
    }
    if (!too_large) text.append(data, n);
    return true;
  });
  if (ConnectionNote* note = HttpFront::note()) note->body_complete = complete;
  if (too_large || res.status == 413) {
    problem(res, req, 413, "payload-too-large", "Payload too large",
            "the request body is over this server's limit of " + std::to_string(limit) + " bytes");
    return false;
  }
  if (!complete) {
    if (const ConnectionNote* note = HttpFront::note(); note && note->deadline_missed) {
      res.set_header("Connection", "close");
      problem(res, req, 408, "request-timeout", "Request timeout",
              "the request body did not arrive within " + std::to_string(options.front.body.count()) + " ms");
      return false;
    }
    problem(res, req, 400, "unreadable-body", "Unreadable body", "the request body could not be read");
    return false;
  }
  return true;
}

void HttpServer::Impl::upload_mesh(const Request& req, Response& res, const httplib::ContentReader& reader) {
  const std::string type = lower(req.get_header_value("Content-Type"));
  std::string media = type.substr(0, type.find(';'));
  media.erase(std::remove_if(media.begin(), media.end(), ::isspace), media.end());
  if (media != "application/octet-stream" && media != "text/plain") {
    reader([](const char*, size_t) { return true; });  // drained unkept: the connection stays in step
    res.set_header("Accept-Post", "application/octet-stream, text/plain");
    return problem(res, req, 415, "unsupported-media-type", "Unsupported media type",
                   "a mesh is uploaded as the .msh file's bytes, application/octet-stream or text/plain, not '" +
                       (media.empty() ? std::string("(none)") : media) + "'");
  }
  // Reading a mesh takes some 3 times its file (the file, the reader's arrays, the compressed copy).
  const auto hold = take_budget(req, res, options.max_mesh_bytes,
                                "this server is reading as many bodies as its memory budget allows; nothing was "
                                "stored; retry after 5 s");
  if (!hold) return;
  std::string bytes;
  if (!read_body(req, res, reader, options.max_mesh_bytes, bytes)) return;
  MeshLibrary::Upload up;
  try {
    up = service.meshes().upload(bytes);
  } catch (const GmshError& e) {
    return problem(res, req, 422, "invalid-mesh", "Invalid mesh", e.what(), error_list(e.what(), ""));
  }
  json doc = mesh_document(up.record, std::move(up.summary));
  res.set_header("Location", "/v1/meshes/" + up.record.id);
  send_json(res, up.created ? 201 : 200, doc);
}

void HttpServer::Impl::invalid(const Request& req, Response& res, const SceneErrors& e, const std::string& prefix,
                               const std::string& what) {
  // Listed up to a bound: 8 MB of equal nodes made a million errors, a 99 MB answer and a
  // peak of 1.9 GB.
  // The reader and the validator stop at kMaxSceneIssues (more() then).
  constexpr size_t kMaxListed = kMaxSceneIssues;
  const auto& issues = e.issues();
  json errors = json::array();
  for (size_t i = 0; i < std::min(issues.size(), kMaxListed); ++i)
    errors.push_back(
        {{"pointer", prefix + (issues[i].pointer == "/" ? "" : issues[i].pointer)}, {"detail", issues[i].detail}});
  const size_t listed = std::min(issues.size(), kMaxListed);
  std::string title = "Invalid " + what;
  problem(res, req, 422, "invalid-" + what, title,
          e.more()
              ? "more than " + std::to_string(listed) + " problems in the " + what + "; the first " +
                    std::to_string(listed) + " found are listed"
              : std::to_string(issues.size()) + " problem(s) in the " + what +
                    (issues.size() > kMaxListed ? "; the first " + std::to_string(kMaxListed) + " are listed" : ""),
          std::move(errors));
}

std::optional<BodyBudget::Hold> HttpServer::Impl::take_budget(const Request& req, Response& res, std::size_t limit,
                                                              const std::string& busy) {
  const auto declared = parse_count(req.get_header_value("Content-Length"));
  auto hold = budget.take(std::min<std::size_t>(declared.value_or(limit), limit), std::chrono::seconds(120));
  if (!hold) {
    res.set_header("Retry-After", "5");
    problem(res, req, 503, "busy", "Busy", busy);
  }
  return hold;
}

void HttpServer::Impl::submit_study(const Request& req, Response& res, const httplib::ContentReader& reader) {
  const auto hold = take_budget(req, res, options.max_body_bytes, kBusyReadingScenes);
  if (!hold) return;
  json body;
  if (!read_json_body(req, res, reader, "a study", body)) return;
  try {
    const json doc = studies.submit(body, res.get_header_value("X-Request-Id"));
    res.set_header("Location", "/v1/studies/" + doc["id"].get<std::string>());
    send_json(res, 201, doc);
  } catch (const SceneErrors& e) {
    invalid(req, res, e, "", "study");
  } catch (const QueueFull& e) {
    res.set_header("Retry-After", std::to_string(e.retry_after_seconds));
    problem(res, req, 503, "queue-full", "Queue full",
            "the job queue has no room for the study's levels; nothing was accepted; retry after " +
                std::to_string(e.retry_after_seconds) + " s");
  } catch (const ShuttingDown&) {
    res.set_header("Retry-After", "10");
    problem(res, req, 503, "shutting-down", "Shutting down", "the server is shutting down; nothing was accepted");
  }
}

void HttpServer::Impl::get_study(const Request& req, Response& res) {
  const std::string id = req.matches[1];
  const auto doc = studies.study(id);
  if (!doc) return problem(res, req, 404, "study-not-found", "Study not found", "no study has id '" + id + "'");
  const std::string format = req.has_param("format") ? req.get_param_value("format") : "json";
  if (format == "csv") {
    res.set_header("Content-Disposition", "attachment; filename=\"study-" + id + ".csv\"");
    res.set_content(objects_csv(study_rows(*doc)), "text/csv; charset=utf-8");
    return;
  }
  if (format != "json")
    return problem(res, req, 400, "bad-parameter", "Bad query parameter", "format must be json or csv");
  send_json(res, 200, *doc);
}

void HttpServer::Impl::study_events(const Request& req, Response& res) {
  const std::string id = req.matches[1];
  if (!studies.study(id))
    return problem(res, req, 404, "study-not-found", "Study not found", "no study has id '" + id + "'");
  if (service.draining()) {
    res.set_header("Retry-After", "10");
    return problem(res, req, 503, "shutting-down", "Shutting down", "the server is shutting down");
  }
  if (open_streams.fetch_add(1) >= options.max_streams) {  // counted with the jobs' streams
    --open_streams;
    res.set_header("Retry-After", "5");
    return problem(res, req, 503, "too-many-streams", "Too many event streams",
                   "this server has " + std::to_string(options.max_streams) +
                       " event streams open; retry later or poll the study");
  }
  struct State {
    std::string last;  // the table last sent
    std::int64_t seq = 0;
    std::chrono::steady_clock::time_point last_write;
  };
  auto state = std::make_shared<State>();
  state->last_write = std::chrono::steady_clock::now();
  res.set_header("Cache-Control", "no-cache");
  res.set_header("X-Accel-Buffering", "no");
  const auto heartbeat = options.heartbeat;
  res.set_chunked_content_provider(
      "text/event-stream",
      [this, id, state, heartbeat](size_t, httplib::DataSink& sink) {
        if (stopping || service.draining()) {
          sink.done();
          return true;
        }
        if (!sink.is_writable()) return false;
        // The table is read from the jobs (server/studies.hpp); a look every 500 ms at most.
        if (state->seq > 0) std::this_thread::sleep_for(std::chrono::milliseconds(500));
        const auto doc = studies.study(id);
        if (!doc) {  // removed meanwhile
          sink.done();
          return true;
        }
        const std::string text = doc->dump();
        const std::string status = (*doc)["status"];
        const bool ended = status != "accepted" && status != "running";
        std::string out;
        if (text != state->last) {
          out = "id: " + std::to_string(++state->seq) + "\nevent: " + (ended ? "study_finished" : "study") +
                "\ndata: " + text + "\n\n";
          state->last = text;
        }
        const auto now = std::chrono::steady_clock::now();
        if (out.empty() && now - state->last_write >= heartbeat) out = ": ping\n\n";
        if (!out.empty()) {
          if (!sink.write(out.data(), out.size())) return false;
          state->last_write = now;
        }
        if (ended) sink.done();
        return true;
      },
      [this](bool) { --open_streams; });
}

void HttpServer::Impl::remove_study(const Request& req, Response& res) {
  const std::string id = req.matches[1];
  if (!studies.remove(id))
    return problem(res, req, 404, "study-not-found", "Study not found", "no study has id '" + id + "'");
  res.status = 204;
}

void HttpServer::Impl::get_mesh(const Request& req, Response& res) {
  const std::string id = req.matches[1];
  const auto rec = service.meshes().find(id);
  if (!rec) return problem(res, req, 404, "mesh-not-found", "Mesh not found", "no uploaded mesh has id '" + id + "'");
  send_json(res, 200, mesh_document(*rec, json::parse(rec->summary)));
}

void HttpServer::Impl::remove_mesh(const Request& req, Response& res) {
  const std::string id = req.matches[1];
  switch (service.meshes().remove(id)) {
    case MeshRemoval::not_found:
      return problem(res, req, 404, "mesh-not-found", "Mesh not found", "no uploaded mesh has id '" + id + "'");
    case MeshRemoval::in_use:
      return problem(res, req, 409, "mesh-in-use", "Mesh in use",
                     "a stored job uses mesh '" + id + "'; remove its jobs first (DELETE /v1/jobs/{id})");
    case MeshRemoval::removed:
      res.status = 204;
  }
}

void HttpServer::Impl::list_jobs(const Request& req, Response& res) {
  std::optional<JobStatus> status;
  int limit = 50;
  std::optional<std::int64_t> before;
  if (req.has_param("status")) {
    status = parse_job_status(req.get_param_value("status"));
    if (!status)
      return problem(res, req, 400, "bad-parameter", "Bad query parameter",
                     "status must be accepted, running, successful, failed or dismissed");
  }
  if (req.has_param("limit")) {
    const auto n = parse_count(req.get_param_value("limit"));
    if (!n || *n < 1 || *n > 1000)
      return problem(res, req, 400, "bad-parameter", "Bad query parameter", "limit must be an integer from 1 to 1000");
    limit = static_cast<int>(*n);
  }
  if (req.has_param("cursor")) {
    before = decode_cursor(req.get_param_value("cursor"));
    if (!before)
      return problem(res, req, 400, "bad-parameter", "Bad query parameter", "cursor is not one this server gave out");
  }
  JobPage page = service.list(status, limit, before);
  json jobs = json::array();
  for (const JobView& v : service.with_progress(std::move(page.jobs))) jobs.push_back(job_document(v));
  const std::string base = req.path;
  std::string query = "?limit=" + std::to_string(limit);
  if (status) query += "&status=" + std::string(to_string(*status));
  json links = json::array({{{"href", base + query}, {"rel", "self"}, {"type", kJson}}});
  if (page.next_before)
    links.push_back(
        {{"href", base + query + "&cursor=" + encode_cursor(*page.next_before)}, {"rel", "next"}, {"type", kJson}});
  send_json(res, 200, {{"jobs", jobs}, {"links", links}});
}

void HttpServer::Impl::get_job(const Request& req, Response& res) {
  const std::string id = req.matches[1];
  const auto view = service.job(id);
  if (!view) return not_found_job(req, res, id);
  send_json(res, 200, job_document(*view));
}

void HttpServer::Impl::dismiss(const Request& req, Response& res) {
  const std::string id = req.matches[1];
  const auto [outcome, view] = service.dismiss(id);
  if (outcome == DismissOutcome::not_found || !view) return not_found_job(req, res, id);
  json doc = job_document(*view);
  if (outcome == DismissOutcome::removed) {
    doc["message"] = "removed with its events and result";
    doc["links"] = json::array();
  }
  send_json(res, 200, doc);
}

void HttpServer::Impl::events(const Request& req, Response& res) {
  const std::string id = req.matches[1];
  const bool ndjson = req.has_param("format") && req.get_param_value("format") == "ndjson";
  if (req.has_param("format") && !ndjson && req.get_param_value("format") != "sse")
    return problem(res, req, 400, "bad-parameter", "Bad query parameter", "format must be sse or ndjson");
  std::int64_t after = 0;
  for (const char* name : {"after", "last_event_id"})
    if (req.has_param(name)) {
      const auto n = parse_count(req.get_param_value(name));
      if (!n)
        return problem(res, req, 400, "bad-parameter", "Bad query parameter",
                       std::string(name) + " must be an event id (an integer >= 0)");
      after = *n;
    }
  if (req.has_header("Last-Event-ID")) {
    const auto n = parse_count(req.get_header_value("Last-Event-ID"));
    if (!n)
      return problem(res, req, 400, "bad-last-event-id", "Bad Last-Event-ID",
                     "Last-Event-ID must be an event id this server gave out");
    after = *n;
  }
  if (!service.job(id)) return not_found_job(req, res, id);
  if (service.draining()) {
    res.set_header("Retry-After", "10");
    return problem(res, req, 503, "shutting-down", "Shutting down", "the server is shutting down");
  }
  if (open_streams.fetch_add(1) >= options.max_streams) {
    --open_streams;
    res.set_header("Retry-After", "5");
    return problem(
        res, req, 503, "too-many-streams", "Too many event streams",
        "this server has " + std::to_string(options.max_streams) + " event streams open; retry later or poll the job");
  }
  struct State {
    std::int64_t last = 0;
    std::uint64_t seen = 0;  // JobService::wait_events's
    std::chrono::steady_clock::time_point last_write;
    bool first = true;
  };
  auto state = std::make_shared<State>();
  state->last = after;
  state->last_write = std::chrono::steady_clock::now();
  res.set_header("Cache-Control", "no-cache");
  res.set_header("X-Accel-Buffering", "no");
  const auto heartbeat = options.heartbeat;
  res.set_chunked_content_provider(
      ndjson ? "application/x-ndjson" : "text/event-stream",
      [this, id, state, ndjson, heartbeat](size_t, httplib::DataSink& sink) {
        if (stopping || service.draining()) {
          sink.done();
          return true;
        }
        std::string out;
        if (state->first && !ndjson) out = "retry: 1000\n\n";
        state->first = false;
        // A client that went away frees its slot now, not at the next write (the heartbeat
        // 15 s on): each wait (at most 500 ms) is preceded by a look at the socket.
        if (!sink.is_writable()) return false;
        const auto now = std::chrono::steady_clock::now();
        const auto until_ping =
            std::chrono::duration_cast<std::chrono::milliseconds>(state->last_write + heartbeat - now);
        const auto wait = std::clamp(until_ping, std::chrono::milliseconds(0), std::chrono::milliseconds(500));
        const EventBatch batch = service.wait_events(id, state->last, wait, 256, &state->seen);
        if (!batch.found) {
          sink.done();
          return true;
        }
        for (const StoredEvent& e : batch.events) {
          if (ndjson) {
            out += e.data;
            out += '\n';
          } else {
            out += "id: " + std::to_string(e.seq) + "\nevent: " + e.type + "\ndata: " + e.data + "\n\n";
          }
          state->last = e.seq;
        }
        const auto after_wait = std::chrono::steady_clock::now();
        if (out.empty() && after_wait - state->last_write >= heartbeat) out = ndjson ? "\n" : ": ping\n\n";
        if (!out.empty()) {
          if (!sink.write(out.data(), out.size())) return false;
          state->last_write = after_wait;
        }
        if (batch.ended) sink.done();
        return true;
      },
      [this](bool) { --open_streams; });
}

void HttpServer::Impl::convergence(const Request& req, Response& res) {
  const std::string id = req.matches[1];
  const auto view = service.job(id);
  if (!view) return not_found_job(req, res, id);
  std::vector<json> rows;
  std::int64_t after = 0;
  while (true) {
    const auto batch = service.events(id, after, 5000, "iteration");
    for (const StoredEvent& e : batch) {
      json ev = json::parse(e.data);
      ev.erase("type");
      rows.push_back(std::move(ev));
      after = e.seq;
    }
    if (batch.size() < 5000) break;
  }
  const std::string format = req.has_param("format") ? req.get_param_value("format") : "";
  const bool csv =
      format == "csv" || (format.empty() && req.get_header_value("Accept").find("text/csv") != std::string::npos);
  if (!format.empty() && format != "csv" && format != "json")
    return problem(res, req, 400, "bad-parameter", "Bad query parameter", "format must be json or csv");
  if (csv) {
    res.set_header("Content-Disposition", "attachment; filename=\"convergence-" + id + ".csv\"");
    res.set_content(objects_csv(rows), "text/csv; charset=utf-8");
    return;
  }
  send_json(res, 200, {{"jobID", id}, {"status", to_string(view->record.status)}, {"iterations", rows}});
}

void HttpServer::Impl::result(const Request& req, Response& res) {
  const std::string id = req.matches[1];
  const auto view = service.job(id);
  if (!view) return not_found_job(req, res, id);
  const std::string format = req.has_param("format") ? req.get_param_value("format") : "json";
  if (format != "json" && format != "csv" && format != "vtk")
    return problem(res, req, 400, "bad-parameter", "Bad query parameter", "format must be json, csv or vtk");
  const auto data = is_finished(view->record.status) ? service.result(id) : std::nullopt;
  if (!data) {
    if (!is_finished(view->record.status))
      return problem(res, req, 404, "result-not-ready", "Result not ready",
                     "job " + id + " is " + std::string(to_string(view->record.status)) +
                         "; its result is ready when it has finished");
    return problem(res, req, 404, "no-result", "No result",
                   "job " + id + " is " + std::string(to_string(view->record.status)) + " and has no result");
  }
  // Stored zstd-compressed: as stored to a client that accepts zstd, gzip-compressed (fast) to
  // one that accepts gzip, as JSON text otherwise. The charset parameter keeps httplib from
  // compressing a compressed body again (it compresses exactly "application/json", with
  // brotli at its slowest quality where the client accepts br).
  if (format == "json") {
    res.set_header("Vary", "Accept-Encoding");
    const char* type = "application/json; charset=utf-8";
    if (is_zstd(*data) && accepts(req, "zstd")) {
      res.set_header("Content-Encoding", "zstd");
      res.set_content(*data, type);
    } else if (accepts(req, "gzip")) {
      res.set_header("Content-Encoding", "gzip");
      res.set_content(gzip_fast(stored_text(*data)), type);
    } else {
      res.set_content(stored_text(*data), kJson);
    }
    return;
  }
  const json doc = json::parse(stored_text(*data));
  if (format == "csv") {
    const std::string table = req.has_param("table") ? req.get_param_value("table") : "nodes";
    const auto& tables = result_csv_tables();
    if (std::find(tables.begin(), tables.end(), table) == tables.end()) {
      std::string names;
      for (const auto& t : tables) names += (names.empty() ? "" : ", ") + t;
      return problem(res, req, 400, "bad-parameter", "Bad query parameter", "table must be one of " + names);
    }
    res.set_header("Content-Disposition", "attachment; filename=\"" + table + "-" + id + ".csv\"");
    res.set_content(result_csv(doc, table), "text/csv; charset=utf-8");
    return;
  }
  const std::string stem = "grip-" + id.substr(0, 8);
  if (req.has_param("step")) {
    const auto step = parse_count(req.get_param_value("step"));
    const size_t count = doc.contains("steps") ? doc["steps"].size() : 0;
    if (!step || *step < 1 || static_cast<size_t>(*step) > count)
      return problem(res, req, 400, "bad-parameter", "Bad query parameter",
                     "step must be from 1 to " + std::to_string(count));
    try {
      res.set_header("Content-Disposition", "attachment; filename=\"" + stem + "_" + std::to_string(*step) + ".vtk\"");
      res.set_content(step_legacy_vtk(doc, static_cast<size_t>(*step - 1)), "text/plain; charset=utf-8");
    } catch (const std::invalid_argument& e) {
      res.headers.erase("Content-Disposition");
      return problem(res, req, 404, "no-step-fields", "No fields for this step", e.what());
    }
    return;
  }
  std::vector<std::pair<std::string, std::string>> files;
  for (auto& f : result_vtk_files(doc, stem)) files.emplace_back(stem + "/" + f.name, std::move(f.content));
  res.set_header("Content-Disposition", "attachment; filename=\"" + stem + "-vtk.tar\"");
  res.set_content(tar_archive(files), "application/x-tar");
}

void HttpServer::Impl::metrics(const Request&, Response& res) {
  const ServiceStats s = service.stats();
  std::ostringstream os;
  os << "# HELP grip_jobs Jobs in the store by status.\n# TYPE grip_jobs gauge\n";
  for (JobStatus st :
       {JobStatus::accepted, JobStatus::running, JobStatus::successful, JobStatus::failed, JobStatus::dismissed}) {
    const auto it = s.jobs.find(st);
    os << "grip_jobs{status=\"" << to_string(st) << "\"} " << (it == s.jobs.end() ? 0 : it->second) << "\n";
  }
  os << "# HELP grip_queue_depth Accepted jobs waiting for a worker.\n# TYPE grip_queue_depth gauge\n"
     << "grip_queue_depth " << s.queue_depth << "\n"
     << "# HELP grip_jobs_running Jobs being solved now.\n# TYPE grip_jobs_running gauge\n"
     << "grip_jobs_running " << s.running << "\n"
     << "# HELP grip_workers Worker threads.\n# TYPE grip_workers gauge\n"
     << "grip_workers " << s.workers << "\n"
     << "# HELP grip_open_streams Open event streams.\n# TYPE grip_open_streams gauge\n"
     << "grip_open_streams " << open_streams.load() << "\n"
     << "# HELP grip_solve_seconds_total Solver wall time of runs finished by this process.\n"
     << "# TYPE grip_solve_seconds_total counter\n"
     << "grip_solve_seconds_total " << s.solve_seconds << "\n"
     << "# HELP grip_contact_iterations_total Contact iterations of runs finished by this process.\n"
     << "# TYPE grip_contact_iterations_total counter\n"
     << "grip_contact_iterations_total " << s.iterations << "\n"
     << "# HELP grip_events_stored_total Events stored by this process.\n"
     << "# TYPE grip_events_stored_total counter\n"
     << "grip_events_stored_total " << s.events << "\n"
     << "# HELP grip_events_waiting Events not yet stored (the database unreachable or slow).\n"
     << "# TYPE grip_events_waiting gauge\n"
     << "grip_events_waiting " << s.events_waiting << "\n"
     << "# HELP grip_store_disk_bytes The job database on disk (SQLite: the file; PostgreSQL: grip's tables).\n"
     << "# TYPE grip_store_disk_bytes gauge\n"
     << "grip_store_disk_bytes " << s.disk_bytes << "\n"
     << "# HELP grip_meshes Uploaded meshes stored (POST /v1/meshes).\n# TYPE grip_meshes gauge\n"
     << "grip_meshes " << s.meshes << "\n"
     << "# HELP grip_mesh_stored_bytes Stored (compressed) bytes of the uploaded meshes.\n"
     << "# TYPE grip_mesh_stored_bytes gauge\n"
     << "grip_mesh_stored_bytes " << s.mesh_bytes << "\n"
     << "# HELP grip_retention_max_jobs Finished jobs kept (0: no bound).\n# TYPE grip_retention_max_jobs gauge\n"
     << "grip_retention_max_jobs " << s.retention.max_jobs << "\n"
     << "# HELP grip_retention_max_age_seconds Age of finished jobs kept (0: no bound).\n"
     << "# TYPE grip_retention_max_age_seconds gauge\n"
     << "grip_retention_max_age_seconds " << s.retention.max_age_seconds << "\n"
     << "# HELP grip_retention_max_bytes Stored bytes of finished jobs kept (0: no bound).\n"
     << "# TYPE grip_retention_max_bytes gauge\n"
     << "grip_retention_max_bytes " << s.retention.max_bytes << "\n"
     << "# HELP grip_jobs_pruned_total Finished jobs removed by retention in this process.\n"
     << "# TYPE grip_jobs_pruned_total counter\n"
     << "grip_jobs_pruned_total " << s.pruned << "\n"
     << "# HELP grip_job_stored_bytes Bytes stored per job (scene, events, compressed result) finished by this "
        "process.\n"
     << "# TYPE grip_job_stored_bytes histogram\n";
  for (const auto& [le, count] : s.stored_bytes_buckets)
    os << "grip_job_stored_bytes_bucket{le=\""
       << (std::isinf(le) ? std::string("+Inf") : std::to_string(static_cast<std::int64_t>(le))) << "\"} " << count
       << "\n";
  os << "grip_job_stored_bytes_sum " << s.stored_bytes_sum << "\n"
     << "grip_job_stored_bytes_count " << s.stored_bytes_count << "\n";
  if (s.db_traffic)  // only where the store measures them (PostgreSQL)
    os << "# HELP grip_db_round_trips_total Queries sent to the database by this process.\n"
       << "# TYPE grip_db_round_trips_total counter\n"
       << "grip_db_round_trips_total " << s.db_traffic->first << "\n"
       << "# HELP grip_db_bytes_total Bytes sent to and received from the database by this process.\n"
       << "# TYPE grip_db_bytes_total counter\n"
       << "grip_db_bytes_total " << s.db_traffic->second << "\n";
  request_metrics.write(os);
  service.write_job_metrics(os);
  res.set_content(os.str(), "text/plain; version=0.0.4; charset=utf-8");
}

void HttpServer::Impl::process_description(const Request&, Response& res) {
  const fs::path dir = options.schemas_dir;
  auto schema_of = [&](const char* name) -> json {
    if (fs::exists(dir / (std::string(name) + ".schema.json"))) return {{"$ref", std::string("/v1/schemas/") + name}};
    return {{"type", "object"}};
  };
  send_json(res, 200,
            {{"id", kProcessId},
             {"title", "2D frictional contact"},
             {"description",
              "Frictional contact of a deformable body against rigid obstacles, solved with the "
              "accelerated contact error vector scheme; events stream every contact iteration."},
             {"version", "0.1.0"},
             {"jobControlOptions", {"async-execute"}},
             {"outputTransmission", {"value"}},
             {"inputs",
              {{"scene",
                {{"title", "Scene"},
                 {"description", "the scene (see /v1/examples)"},
                 {"minOccurs", 1},
                 {"maxOccurs", 1},
                 {"schema", schema_of("scene")}}}}},
             {"outputs", {{"result", {{"title", "Result"}, {"schema", schema_of("result")}}}}},
             {"links",
              {{{"href", "/processes/contact2d/execution"},
                {"rel", "http://www.opengis.net/def/rel/ogc/1.0/execute"},
                {"title", "execute (asynchronous)"}}}}});
}

void HttpServer::Impl::file_list(const Request&, Response& res, const fs::path& dir, const std::string& suffix,
                                 const std::string& route) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string f = entry.path().filename().string();
    if (entry.is_regular_file() && f.size() > suffix.size() &&
        f.compare(f.size() - suffix.size(), suffix.size(), suffix) == 0 &&
        !(suffix == ".json" && f.find(".schema.json") != std::string::npos))
      names.push_back(f.substr(0, f.size() - suffix.size()));
  }
  // The paper's two examples first, then the others by name.
  auto rank = [](const std::string& n) { return n == "beam-on-cylinder" ? 0 : n == "sheet-stretching" ? 1 : 2; };
  std::sort(names.begin(), names.end(),
            [&](const auto& a, const auto& b) { return rank(a) != rank(b) ? rank(a) < rank(b) : a < b; });
  json items = json::array();
  for (const auto& n : names) items.push_back({{"name", n}, {"href", route + n}});
  send_json(res, 200, {{"items", items}});
}

void HttpServer::Impl::file(const Request& req, Response& res, const fs::path& dir, const std::string& suffix) {
  std::string name = req.matches[1];
  if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
    name.resize(name.size() - suffix.size());
  const auto content = safe_name(name) ? read_file(dir / (name + suffix)) : std::nullopt;
  if (!content) return problem(res, req, 404, "not-found", "Not found", "no document named '" + name + "'");
  res.set_content(*content, suffix == ".schema.json" ? "application/schema+json"
                            : suffix == ".msh"       ? "application/octet-stream"
                                                     : kJson);
}

HttpServer::HttpServer(JobService& service, HttpOptions options)
    : impl_(std::make_unique<Impl>(service, std::move(options), open_streams_)) {
  impl_->hooks();
  impl_->routes();
}

HttpServer::~HttpServer() { stop(); }

int HttpServer::bind() {
  const auto& o = impl_->options;
  if (o.port == 0) {
    port_ = impl_->svr.bind_to_any_port(o.host);
    if (port_ <= 0) throw std::runtime_error("cannot bind " + o.host + " to any port");
  } else {
    if (!impl_->svr.bind_to_port(o.host, o.port))
      throw std::runtime_error("cannot bind " + o.host + ":" + std::to_string(o.port));
    port_ = o.port;
  }
  // Listening already: listen() again only changes the backlog.
  if (impl_->listen_fd >= 0 && ::listen(impl_->listen_fd, SOMAXCONN) != 0)
    spdlog::warn("cannot raise the listen backlog: {}", std::strerror(errno));
  return port_;
}

void HttpServer::listen() { impl_->svr.listen_after_bind(); }

void HttpServer::stop() {
  impl_->stopping = true;
  if (impl_->svr.is_running()) impl_->svr.stop();
}

}  // namespace grip::server
