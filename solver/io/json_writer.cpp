#include "solver/io/json_writer.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>

namespace grip {

// std::to_chars writes the shortest decimal that reads back as the double, "%g" style (fmt's compiled "{}"
// took 20 % longer here; its faster Dragonbox entry is not public API).
char* write_number(char* out, double v) {
  if (!std::isfinite(v)) {
    std::memcpy(out, "null", 4);
    return out + 4;
  }
  char* end = std::to_chars(out, out + kMaxNumberChars, v, std::chars_format::general).ptr;
  if (std::none_of(out, end, [](char c) { return c == '.' || c == 'e'; })) {  // "100" reads back as an integer
    std::memcpy(end, ".0", 2);
    end += 2;
  }
  return end;
}

JsonWriter::JsonWriter(std::ostream& out) : out_(out), buffer_(1 << 16) {}

JsonWriter::~JsonWriter() { flush(); }

void JsonWriter::flush() {
  out_.write(buffer_.data(), static_cast<std::streamsize>(size_));
  size_ = 0;
}

void JsonWriter::write_through(std::string_view text) {
  flush();
  if (text.size() > buffer_.size()) {
    out_.write(text.data(), static_cast<std::streamsize>(text.size()));
    return;
  }
  std::memcpy(buffer_.data(), text.data(), text.size());
  size_ = text.size();
}

void JsonWriter::integer(long long v) {
  room(24);
  size_ = static_cast<size_t>(std::to_chars(buffer_.data() + size_, buffer_.data() + buffer_.size(), v).ptr -
                              buffer_.data());
}

void JsonWriter::string(std::string_view s) {
  const bool plain = std::all_of(s.begin(), s.end(), [](char c) { return c >= 0x20 && c != '"' && c != '\\'; });
  if (!plain) {  // nlohmann's escaping (control characters, quotes, backslashes; invalid UTF-8 throws)
    raw(nlohmann::json(s).dump());
    return;
  }
  put('"');
  raw(s);
  put('"');
}

void JsonWriter::value(const nlohmann::json& j) {
  using T = nlohmann::json::value_t;
  switch (j.type()) {
    case T::object: {
      put('{');
      bool first = true;
      for (auto it = j.begin(); it != j.end(); ++it) {
        if (!first) put(',');
        first = false;
        string(it.key());
        put(':');
        value(it.value());
      }
      put('}');
      return;
    }
    case T::array: {
      put('[');
      for (size_t i = 0; i < j.size(); ++i) {
        if (i) put(',');
        value(j[i]);
      }
      put(']');
      return;
    }
    case T::number_float:
      number(j.get<double>());
      return;
    case T::number_integer:
      integer(j.get<long long>());
      return;
    case T::number_unsigned: {
      room(24);
      size_ = static_cast<size_t>(
          std::to_chars(buffer_.data() + size_, buffer_.data() + buffer_.size(), j.get<unsigned long long>()).ptr -
          buffer_.data());
      return;
    }
    case T::string:
      string(j.get_ref<const std::string&>());
      return;
    default:
      raw(j.dump());
      return;  // true, false, null; binary (never in a result)
  }
}

}  // namespace grip
