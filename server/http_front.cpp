#include "server/http_front.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <functional>
#include <thread>
#include <vector>

namespace grip::server {
namespace {

using Clock = std::chrono::steady_clock;

thread_local ConnectionNote* t_note = nullptr;
thread_local bool t_reserved = false;  // this thread is one of the reserved ones

int millis_until(Clock::time_point t) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(t - Clock::now()).count();
  return static_cast<int>(std::clamp<long long>(ms, 0, 1 << 30));
}

// poll() for `events` up to `timeout_ms`, again after a signal; > 0 when ready.
int wait_for(int fd, short events, int timeout_ms) {
  pollfd p{fd, events, 0};
  const auto until = Clock::now() + std::chrono::milliseconds(timeout_ms);
  while (true) {
    const int n = ::poll(&p, 1, timeout_ms);
    if (n >= 0 || errno != EINTR) return n;  // POLLHUP and POLLERR count as ready: recv says
    timeout_ms = millis_until(until);
  }
}

std::string peer_address(int fd) {
  sockaddr_storage a{};
  socklen_t len = sizeof a;
  char text[INET6_ADDRSTRLEN] = "?";
  if (::getpeername(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0) {
    if (a.ss_family == AF_INET) ::inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(&a)->sin_addr, text, sizeof text);
    else if (a.ss_family == AF_INET6)
      ::inet_ntop(AF_INET6, &reinterpret_cast<sockaddr_in6*>(&a)->sin6_addr, text, sizeof text);
  }
  return text;
}

void address_and_port(int fd, bool peer, std::string& ip, int& port) {
  sockaddr_storage a{};
  socklen_t len = sizeof a;
  const int rc = peer ? ::getpeername(fd, reinterpret_cast<sockaddr*>(&a), &len)
                      : ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  if (rc != 0) return;
  char text[INET6_ADDRSTRLEN] = "";
  if (a.ss_family == AF_INET) {
    const auto* in = reinterpret_cast<sockaddr_in*>(&a);
    ::inet_ntop(AF_INET, &in->sin_addr, text, sizeof text);
    port = ntohs(in->sin_port);
  } else if (a.ss_family == AF_INET6) {
    const auto* in = reinterpret_cast<sockaddr_in6*>(&a);
    ::inet_ntop(AF_INET6, &in->sin6_addr, text, sizeof text);
    port = ntohs(in->sin6_port);
  }
  ip = text;
}

// A problem document written straight to the socket, for answers given outside httplib's
// request cycle (a refused connection, a request line that never ended). Best effort: the
// socket does not block.
void write_problem(int fd, int status, const char* reason, const std::string& slug, const std::string& detail,
                   int retry_after) {
  const nlohmann::json body = {{"type", "urn:grip:problem:" + slug},
                               {"title", reason},
                               {"status", status},
                               {"detail", detail},
                               {"errors", {{{"pointer", ""}, {"detail", detail}}}}};
  const std::string text = body.dump();
  std::string head = "HTTP/1.1 " + std::to_string(status) + " " + reason +
                     "\r\nContent-Type: application/problem+json\r\nConnection: close\r\n";
  if (retry_after > 0) head += "Retry-After: " + std::to_string(retry_after) + "\r\n";
  head += "Content-Length: " + std::to_string(text.size()) + "\r\n\r\n";
  const std::string all = head + text;
  (void)::send(fd, all.data(), all.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
}

// Closes after the answer. What the client sent and we did not read is read and dropped
// first: closing a socket with unread bytes resets the connection, and a client that writes
// its whole body before it reads (cpp-httplib's does) then sees a write error instead of the
// answer. Bounded: what has arrived (up to 1 MiB) and, waiting for it, up to `discard` bytes
// more (at most kMaxLingerBytes) within `patience`, 64 KiB at a time and nothing kept; it
// ends as soon as the client closes, and waits no more once `discard` bytes have arrived.
void close_connection(int fd, std::uint64_t discard = 0, std::chrono::milliseconds patience = {}) {
  ::shutdown(fd, SHUT_WR);
  char sink[65536];
  discard = std::min(discard, HttpFront::kMaxLingerBytes);
  std::uint64_t left = discard + (std::uint64_t{1} << 20), got = 0;
  const auto until = Clock::now() + patience;
  while (left > 0) {
    const ssize_t n = ::recv(fd, sink, sizeof sink, MSG_DONTWAIT);
    if (n > 0) {
      left -= std::min<std::uint64_t>(left, static_cast<std::uint64_t>(n));
      got += static_cast<std::uint64_t>(n);
      if (discard > 0 && Clock::now() >= until) break;
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    // Nothing more for now: wait only for the rest of an announced body, and not past `patience`.
    if (n == 0 || errno != EAGAIN || got >= discard || wait_for(fd, POLLIN, millis_until(until)) <= 0) break;
  }
  ::close(fd);
}

// One warning per kind and second at most; the lines not written are counted in the next.
class RateLimitedLog {
 public:
  template <class... Args>
  void warn(spdlog::format_string_t<Args...> fmt, Args&&... args) {
    std::lock_guard lock(mutex_);
    const auto now = Clock::now();
    if (now - last_ < std::chrono::seconds(1)) {
      ++suppressed_;
      return;
    }
    if (suppressed_ > 0) spdlog::warn("(and {} more like the next one in the last second)", suppressed_);
    suppressed_ = 0;
    last_ = now;
    spdlog::warn(fmt, std::forward<Args>(args)...);
  }

 private:
  std::mutex mutex_;
  Clock::time_point last_{};
  long suppressed_ = 0;
};

RateLimitedLog refused_log, slow_log;

// The socket under httplib's parser: reads against the request's deadline and counts the
// head's bytes and lines; writes wait for room up to the I/O timeout.
class GuardedStream final : public httplib::Stream {
 public:
  GuardedStream(int fd, ConnectionNote& note, int io_ms) : fd_(fd), note_(note), io_ms_(io_ms) {}

  void set_deadline(Clock::time_point t) { deadline_ = t; }
  void start_head() {
    head_bytes_ = 0;
    line_bytes_ = 0;
  }

  bool is_readable() const override {
    return pos_ < len_ || wait_for(fd_, POLLIN, std::min(io_ms_, millis_until(deadline_))) > 0;
  }

  // Used by a content provider (DataSink::is_writable) before each write: false once the
  // peer has closed (or shut down its side), else whether there is room within the timeout.
  bool is_writable() const override {
    pollfd p{fd_, POLLIN | POLLRDHUP | POLLOUT, 0};
    if (::poll(&p, 1, 0) > 0) {
      if (p.revents & (POLLRDHUP | POLLHUP | POLLERR)) return false;
      char c;
      if ((p.revents & POLLIN) && ::recv(fd_, &c, 1, MSG_PEEK | MSG_DONTWAIT) == 0) return false;
      if (p.revents & POLLOUT) return true;  // room now: no second poll
    }
    return wait_for(fd_, POLLOUT, io_ms_) > 0;
  }

  ssize_t read(char* out, size_t size) override {
    if (pos_ == len_) {
      // What has arrived is read at once; poll() only when nothing has (a system call less
      // per read: the request usually arrived before the thread got to it).
      ssize_t n = recv_now(buffer_, sizeof buffer_);
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        const int wait_ms = std::min(io_ms_, millis_until(deadline_));
        if (wait_for(fd_, POLLIN, wait_ms) <= 0) {
          if (Clock::now() >= deadline_) note_.deadline_missed = true;
          return -1;
        }
        n = recv_now(buffer_, sizeof buffer_);
      }
      if (n <= 0) return n;
      pos_ = 0;
      len_ = static_cast<size_t>(n);
    }
    size_t n = std::min(size, len_ - pos_);
    if (!note_.in_body) {
      // httplib reads the head a byte at a time: count its lines and its size.
      for (size_t i = 0; i < n; ++i) {
        line_bytes_ = buffer_[pos_ + i] == '\n' ? 0 : line_bytes_ + 1;
        if (line_bytes_ > HttpFront::kMaxLine) note_.line_too_long = true;
      }
      head_bytes_ += n;
      if (head_bytes_ > HttpFront::kMaxHead) {
        note_.head_too_large = true;
        return -1;
      }
    } else {
      note_.body_read += n;
    }
    std::memcpy(out, buffer_ + pos_, n);
    pos_ += n;
    return static_cast<ssize_t>(n);
  }

  // Sent at once where the socket has room; poll() for room (up to the I/O timeout) only when
  // it has none.
  ssize_t write(const char* data, size_t size) override {
    ssize_t n = send_now(data, size);
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      if (wait_for(fd_, POLLOUT, io_ms_) <= 0) return -1;
      n = send_now(data, size);
    }
    return n;
  }

  // Asked by httplib for every request: looked up once per connection.
  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    if (remote_port_ < 0) address_and_port(fd_, true, remote_ip_, remote_port_);
    ip = remote_ip_;
    port = remote_port_;
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    if (local_port_ < 0) address_and_port(fd_, false, local_ip_, local_port_);
    ip = local_ip_;
    port = local_port_;
  }
  socket_t socket() const override { return fd_; }
  bool has_buffered() const { return pos_ < len_; }

 private:
  int fd_;
  ConnectionNote& note_;
  int io_ms_;
  Clock::time_point deadline_ = Clock::time_point::max();
  char buffer_[4096];
  size_t pos_ = 0, len_ = 0;
  size_t head_bytes_ = 0, line_bytes_ = 0;
  mutable std::string remote_ip_, local_ip_;
  mutable int remote_port_ = -1, local_port_ = -1;

  ssize_t recv_now(char* out, size_t size) {
    ssize_t n;
    do n = ::recv(fd_, out, size, MSG_DONTWAIT);
    while (n < 0 && errno == EINTR);
    return n;
  }
  ssize_t send_now(const char* data, size_t size) {
    ssize_t n;
    do n = ::send(fd_, data, size, MSG_NOSIGNAL | MSG_DONTWAIT);
    while (n < 0 && errno == EINTR);
    return n;
  }
};

// httplib's task queue: a thread per connection, up to `max`; past them, connections go to
// the reserved threads (HttpFront::serve answers them briefly). The `max` threads are started
// at once, in the background, and kept: starting a thread costs 0.1 ms here, so a burst of
// 1,000 connections on a pool that grew on demand held the accept loop (and a /v1/health
// behind it) for 120-200 ms; 1,000 idle threads cost 11 MB.
class ConnectionThreads final : public httplib::TaskQueue {
 public:
  ConnectionThreads(int max, int reserved) : max_(max) {
    for (int i = 0; i < reserved; ++i)
      reserved_threads_.emplace_back([this] {
        t_reserved = true;
        run(overflow_, overflow_cv_, false);
      });
    starter_ = std::thread([this] {
      while (true) {  // the lock is let go between threads, so connections are served meanwhile
        std::lock_guard lock(mutex_);
        if (stopping_ || static_cast<int>(threads_.size()) >= max_) return;
        start_thread();
      }
    });
  }

  void enqueue(std::function<void()> fn) override {
    std::lock_guard lock(mutex_);
    if (idle_ > static_cast<int>(jobs_.size())) {
      jobs_.push_back(std::move(fn));
      cv_.notify_one();
    } else if (static_cast<int>(threads_.size()) < max_) {  // the starter has not got this far yet
      jobs_.push_back(std::move(fn));
      start_thread();
    } else {
      overflow_.push_back(std::move(fn));
      overflow_cv_.notify_one();
    }
  }

  void shutdown() override {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    starter_.join();
    cv_.notify_all();
    overflow_cv_.notify_all();
    for (auto& t : reserved_threads_) t.join();
    for (auto& t : threads_) t.join();  // no enqueue() and no starter after stopping_
  }

 private:
  // Holding mutex_. The thread counts as idle from here: enqueue() hands it a connection
  // even before it reaches its first wait (else that connection went to the reserved threads).
  void start_thread() {
    ++idle_;
    threads_.emplace_back([this] { run(jobs_, cv_, true); });
  }

  void run(std::deque<std::function<void()>>& queue, std::condition_variable& cv, bool pooled) {
    std::unique_lock lock(mutex_);
    while (true) {
      cv.wait(lock, [&] { return stopping_ || !queue.empty(); });
      if (pooled) --idle_;
      if (queue.empty()) break;  // stopping
      auto fn = std::move(queue.front());
      queue.pop_front();
      lock.unlock();
      fn();
      lock.lock();
      if (pooled) ++idle_;
    }
  }

  const int max_;
  std::mutex mutex_;
  std::condition_variable cv_, overflow_cv_;
  std::deque<std::function<void()>> jobs_, overflow_;
  std::vector<std::thread> threads_, reserved_threads_;
  std::thread starter_;
  int idle_ = 0;  // pool threads waiting for a connection
  bool stopping_ = false;
};

}  // namespace

HttpFront::HttpFront(FrontLimits limits) : limits_(limits) {
  const int max = std::max(2, limits_.max_connections);
  new_task_queue = [max] { return new ConnectionThreads(max, 2); };
  set_keep_alive_timeout(limits_.keep_alive_seconds);
  set_read_timeout(limits_.io_seconds);
  set_write_timeout(limits_.io_seconds);
}

HttpFront::~HttpFront() = default;

ConnectionNote* HttpFront::note() { return t_note; }

bool HttpFront::admit(const std::string& client) {
  std::lock_guard lock(clients_mutex_);
  int& n = clients_[client];
  if (n >= limits_.per_client) {
    if (n == 0) clients_.erase(client);
    return false;
  }
  ++n;
  return true;
}

void HttpFront::leave(const std::string& client) {
  std::lock_guard lock(clients_mutex_);
  const auto it = clients_.find(client);
  if (it != clients_.end() && --it->second <= 0) clients_.erase(it);
}

bool HttpFront::process_and_close_socket(socket_t sock) {
  ConnectionNote note;
  note.client = peer_address(sock);
  note.overflow = t_reserved;
  if (!admit(note.client)) {
    refused_log.warn("{}: connection refused: over {} open connections from this address", note.client,
                     limits_.per_client);
    write_problem(sock, 503, "Service Unavailable", "too-many-connections",
                  "this address has " + std::to_string(limits_.per_client) +
                      " connections open, this server's limit per client; retry later",
                  1);
    close_connection(sock);
    return false;
  }
  ++open_;
  t_note = &note;
  serve(sock, note);
  t_note = nullptr;
  --open_;
  leave(note.client);
  close_connection(sock, note.discard, limits_.body);
  return true;
}

void HttpFront::serve(socket_t sock, ConnectionNote& note) {
  // A reserved thread gives a connection one short request.
  const auto head_time = note.overflow ? std::min(limits_.head, std::chrono::milliseconds(500)) : limits_.head;
  GuardedStream stream(sock, note, limits_.io_seconds * 1000);
  // Requests a new connection or an idle one may still send on this one: httplib's count.
  size_t left = note.overflow ? 1 : keep_alive_max_count_;
  bool first = true;
  while (svr_sock_ != INVALID_SOCKET && left > 0) {
    // Wait for the next request: the head's time on a new connection, the keep-alive time
    // (in slices, to notice stop()) on an idle one.
    const auto until =
        Clock::now() + (first ? head_time : std::chrono::milliseconds(1000 * limits_.keep_alive_seconds));
    if (!first) ++idle_;
    bool ready = stream.has_buffered();
    while (!ready && svr_sock_ != INVALID_SOCKET && Clock::now() < until)
      ready = wait_for(sock, POLLIN, std::min(250, millis_until(until))) > 0;
    if (!first) --idle_;
    if (!ready) {
      if (first) {
        note.deadline_missed = true;
        slow_log.warn("{}: no request within {} ms of connecting; closed", note.client, head_time.count());
      }
      return;
    }
    ConnectionNote fresh;
    fresh.client = std::move(note.client);
    fresh.overflow = note.overflow;
    note = std::move(fresh);
    stream.start_head();
    stream.set_deadline(first ? until : Clock::now() + head_time);
    first = false;
    const bool close = left == 1 || note.overflow || idle_.load() >= limits_.max_idle || svr_sock_ == INVALID_SOCKET;
    bool closed = false;
    const bool served = process_request(stream, close, closed, [&](httplib::Request& req) {
      // The head is in: the body has its own deadline.
      note.in_body = true;
      stream.set_deadline(Clock::now() + limits_.body);
      note.restart_body_deadline = [&stream, this] { stream.set_deadline(Clock::now() + limits_.body); };
      // A DELETE (or OPTIONS) with neither length nor chunks has no body: httplib would
      // otherwise read one until the client closes.
      if (!req.has_header("Content-Length") && !req.has_header("Transfer-Encoding") && req.method != "POST" &&
          req.method != "PUT" && req.method != "PATCH")
        req.set_header("Content-Length", "0");
    });
    if (!served) {
      // Ended before httplib could answer: the request line never ended, or was too long.
      if (note.head_too_large)
        write_problem(sock, 414, "URI Too Long", "uri-too-long",
                      "the request line is over this server's limit of " + std::to_string(kMaxLine) + " bytes", 0);
      else if (note.deadline_missed && !note.in_body)
        write_problem(sock, 408, "Request Timeout", "request-timeout",
                      "the request head did not arrive within " + std::to_string(head_time.count()) + " ms", 0);
      if (note.deadline_missed || note.head_too_large)
        slow_log.warn("{}: request line {}; closed", note.client,
                      note.head_too_large ? "over the limit" : "not complete in time");
      return;
    }
    if (close || closed || note.close || note.deadline_missed || note.head_too_large || note.line_too_long) return;
    --left;
  }
}

}  // namespace grip::server
