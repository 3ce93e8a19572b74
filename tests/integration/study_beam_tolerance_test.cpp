// The paper's beam (schemas/examples/beam-on-cylinder.json, 40 elements: grip_bench's level 1)
// swept over the contact tolerance through the service gives grip_bench's tolerance curve for
// that scene: at every tolerance the same contact and Newton iterations and factorizations, and
// the same tip deflection, contact force and peak contact stress (so the same errors against
// grip_bench's reference). Only the times differ, by the timing noise (not asserted).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "grip_process.hpp"
#include "study_requests.hpp"

namespace grip::testing {
namespace {

// grip_bench's CSV rows by column name (its reason column is last and may be quoted).
std::vector<std::map<std::string, std::string>> read_csv(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  auto split = [](const std::string& l) {
    std::vector<std::string> cells(1);
    bool quoted = false;
    for (char c : l) {
      if (c == '"') quoted = !quoted;
      else if (c == ',' && !quoted) cells.emplace_back();
      else cells.back() += c;
    }
    return cells;
  };
  if (std::getline(in, line)) header = split(line);
  while (std::getline(in, line)) {
    const auto cells = split(line);
    std::map<std::string, std::string> row;
    for (size_t c = 0; c < header.size() && c < cells.size(); ++c) row[header[c]] = cells[c];
    rows.push_back(std::move(row));
  }
  return rows;
}

TEST(StudyOfThePapersBeam, ToleranceSweepReproducesGripBenchsCurve) {
  TempDir dir;
  const fs::path bench = dir.path() / "bench";
  const std::string command = std::string(GRIP_BENCH) + " --scenes beam --strategies cev --levels 1 --runs 1 --out " +
                              bench.string() + " --source " + source_dir().string() + " > " +
                              (dir.path() / "bench.log").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << read_text(dir.path() / "bench.log");
  std::map<double, std::map<std::string, std::string>> curve;
  for (auto& row : read_csv(bench / "strategies.csv"))
    if (row["scene"] == "beam" && row["strategy"] == "cev" && row["mesh"] == "40")
      curve[std::stod(row["tolerance"])] = row;
  ASSERT_EQ(curve.size(), 5u) << read_text(dir.path() / "bench.log");

  ServerProcess server(dir.path() / "grip.sqlite", {"--workers", "2"}, dir.path() / "serve.log");
  const Api api(server.port());
  json scene = json::parse(read_text(examples_dir() / "beam-on-cylinder.json"));
  scene["solver"]["contact"] = {{"method", "cev"}, {"tolerance", 1e-8}};  // grip_bench's cev: the defaults
  scene["outputs"] = {{{"name", "tip_w"}, {"kind", "displacement"}, {"node", 40}, {"component", "y"}},
                      {{"name", "force_x"}, {"kind", "resultant"}, {"component", "x"}},
                      {{"name", "force_y"}, {"kind", "resultant"}, {"component", "y"}},
                      {{"name", "peak"}, {"kind", "peak_pressure"}}};
  std::vector<double> tolerances;
  for (const auto& [tol, row] : curve) tolerances.push_back(tol);
  const json accepted = post_study(
      api, {{"scene", scene}, {"sweep", {{{"pointer", "/solver/contact/tolerance"}, {"values", tolerances}}}}}, 201);
  const json study = study_when_successful(api, accepted["id"]);
  ASSERT_EQ(study["status"], "successful") << study.dump(2);
  ASSERT_EQ(study["levels"].size(), curve.size());
  for (const json& level : study["levels"]) {
    const double tol = level["parameters"][0];
    const auto& row = curve.at(tol);
    const json summary =
        json::parse(api.get("/v1/jobs/" + level["job"].get<std::string>() + "/result")->body)["summary"];
    const json& out = level["outputs"];
    const double force = std::hypot(out["force_x"].get<double>(), out["force_y"].get<double>());
    std::printf(
        "tolerance %.0e: %d contact iterations (grip_bench %s), %d Newton (%s); tip %.10f (%s), force %.6f (%s), "
        "peak %.6f (%s); %.3f s (grip_bench %s s)\n",
        tol, summary["contact_iterations"].get<int>(), row.at("contact_iterations").c_str(),
        summary["newton_iterations"].get<int>(), row.at("newton_iterations").c_str(), -out["tip_w"].get<double>(),
        row.at("point").c_str(), force, row.at("force").c_str(), out["peak"].get<double>(), row.at("peak").c_str(),
        summary["seconds"].get<double>(), row.at("median_seconds").c_str());
    EXPECT_EQ(summary["contact_iterations"].get<long>(), std::stol(row.at("contact_iterations"))) << tol;
    EXPECT_EQ(summary["newton_iterations"].get<long>(), std::stol(row.at("newton_iterations"))) << tol;
    EXPECT_EQ(summary["factorizations"].get<long>(), std::stol(row.at("factorizations"))) << tol;
    // The CSV keeps 10 significant digits.
    EXPECT_NEAR(-out["tip_w"].get<double>(), std::stod(row.at("point")), 1e-9 * std::abs(std::stod(row.at("point"))))
        << tol;
    EXPECT_NEAR(force, std::stod(row.at("force")), 1e-9 * std::stod(row.at("force"))) << tol;
    EXPECT_NEAR(out["peak"].get<double>(), std::stod(row.at("peak")), 1e-9 * std::stod(row.at("peak"))) << tol;
  }
}

}  // namespace
}  // namespace grip::testing
