#include "server/tar.hpp"

#include <cstdio>
#include <cstring>
#include <ctime>
#include <stdexcept>

namespace grip::server {

std::string tar_archive(const std::vector<std::pair<std::string, std::string>>& files) {
  std::string out;
  const long mtime = static_cast<long>(std::time(nullptr));
  for (const auto& [path, content] : files) {
    if (path.size() > 99) throw std::invalid_argument("tar path too long: " + path);
    char h[512];
    std::memset(h, 0, sizeof h);
    std::memcpy(h, path.data(), path.size());
    std::snprintf(h + 100, 8, "%07o", 0644);  // mode
    std::snprintf(h + 108, 8, "%07o", 0);     // uid
    std::snprintf(h + 116, 8, "%07o", 0);     // gid
    std::snprintf(h + 124, 12, "%011lo", static_cast<unsigned long>(content.size()));
    std::snprintf(h + 136, 12, "%011lo", static_cast<unsigned long>(mtime));
    std::memset(h + 148, ' ', 8);      // checksum counts as spaces
    h[156] = '0';                      // regular file
    std::memcpy(h + 257, "ustar", 6);  // magic with NUL
    std::memcpy(h + 263, "00", 2);     // version
    unsigned sum = 0;
    for (unsigned char c : h) sum += c;
    std::snprintf(h + 148, 8, "%06o", sum);
    h[155] = ' ';
    out.append(h, sizeof h);
    out += content;
    out.append((512 - content.size() % 512) % 512, '\0');
  }
  out.append(1024, '\0');  // two zero blocks end the archive
  return out;
}

}  // namespace grip::server
