// The colours `render` gives a picture's vertices by chain and by element,
// shared by its PNGs and its movies.
#pragma once

#include "skinmesh/render/render.hpp"

#include <map>
#include <string>

namespace skinmesh::app {

// A colour per distinct key, from a palette that tells neighbours apart.
inline Colour palette(size_t k) {
  static const Colour colours[] = {{0.38f, 0.62f, 0.85f}, {0.95f, 0.62f, 0.30f}, {0.45f, 0.75f, 0.45f},
                                   {0.85f, 0.40f, 0.45f}, {0.65f, 0.52f, 0.80f}, {0.70f, 0.60f, 0.45f},
                                   {0.90f, 0.55f, 0.75f}, {0.60f, 0.60f, 0.60f}};
  return colours[k % (sizeof colours / sizeof colours[0])];
}

inline Colour element_colour(const std::string& element) {  // the usual CPK hues, softened
  static const std::map<std::string, Colour> known = {{"C", {0.72f, 0.72f, 0.72f}}, {"N", {0.40f, 0.52f, 0.92f}},
                                                      {"O", {0.92f, 0.38f, 0.35f}}, {"S", {0.95f, 0.85f, 0.35f}},
                                                      {"P", {0.98f, 0.60f, 0.25f}}, {"H", {0.95f, 0.95f, 0.95f}}};
  const auto found = known.find(element);
  return found != known.end() ? found->second : Colour{0.85f, 0.55f, 0.85f};
}

}  // namespace skinmesh::app
