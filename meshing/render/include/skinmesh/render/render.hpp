// Pictures of a surface mesh without a display: orthographic view, the
// mesh fitted to the image, a z-buffer, per-vertex colours shaded by a
// light from the viewer's upper left (Lambert, with an ambient term).
#pragma once

#include "skinmesh/core/surface_mesh.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <ostream>
#include <vector>

namespace skinmesh {

using Colour = std::array<float, 3>;  // red, green, blue in [0, 1]

// Where the view is centred and its scale: the pictures of a movie share one,
// so that the camera stays still while the mesh moves.
struct ViewFit {
  double centre_x = 0, centre_y = 0;  // Angstrom, in the turned frame (x right, y up)
  double pixels_per_angstrom = 1;     // in the image's pixels
};

struct RenderOptions {
  int width = 800, height = 600;      // pixels
  double yaw = 30, pitch = -20;       // degrees: the view turned about the vertical, then the horizontal axis
  double margin = 0.05;               // of the image's smaller side, left around the mesh's outline
  Colour background{1.0f, 1.0f, 1.0f};
  Colour colour{0.62f, 0.74f, 0.88f}; // every vertex's, when no per-vertex colours are given
  std::optional<ViewFit> fit;         // empty: the mesh fitted to the image
};

// The fit that frames every one of the meshes, turned and with the margin
// of `options`. Throws ContractError when they have no vertex.
ViewFit fit_view(const std::vector<const SurfaceMesh*>& meshes, const RenderOptions& options);

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // row by row from the top, three bytes a pixel
  long covered = 0;               // pixels the mesh covers
  double pixels_per_angstrom = 0; // the scale the mesh was fitted at
};

// `colours`: one per vertex, or empty for options.colour. Throws
// ContractError for sizes outside 1..16384 or colours of another count.
Image render_mesh(const SurfaceMesh& mesh, const RenderOptions& options, const std::vector<Colour>& colours = {});

// PNG, 8-bit RGB. Throws OutputError when the stream fails.
void write_png(std::ostream& out, const Image& image);

}  // namespace skinmesh
