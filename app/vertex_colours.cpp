#include "vertex_colours.hpp"

#include "render_colours.hpp"

#include "skinmesh/core/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace skinmesh::app {
namespace {

Rgb rgb(double r, double g, double b) {
  const auto byte = [](double x) { return static_cast<std::uint8_t>(std::lround(std::clamp(x, 0.0, 1.0) * 255)); };
  return {byte(r), byte(g), byte(b)};
}

Rgb mix(const Rgb& a, const Rgb& b, double w) {
  Rgb out;
  for (size_t k = 0; k < 3; ++k) out[k] = static_cast<std::uint8_t>(std::lround(a[k] + w * (b[k] - a[k])));
  return out;
}

// The palettes `render` draws with (render_colours.hpp), so that a picture
// and a file agree.
Rgb rgb(const Colour& c) { return rgb(c[0], c[1], c[2]); }
Rgb chain_rgb(size_t k) { return rgb(palette(k)); }
Rgb element_rgb(const std::string& element) { return rgb(element_colour(element)); }

Rgb patch_colour(int dim) {
  static const Rgb by_dim[] = {rgb(0.45, 0.65, 0.90), rgb(0.98, 0.80, 0.40), rgb(0.95, 0.55, 0.35),
                               rgb(0.85, 0.35, 0.40)};
  return by_dim[std::clamp(dim, 0, 3)];
}

// Blue at 0 through cyan, green and yellow to red at 1.
Rgb spectrum(double x) {
  const double hue = (1 - std::clamp(x, 0.0, 1.0)) * 240.0 / 60.0;  // sextant of the hue circle
  const double f = hue - std::floor(hue);
  switch (static_cast<int>(hue)) {
    case 0: return rgb(1, f, 0);
    case 1: return rgb(1 - f, 1, 0);
    case 2: return rgb(0, 1, f);
    case 3: return rgb(0, 1 - f, 1);
    default: return rgb(0, 0, 1);
  }
}

std::vector<Rgb> quality_colours(const SurfaceMesh& mesh) {
  std::vector<double> smallest(mesh.vertices.size(), 180.0);
  for (const auto& t : mesh.triangles) {
    double angle = 180;
    for (size_t k = 0; k < 3; ++k) {
      const Eigen::Vector3d& p = mesh.vertices[static_cast<size_t>(t[k])];
      const Eigen::Vector3d u = mesh.vertices[static_cast<size_t>(t[(k + 1) % 3])] - p;
      const Eigen::Vector3d w = mesh.vertices[static_cast<size_t>(t[(k + 2) % 3])] - p;
      angle = std::min(angle, std::atan2(u.cross(w).norm(), u.dot(w)) * 180.0 / M_PI);
    }
    for (int v : t) smallest[static_cast<size_t>(v)] = std::min(smallest[static_cast<size_t>(v)], angle);
  }
  const Rgb red = rgb(0.85, 0.20, 0.20), yellow = rgb(0.95, 0.85, 0.30), blue = rgb(0.30, 0.50, 0.90);
  std::vector<Rgb> out;
  for (double a : smallest)
    out.push_back(a <= 40 ? mix(red, yellow, std::clamp((a - 20) / 20, 0.0, 1.0))
                          : mix(yellow, blue, std::clamp((a - 40) / 20, 0.0, 1.0)));
  return out;
}

}  // namespace

const std::vector<std::string>& colouring_names() {
  static const std::vector<std::string> names{"none", "chain", "residue", "element", "patch", "quality"};
  return names;
}

Colouring colouring_from_name(const std::string& name) {
  const auto& names = colouring_names();
  const auto found = std::find(names.begin(), names.end(), name);
  if (found == names.end()) contract_error("--colour: '" + name + "' is none of none, chain, residue, element, patch, quality");
  return static_cast<Colouring>(found - names.begin());
}

bool colours_by_atom(Colouring c) {
  return c == Colouring::chain || c == Colouring::residue || c == Colouring::element;
}

std::vector<Rgb> atom_colours(Colouring c, const std::vector<Atom>& atoms) {
  std::vector<Rgb> out;
  if (!colours_by_atom(c)) return out;
  std::map<std::string, size_t> chains;
  std::map<std::tuple<std::string, int, char, std::string>, size_t> residues;
  for (const Atom& a : atoms) {
    chains.emplace(a.chain, chains.size());
    residues.emplace(std::make_tuple(a.chain, a.residue_number, a.insertion_code, a.residue), residues.size());
  }
  const double last = static_cast<double>(std::max<size_t>(residues.size(), 2) - 1);
  for (const Atom& a : atoms) {
    if (c == Colouring::chain) out.push_back(chain_rgb(chains.at(a.chain)));
    else if (c == Colouring::element) out.push_back(element_rgb(a.element));
    else
      out.push_back(spectrum(static_cast<double>(residues.at(std::make_tuple(a.chain, a.residue_number,
                                                                             a.insertion_code, a.residue))) /
                             last));
  }
  return out;
}

std::vector<Rgb> vertex_colours(Colouring c, const SurfaceMesh& mesh, const std::vector<int>& patch,
                                const std::vector<Rgb>& atom_colour) {
  switch (c) {
    case Colouring::none: return {};
    case Colouring::patch: {
      std::vector<Rgb> out;
      for (int d : patch) out.push_back(patch_colour(d));
      return out;
    }
    case Colouring::quality: return quality_colours(mesh);
    default: return atom_colour;
  }
}

}  // namespace skinmesh::app
