// Disk bounded (issue 34.3): results are stored gzip-compressed and served as stored to a
// client that accepts gzip (inflated to one that does not), each finished job's stored bytes
// are reported, and retention keeps the store at its bounds while jobs keep coming.
#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>

#include "grip_process.hpp"

namespace grip::testing {
namespace {

std::string inflate_gzip(const std::string& data) {
  z_stream z{};
  EXPECT_EQ(inflateInit2(&z, 15 + 16), Z_OK);
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  z.avail_in = static_cast<uInt>(data.size());
  std::string out;
  char buffer[65536];
  int rc = Z_OK;
  while (rc == Z_OK) {
    z.next_out = reinterpret_cast<Bytef*>(buffer);
    z.avail_out = sizeof buffer;
    rc = inflate(&z, Z_NO_FLUSH);
    out.append(buffer, sizeof buffer - z.avail_out);
  }
  inflateEnd(&z);
  EXPECT_EQ(rc, Z_STREAM_END);
  return out;
}

// The value of an unlabelled sample in /v1/metrics.
double metric(const Api& api, const std::string& name) {
  const auto r = api.get("/v1/metrics");
  if (!r) throw std::runtime_error("no /v1/metrics");
  const size_t at = r->body.find("\n" + name + " ");
  if (at == std::string::npos) throw std::runtime_error("no " + name + " in /v1/metrics");
  return std::stod(r->body.substr(at + name.size() + 2));
}

TEST(Retention, TheSlidingBlocksResultIsStoredCompressedAndServedAsStoredOrInflated) {
  TempDir dir;
  ServerProcess server(dir.path() / "grip.sqlite", {}, dir.path() / "serve.log");
  const Api api(server.port());
  const std::string id = api.submit(json::parse(read_text(examples_dir() / "sliding-block.json")));
  const json job = api.wait_status(id, {"successful"});
  ASSERT_TRUE(job.contains("stored_bytes")) << job.dump();
  const std::int64_t stored = job["stored_bytes"];
  std::printf("sliding block: %lld bytes stored\n", static_cast<long long>(stored));
  // 721 KB before compression (a 693 KB result); gzip -9 makes the result 215 KB (its numbers
  // are full-precision doubles: zstd -19 --long reaches 91 KB, xz -9e 86 KB).
  EXPECT_LT(stored, 240 * 1024);

  // A client that does not ask for gzip gets the JSON (httplib's client asks by default).
  httplib::Client plain("127.0.0.1", server.port());
  plain.set_decompress(false);
  const auto json_text = plain.Get("/v1/jobs/" + id + "/result", {{"Accept-Encoding", "identity"}});
  ASSERT_TRUE(json_text);
  ASSERT_EQ(json_text->status, 200);
  EXPECT_FALSE(json_text->has_header("Content-Encoding"));
  const json result = json::parse(json_text->body);
  EXPECT_EQ(result["steps"].size(), 12u);
  // One that accepts gzip gets the stored bytes, which inflate to the same document.
  const auto gz = plain.Get("/v1/jobs/" + id + "/result", {{"Accept-Encoding", "gzip, deflate"}});
  ASSERT_TRUE(gz);
  ASSERT_EQ(gz->status, 200);
  EXPECT_EQ(gz->get_header_value("Content-Encoding"), "gzip");
  EXPECT_LT(static_cast<std::int64_t>(gz->body.size()), stored);
  EXPECT_LT(3 * gz->body.size(), json_text->body.size());
  EXPECT_EQ(inflate_gzip(gz->body), json_text->body);
  // The other formats read the stored result too.
  const auto csv = plain.Get("/v1/jobs/" + id + "/result?format=csv", {{"Accept-Encoding", "identity"}});
  ASSERT_TRUE(csv);
  EXPECT_EQ(csv->status, 200);
  EXPECT_EQ(metric(api, "grip_job_stored_bytes_count"), 1);
  EXPECT_EQ(metric(api, "grip_job_stored_bytes_sum"), static_cast<double>(stored));
}

TEST(Retention, AThousandSmallJobsWithARetentionOf100LeaveAtMost100AndASmallFile) {
  TempDir dir;
  const auto db = dir.path() / "grip.sqlite";
  ServerProcess server(db, {"--retain-jobs", "100", "--prune-interval", "0.2", "--queue", "2000"},
                       dir.path() / "serve.log");
  const Api api(server.port());
  const json small = json::parse(read_text(source_dir() / "tests" / "load" / "small-job.json"));
  std::vector<std::string> ids;
  for (int i = 0; i < 1000; ++i) ids.push_back(api.submit(small));
  // Every job ends (or has been removed once finished).
  for (const std::string& id : ids) {
    const auto r = api.get("/v1/jobs/" + id);
    ASSERT_TRUE(r);
    if (r->status == 404) continue;
    const json doc = api.wait_status(id, {"successful", "failed"});
    EXPECT_EQ(doc["status"], "successful") << doc.dump();
  }
  // The pruner's next passes.
  int listed = 0;
  for (int tries = 0; tries < 100; ++tries) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    listed = static_cast<int>(json::parse(api.get("/v1/jobs?limit=1000")->body)["jobs"].size());
    if (listed <= 100) break;
  }
  EXPECT_LE(listed, 100);
  EXPECT_GE(listed, 90);  // the newest are kept
  EXPECT_EQ(metric(api, "grip_retention_max_jobs"), 100);
  EXPECT_GE(metric(api, "grip_jobs_pruned_total"), 900);
  const double file = static_cast<double>(std::filesystem::file_size(db)) / (1 << 20);
  const double wal = std::filesystem::exists(db.string() + "-wal")
                         ? static_cast<double>(std::filesystem::file_size(db.string() + "-wal")) / (1 << 20)
                         : 0.0;
  std::printf("1000 small jobs, retention 100: %d kept, database %.2f MB (+ WAL %.2f MB), disk_bytes %.2f MB\n",
              listed, file, wal, metric(api, "grip_store_disk_bytes") / (1 << 20));
  EXPECT_LT(file, 20.0);
}

}  // namespace
}  // namespace grip::testing
