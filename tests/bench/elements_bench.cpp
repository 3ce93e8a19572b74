// Hertz on each element kind: the error of a and p0 against the wall time, at elements of a
// given size near the pole (bench/results/elements.md). Run by hand:
//   build/tests/bench/grip_elements_bench [kinds, default q9,t6] [runs per timing, default 3]
// Prints one markdown row per kind and size: a/h by element size, the nodes that touch,
// dofs, the median wall time of reading the scene (mesh generation and checks) and solving it,
// the last run's solving time and real solves, and the errors of the fitted a and p0 and of
// the peak nodal stress.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <sstream>

#include "tests/support/contact_profile.hpp"
#include "tests/support/scenes.hpp"

using namespace grip;
using namespace grip::testing;
using nlohmann::json;

int main(int argc, char** argv) {
  std::vector<std::string> kinds{"q9", "t6"};
  if (argc > 1) {
    kinds.clear();
    std::stringstream list(argv[1]);
    for (std::string k; std::getline(list, k, ',');) kinds.push_back(k);
  }
  const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  std::printf(
      "| kind | size mm | a/h | nodes in contact | dofs | seconds | of which solving | real solves | a err %% | p0 err "
      "%% | peak err %% |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const double size : {0.1, 0.05, 0.025, 0.01325})
    for (const std::string& kind : kinds) {
      json j = with_pole_elements(example_scene("hertz"), size);
      j["body"]["element"] = kind;
      std::vector<double> seconds;
      std::optional<Solved> solved;
      for (int r = 0; r < runs; ++r) {
        const auto start = std::chrono::steady_clock::now();
        solved.reset();
        solved.emplace(Solved{read_scene(j), {}});
        Solved& s = *solved;
        s.run = run_load_steps(s.scene.problem, s.scene.steps, s.scene.params);
        seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        if (!s.run.completed) {
          std::printf("| %s | %g | failed: %s |\n", kind.c_str(), size, s.run.reason.c_str());
          break;
        }
      }
      const Solved& s = *solved;
      if (!s.run.completed) continue;
      std::sort(seconds.begin(), seconds.end());
      const StepRecord& rec = s.run.steps.back();
      const json& body = s.scene.effective["body"];
      const HertzContact closed =
          hertz_contact(body, -reaction_resultant(s.scene.problem, rec).y() / body["thickness"].get<double>());
      const auto nodes = contact_profile(s.scene.problem, rec);
      const EllipseFit fit = fit_semi_ellipse(nodes);
      double peak = 0.0;
      int touching = 0;
      for (const auto& n : nodes) {
        peak = std::max(peak, -n.sigma_n);
        touching += n.p_n < 0;
      }
      std::printf("| %s | %g | %.0f | %d | %d | %.3f | %.3f | %ld | %+.3f | %+.3f | %+.3f |\n", kind.c_str(), size,
                  closed.a / size, touching, s.scene.problem.body->dof_count(), seconds[seconds.size() / 2],
                  s.run.seconds, static_cast<long>(s.run.counters.solves), 100 * (fit.a / closed.a - 1),
                  100 * (fit.p0 / closed.p0 - 1), 100 * (peak / closed.p0 - 1));
      std::fflush(stdout);
    }
}
