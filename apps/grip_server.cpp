// grip-server: the HTTP/JSON service and its health probe, an executable of its own so that
// `grip solve` does not load the service's libraries (libpq, cpp-httplib and their TLS chains:
// 30-40 ms of start-up per solve). Users type `grip serve` / `grip healthcheck`: grip runs this
// file's executable from its own directory with the same arguments.
//   grip-server serve [options]        (grip serve --help)
//   grip-server healthcheck [--host H] [--port P]
#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

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

}  // namespace

int main(int argc, char** argv) {
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
