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
  cmd.add_flag("--ascii", o.ascii, "write the PLY frames as text (PyMOL 2.5 opens text PLY only)");
  cmd.add_option("--colour,--color", o.colour, colouring_help())
      ->check(CLI::IsMember(colouring_names()))->capture_default_str();
}

}  // namespace skinmesh::app
