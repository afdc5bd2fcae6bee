#include "skinmesh/core/number_text.hpp"

#include <cstdio>

namespace skinmesh {

std::string exact_number_text(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

}  // namespace skinmesh
