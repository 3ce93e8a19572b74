#pragma once
// The fixed-size element kernels are templates on the element's node count; this turns the
// count known at run time into that template argument, once for every kernel.
#include <stdexcept>
#include <string>
#include <type_traits>

namespace grip {

// Calls kernel(std::integral_constant<int, N>{}) for N == nodes, N one of Counts; a count
// without a kernel is a programming error (the scene reader refuses such elements first).
template <int... Counts, class Kernel>
void with_node_count(int nodes, const char* kernel_name, Kernel&& kernel) {
  const bool found = ((nodes == Counts && (kernel(std::integral_constant<int, Counts>{}), true)) || ...);
  if (found) return;
  std::string counts;
  ((counts += (counts.empty() ? "" : ", ") + std::to_string(Counts)), ...);
  throw std::logic_error(std::string(kernel_name) + ": no element of " + std::to_string(nodes) +
                         " nodes (kernels for " + counts + ")");
}

}  // namespace grip
