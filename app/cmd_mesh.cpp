// skinmesh mesh: the quality mesh of a molecule's skin, written with normals and
// per-vertex attributes, graded, and checked against the guarantees before any
// file is written.
#include "commands.hpp"
#include "molecule_options.hpp"
#include "output_file.hpp"
#include "quality_report.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/meshing/mesh_quality.hpp"
#include "skinmesh/meshing/mesh_write.hpp"
#include "skinmesh/meshing/skin_mesher.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <iostream>

namespace skinmesh::app {
namespace {

using json = nlohmann::json;

// The atom that owns a vertex: of the balls of its mixed cell, the one with the
// smallest power distance (the atom whose region of the power diagram holds
// the vertex's Voronoi part).
VertexAttributes attributes_of(const SkinComplex& complex, const SurfaceMesh& mesh) {
  VertexAttributes a;
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const MixedCell& cell = complex.cell(mesh.cells[v]);
    int best = cell.balls[0];
    for (int k = 1; k <= cell.dim; ++k) {
      const int b = cell.balls[static_cast<size_t>(k)];
      if (complex.balls()[static_cast<size_t>(b)].power(mesh.vertices[v]) <
          complex.balls()[static_cast<size_t>(best)].power(mesh.vertices[v]))
        best = b;
    }
    a.patch.push_back(cell.dim);
    a.atom.push_back(best);
  }
  return a;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

void add_mesh_command(CLI::App& app, const GlobalOptions& global, int& exit_code) {
  struct Options {
    MoleculeOptions molecule;
    std::string output, report, svg;
    MeshingOptions meshing;
    bool single_precision = false;
    bool no_self_intersections = false;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("mesh", "quality triangle mesh of the molecular skin");
  add_molecule_options(*cmd, o->molecule);
  cmd->add_option("--output,-o", o->output, "mesh file: .ply .off .obj .stl .vtp .msh (Gmsh), or .vert (MSMS .vert + .face)")
      ->required();
  cmd->add_option("--report", o->report, "write the quality report as JSON");
  cmd->add_option("--svg", o->svg, "write a histogram of the smallest angles as SVG");
  cmd->add_option("--min-angle", o->meshing.min_angle, "smallest angle of every triangle, degrees (at most 30)")
      ->check(CLI::Range(1.0, 30.0))
      ->capture_default_str();
  cmd->add_option("--epsilon", o->meshing.sizing.epsilon,
                  "curvature-relative size: edge length / local radius of curvature")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--edge-length", o->meshing.edge_length,
                  "largest edge length in Angstrom, uniform wherever the curvature allows it (--epsilon still "
                  "bounds it where the skin bends more, which keeps the topology)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--contract-below", o->meshing.contract_below,
                  "clean-up: contract edges shorter than this times the local target length (0: off)")
      ->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  cmd->add_option("--min-size", o->meshing.sizing.min_size, "smallest target edge length on hyperboloid patches, A")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--max-size", o->meshing.sizing.max_size, "largest target edge length, A")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--tolerance", o->meshing.tolerance,
                  "largest distance from a triangle's circumcentre to the skin along its normal, A")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--max-triangles", o->meshing.max_triangles, "stop with an error past this many triangles")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--threads", o->meshing.threads, "threads for the parallel passes (0: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--float", o->single_precision, "write single-precision coordinates (smaller files)");
  cmd->add_flag("--no-self-intersections", o->no_self_intersections, "skip the exact self-intersection check");
  cmd->callback([o, &global, &exit_code]() {
    const bool progress = !global.quiet && !global.json;
    const auto start = std::chrono::steady_clock::now();
    const MeshFormat format = mesh_format_from_path(o->output);
    const Molecule m = read_molecule(o->molecule.path, o->molecule.read);
    if (progress)
      for (const std::string& w : m.warnings) std::cerr << "skinmesh: warning: " << w << "\n";
    if (m.atoms.empty()) throw InputError(o->molecule.path, 0, "no atoms left to mesh");
    const auto balls = balls_from_molecule(m, o->molecule.shrink, o->molecule.convention());
    const SkinComplex complex = build_skin_complex(balls, {o->molecule.shrink});
    const double seconds_complex = seconds_since(start);

    MeshingOptions meshing = o->meshing;
    if (progress)
      meshing.progress = [](const MeshingProgress& p) {
        std::fprintf(stderr, "\rskinmesh: %-9s %9ld vertices, %8ld pending", p.stage, p.vertices, p.pending);
        std::fflush(stderr);
      };
    SkinMeshResult result;
    try {
      result = mesh_skin(complex, meshing);
    } catch (const MeshingError& e) {
      if (progress) std::cerr << "\n";
      std::cerr << "skinmesh: error: " << o->molecule.path << ": " << e.what() << "\n";
      exit_code = 3;
      return;
    }
    if (progress) std::cerr << "\rskinmesh: meshed; grading" << std::string(40, ' ') << "\n";

    const auto grade_start = std::chrono::steady_clock::now();
    GradeOptions grade;
    grade.check_self_intersections = !o->no_self_intersections;
    const MeshQuality q = grade_mesh(result.mesh, grade);
    json error = on_surface_error_json(result.mesh.vertices, balls, o->molecule.shrink);
    const double seconds_grading = seconds_since(grade_start);

    // The guarantees, measured on the mesh about to be written.
    const double max_error = error["max"].get<double>();
    const bool angle_ok = q.triangles > 0 && q.min_angle >= meshing.min_angle - 1e-9;
    const bool surface_ok = max_error <= 1e-9;
    const bool manifold_ok = q.closed && q.manifold && q.oriented && q.volume > 0;
    const bool intersections_ok = !grade.check_self_intersections || (q.self_intersections_checked && q.self_intersecting_pairs == 0);
    json guarantees = {{"min_angle_at_least_bound", angle_ok},
                       {"vertices_on_skin_within_1e-9", surface_ok},
                       {"closed_oriented_manifold", manifold_ok},
                       {"no_self_intersections", grade.check_self_intersections ? json(intersections_ok) : json(nullptr)}};

    const MeshingStats& s = result.stats;
    json report = {
        {"molecule", o->molecule.path},
        {"atoms", m.atoms.size()},
        {"shrink", o->molecule.shrink},
        {"weights", convention_name(o->molecule.convention())},
        {"output", o->output},
        {"format", mesh_format_name(format)},
        {"options",
         {{"min_angle_deg", meshing.min_angle},
          {"epsilon", meshing.edge_length > 0 ? json(nullptr) : json(meshing.sizing.epsilon)},
          {"edge_length", meshing.edge_length > 0 ? json(meshing.edge_length) : json(nullptr)},
          {"min_size", meshing.sizing.min_size},
          {"max_size", meshing.sizing.max_size},
          {"tolerance", meshing.tolerance},
          {"contract_below", meshing.contract_below},
          {"max_triangles", meshing.max_triangles}}},
        {"quality", to_json(q)},
        {"on_surface_error", error},
        {"guarantees", guarantees},
        {"refinement",
         {{"seeds", s.seeds},
          {"inserted_for_size", s.inserted_size},
          {"inserted_for_distance", s.inserted_distance},
          {"inserted_for_angle", s.inserted_shape},
          {"inserted_for_topology", s.inserted_topology},
          {"passes", s.passes},
          {"contracted_edges", s.contracted},
          {"contraction_attempts", s.contraction_attempts}}},
        {"seconds",
         {{"complex", seconds_complex},
          {"seeding", s.seconds_seeding},
          {"refining", s.seconds_refining},
          {"contracting", s.seconds_contracting},
          {"meshing", s.seconds_total},
          {"grading", seconds_grading}}}};

    if (!(angle_ok && surface_ok && manifold_ok && intersections_ok)) {
      std::cerr << "skinmesh: error: " << o->molecule.path
                << ": the mesh fails a guarantee (see below); nothing written\n"
                << guarantees.dump(2) << "\n";
      exit_code = 3;
      return;
    }

    const VertexAttributes attributes = attributes_of(complex, result.mesh);
    MeshWriteOptions write;
    write.single_precision = o->single_precision;
    if (format == MeshFormat::msms) {
      const std::string stem = o->output.substr(0, o->output.size() - 5);
      write_file_atomically(stem + ".vert", [&](std::ostream& out) { write_msms_vert(out, result.mesh, &attributes, write); });
      write_file_atomically(stem + ".face", [&](std::ostream& out) { write_msms_face(out, result.mesh, &attributes); });
    } else {
      write_file_atomically(o->output, [&](std::ostream& out) { write_mesh(out, result.mesh, format, &attributes, write); });
    }
    report["seconds"]["total"] = seconds_since(start);
    if (!o->report.empty())
      write_file_atomically(o->report, [&](std::ostream& out) { out << report.dump(2) << "\n"; });
    if (!o->svg.empty()) write_file_atomically(o->svg, [&](std::ostream& out) { write_svg(out, q, o->output); });

    if (global.json) {
      std::cout << report.dump(2) << "\n";
    } else if (!global.quiet) {
      print_quality_summary(std::cout, o->output, q);
      std::cout << "  on-surface error: max " << max_error << " A, mean " << error["mean"].get<double>()
                << " A (oracle)\n"
                << "  guarantees:  angle >= " << meshing.min_angle << " deg, vertices on the skin, closed "
                << "oriented manifold" << (grade.check_self_intersections ? ", no self-intersections" : "")
                << ": all hold\n"
                << "  time:        " << report["seconds"]["total"].get<double>() << " s (complex "
                << seconds_complex << ", meshing " << s.seconds_total << ", grading " << seconds_grading << ")\n";
    }
    exit_code = 0;
  });
}

}  // namespace skinmesh::app
