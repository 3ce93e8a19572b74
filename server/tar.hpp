#pragma once
// A POSIX ustar archive of in-memory files: the VTK download is one response of many files.
#include <string>
#include <utility>
#include <vector>

namespace grip::server {

// (path, content) pairs; paths up to 100 characters.
std::string tar_archive(const std::vector<std::pair<std::string, std::string>>& files);

}  // namespace grip::server
