#include "skinmesh/core/radii.hpp"

#include <algorithm>
#include <cctype>

namespace skinmesh {

const std::vector<std::pair<std::string, double>>& bondi_table() {
  // Bondi (1964), Table I. Angstrom.
  static const std::vector<std::pair<std::string, double>> table = {
      {"H", 1.20},  {"HE", 1.40}, {"LI", 1.82}, {"C", 1.70},  {"N", 1.55},  {"O", 1.52},
      {"F", 1.47},  {"NE", 1.54}, {"NA", 2.27}, {"MG", 1.73}, {"SI", 2.10}, {"P", 1.80},
      {"S", 1.80},  {"CL", 1.75}, {"AR", 1.88}, {"K", 2.75},  {"NI", 1.63}, {"CU", 1.40},
      {"ZN", 1.39}, {"GA", 1.87}, {"AS", 1.85}, {"SE", 1.90}, {"BR", 1.85}, {"KR", 2.02},
      {"PD", 1.63}, {"AG", 1.72}, {"CD", 1.58}, {"IN", 1.93}, {"SN", 2.17}, {"TE", 2.06},
      {"I", 1.98},  {"XE", 2.16}, {"PT", 1.72}, {"AU", 1.66}, {"HG", 1.55}, {"TL", 1.96},
      {"PB", 2.02}, {"U", 1.86},
  };
  return table;
}

std::optional<double> bondi_radius(const std::string& element) {
  std::string key = element;
  std::transform(key.begin(), key.end(), key.begin(), [](unsigned char c) { return std::toupper(c); });
  if (key == "D") key = "H";  // deuterium
  for (const auto& [symbol, radius] : bondi_table())
    if (symbol == key) return radius;
  return std::nullopt;
}

}  // namespace skinmesh
