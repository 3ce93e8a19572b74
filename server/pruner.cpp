#include "server/pruner.hpp"

#include <spdlog/spdlog.h>

#include "server/util.hpp"

namespace grip::server {

Pruner::Pruner(Store& store, Retention retention, std::chrono::milliseconds interval)
    : store_(store), retention_(retention), interval_(interval) {
  thread_ = std::thread([this] { loop(); });
}

Pruner::~Pruner() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void Pruner::loop() {
  std::unique_lock lock(mutex_);
  while (!cv_.wait_for(lock, interval_, [&] { return stop_; })) {
    lock.unlock();
    try {
      const std::int64_t n = store_.prune(retention_, now_iso8601());
      pruned_ += n;
      if (n > 0) spdlog::info("retention: removed {} finished job(s)", n);
    } catch (const std::exception& e) {
      spdlog::warn("retention: cannot prune now: {}", e.what());
    }
    lock.lock();
  }
}

}  // namespace grip::server
