#pragma once
// Test support: a throwaway PostgreSQL cluster (Debian's `postgresql` package: initdb and
// pg_ctl) in a temporary folder on a free loopback port, run as an unprivileged user when the
// tests run as root, stopped and removed at the end. No mocks: the real server.
#include <netinet/in.h>
#include <pwd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

namespace grip::testing {

class PostgresCluster {
 public:
  // The newest installed server's programs, if any.
  static std::optional<std::filesystem::path> bin_dir() {
    namespace fs = std::filesystem;
    std::optional<fs::path> best;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator("/usr/lib/postgresql", ec))
      if (fs::exists(e.path() / "bin" / "initdb") && (!best || e.path() > best->parent_path())) best = e.path() / "bin";
    return best;
  }

  // Throws std::runtime_error (with the reason) when no cluster can be started.
  PostgresCluster() {
    namespace fs = std::filesystem;
    const auto bin = bin_dir();
    if (!bin) throw std::runtime_error("no PostgreSQL server installed (/usr/lib/postgresql/*/bin/initdb)");
    bin_ = *bin;
    std::string tmpl = (fs::temp_directory_path() / "grip-pg-XXXXXX").string();
    if (!mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
    dir_ = tmpl;
    if (getuid() == 0) {
      // initdb refuses root: the package's own user, else nobody.
      const passwd* pw = getpwnam("postgres");
      if (!pw) pw = getpwnam("nobody");
      if (!pw) throw std::runtime_error("no unprivileged user to run PostgreSQL as");
      as_user_ = std::string("runuser -u ") + pw->pw_name + " -- ";
      if (chown(dir_.c_str(), pw->pw_uid, pw->pw_gid) != 0) throw std::runtime_error("chown failed");
    }
    port_ = free_port();
    run(bin_ / "initdb", "-D " + data() + " -U grip -A trust -E UTF8 --no-sync > " + log("initdb") + " 2>&1");
    start();
  }
  ~PostgresCluster() {
    stop();
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  PostgresCluster(const PostgresCluster&) = delete;
  PostgresCluster& operator=(const PostgresCluster&) = delete;

  int port() const { return port_; }
  // A fresh database on this cluster; its URL.
  std::string new_database() {
    const std::string name = "t" + std::to_string(++databases_);
    run(bin_ / "createdb",
        "-h 127.0.0.1 -p " + std::to_string(port_) + " -U grip " + name + " >> " + log("createdb") + " 2>&1");
    return url(name);
  }
  std::string url(const std::string& database) const {
    return "postgresql://grip@127.0.0.1:" + std::to_string(port_) + "/" + database;
  }
  void start() {
    run(bin_ / "pg_ctl", "-D " + data() + " -l " + log("server") + " -w -t 60 -o \"-p " + std::to_string(port_) +
                             " -k " + dir_.string() +
                             " -c listen_addresses=127.0.0.1 -c max_connections=300\" start > " + log("pg_ctl") +
                             " 2>&1");
    running_ = true;
  }
  // `fast` disconnects every client at once (what an outage looks like to them).
  void stop() {
    if (!running_) return;
    run(bin_ / "pg_ctl", "-D " + data() + " -m fast -w stop >> " + log("pg_ctl") + " 2>&1", false);
    running_ = false;
  }
  std::string server_log() const { return dir_.string() + "/server.log"; }

 private:
  std::string data() const { return dir_.string() + "/data"; }
  std::string log(const char* name) const { return dir_.string() + "/" + name + ".log"; }
  void run(const std::filesystem::path& program, const std::string& args, bool check = true) {
    const std::string cmd = as_user_ + program.string() + " " + args;
    if (std::system(cmd.c_str()) != 0 && check) throw std::runtime_error("failed: " + cmd);
  }
  static int free_port() {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    socklen_t len = sizeof a;
    if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
        ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
      ::close(fd);
      throw std::runtime_error("no free port");
    }
    ::close(fd);
    return ntohs(a.sin_port);
  }

  std::filesystem::path bin_;
  std::filesystem::path dir_;
  std::string as_user_;
  int port_ = 0;
  int databases_ = 0;
  bool running_ = false;
};

}  // namespace grip::testing
