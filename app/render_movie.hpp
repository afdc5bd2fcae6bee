// skinmesh render MORPH_DIR --movie OUT.mp4: a movie of a morph without a
// display. Each picture is drawn by the project's rasteriser
// (skinmesh/render) at one camera for the whole movie; between two frames the
// vertices whose id both frames hold move on the straight line between their
// places and the two frames cross-fade (as the viewer shows them). The
// pictures are piped to ffmpeg (found on PATH when the command runs).
#pragma once

#include "skinmesh/render/render.hpp"

#include <string>

namespace skinmesh::app {

struct MovieOptions {
  std::string path;              // .mp4 (H.264) or .webm (VP9)
  double seconds = 5;            // the movie's length, t = first frame's to last frame's
  double fps = 25;               // pictures a second
  std::string colour = "patch";  // patch, age, uniform; chain or element from the morph's atom tables
  RenderOptions view;            // size and camera; its fit is set to frame every frame
};

// What can be checked before any work: the file's extension, even sizes
// (the encoders' 4:2:0 colour needs them), a colour the morph can give, and
// ffmpeg on PATH. Throws ContractError (a bad option) or Error (no ffmpeg).
void check_movie(const MovieOptions& o, const std::string& morph_dir);

struct MovieSummary {
  long pictures = 0;  // in the movie
  size_t frames = 0;  // of the morph
  std::string encoder;
};

// Writes the movie (all or nothing). Throws InputError for a bad directory,
// Error when ffmpeg fails.
MovieSummary write_movie(const MovieOptions& o, const std::string& morph_dir);

}  // namespace skinmesh::app
