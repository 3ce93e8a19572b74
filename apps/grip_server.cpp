// grip-server: the HTTP/JSON service and its health probe, an executable of its own so that
// `grip solve` does not load the service's libraries (libpq, cpp-httplib and their TLS chains:
// 30-40 ms of start-up per solve). Users type `grip serve` / `grip healthcheck`: grip runs this
// file's executable from its own directory with the same arguments.
//   grip-server serve [options]        (grip serve --help)
//   grip-server healthcheck [--host H] [--port P]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include "apps/process_tuning.hpp"
#include "server/serve.hpp"

namespace {

int serve(const std::vector<std::string>& args) {
  if (!args.empty() && (args[0] == "--help" || args[0] == "-h")) {
    std::fputs(grip::server::serve_usage().c_str(), stdout);
    return 0;
  }
  grip::server::ServeConfig config;
  try {
    config = grip::server::read_serve_config(args);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "grip serve: %s\n%s", e.what(), grip::server::serve_usage().c_str());
    return 2;
  }
  return grip::server::serve(config);
}

// grip serve runs without glibc's per-thread cache of freed blocks (tcache): a connection
// thread that read a large scene kept up to 7 blocks of each small size in it, scattered over
// the pages the scene's parse had used, and malloc_trim cannot return a page that holds one (8
// hostile 6 MB scenes left 26.8 MB against 21.6 MB idle; without the cache 19.6 MB). The cache
// is a tunable only (GLIBC_TUNABLES, read at start), so the server starts itself once more
// with it; a load run showed no change in CPU time per job (docs/limits.md#memory).
void without_thread_cache(char** argv) {
  const char* now = std::getenv("GLIBC_TUNABLES");
  const std::string before = now ? now : "";
  if (before.find("glibc.malloc.tcache_count") != std::string::npos) return;
  const std::string tunables = (before.empty() ? "" : before + ":") + "glibc.malloc.tcache_count=0";
  setenv("GLIBC_TUNABLES", tunables.c_str(), 1);
  execv("/proc/self/exe", argv);  // returns only on failure: then the server runs with the cache
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "serve") without_thread_cache(argv);
  grip::tune_process();
  const std::string command = argc > 1 ? argv[1] : "";
  const std::vector<std::string> args(argv + std::min(argc, 2), argv + argc);
  if (command == "serve") return serve(args);
  if (command == "healthcheck") return grip::server::healthcheck(args);
  std::fprintf(stderr,
               "usage: grip serve [options]   (grip serve --help)\n"
               "       grip healthcheck [--host H] [--port P]\n");
  return 2;
}
