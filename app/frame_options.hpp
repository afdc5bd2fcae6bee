// The options of the commands that write a directory of frames (morph,
// trajectory) about how the frames are written.
#pragma once

#include "commands.hpp"
#include "morph_frames.hpp"
#include "vertex_colours.hpp"

#include <CLI/CLI.hpp>

namespace skinmesh::app {

inline void add_frame_file_options(CLI::App& cmd, FrameFileOptions& o) {
  cmd.add_option("--format", o.formats,
                 "mesh formats, comma-separated: ply vtp off obj stl (a file per frame; frames.pvd needs vtp) and "
                 "glb (every frame in one frames.glb, played by its animation)")
      ->delimiter(',')->check(CLI::IsMember({"ply", "vtp", "off", "obj", "stl", "glb"}))->capture_default_str();
  cmd.add_flag("--ascii", o.ascii, "write the PLY and VTP frames as text (PyMOL 2.5 opens text PLY only)");
  cmd.add_option("--colour,--color", o.colour, colouring_help())
      ->check(CLI::IsMember(colouring_names()))->capture_default_str();
}

// --no-self-intersections, and --self-intersections: which pairs of a
// frame's triangles the exact test looks at.
inline void add_frame_crossing_options(CLI::App& cmd, FrameCrossingOptions& o) {
  CLI::Option* skip = cmd.add_flag("--no-self-intersections", o.skip, "skip the exact self-intersection check");
  cmd.add_option("--self-intersections", o.pairs,
                 "pairs of triangles the exact self-intersection check tests: changed (the first frame's all, then "
                 "those with a triangle that changed since the frame before) or all (every pair of every frame)")
      ->check(CLI::IsMember({"changed", "all"}))->capture_default_str()->excludes(skip);
}

}  // namespace skinmesh::app
