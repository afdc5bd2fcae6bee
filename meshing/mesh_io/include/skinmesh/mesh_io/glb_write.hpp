// glTF 2.0 binary (.glb): one mesh, or the frames of a morph as one file
// whose animation shows one frame at a time. Positions and normals go out
// as 32-bit floats (glTF has no doubles), triangles as 32-bit indices.
#pragma once

#include "skinmesh/core/surface_mesh.hpp"
#include "skinmesh/mesh_io/mesh_write.hpp"

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace skinmesh {

// A frame as the file holds it, made compact as soon as the frame is done so
// that a long morph keeps only this much of each frame until it is written.
struct GlbFrame {
  std::vector<float> positions;        // x y z per vertex, Angstrom
  std::vector<float> normals;          // unit, per vertex; empty when the mesh has none
  std::vector<std::uint8_t> colours;   // linear RGBA per vertex; empty: none
  std::vector<std::uint32_t> indices;  // three per triangle, counter-clockwise from outside
  std::string name;                    // the node's name ("frame_0003")
  double seconds = 0;                  // when the animation shows it (frames only)
};

// `colours`: sRGB per vertex, or empty.
GlbFrame glb_frame(const SurfaceMesh& mesh, const std::vector<Rgb>& colours, const std::string& name = "skin",
                   double seconds = 0);

// One frame: a scene of one node. Several: a node per frame, each visible
// (scale 1) from its `seconds` to the next frame's and scaled to 0
// otherwise, by an animation of STEP samplers on the nodes' scale; the
// frames' seconds must increase. Throws ContractError for no frame.
void write_glb(std::ostream& out, const std::vector<GlbFrame>& frames, const std::string& generator = "skinmesh");

}  // namespace skinmesh
