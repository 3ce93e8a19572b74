#pragma once
// gzip (RFC 1952) through zlib: results are stored compressed and served as they are stored
// to clients that accept gzip (docs/limits.md#results-on-disk).
#include <string>
#include <string_view>

namespace grip::server {

std::string gzip(std::string_view text);
// The text of a gzip member; std::runtime_error when `data` is not one.
std::string gunzip(std::string_view data);
// Starts with gzip's magic number (JSON text never does).
inline bool is_gzip(std::string_view data) {
  return data.size() >= 2 && static_cast<unsigned char>(data[0]) == 0x1f && static_cast<unsigned char>(data[1]) == 0x8b;
}

}  // namespace grip::server
