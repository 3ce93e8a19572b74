// Malformed requests against one running `grip serve` (default limits): a table of requests,
// each with the 4xx it must get as an RFC 9457 problem document (`detail`, `errors[]` of
// {pointer, detail}) and, where a field is at fault, that field's JSON pointer. After every
// request the server must answer /v1/health; at the end the jobs solved before the table are
// still there, successful, with the same stored result, and no malformed request made a job.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <set>

#include "grip_process.hpp"

namespace grip::testing {
namespace {

using Clock = std::chrono::steady_clock;

struct Row {
  std::string what;  // the table's first column
  int status = 0;
  std::optional<std::string> pointer;  // one of errors[].pointer ("": the whole request)
  std::string method = "POST";
  std::string path = "/v1/jobs";
  std::string body;
  std::string content_type = "application/json";  // empty: no Content-Type
  httplib::Headers headers;
  size_t streamed_bytes = 0;  // instead of `body`: this many spaces from a content provider
  bool chunked = false;       // ... without a Content-Length
};

std::string repeat(const std::string& s, size_t n) {
  std::string out;
  out.reserve(s.size() * n);
  for (size_t i = 0; i < n; ++i) out += s;
  return out;
}

// `text` with the first `from` replaced by `to` (the replaced text must be there).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("no '" + from + "' in the text");
  return text.replace(at, from.size(), to);
}

template <class F>
std::string edited(json scene, F edit) {
  edit(scene);
  return scene.dump();
}

httplib::Result send(const Api& api, const Row& row) {
  // Generous, but far below "hangs": every row is answered in well under a second or two.
  httplib::Client cli = api.client(20);
  cli.set_write_timeout(20);
  if (row.streamed_bytes > 0) {
    const std::string block(1 << 16, ' ');
    if (row.chunked) {
      auto sent = std::make_shared<size_t>(0);
      return cli.Post(
          row.path.c_str(), row.headers,
          [&, sent](size_t, httplib::DataSink& sink) {
            if (*sent >= row.streamed_bytes) {
              sink.done();
              return true;
            }
            const size_t n = std::min(block.size(), row.streamed_bytes - *sent);
            *sent += n;
            return sink.write(block.data(), n);
          },
          row.content_type.c_str());
    }
    return cli.Post(
        row.path.c_str(), row.headers, row.streamed_bytes,
        [&](size_t offset, size_t length, httplib::DataSink& sink) {
          return sink.write(block.data(), std::min({block.size(), length, row.streamed_bytes - offset}));
        },
        row.content_type.c_str());
  }
  httplib::Request req;
  req.method = row.method;
  req.path = row.path;
  req.headers = row.headers;
  if (!row.content_type.empty()) req.headers.emplace("Content-Type", row.content_type);
  req.body = row.body;
  return cli.send(req);
}

TEST(MalformedRequests, TableOfBadRequestsGetTheirProblemAndHarmNothing) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {}, dir.path() / "server.log");
  const Api api(server.port());

  // ---- good jobs first: small and fast; their stored results are compared at the end.
  const json beam = json::parse(read_text(examples_dir() / "beam-on-cylinder.json"));
  const json block = json::parse(read_text(examples_dir() / "sliding-block.json"));
  const json sheet = json::parse(read_text(examples_dir() / "sheet-stretching.json"));
  json small_block = block;
  small_block["body"]["mesh"]["rectangle"]["divisions"] = {6, 3};
  std::vector<std::string> good;
  auto r = api.post_json("/v1/jobs", small_block.dump(), {{"Idempotency-Key", "good-1"}});
  ASSERT_TRUE(r && r->status == 201) << (r ? r->body : "no response");
  good.push_back(json::parse(r->body)["jobID"]);
  good.push_back(api.submit(beam_scene(10, 3)));
  std::map<std::string, std::string> results;
  for (const auto& id : good) {
    ASSERT_EQ(api.wait_status(id, {"successful", "failed"})["status"], "successful");
    auto res = api.get("/v1/jobs/" + id + "/result");
    ASSERT_TRUE(res && res->status == 200);
    results[id] = res->body;
  }
  const std::string job = "/v1/jobs/" + good[1];

  // ---- the table
  const std::string beam_text = beam.dump();  // compact: "young":210000
  std::vector<Row> rows = {
      // 400: not JSON, or JSON this server does not read
      {"truncated JSON (first 200 bytes of a scene)", 400, "", "POST", "/v1/jobs", beam_text.substr(0, 200)},
      {"empty body", 400, "", "POST", "/v1/jobs", ""},
      {"whitespace only", 400, "", "POST", "/v1/jobs", " \n\t "},
      {"NaN as a bare word (young: NaN)", 400, "", "POST", "/v1/jobs", replaced(beam_text, "210000", "NaN")},
      {"Infinity as a bare word (young: -Infinity)", 400, "", "POST", "/v1/jobs",
       replaced(beam_text, "210000", "-Infinity")},
      {"number out of double range (young: 1e400)", 400, "", "POST", "/v1/jobs",
       replaced(beam_text, "210000", "1e400")},
      {"bad UTF-8 in a string (0xFF)", 400, "", "POST", "/v1/jobs", replaced(beam_text, "beam-on", "beam-\xff-on")},
      {"overlong UTF-8 (0xC0 0xAF)", 400, "", "POST", "/v1/jobs", replaced(beam_text, "beam-on", "beam-\xc0\xaf-on")},
      {"lone surrogate escape \\ud800", 400, "", "POST", "/v1/jobs", replaced(beam_text, "beam-on", "beam-\\ud800-on")},
      {"byte order mark only", 400, "", "POST", "/v1/jobs", "\xef\xbb\xbf"},
      {"trailing garbage after the scene", 400, "", "POST", "/v1/jobs", beam_text + " x"},
      {"trailing comma", 400, "", "POST", "/v1/jobs", beam_text.substr(0, beam_text.size() - 1) + ",}"},
      {"single quotes", 400, "", "POST", "/v1/jobs", "{'body': 1}"},
      {"a comment", 400, "", "POST", "/v1/jobs", "/* scene */" + beam_text},
      {"100000 nested arrays", 400, "", "POST", "/v1/jobs", repeat("[", 100000) + repeat("]", 100000)},
      {"100000 nested arrays as a field's value", 400, "", "POST", "/v1/jobs",
       replaced(beam_text, "210000", repeat("[", 100000) + repeat("]", 100000))},
      {"100000 nested objects", 400, "", "POST", "/v1/jobs", repeat("{\"a\":", 100000) + "1" + repeat("}", 100000)},
      {"1000000 unclosed [", 400, "", "POST", "/v1/jobs", repeat("[", 1000000)},
      {"Idempotency-Key of 300 characters",
       400,
       "",
       "POST",
       "/v1/jobs",
       beam_text,
       "application/json",
       {{"Idempotency-Key", std::string(300, 'k')}}},
      // 413, 415
      {"100 MB body with a Content-Length", 413, "", "POST", "/v1/jobs", "", "application/json", {}, 100'000'000},
      {"100 MB body, chunked", 413, "", "POST", "/v1/jobs", "", "application/json", {}, 100'000'000, true},
      {"Content-Type text/plain", 415, "", "POST", "/v1/jobs", beam_text, "text/plain"},
      {"no Content-Type", 415, "", "POST", "/v1/jobs", beam_text, ""},
      {"Content-Type application/x-www-form-urlencoded", 415, "", "POST", "/v1/jobs", "a=1",
       "application/x-www-form-urlencoded"},
      {"Content-Type application/jsonx", 415, "", "POST", "/v1/jobs", beam_text, "application/jsonx"},
      // 422: JSON, but not a scene; the pointer names the field
      {"a JSON array", 422, "", "POST", "/v1/jobs", "[1, 2]"},
      {"a JSON number", 422, "", "POST", "/v1/jobs", "42"},
      {"a JSON string", 422, "", "POST", "/v1/jobs", "\"scene\""},
      {"null", 422, "", "POST", "/v1/jobs", "null"},
      {"byte order mark + [] (the mark is skipped)", 422, "", "POST", "/v1/jobs", "\xef\xbb\xbf[]"},
      {"empty object", 422, "/body", "POST", "/v1/jobs", "{}"},
      {"young \"NaN\" (a string)", 422, "/body/material/young", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["material"]["young"] = "NaN"; })},
      {"radius \"Infinity\" (a string)", 422, "/obstacles/0/shape/radius", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["obstacles"][0]["shape"]["radius"] = "Infinity"; })},
      {"young \"210000\" (a number as a string)", 422, "/body/material/young", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["material"]["young"] = "210000"; })},
      {"beam elements 10.5", 422, "/body/mesh/elements", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["mesh"]["elements"] = 10.5; })},
      {"beam elements -5", 422, "/body/mesh/elements", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["mesh"]["elements"] = -5; })},
      {"beam elements 1000000", 422, "/body/mesh/elements", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["mesh"]["elements"] = 1000000; })},
      {"rectangle divisions [1000, 1000] (1e6 nodes)", 422, "/body/mesh", "POST", "/v1/jobs",
       edited(block,
              [](json& s) {
                s["body"]["mesh"]["rectangle"]["divisions"] = {1000, 1000};
              })},
      {"rectangle divisions [-20, 10]", 422, "/body/mesh/rectangle/divisions/0", "POST", "/v1/jobs",
       edited(block,
              [](json& s) {
                s["body"]["mesh"]["rectangle"]["divisions"] = {-20, 10};
              })},
      {"rectangle size [-20, 10]", 422, "/body/mesh/rectangle/size/0", "POST", "/v1/jobs",
       edited(block,
              [](json& s) {
                s["body"]["mesh"]["rectangle"]["size"] = {-20, 10};
              })},
      {"200000 equal membrane nodes (errors listed up to 100)", 422, "/body/mesh/nodes/1", "POST", "/v1/jobs",
       edited(sheet,
              [](json& s) {
                s["body"]["mesh"] = {{"nodes", json(200000, json::array({0, 0}))}};
              })},
      {"steps -3", 422, "/steps", "POST", "/v1/jobs", edited(beam, [](json& s) { s["steps"] = -3; })},
      {"steps 1000000000", 422, "/steps", "POST", "/v1/jobs", edited(beam, [](json& s) { s["steps"] = 1000000000; })},
      {"steps 20000 (over --max-steps 10000)", 422, "/steps", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["steps"] = 20000; })},
      {"steps: a list of 1000000 load factors", 422, "/steps", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["steps"] = json(1000000, 0.5); })},
      {"stage steps 1000000", 422, "/stages/1/steps", "POST", "/v1/jobs",
       edited(block, [](json& s) { s["stages"][1]["steps"] = 1000000; })},
      {"solver max_iterations 1e12", 422, "/solver/contact/max_iterations", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["solver"]["contact"]["max_iterations"] = 1000000000000LL; })},
      {"tolerance -1", 422, "/solver/contact/tolerance", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["solver"]["contact"]["tolerance"] = -1; })},
      {"section depth 0", 422, "/body/section/depth", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["section"]["depth"] = 0; })},
      {"section width -2", 422, "/body/section/width", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["section"]["width"] = -2; })},
      {"young 0", 422, "/body/material/young", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["material"]["young"] = 0; })},
      {"poisson 0.62", 422, "/body/material/poisson", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["material"]["poisson"] = 0.62; })},
      {"continuum thickness 0", 422, "/body/thickness", "POST", "/v1/jobs",
       edited(block, [](json& s) { s["body"]["thickness"] = 0; })},
      {"continuum thickness -1", 422, "/body/thickness", "POST", "/v1/jobs",
       edited(block, [](json& s) { s["body"]["thickness"] = -1; })},
      {"load on node 41 of 0..40", 422, "/body/loads/0/node", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["loads"][0]["node"] = 41; })},
      {"support on node -1", 422, "/body/supports/0/node", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["supports"][0]["node"] = -1; })},
      {"solver.start names a missing obstacle", 422, "/solver/start/obstacle", "POST", "/v1/jobs",
       edited(sheet, [](json& s) { s["solver"]["start"]["obstacle"] = "nope"; })},
      {"stage factors name a missing load case", 422, "/stages/1/factors/nope", "POST", "/v1/jobs",
       edited(block,
              [](json& s) {
                s["stages"][1]["factors"] = {{"nope", 1}};
              })},
      {"stage friction names a missing obstacle", 422, "/stages/1/friction/nowhere", "POST", "/v1/jobs",
       edited(block,
              [](json& s) {
                s["stages"][1]["friction"] = {{"nowhere", 0.1}};
              })},
      {"obstacles an object", 422, "/obstacles", "POST", "/v1/jobs",
       edited(beam,
              [](json& s) {
                s["obstacles"] = {{"a", 1}};
              })},
      {"body an array", 422, "/body", "POST", "/v1/jobs", edited(beam, [](json& s) { s["body"] = {1}; })},
      {"loads[0] a number", 422, "/body/loads/0", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["loads"][0] = 5; })},
      {"force with 3 components", 422, "/body/loads/0/force", "POST", "/v1/jobs",
       edited(beam,
              [](json& s) {
                s["body"]["loads"][0]["force"] = {0, -500, 1};
              })},
      {"unknown top-level field", 422, "/colour", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["colour"] = "red"; })},
      {"unknown nested field", 422, "/body/material/colour", "POST", "/v1/jobs",
       edited(beam, [](json& s) { s["body"]["material"]["colour"] = "red"; })},
      {"duplicate key steps (the last, -1, counts)", 422, "/steps", "POST", "/v1/jobs",
       beam_text.substr(0, beam_text.size() - 1) + ",\"steps\":-1}"},
      {"OGC execute with inputs.scene = 5", 422, "/inputs/scene", "POST", "/processes/contact2d/execution",
       "{\"inputs\": {\"scene\": 5}}"},
      {"Idempotency-Key reused with another scene",
       422,
       "",
       "POST",
       "/v1/jobs",
       edited(small_block, [](json& s) { s["name"] = "another"; }),
       "application/json",
       {{"Idempotency-Key", "good-1"}}},
      // GET /v1/jobs parameters
      {"GET /v1/jobs?limit=-1", 400, "", "GET", "/v1/jobs?limit=-1"},
      {"GET /v1/jobs?limit=abc", 400, "", "GET", "/v1/jobs?limit=abc"},
      {"GET /v1/jobs?limit=0", 400, "", "GET", "/v1/jobs?limit=0"},
      {"GET /v1/jobs?limit=1001", 400, "", "GET", "/v1/jobs?limit=1001"},
      {"GET /v1/jobs?limit=99999999999999999999", 400, "", "GET", "/v1/jobs?limit=99999999999999999999"},
      {"GET /v1/jobs?status=sleeping", 400, "", "GET", "/v1/jobs?status=sleeping"},
      {"GET /v1/jobs?cursor=garbage", 400, "", "GET", "/v1/jobs?cursor=garbage"},
      {"GET /v1/jobs?cursor=c1ffffffffffffffff (above int64)", 400, "", "GET", "/v1/jobs?cursor=c1ffffffffffffffff"},
      // unknown jobs and routes
      {"GET an unknown job id", 404, "", "GET", "/v1/jobs/00000000-0000-4000-8000-000000000000"},
      {"GET /v1/jobs/nope/result", 404, "", "GET", "/v1/jobs/nope/result"},
      {"GET /v1/jobs/nope/events", 404, "", "GET", "/v1/jobs/nope/events"},
      {"GET /v1/jobs/nope/convergence", 404, "", "GET", "/v1/jobs/nope/convergence"},
      {"DELETE /v1/jobs/nope", 404, "", "DELETE", "/v1/jobs/nope"},
      {"PUT /v1/jobs (405, Allow: GET, POST)", 405, "", "PUT", "/v1/jobs", "{}"},
      {"GET /v1/nothing-here", 404, "", "GET", "/v1/nothing-here"},
      // events and result of a real job
      {"events with Last-Event-ID: abc", 400, "", "GET", job + "/events", "", "", {{"Last-Event-ID", "abc"}}},
      {"events with Last-Event-ID: -1", 400, "", "GET", job + "/events", "", "", {{"Last-Event-ID", "-1"}}},
      {"events with Last-Event-ID: 99999999999999999999",
       400,
       "",
       "GET",
       job + "/events",
       "",
       "",
       {{"Last-Event-ID", "99999999999999999999"}}},
      {"events?after=x", 400, "", "GET", job + "/events?after=x"},
      {"events?format=xml", 400, "", "GET", job + "/events?format=xml"},
      {"result?format=xml", 400, "", "GET", job + "/result?format=xml"},
      {"result?format=vtk&step=0", 400, "", "GET", job + "/result?format=vtk&step=0"},
      {"result?format=csv&table=nope", 400, "", "GET", job + "/result?format=csv&table=nope"},
  };

  std::string table = "| request | status | pointer |\n|---|---|---|\n";
  for (const Row& row : rows) {
    SCOPED_TRACE(row.what);
    const auto t0 = Clock::now();
    const auto res = send(api, row);
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    ASSERT_TRUE(res) << "no answer: " << httplib::to_string(res.error());
    EXPECT_LT(seconds, 15.0);
    EXPECT_EQ(res->status, row.status) << res->body.substr(0, 300);
    EXPECT_EQ(res->get_header_value("Content-Type"), "application/problem+json");
    const json p = json::parse(res->body, nullptr, false);
    ASSERT_TRUE(p.is_object()) << res->body.substr(0, 300);
    EXPECT_EQ(p.value("status", 0), row.status);
    EXPECT_FALSE(p.value("detail", std::string()).empty());
    ASSERT_TRUE(p.contains("errors") && p["errors"].is_array() && !p["errors"].empty()) << res->body;
    EXPECT_LE(p["errors"].size(), 100u);
    std::set<std::string> pointers;
    for (const auto& e : p["errors"]) {
      ASSERT_TRUE(e.contains("pointer") && e["pointer"].is_string()) << e;
      EXPECT_FALSE(e.value("detail", std::string()).empty()) << e;
      pointers.insert(e["pointer"].get<std::string>());
    }
    if (row.pointer) EXPECT_TRUE(pointers.count(*row.pointer)) << "pointers: " << p["errors"].dump().substr(0, 300);
    const auto health = api.client(5).Get("/v1/health");
    ASSERT_TRUE(health && health->status == 200) << "the server stopped answering after: " << row.what;
    table += "| " + row.what + " | " + std::to_string(res->status) + " | " +
             (row.pointer ? "`" + (row.pointer->empty() ? std::string("\"\"") : *row.pointer) + "`" : "") + " |\n";
  }
  std::printf("%zu rows\n%s", rows.size(), table.c_str());
  EXPECT_GE(rows.size(), 30u);

  // ---- nothing harmed: the same jobs, successful, with the same stored results
  const auto list = api.get("/v1/jobs?limit=1000");
  ASSERT_TRUE(list && list->status == 200);
  EXPECT_EQ(json::parse(list->body)["jobs"].size(), good.size()) << "a malformed request made a job";
  for (const auto& id : good) {
    EXPECT_EQ(api.job(id)["status"], "successful");
    auto res = api.get("/v1/jobs/" + id + "/result");
    ASSERT_TRUE(res && res->status == 200);
    EXPECT_TRUE(res->body == results[id]) << "the stored result of " << id << " changed";
  }
  EXPECT_EQ(server.terminate(std::chrono::seconds(30)), 0) << server.log();
}

// Reads everything the server sends on a raw connection until it closes it (or `patience`
// passes); the text and the seconds it took.
std::pair<std::string, double> read_until_closed(int fd, std::chrono::seconds patience) {
  const auto t0 = Clock::now();
  timeval tv{1, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::string text;
  char buf[4096];
  while (Clock::now() - t0 < patience) {
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n == 0) break;
    if (n > 0) text.append(buf, static_cast<size_t>(n));
  }
  return {text, std::chrono::duration<double>(Clock::now() - t0).count()};
}

int connect_raw(int port, const std::string& sent) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (fd < 0 || ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) return -1;
  ::send(fd, sent.data(), sent.size(), 0);
  return fd;
}

// A client that stops in the middle of its request holds one HTTP thread until the deadline
// of its head (5 s) or body (10 s), never the server: /v1/health answers meanwhile, and the
// stalled request is answered with a 408 naming the deadline and closed.
TEST(MalformedRequests, StalledRequestsTimeOutAndBlockNothing) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {}, dir.path() / "server.log");
  const Api api(server.port());
  const int body = connect_raw(server.port(),
                               "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                               "Content-Length: 100\r\n\r\n{\"body\":");
  const int head = connect_raw(server.port(), "GET /v1/health HTTP/1.1\r\nHost: x\r\n");
  ASSERT_GE(body, 0);
  ASSERT_GE(head, 0);
  const auto health = api.client(5).Get("/v1/health");
  ASSERT_TRUE(health && health->status == 200);
  for (const int fd : {body, head}) {
    const auto [text, seconds] = read_until_closed(fd, std::chrono::seconds(40));
    ::close(fd);
    EXPECT_LT(seconds, 30.0);
    EXPECT_EQ(text.rfind("HTTP/1.1 408", 0), 0u) << text;
    EXPECT_NE(text.find(fd == body ? "request body did not arrive within 10000 ms"
                                   : "request head did not arrive within 5000 ms"),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("application/problem+json"), std::string::npos) << text;
  }
  EXPECT_EQ(api.get("/v1/health")->status, 200);
}

}  // namespace
}  // namespace grip::testing
