// grip: command line entry point.
//   grip solve SCENE.json [--out RESULT.json] [--events EVENTS.ndjson] [--threads N]
//   grip serve [options]        the HTTP/JSON service (grip serve --help)
//   grip healthcheck [--host H] [--port P]
//   grip mesh-info MESH.msh     what a gmsh mesh holds, as JSON (the service's answer to an upload)
//   grip mesh PART.geo [-o PART.msh] [--order 2]   meshes a geometry with the gmsh executable
// serve and healthcheck run grip-server (apps/grip_server.cpp) from grip's own directory, so
// that solving does not load the service's libraries.
// Exit codes of solve: 0 solved, 1 a step failed, 2 usage or scene error.
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "apps/process_tuning.hpp"
#include "apps/result_writer.hpp"
#include "apps/thread_team.hpp"
#include "solver/elements/continuum.hpp"
#include "solver/io/gmsh_mesh.hpp"
#include "solver/io/result.hpp"
#include "solver/io/schema_validation.hpp"

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: grip solve SCENE.json [--out RESULT.json] [--events EVENTS.ndjson] [--threads N]\n"
               "       grip serve [options]   (grip serve --help)\n"
               "       grip healthcheck [--host H] [--port P]\n"
               "       grip mesh-info MESH.msh\n"
               "       grip mesh PART.geo [-o PART.msh] [--order 2]\n");
  return 2;
}

// The solver's independent tasks (the bodies' own factorizations and solves) on up to `threads`
// threads, kept for the whole solve (apps/thread_team.hpp): the solver starts none of its own.
// Empty (one after another) for one thread.
grip::ParallelFor on_threads(int threads) {
  if (threads <= 1) return {};
  auto team = std::make_shared<grip::ThreadTeam>(threads);
  return [team](int count, const std::function<void(int)>& task) { team->run(count, task); };
}

int solve(int argc, char** argv) {
  std::string scene_path, out_path, events_path;
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--threads" && i + 1 < argc && std::atoi(argv[i + 1]) >= 1) threads = std::atoi(argv[++i]);
    else if ((a == "--out" || a == "--events") && i + 1 < argc) (a == "--out" ? out_path : events_path) = argv[++i];
    else if (!a.empty() && a[0] != '-' && scene_path.empty()) scene_path = a;
    else return usage();
  }
  if (scene_path.empty()) return usage();

  // Wall and CPU seconds of the phases around the solver (reading, writing), printed last.
  auto now = [] {
    timespec cpu;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu);
    return std::pair<double, double>{
        std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(),
        cpu.tv_sec + 1e-9 * cpu.tv_nsec};
  };
  const auto start = now();
  // The scene schema's validator (5 ms) is built on a thread while the scene is read and its
  // mesh generated; the reader validates last.
  std::jthread validator([] { grip::prepare_schema(grip::SchemaName::scene); });
  grip::Scene scene;
  try {
    scene = grip::read_scene_file(scene_path);
  } catch (const grip::SceneErrors& e) {
    std::fprintf(stderr, "%s: invalid scene\n", scene_path.c_str());
    for (const auto& issue : e.issues())
      std::fprintf(stderr, "  %s: %s\n", issue.pointer.c_str(), issue.detail.c_str());
    return 2;
  }

  std::ofstream events;
  if (!events_path.empty()) {
    events.open(events_path);
    if (!events) {
      std::fprintf(stderr, "cannot write %s\n", events_path.c_str());
      return 2;
    }
  }
  auto emit = [&](const nlohmann::json& ev) {
    // Flushed per event: a reader (tail -f) sees a long step as it runs (two cylinders with
    // uzawa wrote nothing for over 2 minutes).
    if (events.is_open()) events << ev.dump() << '\n' << std::flush;
  };
  std::printf("%5s %12s %6s %6s %6s %12s %7s %6s %6s %9s  %s\n", "step", "load_factor", "iters", "passes", "newton",
              "||v||_2", "contact", "stick", "slip", "ms", "status");
  // With --out, the result is written on a thread of its own while the solve runs: the members
  // known before it, then each finished step while the next one solves.
  std::optional<grip::ResultWriter> writer;
  if (!out_path.empty()) writer.emplace(out_path, scene);
  grip::SteppingObserver observer;
  observer.step_started = [&](int step, double lf) { emit(grip::step_started_event(step, lf)); };
  observer.iteration = [&](const grip::IterationEvent& ev) { emit(grip::iteration_event(ev)); };
  observer.step_finished = [&](const grip::StepRecord& rec) {
    emit(grip::step_finished_event(scene.problem, rec, scene.output));
    if (writer) writer->add_step(rec);
    const auto& last = rec.history.empty() ? grip::IterationEvent{} : rec.history.back();
    std::printf("%5d %12.6g %6d %6d %6d %12.3e %7d %6d %6d %9.2f  %s\n", rec.index, rec.load_factor, rec.solves,
                rec.passes, rec.newton_iterations, last.v2, last.stick + last.slip, last.stick, last.slip,
                rec.seconds * 1e3,
                rec.converged ? (rec.warning.empty() ? "converged" : ("converged; warning: " + rec.warning).c_str())
                              : rec.reason.c_str());
    std::fflush(stdout);
  };
  scene.params.newton.parallel = on_threads(threads);
  grip::assemble_on(*scene.problem.body, scene.params.newton.parallel);  // the continua's element kernels
  const auto read = now();
  const grip::RunResult run = grip::run_load_steps(scene.problem, scene.steps, scene.params, observer);
  const auto solved = now();
  emit(run.completed ? nlohmann::json{{"type", "job_finished"}}
                     : grip::job_failed_event(run.failure, run.reason, run.failure_step));
  std::printf("total: %ld contact iterations, %ld Newton iterations, %ld factorizations, %.3f s\n", run.counters.solves,
              run.counters.newton_iterations, run.counters.factorizations, run.seconds);
  if (writer) {  // the last step's text and the members the run decides
    if (!writer->finish(run)) {
      std::fprintf(stderr, "cannot write %s\n", out_path.c_str());
      return 2;
    }
  }
  const auto written = now();
  std::printf("read %.3f s (cpu %.3f), solve %.3f s (cpu %.3f), write %.3f s (cpu %.3f)\n", read.first - start.first,
              read.second - start.second, solved.first - read.first, solved.second - read.second,
              written.first - solved.first, written.second - solved.second);
  if (!run.completed) std::fprintf(stderr, "%s\n", run.reason.c_str());
  // The process ends here and its memory goes with it: no destructor runs, neither the scene's
  // and the run's (2 % of a refined Hertz run: 11,520 elements' fields of 10 steps) nor the
  // static ones std::exit would run (the schema validators: 1 M instructions). The result and
  // event files are closed and stdout flushed first; nothing else holds output.
  events.close();
  std::fflush(nullptr);
  std::_Exit(run.completed ? 0 : 1);
}

// mesh-info: gmsh_mesh_summary of a .msh file on stdout; a file grip cannot read: its reason, exit code 2.
int mesh_info(int argc, char** argv) {
  if (argc != 3) return usage();
  try {
    std::cout << grip::gmsh_mesh_summary(grip::read_gmsh_file(argv[2])).dump(2) << '\n';
    return 0;
  } catch (const grip::GmshError& e) {
    std::fprintf(stderr, "grip mesh-info: %s\n", e.what());
    return 2;
  }
}

// The gmsh executable on PATH, or "" (this command only: the service never runs gmsh, since a
// .geo can call the shell).
std::string find_gmsh() {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "";
  for (size_t start = 0; start <= dirs.size();) {
    const size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::string candidate = (end > start ? dirs.substr(start, end - start) : ".") + "/gmsh";
    struct stat st {};
    if (stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) && access(candidate.c_str(), X_OK) == 0)
      return candidate;
    start = end + 1;
  }
  return "";
}

// mesh: `gmsh PART.geo -2 -format msh41 [-order N] -o PART.msh` (gmsh's messages on stderr),
// then the file read back as the service would read it: its summary on stdout.
int mesh(int argc, char** argv) {
  std::string geo, out, order;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if ((a == "-o" || a == "--out") && i + 1 < argc) out = argv[++i];
    else if (a == "--order" && i + 1 < argc) order = argv[++i];
    else if (geo.empty() && !a.empty() && a[0] != '-') geo = a;
    else return usage();
  }
  if (geo.empty() || (!order.empty() && order != "1" && order != "2")) return usage();
  if (out.empty()) out = geo.substr(0, geo.size() - (geo.ends_with(".geo") ? 4 : 0)) + ".msh";
  if (access(geo.c_str(), R_OK) != 0) {
    std::fprintf(stderr, "grip mesh: cannot read %s: %s\n", geo.c_str(), std::strerror(errno));
    return 2;
  }
  const std::string gmsh = find_gmsh();
  if (gmsh.empty()) {
    std::fprintf(stderr,
                 "grip mesh: the gmsh executable is not on PATH; install Debian's gmsh (apt-get install gmsh), or "
                 "mesh %s with gmsh elsewhere and give grip the .msh file\n",
                 geo.c_str());
    return 2;
  }
  std::vector<std::string> args = {gmsh, geo, "-2", "-format", "msh41", "-o", out};
  if (!order.empty()) args.insert(args.end(), {"-order", order});
  std::vector<char*> cargv;
  for (std::string& a : args) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  std::remove(out.c_str());  // a file left from before is not this run's mesh
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, STDERR_FILENO, STDOUT_FILENO);  // stdout: the summary only
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, gmsh.c_str(), &actions, nullptr, cargv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    std::fprintf(stderr, "grip mesh: cannot run %s: %s\n", gmsh.c_str(), std::strerror(spawned));
    return 2;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || access(out.c_str(), R_OK) != 0) {
    std::fprintf(stderr, "grip mesh: gmsh did not mesh %s (%s; its messages are above)\n", geo.c_str(),
                 WIFEXITED(status) ? ("exit code " + std::to_string(WEXITSTATUS(status))).c_str() : "killed");
    return 2;
  }
  try {
    std::cout << grip::gmsh_mesh_summary(grip::read_gmsh_file(out)).dump(2) << '\n';
    std::fprintf(stderr, "grip mesh: wrote %s\n", out.c_str());
    return 0;
  } catch (const grip::GmshError& e) {
    std::fprintf(stderr, "grip mesh: gmsh wrote a mesh grip cannot solve: %s\n", e.what());
    return 2;
  }
}

// serve and healthcheck: grip-server next to this executable, with the same arguments.
int run_server(char** argv) {
  char self[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  std::string path = n > 0 ? std::string(self, n) : std::string(argv[0]);
  path = path.substr(0, path.find_last_of('/') + 1) + "grip-server";
  argv[0] = path.data();
  execv(path.c_str(), argv);
  std::fprintf(stderr, "grip %s: cannot run %s: %s\n", argv[1], path.c_str(), std::strerror(errno));
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  grip::tune_process();
  if (argc < 2) return usage();
  const std::string command = argv[1];
  if (command == "solve") {
    grip::heap_on_huge_pages();
    return solve(argc, argv);
  }
  if (command == "serve" || command == "healthcheck") return run_server(argv);
  if (command == "mesh-info") return mesh_info(argc, argv);
  if (command == "mesh") return mesh(argc, argv);
  return usage();
}
