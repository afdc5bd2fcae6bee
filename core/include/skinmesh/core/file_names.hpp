// File-name helpers shared by the molecule and mesh readers (format by extension).
#pragma once

#include <algorithm>
#include <cctype>
#include <string>

namespace skinmesh {

inline std::string lowercase(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// Case-insensitive: has_extension("A.PDB", ".pdb") is true.
inline bool has_extension(const std::string& path, const std::string& extension) {
  const std::string name = lowercase(path);
  return name.size() >= extension.size() &&
         name.compare(name.size() - extension.size(), extension.size(), extension) == 0;
}

}  // namespace skinmesh
