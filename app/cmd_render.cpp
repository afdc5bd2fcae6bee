// skinmesh render: a PNG picture of a molecule's skin (meshed first, coloured
// by patch type, element or chain) or of any mesh file, or a movie of a
// morph directory (render_movie.hpp), without a display.
#include "commands.hpp"
#include "exit_codes.hpp"
#include "molecule_options.hpp"
#include "output_file.hpp"
#include "quality_report.hpp"
#include "render_colours.hpp"
#include "render_movie.hpp"

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/error.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/mesh_io/mesh_read.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/render/render.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <iostream>
#include <map>

namespace skinmesh::app {
namespace {

using json = nlohmann::json;

struct RenderCommandOptions {
  MoleculeOptions molecule;  // the input: a molecule, or a mesh file by its extension
  std::string output;
  std::string colour = "patch";
  RenderOptions view;
  MovieOptions movie;  // with --movie: its path, length and rate
};

void add_render_options(CLI::App& cmd, RenderCommandOptions& o) {
  cmd.add_option("input", o.molecule.path,
                 "a molecule (meshed with the defaults of `mesh`), a mesh file (.ply .off .obj .stl .msh .vert), or a "
                 "morph directory (with --movie)")
      ->required();
  add_molecule_settings(cmd, o.molecule);
  cmd.add_option("--output,-o", o.output, "PNG file (a molecule or a mesh file)");
  CLI::Option* movie = cmd.add_option("--movie", o.movie.path,
                                      "a morph directory's movie: .mp4 (H.264) or .webm (VP9), made by ffmpeg; ids "
                                      "interpolated between frames");
  cmd.add_option("--seconds", o.movie.seconds, "the movie's length")
      ->check(finite_number())
      ->check(CLI::Range(0.04, 3600.0))
      ->needs(movie);
  cmd.add_option("--fps", o.movie.fps, "the movie's pictures a second")
      ->check(finite_number())
      ->check(CLI::Range(1.0, 120.0))
      ->needs(movie);
  cmd.add_option("--colour,--color", o.colour,
                 "a molecule's vertices by patch (sphere, saddle, concave), element, chain, or uniform; a mesh file "
                 "is uniform; a movie by patch, age (frames its id has lived), uniform, or chain or element (from "
                 "the morph's atom tables)")
      ->check(CLI::IsMember({"patch", "element", "chain", "uniform", "age"}));
  cmd.add_option("--width", o.view.width, "pixels")->check(CLI::Range(16, 8192));
  cmd.add_option("--height", o.view.height, "pixels")->check(CLI::Range(16, 8192));
  cmd.add_option("--yaw", o.view.yaw, "degrees about the vertical axis")->check(finite_number());
  cmd.add_option("--pitch", o.view.pitch, "degrees about the horizontal axis, after the yaw")->check(finite_number());
}

bool is_mesh_file(const std::string& path) {
  for (const char* ext : {".ply", ".off", ".obj", ".stl", ".msh", ".vert", ".face"})
    if (path.size() > std::string(ext).size() && path.compare(path.size() - std::string(ext).size(), std::string::npos, ext) == 0)
      return true;
  return false;
}

// The skin of the molecule, meshed, and a colour per vertex.
SurfaceMesh molecule_mesh(const RenderCommandOptions& o, std::vector<Colour>& colours) {
  const Molecule m = read_molecule(o.molecule.path, o.molecule.read);
  if (m.atoms.empty()) input_error(o.molecule.path, 0, "no atoms left to mesh");
  const SkinComplex complex = build_skin_complex(balls_from_molecule(m, o.molecule.shrink, o.molecule.convention()),
                                                 {o.molecule.shrink});
  SkinMeshResult made = mesh_skin(complex);
  if (made.status == MeshingStatus::empty_skin) input_error(o.molecule.path, 0, made.message);
  if (made.status != MeshingStatus::ok) throw Error(o.molecule.path + ": " + made.message);
  std::map<std::string, size_t> chains;
  for (const Atom& a : m.atoms) chains.emplace(a.chain, chains.size());
  if (o.colour != "uniform")
    for (size_t v = 0; v < made.mesh.vertices.size(); ++v) {
      const int cell = made.mesh.cells[v];
      const Atom& atom = m.atoms[static_cast<size_t>(complex.owning_ball(made.mesh.vertices[v], cell))];
      if (o.colour == "patch") {
        static const Colour by_dim[] = {{0.45f, 0.65f, 0.90f}, {0.98f, 0.80f, 0.40f}, {0.95f, 0.55f, 0.35f},
                                        {0.85f, 0.35f, 0.40f}};
        colours.push_back(by_dim[complex.cell(cell).dim]);
      } else if (o.colour == "element") {
        colours.push_back(element_colour(atom.element));
      } else {
        colours.push_back(palette(chains[atom.chain]));
      }
    }
  return std::move(made.mesh);
}

ExitCode run_movie(const RenderCommandOptions& o, const GlobalOptions& global) {
  if (!o.output.empty()) contract_error("render: give --movie or --output, not both");
  MovieOptions movie = o.movie;
  movie.colour = o.colour;
  movie.view = o.view;
  check_movie(movie, o.molecule.path);
  check_writable({movie.path});
  const MovieSummary made = write_movie(movie, o.molecule.path);
  const json report = {{"input", o.molecule.path}, {"movie", movie.path},     {"width", o.view.width},
                       {"height", o.view.height},  {"pictures", made.pictures}, {"fps", movie.fps},
                       {"frames", made.frames},     {"encoder", made.encoder}, {"colour", movie.colour}};
  if (global.json) std::cout << json_text(report) << "\n";
  else if (!global.quiet)
    std::cout << movie.path << ": " << made.pictures << " pictures of " << o.view.width << " x " << o.view.height << " ("
              << made.encoder << "), " << made.frames << " frames of the morph\n";
  return ExitCode::ok;
}

ExitCode run_render(const RenderCommandOptions& o, const GlobalOptions& global) {
  if (!o.movie.path.empty()) return run_movie(o, global);
  if (o.output.empty()) contract_error("render: --output (a PNG) is required, or --movie for a morph directory");
  if (std::filesystem::is_directory(o.molecule.path))
    contract_error("render: " + o.molecule.path + " is a directory: a morph's is drawn with --movie OUT.mp4");
  if (o.colour == "age") contract_error("render: --colour age is a morph's (with --movie)");
  check_writable({o.output});
  std::vector<Colour> colours;
  const SurfaceMesh mesh = is_mesh_file(o.molecule.path) ? read_surface_mesh(o.molecule.path) : molecule_mesh(o, colours);
  if (mesh.triangles.empty()) input_error(o.molecule.path, 0, "no triangles to draw");
  const Image image = render_mesh(mesh, o.view, colours);
  write_file_atomically(o.output, [&](std::ostream& out) { write_png(out, image); });
  const json report = {{"input", o.molecule.path},           {"output", o.output},
                       {"width", image.width},               {"height", image.height},
                       {"covered_pixels", image.covered},    {"pixels_per_angstrom", image.pixels_per_angstrom},
                       {"triangles", mesh.triangles.size()}, {"colour", is_mesh_file(o.molecule.path) ? "uniform" : o.colour}};
  if (global.json) std::cout << json_text(report) << "\n";
  else if (!global.quiet)
    std::cout << o.output << ": " << image.width << " x " << image.height << " pixels, " << mesh.triangles.size()
              << " triangles drawn, " << image.covered << " pixels covered\n";
  return ExitCode::ok;
}

}  // namespace

void add_render_command(CLI::App& app, const GlobalOptions& global, int& exit_code) {
  add_command(app, "render", "a PNG picture of a molecule's skin or of a mesh file, without a display", global,
              exit_code, add_render_options, run_render);
}

}  // namespace skinmesh::app
