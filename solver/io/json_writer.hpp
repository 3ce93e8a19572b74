#pragma once
// Writing large JSON documents (results of refined meshes) as they are made: a buffer written
// to the stream in blocks, numbers formatted without a JSON document or a stream call per number.
// Every double is written as the shortest decimal that reads back as the same double, with a
// point or an exponent (it reads back as a floating-point number); null where not finite.
#include <cstring>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace grip {

// The room write_number needs: its longest number is 24 characters ("-2.2250738585072014e-308").
constexpr int kMaxNumberChars = 40;
// v at `out` (kMaxNumberChars free); returns the number's end.
char* write_number(char* out, double v);

class JsonWriter {
 public:
  explicit JsonWriter(std::ostream& out);
  ~JsonWriter();  // writes what is buffered
  JsonWriter(const JsonWriter&) = delete;
  JsonWriter& operator=(const JsonWriter&) = delete;

  void raw(std::string_view text) {  // text as it is (keys quoted by the caller, punctuation)
    if (size_ + text.size() > buffer_.size()) return write_through(text);
    std::memcpy(buffer_.data() + size_, text.data(), text.size());
    size_ += text.size();
  }
  void put(char c) {
    room(1);
    buffer_[size_++] = c;
  }
  void number(double v) {
    room(kMaxNumberChars);
    size_ = static_cast<size_t>(write_number(buffer_.data() + size_, v) - buffer_.data());
  }
  void integer(long long v);
  void string(std::string_view s);  // quoted and escaped as nlohmann does
  // A small value (a step's summary, the scene): objects' keys in nlohmann's order (sorted),
  // numbers as number() and integer() write them.
  void value(const nlohmann::json& j);
  void flush();

 private:
  void write_through(std::string_view text);
  void room(size_t n) {
    if (size_ + n > buffer_.size()) flush();
  }
  std::ostream& out_;
  std::vector<char> buffer_;
  size_t size_ = 0;
};

}  // namespace grip
