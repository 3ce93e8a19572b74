#include "server/body_budget.hpp"

#include <malloc.h>

#include <algorithm>

namespace grip::server {

std::optional<BodyBudget::Hold> BodyBudget::take(std::size_t bytes, std::chrono::milliseconds patience) {
  std::unique_lock lock(mutex_);
  // Larger than the whole budget: alone.
  const std::size_t need = std::min(bytes, total_);
  ++waiting_;
  const bool got = freed_.wait_for(lock, patience, [&] { return used_ + need <= total_; });
  --waiting_;
  if (!got) return std::nullopt;
  used_ += need;
  return Hold(this, need);
}

void BodyBudget::give_back(std::size_t bytes) {
  {
    std::lock_guard lock(mutex_);
    used_ -= bytes;
  }
  freed_.notify_all();
}

std::size_t BodyBudget::in_use() const {
  std::lock_guard lock(mutex_);
  return used_;
}

std::size_t BodyBudget::waiting() const {
  std::lock_guard lock(mutex_);
  return waiting_;
}

BodyBudget::Hold::~Hold() {
  if (!budget_) return;
  budget_->give_back(bytes_);
  // glibc keeps what the parse freed in this thread's arena; 8 large submissions left 5 GB
  // resident until restart.
  if (bytes_ >= kTrimAbove) malloc_trim(0);
}

}  // namespace grip::server
