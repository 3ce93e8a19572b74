#include "solver/io/json_writer.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>

// fmt comes with spdlog (Debian's libspdlog-dev is built on libfmt-dev). Its Dragonbox gives the
// shortest decimal significand and exponent that read back as the double in about a third of
// std::to_chars's instructions (libstdc++ 12: ~530 per double, most of a refined result's writing).
#include <fmt/format.h>

namespace grip {

namespace {

// "00".."99": two digits per division.
constexpr char kDigitPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

constexpr uint64_t kPowersOf10[20] = {1ull, 10ull, 100ull, 1000ull, 10000ull, 100000ull, 1000000ull,
                                      10000000ull, 100000000ull, 1000000000ull, 10000000000ull,
                                      100000000000ull, 1000000000000ull, 10000000000000ull,
                                      100000000000000ull, 1000000000000000ull, 10000000000000000ull,
                                      100000000000000000ull, 1000000000000000000ull,
                                      10000000000000000000ull};

int digit_count(uint64_t s) {
  const int n = ((64 - __builtin_clzll(s | 1)) * 1233) >> 12;  // log10(2) ~ 1233 / 4096
  return n + (s >= kPowersOf10[n]);
}

// Four digits of v < 10000 at out[0, 4).
void write_four(char* out, uint32_t v) {
  std::memcpy(out, kDigitPairs + 2 * (v / 100), 2);
  std::memcpy(out + 2, kDigitPairs + 2 * (v % 100), 2);
}

// The n decimal digits of s at out[0, n): four at a time, in 32-bit arithmetic below 10^8.
void write_digits(char* out, uint64_t s, int n) {
  char* end = out + n;
  if (n > 8) {
    const uint32_t low = static_cast<uint32_t>(s % 100000000);
    s /= 100000000;
    write_four(end - 4, low % 10000);
    write_four(end - 8, low / 10000);
    end -= 8;
    n -= 8;
  }
  uint32_t high = static_cast<uint32_t>(s);
  for (; n >= 4; n -= 4, high /= 10000) {
    end -= 4;
    write_four(end, high % 10000);
  }
  if (n >= 2) {
    end -= 2;
    std::memcpy(end, kDigitPairs + 2 * (high % 100), 2);
    high /= 100;
    n -= 2;
  }
  if (n) *--end = static_cast<char>('0' + high);
}

}  // namespace

// The copies below are of fixed sizes (the compiler makes them a few moves, no library call):
// they may write scratch beyond the number's end, within kMaxNumberChars.
char* write_number(char* out, double v) {
  if (!std::isfinite(v)) {
    std::memcpy(out, "null", 4);
    return out + 4;
  }
  if (std::signbit(v)) {
    *out++ = '-';
    v = -v;
  }
  if (v == 0) {
    std::memcpy(out, "0.0", 3);
    return out + 3;
  }
  const auto dec = fmt::detail::dragonbox::to_decimal(v);  // v = significand x 10^exponent, shortest
  const int n = digit_count(dec.significand);  // at most 17
  const int point = n + dec.exponent;          // v = 0.d1 d2 ... dn x 10^point
  if (point > 0 && point <= 17) {              // fixed: ddd.ddd or ddd000.0
    if (point >= n) {
      write_digits(out, dec.significand, n);
      std::memset(out + n, '0', 17);
      out += point;
      std::memcpy(out, ".0", 2);
      return out + 2;
    }
    char digits[40] = {};
    write_digits(digits, dec.significand, n);
    std::memcpy(out, digits, 17);
    out[point] = '.';
    std::memcpy(out + point + 1, digits + point, 16);
    return out + n + 1;
  }
  if (point <= 0 && point > -5) {  // fixed: 0.000ddd
    std::memcpy(out, "0.00000", 8);
    write_digits(out + 2 - point, dec.significand, n);
    return out + 2 - point + n;
  }
  // scientific: d.ddde-07, de+22 (two exponent digits at least, as printf and to_chars write)
  write_digits(out + 1, dec.significand, n);
  out[0] = out[1];
  out[1] = '.';
  out += n > 1 ? n + 1 : 1;
  int e = point - 1;
  *out++ = 'e';
  *out++ = e < 0 ? '-' : '+';
  if (e < 0) e = -e;
  if (e >= 100) {
    *out++ = static_cast<char>('0' + e / 100);
    e %= 100;
  }
  std::memcpy(out, kDigitPairs + 2 * e, 2);
  return out + 2;
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
    case T::number_float: number(j.get<double>()); return;
    case T::number_integer: integer(j.get<long long>()); return;
    case T::number_unsigned: {
      room(24);
      size_ = static_cast<size_t>(
          std::to_chars(buffer_.data() + size_, buffer_.data() + buffer_.size(), j.get<unsigned long long>()).ptr -
          buffer_.data());
      return;
    }
    case T::string: string(j.get_ref<const std::string&>()); return;
    default: raw(j.dump()); return;  // true, false, null; binary (never in a result)
  }
}

}  // namespace grip
