#include "server/compression.hpp"

#include <zlib.h>
#include <zstd.h>

#include <memory>
#include <stdexcept>

namespace grip::server {

namespace {

// Level 1 for most results: the load run's small job (88.8 KB) to 14.9 KB at 400 MB/s, smaller
// and a fifth faster than level 3, zstd's default (15.1 KB at 320-350 MB/s); level 9: 1.1 ms,
// 13.2 KB, and a seventh of the server's time in a load run.
// Level 16, the optimal parser, some 100 ns a byte, for large results, whose steps repeat
// one another's numbers far apart: the sliding block's 482 KB to 39 KB (46 KB at level 9) in
// 40 ms of its 140 ms solve.
constexpr int kZstdLevel = 1, kZstdLargeLevel = 16;
constexpr size_t kLargeResult = 256 * 1024;
constexpr int kGzipWindow = 15 + 16;  // 32 KB window, gzip header and trailer

// ZSTD_compress writes the text's size in the frame's header.
std::string unzstd(std::string_view data) {
  const unsigned long long size = ZSTD_getFrameContentSize(data.data(), data.size());
  if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN)
    throw std::runtime_error("zstd: the data is not a zstd frame with its size");
  std::string out(size, '\0');
  const size_t n = ZSTD_decompress(out.data(), out.size(), data.data(), data.size());
  if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
  if (n != size) throw std::runtime_error("zstd: the frame is shorter than its header says");
  return out;
}

std::string gunzip(std::string_view data) {
  z_stream z{};
  if (inflateInit2(&z, kGzipWindow) != Z_OK) throw std::runtime_error("gunzip: cannot start zlib");
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  z.avail_in = static_cast<uInt>(data.size());
  std::string out;
  char buffer[1 << 16];
  int rc = Z_OK;
  while (rc == Z_OK) {
    z.next_out = reinterpret_cast<Bytef*>(buffer);
    z.avail_out = sizeof buffer;
    rc = inflate(&z, Z_NO_FLUSH);
    out.append(buffer, sizeof buffer - z.avail_out);
    if (rc == Z_BUF_ERROR && z.avail_in == 0) break;  // truncated
  }
  inflateEnd(&z);
  if (rc != Z_STREAM_END) throw std::runtime_error("gunzip: the data is not a whole gzip member");
  return out;
}

}  // namespace

std::string zstd(std::string_view text, int level) {
  std::string out(ZSTD_compressBound(text.size()), '\0');
  if (level == 0) level = text.size() >= kLargeResult ? kZstdLargeLevel : kZstdLevel;
  // One context per thread, kept: a new one per result allocated its tables (hundreds of KB)
  // every time.
  thread_local const std::unique_ptr<ZSTD_CCtx, decltype(&ZSTD_freeCCtx)> context(ZSTD_createCCtx(), ZSTD_freeCCtx);
  if (!context) throw std::runtime_error("zstd: cannot make a compression context");
  const size_t n = ZSTD_compressCCtx(context.get(), out.data(), out.size(), text.data(), text.size(), level);
  if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
  out.resize(n);
  return out;
}

std::string gzip_fast(std::string_view text) {
  z_stream z{};
  if (deflateInit2(&z, Z_BEST_SPEED, Z_DEFLATED, kGzipWindow, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw std::runtime_error("gzip: cannot start zlib");
  std::string out(deflateBound(&z, static_cast<uLong>(text.size())), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  z.avail_in = static_cast<uInt>(text.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw std::runtime_error("gzip: zlib did not finish");
  return out;
}

std::string stored_text(std::string_view stored) {
  if (is_zstd(stored)) return unzstd(stored);
  if (is_gzip(stored)) return gunzip(stored);
  return std::string(stored);
}

}  // namespace grip::server
