#pragma once
// grip solve's result steps written on a thread of their own while the next step solves (the
// solver stays single-threaded, DESIGN.md): the solver's observer hands each finished step's
// output over, the thread formats it into memory, and write_result puts the texts in place
// after the solve (the result's head, written first, needs the run's counters). The bytes are
// those of write_result(out, scene, run).
//
// The texts are held in anonymous mappings with transparent huge pages asked for: on this
// kind of virtual machine a page fault costs about 10 us, and 28 MB of text (Hertz a/h 40) in
// 4 KiB pages took 0.1 s of system time, more than formatting it.
#include <sys/mman.h>

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <mutex>
#include <new>
#include <ostream>
#include <streambuf>
#include <string_view>
#include <thread>
#include <vector>

#include "solver/io/result.hpp"

namespace grip {

// A growing text in an anonymous mapping (mremap moves it without copying pages).
class MappedText : public std::streambuf {
 public:
  MappedText() = default;
  MappedText(MappedText&& o) noexcept : data_(o.data_), size_(o.size_), capacity_(o.capacity_) {
    o.data_ = nullptr;
    o.size_ = o.capacity_ = 0;
  }
  MappedText(const MappedText&) = delete;
  MappedText& operator=(const MappedText&) = delete;
  ~MappedText() override {
    if (data_) munmap(data_, capacity_);
  }
  std::string_view view() const { return {data_, size_}; }

 protected:
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    reserve(size_ + n);
    std::memcpy(data_ + size_, s, n);
    size_ += n;
    return n;
  }
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    const char ch = traits_type::to_char_type(c);
    xsputn(&ch, 1);
    return c;
  }

 private:
  static constexpr size_t kHuge = size_t{2} << 20;
  void reserve(size_t n) {
    if (n <= capacity_) return;
    const size_t capacity = std::max(2 * capacity_, (n + kHuge - 1) / kHuge * kHuge);
    void* p = data_ ? mremap(data_, capacity_, capacity, MREMAP_MAYMOVE)
                    : mmap(nullptr, capacity, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    madvise(p, capacity, MADV_HUGEPAGE);  // a hint: without it, 4 KiB pages
    data_ = static_cast<char*>(p);
    capacity_ = capacity;
  }
  char* data_ = nullptr;
  size_t size_ = 0, capacity_ = 0;
};

class StepWriter {
 public:
  StepWriter() : thread_([this] { run(); }) {}
  ~StepWriter() { finish(); }
  StepWriter(const StepWriter&) = delete;
  StepWriter& operator=(const StepWriter&) = delete;

  void add(StepOutput step) {
    {
      std::lock_guard lock(mutex_);
      queue_.push_back(std::move(step));
    }
    ready_.notify_one();
  }
  // Waits for the steps handed over; their texts in order, valid while this writer lives.
  std::vector<std::string_view> finish() {
    {
      std::lock_guard lock(mutex_);
      done_ = true;
    }
    ready_.notify_one();
    if (thread_.joinable()) thread_.join();
    std::vector<std::string_view> views;
    for (const MappedText& t : texts_) views.push_back(t.view());
    return views;
  }

 private:
  void run() {
    for (;;) {
      StepOutput step;
      {
        std::unique_lock lock(mutex_);
        ready_.wait(lock, [this] { return done_ || !queue_.empty(); });
        if (queue_.empty()) return;
        step = std::move(queue_.front());
        queue_.pop_front();
      }
      texts_.emplace_back();  // texts_: this thread's until finish joins it
      std::ostream out(&texts_.back());
      write_step(out, step);
    }
  }

  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<StepOutput> queue_;
  bool done_ = false;
  std::deque<MappedText> texts_;  // a deque: a text's streambuf does not move while written
  std::thread thread_;  // last: started once the members it uses exist
};

}  // namespace grip
