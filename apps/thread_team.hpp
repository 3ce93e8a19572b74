#pragma once
// grip solve's threads for the solver's independent tasks (the bodies' own factorizations and
// solves), started once and kept for the whole solve. A thread started per parallel call (about
// 750 calls in the refined two cylinders, many of them one back-substitution per body) cost
// its start and join, and faulted in its stack and heap pages afresh every time: 5,300-5,700
// minor faults and 1,500 context switches against 540-690 and 1 with one thread, which ate most
// of what the second core saves.
#include <atomic>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace grip {

class ThreadTeam {
 public:
  // The calling thread and `threads - 1` helpers.
  explicit ThreadTeam(int threads) {
    for (int t = 1; t < threads; ++t) helpers_.emplace_back([this] { serve(); });
  }
  ~ThreadTeam() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (auto& h : helpers_) h.join();
  }
  ThreadTeam(const ThreadTeam&) = delete;
  ThreadTeam& operator=(const ThreadTeam&) = delete;

  // task(0) .. task(count - 1) on the team, the caller taking its share; returns when all are
  // done, rethrowing the first task's exception. A call from inside a task runs serially.
  void run(int count, const std::function<void(int)>& task) {
    if (inside_ || helpers_.empty()) {
      for (int k = 0; k < count; ++k) task(k);
      return;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      task_ = &task;
      count_ = count;
      next_ = 0;
      failed_ = false;
      failure_ = nullptr;
      busy_ = static_cast<int>(helpers_.size());
      ++generation_;
    }
    wake_.notify_all();
    work();
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return busy_ == 0; });  // every helper is past this call's tasks
    if (failure_) std::rethrow_exception(failure_);
  }

 private:
  void serve() {
    long seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
      }
      work();
      {
        std::lock_guard<std::mutex> lock(mutex_);
        --busy_;
      }
      done_.notify_one();
    }
  }

  void work() {
    inside_ = true;
    for (int k; (k = next_++) < count_;) try {
        (*task_)(k);
      } catch (...) {
        if (!failed_.exchange(true)) failure_ = std::current_exception();
      }
    inside_ = false;
  }

  std::vector<std::thread> helpers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  bool stop_ = false;
  long generation_ = 0;
  int busy_ = 0;
  const std::function<void(int)>* task_ = nullptr;
  int count_ = 0;
  std::atomic<int> next_{0};
  std::atomic<bool> failed_{false};
  std::exception_ptr failure_;
  static inline thread_local bool inside_ = false;
};

}  // namespace grip
