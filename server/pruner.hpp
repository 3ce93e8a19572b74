#pragma once
// Retention: a thread that removes the finished jobs beyond the store's Retention every
// `interval` (each store hands the space back; docs/limits.md#results-on-disk). Every
// replica of a shared store may run one: removals of the same jobs are idempotent.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

#include "server/store.hpp"

namespace grip::server {

class Pruner {
 public:
  Pruner(Store& store, Retention retention, std::chrono::milliseconds interval);
  ~Pruner();
  Pruner(const Pruner&) = delete;
  Pruner& operator=(const Pruner&) = delete;

  // Jobs removed by this process so far.
  std::int64_t pruned() const { return pruned_; }

 private:
  void loop();

  Store& store_;
  const Retention retention_;
  const std::chrono::milliseconds interval_;
  std::atomic<std::int64_t> pruned_{0};
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace grip::server
