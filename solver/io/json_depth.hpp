#pragma once
// A bound on how deeply a JSON text nests, checked before parsing. nlohmann's parser takes
// any depth, but copying, dumping and validating a value recurse once per level: 100000
// nested arrays overflowed an HTTP thread's stack, and a few MB of '[' crash `grip solve`.
#include <string_view>

namespace grip {

inline constexpr int kMaxJsonDepth = 64;  // a scene needs about 8

// Whether `text` nests arrays and objects deeper than `limit` (strings skipped).
inline bool nested_deeper_than(std::string_view text, int limit) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > limit) return true;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return false;
}

}  // namespace grip
