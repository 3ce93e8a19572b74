#pragma once
// A bound on the memory that submitted scenes take while they are read and checked: each
// submission holds its body's length of a byte budget from before its body is read until its
// answer is built, and waits while the budget is spent. Parsing and checking a scene takes
// about 30 times its text (its parsed JSON, the reader's copy, the checks; docs/limits.md#memory),
// so the process's peak stays near 30 x budget whatever the number of clients; a body larger
// than the whole budget is let in alone. Each large submission's end hands its freed memory back to the system (malloc_trim),
// where glibc would keep it in its per-thread arenas.
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <optional>

namespace grip::server {

class BodyBudget {
 public:
  explicit BodyBudget(std::size_t bytes) : total_(bytes) {}

  class Hold {
   public:
    Hold(Hold&& other) noexcept : budget_(other.budget_), bytes_(other.bytes_) { other.budget_ = nullptr; }
    Hold(const Hold&) = delete;
    Hold& operator=(const Hold&) = delete;
    Hold& operator=(Hold&&) = delete;
    ~Hold();

   private:
    friend class BodyBudget;
    Hold(BodyBudget* budget, std::size_t bytes) : budget_(budget), bytes_(bytes) {}
    BodyBudget* budget_;
    std::size_t bytes_;
  };

  // `bytes` of the budget, waiting up to `patience` for them; nullopt when they did not free.
  std::optional<Hold> take(std::size_t bytes, std::chrono::milliseconds patience);

  std::size_t total() const { return total_; }
  std::size_t in_use() const;
  std::size_t waiting() const;

  // A submission at least this large gives its memory back to the system when it ends.
  static constexpr std::size_t kTrimAbove = 1u << 20;

 private:
  void give_back(std::size_t bytes);

  const std::size_t total_;
  mutable std::mutex mutex_;
  std::condition_variable freed_;
  std::size_t used_ = 0;
  std::size_t waiting_ = 0;
};

}  // namespace grip::server
