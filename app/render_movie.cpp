#include "render_movie.hpp"

#include "interrupt.hpp"
#include "output_file.hpp"
#include "render_colours.hpp"
#include "view_input.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/mesh_io/mesh_read.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unordered_map>

namespace skinmesh::app {
namespace {

namespace fs = std::filesystem;

std::string find_ffmpeg() {
  const char* path = std::getenv("PATH");
  std::istringstream folders(path ? path : "");
  for (std::string folder; std::getline(folders, folder, ':');) {
    const fs::path candidate = fs::path(folder.empty() ? "." : folder) / "ffmpeg";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  throw Error("render --movie needs ffmpeg, and none is on PATH (Debian: apt-get install ffmpeg); nothing written");
}

bool ends_with(const std::string& s, const std::string& end) {
  return s.size() >= end.size() && s.compare(s.size() - end.size(), end.size(), end) == 0;
}

struct MovieFrame {
  double t = 0;
  SurfaceMesh mesh;
  std::vector<double> ids;                       // empty when the frame has none
  std::unordered_map<double, size_t> index;      // id -> vertex
  std::vector<Colour> colours;
};

// An atom table's column, by atom index.
std::vector<std::string> table_column(const std::string& path, const std::string& column) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  auto split = [](const std::string& text) {
    std::vector<std::string> w;
    std::istringstream s(text);
    for (std::string x; std::getline(s, x, '\t');) w.push_back(x);
    return w;
  };
  const std::vector<std::string> head = split(line);
  const size_t at = static_cast<size_t>(std::find(head.begin(), head.end(), column) - head.begin());
  const size_t index = static_cast<size_t>(std::find(head.begin(), head.end(), "index") - head.begin());
  std::vector<std::string> out;
  for (long number = 2; std::getline(in, line); ++number) {
    const std::vector<std::string> w = split(line);
    if (w.size() <= std::max(at, index)) continue;
    const long k = std::strtol(w[index].c_str(), nullptr, 10);
    if (k < 0 || k > 100000000) input_error(path, number, "an atom index out of range");
    if (out.size() <= static_cast<size_t>(k)) out.resize(static_cast<size_t>(k) + 1);
    out[static_cast<size_t>(k)] = w[at];
  }
  return out;
}

Colour ramp(double x) {  // 0 red, 1/2 yellow, 1 blue-green, as the viewer's
  const Colour stops[3] = {{0.80f, 0.15f, 0.15f}, {0.97f, 0.85f, 0.30f}, {0.25f, 0.62f, 0.75f}};
  const double u = std::clamp(x, 0.0, 1.0) * 2;
  const size_t k = std::min<size_t>(1, static_cast<size_t>(u));
  const float f = static_cast<float>(u - static_cast<double>(k));
  Colour c;
  for (size_t i = 0; i < 3; ++i) c[i] = stops[k][i] + f * (stops[k + 1][i] - stops[k][i]);
  return c;
}


// Each frame's colours: by patch type, by the age of its ids (frames lived,
// as the viewer's), uniform, or by the chain or element of its atom (the
// colours of render's PNGs).
void colour_frames(std::vector<MovieFrame>& frames, std::vector<std::map<std::string, std::vector<double>>>& props,
                   const MovieOptions& o, const ViewInput& input) {
  static const Colour by_patch[] = {{0.45f, 0.65f, 0.90f}, {0.98f, 0.80f, 0.40f}, {0.95f, 0.55f, 0.35f}, {0.85f, 0.35f, 0.40f}};
  std::map<std::string, std::vector<std::string>> column;  // side -> chain or element by atom
  std::map<std::string, size_t> ordinal;
  if (o.colour == "chain" || o.colour == "element")
    for (const auto& [side, path] : input.atoms) column[side] = table_column(path, o.colour);
  std::vector<int> age_before;
  for (size_t k = 0; k < frames.size(); ++k) {
    MovieFrame& f = frames[k];
    const auto& p = props[k];
    std::vector<int> age(f.mesh.vertices.size(), 1);
    for (size_t v = 0; v < age.size(); ++v) {
      if (k > 0 && !f.ids.empty()) {
        const auto j = frames[k - 1].index.find(f.ids[v]);
        if (j != frames[k - 1].index.end()) age[v] = age_before[j->second] + 1;
      }
      Colour c = o.view.colour;
      if (o.colour == "patch" && p.count("patch")) c = by_patch[std::clamp(static_cast<int>(p.at("patch")[v]), 0, 3)];
      else if (o.colour == "age") c = ramp((age[v] - 1) / std::max(1.0, static_cast<double>(frames.size() - 1)));  // new red, old blue-green
      else if (o.colour == "chain" || o.colour == "element") {
        c = {0.55f, 0.55f, 0.58f};
        for (const char* side : {"source", "target"}) {
          const long a = vertex_atom(p, v, side);
          if (a < 0 || !column.count(side) || static_cast<size_t>(a) >= column[side].size()) continue;
          const std::string& key = column[side][static_cast<size_t>(a)];
          c = o.colour == "element" ? element_colour(key) : palette(ordinal.emplace(key, ordinal.size()).first->second);
          break;
        }
      }
      f.colours.push_back(c);
    }
    age_before = std::move(age);
  }
}

std::vector<MovieFrame> load_frames(const MovieOptions& o, const ViewInput& input) {
  std::vector<MovieFrame> frames;
  std::vector<std::map<std::string, std::vector<double>>> props;
  for (const ViewFrame& vf : input.frames) {
    PlyMesh ply = read_ply_with_properties(vf.path);
    MovieFrame f;
    f.t = vf.t;
    f.mesh = std::move(ply.mesh);
    f.mesh.normals.clear();  // moved vertices: normals from the moved triangles
    if (ply.vertex_properties.count("id")) f.ids = ply.vertex_properties.at("id");
    for (size_t v = 0; v < f.ids.size(); ++v) f.index.emplace(f.ids[v], v);
    frames.push_back(std::move(f));
    props.push_back(std::move(ply.vertex_properties));
  }
  colour_frames(frames, props, o, input);
  return frames;
}

// Frame `from`'s mesh at share s of the way to `to`: each vertex whose id
// `to` holds on the straight line between its two places.
SurfaceMesh moved(const MovieFrame& from, const MovieFrame& to, double s) {
  SurfaceMesh m = from.mesh;
  for (size_t v = 0; v < from.ids.size(); ++v) {
    const auto j = to.index.find(from.ids[v]);
    if (j != to.index.end()) m.vertices[v] += s * (to.mesh.vertices[j->second] - m.vertices[v]);
  }
  return m;
}

// The picture at t: the two frames around it, moved towards each other,
// cross-faded by s.
Image picture_at(const std::vector<MovieFrame>& frames, double t, const RenderOptions& view) {
  size_t k = 0;
  while (k + 2 < frames.size() && t > frames[k + 1].t) ++k;
  const MovieFrame& a = frames[k];
  const MovieFrame& b = frames[std::min(k + 1, frames.size() - 1)];
  const double s = &a == &b ? 0 : std::clamp((t - a.t) / (b.t - a.t), 0.0, 1.0);
  Image image = render_mesh(moved(a, b, s), view, a.colours);
  if (s <= 0) return image;
  const Image other = render_mesh(moved(b, a, 1 - s), view, b.colours);
  for (size_t i = 0; i < image.rgb.size(); ++i)
    image.rgb[i] = static_cast<std::uint8_t>(std::lround((1 - s) * image.rgb[i] + s * other.rgb[i]));
  return image;
}

std::string encoder_arguments(const std::string& path) {
  return ends_with(path, ".webm") ? "-c:v libvpx-vp9 -b:v 0 -crf 34 -row-mt 1 -pix_fmt yuv420p"
                                  : "-c:v libx264 -preset medium -crf 20 -pix_fmt yuv420p -movflags +faststart";
}

// Pipes the pictures to ffmpeg, which writes `temporary`.
void encode(const std::vector<MovieFrame>& frames, const MovieOptions& o, long pictures, const std::string& temporary) {
  const std::string command = find_ffmpeg() + " -hide_banner -loglevel error -nostdin -y -f rawvideo -pix_fmt rgb24 -s " +
                              std::to_string(o.view.width) + "x" + std::to_string(o.view.height) + " -framerate " +
                              std::to_string(o.fps) + " -i - " + encoder_arguments(o.path) + " '" + temporary + "'";
  const auto old_handler = std::signal(SIGPIPE, SIG_IGN);  // ffmpeg stopping early is an error, not our end
  FILE* pipe = ::popen(command.c_str(), "w");
  if (!pipe) throw Error("cannot start ffmpeg: " + command);
  bool written = true;
  const double t0 = frames.front().t, t1 = frames.back().t;
  for (long i = 0; i < pictures && written; ++i) {
    const double t = pictures == 1 ? t0 : t0 + (t1 - t0) * static_cast<double>(i) / static_cast<double>(pictures - 1);
    const Image image = picture_at(frames, t, o.view);
    written = std::fwrite(image.rgb.data(), 1, image.rgb.size(), pipe) == image.rgb.size();
  }
  const int status = ::pclose(pipe);
  std::signal(SIGPIPE, old_handler);
  if (!written || status != 0) throw Error(o.path + ": ffmpeg failed (" + command + "); nothing written");
}

}  // namespace

void check_movie(const MovieOptions& o, const std::string& morph_dir) {
  if (!ends_with(o.path, ".mp4") && !ends_with(o.path, ".webm"))
    contract_error("--movie " + o.path + ": the movie must be .mp4 (H.264) or .webm (VP9)");
  if (o.view.width % 2 || o.view.height % 2)
    contract_error("--movie: --width and --height must be even (the encoders' colour sampling halves them)");
  if (!fs::is_directory(morph_dir))
    contract_error("--movie: " + morph_dir + " is not a morph directory (a movie shows a morph's frames)");
  if (o.colour == "chain" || o.colour == "element") {
    if (!fs::is_regular_file(fs::path(morph_dir) / "source_atoms.tsv") &&
        !fs::is_regular_file(fs::path(morph_dir) / "target_atoms.tsv"))
      contract_error("--colour " + o.colour + " needs the morph's atom tables (source_atoms.tsv, target_atoms.tsv) in " +
                     morph_dir);
  }
  find_ffmpeg();
}

MovieSummary write_movie(const MovieOptions& o, const std::string& morph_dir) {
  const ViewInput input = find_view_input(morph_dir);
  std::vector<MovieFrame> frames = load_frames(o, input);
  std::vector<const SurfaceMesh*> meshes;
  for (const MovieFrame& f : frames) meshes.push_back(&f.mesh);
  MovieOptions fixed = o;
  fixed.view.fit = fit_view(meshes, o.view);  // one camera for the whole movie
  const long pictures = std::max(1L, std::lround(o.seconds * o.fps));
  const std::string temporary =
      (fs::temp_directory_path() / ("skinmesh-movie-" + std::to_string(::getpid()) + fs::path(o.path).extension().string()))
          .string();
  RemovedOnInterrupt guard(temporary);
  try {
    encode(frames, fixed, pictures, temporary);
    write_file_atomically(o.path, [&](std::ostream& out) {
      std::ifstream in(temporary, std::ios::binary);
      out << in.rdbuf();
    });
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
  fs::remove(temporary);
  return {pictures, frames.size(), ends_with(o.path, ".webm") ? "VP9" : "H.264"};
}

}  // namespace skinmesh::app
