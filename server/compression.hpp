#pragma once
// Stored results (docs/limits.md#results-on-disk): compressed with zstd (libzstd) and served as
// stored to clients that accept zstd. Results stored by earlier versions, gzip-compressed or as
// JSON text, are still read.
#include <string>
#include <string_view>

namespace grip::server {

// zstd at level 3, or 16 (its optimal parser) for a text of 256 KiB or more: a result's steps
// repeat one another's numbers at distances gzip's 32 KB window cannot reach.
// `level` other than 0: that level (an uploaded mesh: 3, some 300 MB/s, where 16 would take
// a minute for a 64 MiB file).
std::string zstd(std::string_view text, int level = 0);
// gzip (RFC 1952) at zlib's fastest level: a stored result sent to a client that accepts gzip
// but not zstd (httplib's own compression would pick brotli at its slowest quality).
std::string gzip_fast(std::string_view text);
// The JSON text of a stored result, whichever of the three forms it has; std::runtime_error
// when compressed data is not whole.
std::string stored_text(std::string_view stored);
inline bool is_zstd(std::string_view data) {
  return data.size() >= 4 && static_cast<unsigned char>(data[0]) == 0x28 &&
         static_cast<unsigned char>(data[1]) == 0xb5 && static_cast<unsigned char>(data[2]) == 0x2f &&
         static_cast<unsigned char>(data[3]) == 0xfd;
}
// Starts with gzip's magic number (JSON text never does).
inline bool is_gzip(std::string_view data) {
  return data.size() >= 2 && static_cast<unsigned char>(data[0]) == 0x1f && static_cast<unsigned char>(data[1]) == 0x8b;
}

}  // namespace grip::server
