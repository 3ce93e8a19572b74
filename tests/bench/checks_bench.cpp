// grip_checks_bench: the cost of the step checks (solver/stepping/step_checks.hpp) on the shipped
// examples: each solved `repeats` times (default 3), the fastest run's whole solve and the time
// spent in the checks. Run by hand; the numbers go to bench/results/robustness.md.
//   build/tests/bench/grip_checks_bench [repeats]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "solver/io/scene.hpp"

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(std::string(GRIP_SOURCE_DIR) + "/schemas/examples"))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  double all = 0, checks = 0;
  std::printf("| example | solve (s) | checks (s) | share |\n|---|---|---|---|\n");
  for (const auto& f : files) {
    double best = 1e300, best_checks = 0;
    for (int k = 0; k < repeats; ++k) {
      grip::Scene scene = grip::read_scene_file(f.string());
      const grip::RunResult run = grip::run_load_steps(scene.problem, scene.steps, scene.params);
      if (run.seconds < best) {
        best = run.seconds;
        best_checks = run.check_seconds;
      }
    }
    all += best;
    checks += best_checks;
    std::printf("| %s | %.4f | %.5f | %.2f %% |\n", f.stem().c_str(), best, best_checks, 100 * best_checks / best);
  }
  std::printf("| all | %.4f | %.5f | %.2f %% |\n", all, checks, 100 * checks / all);
}
