#pragma once
// grip solve's result written to its file while the solve runs (the solver stays
// single-threaded, docs/design.md#principles): the head before the solve, each step as the solver's
// observer hands it over, the tail after the solve (solver/io/result.hpp: result_head_parts,
// result_step_parts, result_tail_parts). A thread of its own formats the parts into memory and
// writes each text to the file as soon as it and the ones before it are formatted, so after the
// solve only the last step and the tail are left. The bytes are write_result's.
//
// The texts are held in anonymous mappings with transparent huge pages asked for, reused once
// written: on this kind of virtual machine a page fault costs about 10 us, and 28 MB of text
// (Hertz a/h 40) in fresh 4 KiB pages took 0.1 s of system time, more than formatting it.
#include <sys/mman.h>

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <fstream>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <ostream>
#include <streambuf>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
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
  MappedText& operator=(MappedText&& o) noexcept {
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
    std::swap(capacity_, o.capacity_);
    return *this;
  }
  MappedText(const MappedText&) = delete;
  MappedText& operator=(const MappedText&) = delete;
  ~MappedText() override {
    if (data_) munmap(data_, capacity_);
  }
  std::string_view view() const { return {data_, size_}; }
  void clear() { size_ = 0; }  // the pages stay, to be written again

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

// A result's texts (lists of parts), formatted and written to its file in the order they are
// handed over: their parts by the writer's thread while the solve runs, and after it by the
// thread that calls finish too, so that the last step's formatting is shared by both cores.
class ResultWriter {
 public:
  // The result of `scene` into the file at `path`, its head first. The thread first opens the
  // file: truncating an old result (ext4 frees its blocks: 5-25 ms for 28 MB here) happens
  // while the solve runs.
  ResultWriter(std::string path, const Scene& scene)
      : path_(std::move(path)), scene_(scene), thread_([this] { run(); }) {
    add(result_head_parts(scene_));
  }
  // Without finish, what was not yet written is left out.
  ~ResultWriter() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  ResultWriter(const ResultWriter&) = delete;
  ResultWriter& operator=(const ResultWriter&) = delete;

  // A finished step (from the solver's observer): its output is copied here, formatted and
  // written on the thread.
  void add_step(const StepRecord& rec) {
    auto step = std::make_shared<const StepOutput>(step_output(scene_.problem, rec, scene_.output));
    add(result_step_parts(*step, static_cast<size_t>(rec.index - 1)), step);
  }
  // The run's end: formats what is left on this thread too (the last step, the tail), and
  // returns once everything is in the file and the file closed: whether it was written.
  bool finish(const RunResult& run) {
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [this] { return effects_.has_value(); });
    }
    add(result_tail_parts(std::move(*effects_), run));
    std::unique_lock lock(mutex_);
    finishing_ = true;
    changed_.notify_all();
    while (!closed_)
      if (!format_next(lock, kCaller)) changed_.wait(lock);
    return written_;
  }

 private:
  static constexpr int kThread = 0, kCaller = 1;  // whose memory a part's text goes to
  struct Piece {
    int text = kThread;
    size_t begin = 0, end = 0;
  };
  struct Text {
    std::vector<ResultPart> parts;
    std::shared_ptr<const void> keep;
    size_t claimed = 0, formatted = 0;  // parts [0, claimed) taken; how many are done
    std::vector<Piece> pieces;          // each part's text
    MappedText texts[2];                // the thread's and the caller's
  };

  // A text written after the ones handed over before; `keep` holds what its parts refer to
  // until it is written.
  void add(std::vector<ResultPart> parts, std::shared_ptr<const void> keep = {}) {
    auto text = std::make_unique<Text>();
    text->parts = std::move(parts);
    text->keep = std::move(keep);
    text->pieces.resize(text->parts.size());
    {
      std::lock_guard lock(mutex_);
      for (MappedText& t : text->texts)
        if (!spare_.empty()) {
          t = std::move(spare_.back());
          spare_.pop_back();
        }
      texts_.push_back(std::move(text));
    }
    changed_.notify_all();
  }
  // Formats the first part nobody has taken, if any (the lock is released meanwhile).
  bool format_next(std::unique_lock<std::mutex>& lock, int who) {
    auto it = std::find_if(texts_.begin(), texts_.end(), [](const auto& t) { return t->claimed < t->parts.size(); });
    if (it == texts_.end()) return false;
    Text& text = **it;  // not written (nor moved) before its parts are formatted
    const size_t part = text.claimed++;
    lock.unlock();
    MappedText& memory = text.texts[who];
    const size_t begin = memory.view().size();
    {
      std::ostream out(&memory);
      JsonWriter w(out);
      text.parts[part](w);
    }
    const Piece piece{who, begin, memory.view().size()};
    lock.lock();
    text.pieces[part] = piece;
    ++text.formatted;
    changed_.notify_all();
    return true;
  }

  // Writes the first text if it is formatted, and keeps its memory for the next ones.
  bool write_first(std::unique_lock<std::mutex>& lock) {
    if (texts_.empty() || texts_.front()->formatted < texts_.front()->parts.size()) return false;
    std::unique_ptr<Text> text = std::move(texts_.front());
    texts_.pop_front();
    lock.unlock();
    for (const Piece& p : text->pieces) file_.write(text->texts[p.text].view().data() + p.begin, p.end - p.begin);
    text->parts.clear();
    text->keep.reset();  // the step's tables
    lock.lock();
    for (MappedText& t : text->texts) {
      t.clear();
      spare_.push_back(std::move(t));
    }
    return true;
  }

  void run() {
    file_.open(path_);
    nlohmann::json effects =
        effects_json(scene_);  // while the solve runs (the element quality: 2.9 M instructions at Hertz a/h 20)
    std::unique_lock lock(mutex_);
    effects_ = std::move(effects);
    changed_.notify_all();
    while (!stop_) {
      if (write_first(lock) || format_next(lock, kThread)) continue;
      if (finishing_ && texts_.empty()) {
        file_.close();
        written_ = !file_.fail();
        closed_ = true;
        changed_.notify_all();
        return;
      }
      changed_.wait(lock);
    }
  }

  const std::string path_;
  const Scene& scene_;
  std::ofstream file_;  // the thread's
  std::mutex mutex_;
  std::condition_variable changed_;  // the effects made, a text added, a part formatted, finishing, closed, stop
  std::deque<std::unique_ptr<Text>> texts_;  // not yet written, in order
  std::vector<MappedText> spare_;            // written texts' memory
  std::optional<nlohmann::json> effects_;    // effects_json(scene), made on the thread
  bool finishing_ = false, closed_ = false, written_ = false, stop_ = false;
  std::thread thread_;  // last: started once the members it uses exist
};

}  // namespace grip
