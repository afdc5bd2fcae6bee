// skinmesh mesh: the quality mesh of a molecule's skin, written with normals and
// per-vertex attributes, graded, and checked against the guarantees before any
// file is written.
#include "commands.hpp"
#include "exit_codes.hpp"
#include "meshing_feedback.hpp"
#include "molecule_options.hpp"
#include "output_file.hpp"
#include "quality_report.hpp"
#include "vertex_colours.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/mesh_io/atom_table.hpp"
#include "skinmesh/mesh_io/mesh_write.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/quality/guarantees.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>

namespace skinmesh::app {
namespace {

using json = nlohmann::json;

struct MeshCommandOptions {
  MoleculeOptions molecule;
  std::string output, report, svg;
  MeshingOptions meshing;
  double max_memory_gb = 0;  // 0: the memory available when the command starts
  bool single_precision = false;
  bool ascii = false;              // PLY as text (PyMOL 2.5 reads no binary PLY)
  std::string colour = "patch";    // per-vertex colours of PLY and glTF (vertex_colours.hpp)
  bool no_self_intersections = false;
  bool outer_only = false;  // drop the components another encloses (cavities, islands in them)
};

// The patch type and the atom that owns each vertex (atom, and atomid,
// unsigned, which Mol* groups a PLY by), and the colours asked for.
VertexAttributes attributes_of(const SkinComplex& complex, const SurfaceMesh& mesh, const Molecule& m,
                               Colouring colouring) {
  VertexAttributes a;
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    a.patch.push_back(complex.cell(mesh.cells[v]).dim);
    a.atom.push_back(complex.owning_ball(mesh.vertices[v], mesh.cells[v]));
  }
  a.more = {{"atomid", PropertyType::uint32, a.atom}};
  std::vector<Rgb> by_atom;
  if (colours_by_atom(colouring)) {
    const std::vector<Rgb> table = atom_colours(colouring, m.atoms);
    for (int atom : a.atom) by_atom.push_back(table[static_cast<size_t>(atom)]);
  }
  a.colours = vertex_colours(colouring, mesh, a.patch, by_atom);
  return a;
}

// OUT.ply -> OUT.atoms.tsv (the table the per-vertex atom indices name).
std::string atom_table_path(const std::string& mesh_path) {
  return std::filesystem::path(mesh_path).replace_extension(".atoms.tsv").string();
}

void add_mesh_options(CLI::App& cmd, MeshCommandOptions& o) {
  add_molecule_options(cmd, o.molecule);
  cmd.add_option("--output,-o", o.output,
                 "mesh file: .ply .off .obj .stl .vtp .msh (Gmsh), .glb (glTF), or .vert (MSMS .vert + .face); "
                 "the table of its atoms goes beside it (OUT.atoms.tsv)")
      ->required();
  cmd.add_option("--colour,--color", o.colour, colouring_help())
      ->check(CLI::IsMember(colouring_names()))->capture_default_str();
  cmd.add_flag("--ascii", o.ascii, "write a PLY or VTP as text (PyMOL 2.5 opens text PLY only)");
  cmd.add_flag("--outer-only", o.outer_only,
               "keep only the outer surface: drop every component another encloses (cavities, and anything inside "
               "them), as a boundary-element solver of the exterior wants");
  cmd.add_option("--report", o.report, "write the quality report as JSON");
  cmd.add_option("--svg", o.svg, "write a histogram of the smallest angles as SVG");
  cmd.add_option("--min-angle", o.meshing.min_angle, "smallest angle of every triangle, degrees (at most 30)")
      ->check(finite_number())->check(CLI::Range(1.0, 30.0))
      ->capture_default_str();
  cmd.add_option("--epsilon", o.meshing.sizing.epsilon, "curvature-relative size: edge length / local radius of curvature")
      ->check(finite_number())->check(positive_number())
      ->capture_default_str();
  cmd.add_option("--edge-length", o.meshing.edge_length,
                 "largest edge length in Angstrom, uniform wherever the curvature allows it (--epsilon still "
                 "bounds it where the skin bends more, which keeps the topology); 0: none, curvature only")
      ->check(finite_number())->check(non_negative_number())->capture_default_str();
  cmd.add_option("--contract-below", o.meshing.contract_below,
                 "clean-up: contract edges shorter than this times the local target length (0: off)")
      ->check(finite_number())->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  cmd.add_option("--min-size", o.meshing.sizing.min_size, "smallest target edge length on hyperboloid patches, A")
      ->check(finite_number())->check(positive_number())
      ->capture_default_str();
  cmd.add_option("--max-size", o.meshing.sizing.max_size, "largest target edge length, A")
      ->check(finite_number())->check(positive_number())
      ->capture_default_str();
  cmd.add_option("--tolerance", o.meshing.tolerance,
                 "largest distance from a triangle's circumcentre to the skin along its normal, A")
      ->check(finite_number())->check(positive_number())
      ->capture_default_str();
  cmd.add_option("--max-triangles", o.meshing.max_triangles, "stop with an error past this many triangles")
      ->check(finite_number())->check(positive_number())
      ->capture_default_str();
  cmd.add_option("--max-memory", o.max_memory_gb,
                 "refuse at once a job whose estimated memory passes this many GB (0: the memory available now)")
      ->check(finite_number())->check(non_negative_number())
      ->capture_default_str();
  cmd.add_option("--threads", o.meshing.threads, "threads for the parallel passes (0: all)")->check(finite_number())->check(non_negative_number());
  cmd.add_flag("--float", o.single_precision, "write single-precision coordinates (smaller files)");
  cmd.add_flag("--no-self-intersections", o.no_self_intersections, "skip the exact self-intersection check");
}

// Every file the command will write.
std::vector<std::string> output_paths(const MeshCommandOptions& o, MeshFormat format) {
  std::vector<std::string> paths;
  if (format == MeshFormat::msms) {
    const std::string stem = o.output.substr(0, o.output.size() - 5);
    paths = {stem + ".vert", stem + ".face"};
  } else {
    paths = {o.output};
  }
  paths.push_back(atom_table_path(o.output));
  if (!o.svg.empty()) paths.push_back(o.svg);
  if (!o.report.empty()) paths.push_back(o.report);
  return paths;
}

// The mesh, its attributes, the report and the histogram, all or none.
void write_outputs(const MeshCommandOptions& o, MeshFormat format, const SkinComplex& complex, const Molecule& m,
                   const SurfaceMesh& mesh, const MeshQuality& q, json& report, Clock::time_point start) {
  const VertexAttributes attributes = attributes_of(complex, mesh, m, colouring_from_name(o.colour));
  MeshWriteOptions write;
  write.single_precision = o.single_precision;
  write.ascii = o.ascii;
  OutputSet outputs;
  if (format == MeshFormat::msms) {
    const std::string stem = o.output.substr(0, o.output.size() - 5);
    outputs.add(stem + ".vert", [&](std::ostream& out) { write_msms_vert(out, mesh, &attributes, write); });
    outputs.add(stem + ".face", [&](std::ostream& out) { write_msms_face(out, mesh, &attributes); });
  } else {
    outputs.add(o.output, [&](std::ostream& out) { write_mesh(out, mesh, format, &attributes, write); });
  }
  outputs.add(atom_table_path(o.output), [&](std::ostream& out) { write_atom_table(out, m); });
  if (!o.svg.empty()) outputs.add(o.svg, [&](std::ostream& out) { write_svg(out, q, o.output); });
  report["seconds"]["total"] = seconds_since(start);
  if (!o.report.empty()) outputs.add(o.report, [&](std::ostream& out) { out << json_text(report) << "\n"; });
  outputs.commit();
}

void print_summary(const MeshCommandOptions& o, const GuaranteeReport& g, const json& report) {
  print_quality_summary(std::cout, o.output, g.quality);
  const json& seconds = report["seconds"];
  const json& area = report["skin_area"];
  std::cout << "  skin area:   " << area["skin"].get<double>() << " A^2 (+- " << area["uncertainty"].get<double>()
            << "); the triangles' is " << 100 * area["mesh_relative_error"].get<double>() << "% off\n";
  std::cout << "  on-surface error: max " << g.surface_error.max << " A, mean " << g.surface_error.mean
            << " A (oracle)\n"
            << "  guarantees:  angle >= " << o.meshing.min_angle << " deg, vertices on the skin, closed "
            << "oriented manifold" << (g.no_self_intersections ? ", no self-intersections" : "")
            << (g.topology ? ", the skin's topology" : "") << ": all hold\n"
            << "  time:        " << seconds["total"].get<double>() << " s (complex "
            << seconds["complex"].get<double>() << ", meshing " << seconds["meshing"].get<double>() << ", grading "
            << seconds["grading"].get<double>() << ")\n";
}

ExitCode run_mesh(const MeshCommandOptions& o, const GlobalOptions& global) {
  const bool progress = !global.quiet && !global.json;
  const auto start = Clock::now();
  const MeshFormat format = mesh_format_from_path(o.output);
  if (o.ascii && format != MeshFormat::ply && format != MeshFormat::vtp)
    contract_error("--ascii: only a PLY or VTP has a text form to choose (" + o.output + ")");
  check_writable(output_paths(o, format));
  const Molecule m = read_molecule(o.molecule.path, o.molecule.read);
  if (progress)
    for (const std::string& w : m.warnings) std::cerr << "skinmesh: warning: " << w << "\n";
  if (m.atoms.empty()) input_error(o.molecule.path, 0, "no atoms left to mesh");
  const auto balls = balls_from_molecule(m, o.molecule.shrink, o.molecule.convention());
  const SkinComplex complex = build_skin_complex(balls, {o.molecule.shrink});
  const double seconds_complex = seconds_since(start);

  MeshingOptions meshing = o.meshing;
  meshing.max_memory_bytes = memory_limit_bytes(o.max_memory_gb);
  const auto line = std::make_shared<ProgressLine>(progress);
  if (progress) meshing.progress = meshing_progress_line(line);
  const SkinMeshResult result = mesh_skin(complex, meshing);
  line->finish();
  if (result.status == MeshingStatus::empty_skin) input_error(o.molecule.path, 0, result.message);
  if (result.status != MeshingStatus::ok) {
    std::cerr << "skinmesh: error: " << o.molecule.path << ": " << result.message << "\n";
    if (result.status == MeshingStatus::over_budget) std::cerr << "skinmesh: " << over_budget_hint(result) << "\n";
    return ExitCode::not_met;
  }
  if (progress) std::cerr << "skinmesh: meshed; grading\n";
  SurfaceMesh outer;
  if (o.outer_only) outer = outer_surface(result.mesh);
  const SurfaceMesh& mesh = o.outer_only ? outer : result.mesh;

  const auto grade_start = Clock::now();
  GuaranteeOptions bounds;
  bounds.min_angle = meshing.min_angle;
  bounds.self_intersections = o.no_self_intersections ? SelfIntersectionCheck::skip : SelfIntersectionCheck::exact;
  bounds.topology = !o.outer_only;  // the voids' surfaces are dropped: not the skin's topology
  const GuaranteeReport g = check_guarantees(mesh, balls, o.molecule.shrink, bounds);
  const double seconds_checking = seconds_since(grade_start);
  const SkinArea skin = skin_area(complex, mesh);
  const double seconds_grading = seconds_since(grade_start);

  const MeshingStats& s = result.stats;
  json report = {{"skinmesh_version", version_text()},
                 {"command_line", global.command_line},
                 {"molecule", o.molecule.path},
                 {"atoms", m.atoms.size()},
                 {"shrink", o.molecule.shrink},
                 {"weights", convention_name(o.molecule.convention())},
                 {"output", o.output},
                 {"format", mesh_format_name(format)},
                 {"atom_table", atom_table_path(o.output)},
                 {"colour", o.colour},
                 {"options", options_json(meshing)},
                 {"quality", to_json(g.quality)},
                 {"outer_only", o.outer_only},
                 {"components_dropped", o.outer_only ? surface_components(result.mesh).enclosed_volume.size() -
                                                           surface_components(mesh).enclosed_volume.size()
                                                     : 0},
                 {"skin_area", skin_area_json(skin, g.quality.area)},
                 {"on_surface_error", to_json(g.surface_error)},
                 {"guarantees", guarantees_json(g)},
                 {"refinement", refinement_json(s)},
                 {"estimated_triangles", std::llround(result.estimated_triangles)},
                 {"seconds",
                  {{"complex", seconds_complex},
                   {"seeding", s.seconds_seeding},
                   {"refining", s.seconds_refining},
                   {"contracting", s.seconds_contracting},
                   {"meshing", s.seconds_total},
                   {"grading", seconds_grading},
                   {"checking", seconds_checking},
                   {"skin_area", seconds_grading - seconds_checking}}}};
  if (!g.all_hold()) {
    std::cerr << "skinmesh: error: " << o.molecule.path << ": the mesh fails a guarantee (see below); nothing written\n"
              << json_text({{"guarantees", report["guarantees"]},
                            {"on_surface_error", report["on_surface_error"]},
                            {"min_angle", g.quality.min_angle}})
              << "\n";
    return ExitCode::not_met;
  }
  write_outputs(o, format, complex, m, mesh, g.quality, report, start);
  if (global.json) std::cout << json_text(report) << "\n";
  else if (!global.quiet) print_summary(o, g, report);
  return ExitCode::ok;
}

}  // namespace

void add_mesh_command(CLI::App& app, const GlobalOptions& global, int& exit_code) {
  add_command(app, "mesh", "quality triangle mesh of the molecular skin", global, exit_code, add_mesh_options,
              run_mesh);
}

}  // namespace skinmesh::app
