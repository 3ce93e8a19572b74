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
#include <fstream>
#include <memory>
#include <mutex>
#include <new>
#include <ostream>
#include <stdexcept>
#include <streambuf>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "solver/io/json_writer.hpp"
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

// The steps' texts, formatted part by part (step_parts): by the writer's thread while the
// solve runs, and after it by the thread that asks for them too, so that the last step's
// formatting is shared by both cores while the earlier steps are being written out.
class StepWriter {
 public:
  // With a path, the thread first opens the result file there: truncating an old result
  // (ext4 frees its blocks: 5-25 ms for 28 MB here) happens while the solve runs.
  explicit StepWriter(std::string path = {}) : path_(std::move(path)), opened_(path_.empty()), thread_([this] { run(); }) {}
  ~StepWriter() {
    {
      std::lock_guard lock(mutex_);
      done_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  StepWriter(const StepWriter&) = delete;
  StepWriter& operator=(const StepWriter&) = delete;

  void add(StepOutput output) {
    auto step = std::make_unique<Step>();
    step->output = std::move(output);
    step->parts = step_parts(step->output);
    step->pieces.resize(step->parts.size());
    {
      std::lock_guard lock(mutex_);
      steps_.push_back(std::move(step));
    }
    changed_.notify_all();
  }
  // Step k's text in pieces (their concatenation is write_step's text), formatting what is
  // left of it on this thread too. Valid while this writer lives; call from one thread.
  std::vector<std::string_view> text(size_t k) {
    std::unique_lock lock(mutex_);
    if (k >= steps_.size())
      throw std::logic_error("StepWriter: step " + std::to_string(k) + " was not handed over (" +
                             std::to_string(steps_.size()) + " were)");
    const Step& step = *steps_[k];
    while (step.formatted < step.parts.size())
      if (!format_next(lock, kCaller)) changed_.wait(lock);
    std::vector<std::string_view> pieces;
    for (const Piece& p : step.pieces) pieces.push_back(step.texts[p.text].view().substr(p.begin, p.end - p.begin));
    return pieces;
  }
  // The file opened on the thread (nullptr without a path), once it is open.
  std::ofstream* file() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return opened_; });
    return path_.empty() ? nullptr : &file_;
  }

 private:
  static constexpr int kThread = 0, kCaller = 1;  // whose text a part goes to
  struct Piece {
    int text = kThread;
    size_t begin = 0, end = 0;
  };
  struct Step {
    StepOutput output;
    std::vector<StepPart> parts;  // of output
    size_t claimed = 0, formatted = 0;  // parts [0, claimed) taken; how many are done
    std::vector<Piece> pieces;  // each part's text
    MappedText texts[2];  // the thread's and the caller's
  };

  // Formats the first part nobody has taken, if any (the lock is released meanwhile).
  bool format_next(std::unique_lock<std::mutex>& lock, int who) {
    while (next_ < steps_.size() && steps_[next_]->claimed == steps_[next_]->parts.size()) ++next_;
    if (next_ == steps_.size()) return false;
    Step& step = *steps_[next_];
    const size_t part = step.claimed++;
    lock.unlock();
    MappedText& text = step.texts[who];
    const size_t begin = text.view().size();
    {
      std::ostream out(&text);
      JsonWriter w(out);
      step.parts[part](w);
    }
    const Piece piece{who, begin, text.view().size()};
    lock.lock();
    step.pieces[part] = piece;
    ++step.formatted;
    changed_.notify_all();
    return true;
  }

  void run() {
    if (!path_.empty()) {
      file_.open(path_);
      std::lock_guard lock(mutex_);
      opened_ = true;
    }
    changed_.notify_all();
    std::unique_lock lock(mutex_);
    while (!done_)
      if (!format_next(lock, kThread)) changed_.wait(lock);
  }

  const std::string path_;
  std::ofstream file_;
  std::mutex mutex_;
  std::condition_variable changed_;  // a step added, a part formatted, the file opened, done
  std::vector<std::unique_ptr<Step>> steps_;  // a Step does not move while its parts are formatted
  size_t next_ = 0;  // the first step that may have a part nobody has taken
  bool opened_, done_ = false;
  std::thread thread_;  // last: started once the members it uses exist
};

}  // namespace grip
