#pragma once
// Numbers in messages: %g, six significant digits, so that a small or a huge value shows its
// size (7.5e-09, 3e-07, 1e+296) where std::to_string's fixed six decimals read 0.000000 or a
// 300-digit number.
#include <cstdio>
#include <string>

namespace grip {

inline std::string number_text(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", x);
  return text;
}

}  // namespace grip
