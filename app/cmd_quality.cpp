// skinmesh quality: grade any triangle mesh; with --molecule, also how far each
// vertex is from that molecule's skin (by the oracle of docs/math.md section 2).
#include "commands.hpp"
#include "exit_codes.hpp"
#include "molecule_options.hpp"
#include "output_file.hpp"
#include "quality_report.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/mesh_io/mesh_read.hpp"
#include "skinmesh/quality/mesh_quality.hpp"
#include "skinmesh/quality/on_surface_error.hpp"
#include "skinmesh/quality/tet_quality.hpp"
#include "skinmesh/volume/volume_mesh.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <optional>

namespace skinmesh::app {

using json = nlohmann::json;

namespace {

struct QualityCommandOptions {
  std::string mesh;
  std::string svg;
  bool no_self_intersections = false;
  double max_box_pairs = kDefaultBoxPairsPerTriangle;  // per triangle, on average
  bool tetgen = false;
  MoleculeOptions molecule;
};

void add_quality_options(CLI::App& cmd, QualityCommandOptions& o) {
  cmd.add_option("mesh", o.mesh, "mesh file")->required();
  cmd.add_option("--molecule", o.molecule.path, "also measure each vertex's distance to this molecule's skin");
  cmd.add_option("--svg", o.svg, "write a histogram of the smallest angles as SVG");
  cmd.add_flag("--no-self-intersections", o.no_self_intersections, "skip the exact self-intersection check");
  cmd.add_option("--max-box-pairs", o.max_box_pairs,
                 "refuse a mesh whose self-intersection check meets more than this many pairs of triangles with "
                 "overlapping boxes per triangle (a skin mesh has about 6)")
      ->check(finite_number())->check(positive_number())
      ->capture_default_str();
  cmd.add_flag("--tetgen", o.tetgen, "also count self-intersections with TetGen's -d check (a second opinion)");
  add_molecule_settings(cmd, o.molecule);
}

void grade_tets(const std::string& file, const TetMesh& tets, const GlobalOptions& global) {
  const TetQuality q = grade_tet_mesh(tets);
  json report = tet_report(tets, q);
  report["file"] = file;
  if (global.json) {
    std::cout << json_text(report) << "\n";
    return;
  }
  std::cout << file << ": " << q.points << " points, " << q.tets << " tetrahedra, volume " << q.volume << " A^3\n";
  print_tet_quality(std::cout, q);
  for (const auto& [r, v] : report["regions"].items())
    std::cout << "  region " << r << ": " << v["tetrahedra"].get<long>() << " tetrahedra, volume "
              << v["volume"].get<double>() << " A^3\n";
  std::cout << "  boundary:        " << report["boundary_faces"].get<long>() << " faces; "
            << report["boundary_faces_not_marked"].get<long>() << " not among the marked faces, "
            << report["marked_faces_not_on_boundary"].get<long>() << " marked faces not on a boundary\n";
}

// A mesh whose triangles overlap far more than a surface's: the check would
// take time (and, counted, pairs) growing as the square of its size.
ExitCode refuse_box_pairs(const QualityCommandOptions& o, const GradeOptions& grade, const MeshQuality& q) {
  std::cerr << "skinmesh: error: " << o.mesh << ": the self-intersection check stopped after " << q.self_intersection_box_pairs
      << " pairs of triangles with overlapping bounding boxes, more than its bound of "
      << grade.max_box_pairs(q.triangles) << " (" << o.max_box_pairs << " per triangle, --max-box-pairs; a skin mesh has "
      << "about 6): its triangles pile on each other. Raise --max-box-pairs to count them all, or grade the "
      << "rest with --no-self-intersections\n";
  return ExitCode::not_met;
}

ExitCode grade_surface(const QualityCommandOptions& o, const SurfaceMesh& mesh, const GlobalOptions& global) {
  GradeOptions grade;
  grade.self_intersections = o.no_self_intersections ? SelfIntersectionCheck::skip : SelfIntersectionCheck::exact;
  grade.max_box_pairs_per_triangle = o.max_box_pairs;
  const MeshQuality q = grade_mesh(mesh, grade);
  if (q.self_intersections_over_bound) return refuse_box_pairs(o, grade, q);
  json report = to_json(q);
  report["file"] = o.mesh;
  if (o.tetgen) {
    const long triangles = tetgen_self_intersections(mesh);
    report["tetgen_self_intersecting_triangles"] = triangles >= 0 ? json(triangles) : json(nullptr);
  }
  if (!o.molecule.path.empty()) {
    const Molecule m = read_molecule(o.molecule.path, o.molecule.read);
    const auto balls = balls_from_molecule(m, o.molecule.shrink, o.molecule.convention());
    json error = to_json(on_surface_error(mesh.vertices, balls, o.molecule.shrink));
    error["molecule"] = o.molecule.path;
    error["shrink"] = o.molecule.shrink;
    error["weights"] = convention_name(o.molecule.convention());
    report["on_surface_error"] = error;
  }
  if (!o.svg.empty()) write_file_atomically(o.svg, [&](std::ostream& out) { write_svg(out, q, o.mesh); });
  if (global.json) {
    std::cout << json_text(report) << "\n";
    return ExitCode::ok;
  }
  print_quality_summary(std::cout, o.mesh, q);
  if (report.contains("tetgen_self_intersecting_triangles"))
    std::cout << "  TetGen -d:   "
              << (report["tetgen_self_intersecting_triangles"].is_null()
                      ? std::string("TetGen stopped with an error")
                      : std::to_string(report["tetgen_self_intersecting_triangles"].get<long>()) + " triangles meet another")
              << "\n";
  if (report.contains("on_surface_error"))
    std::cout << "  on-surface error: max " << report["on_surface_error"]["max"].get<double>() << " A, mean "
              << report["on_surface_error"]["mean"].get<double>() << " A (oracle, " << o.molecule.path << ")\n";
  return ExitCode::ok;
}

// Tetrahedral meshes (TetGen's files, or a Gmsh file with tetrahedra) are
// graded as volumes, everything else as a surface; a Gmsh file is read once,
// whichever it holds.
ExitCode run_quality(const QualityCommandOptions& o, const GlobalOptions& global) {
  const auto ends_with = [&](const std::string& ext) {
    return o.mesh.size() > ext.size() && o.mesh.compare(o.mesh.size() - ext.size(), std::string::npos, ext) == 0;
  };
  std::optional<TetMesh> gmsh;
  if (ends_with(".msh")) gmsh = read_gmsh_volume(o.mesh);
  const bool tetgen_files = ends_with(".node") || ends_with(".ele");
  if (tetgen_files || (gmsh && !gmsh->tets.empty())) {
    grade_tets(o.mesh, tetgen_files ? read_tet_mesh(o.mesh) : std::move(*gmsh), global);
    return ExitCode::ok;
  }
  SurfaceMesh mesh;
  if (gmsh) {
    if (gmsh->faces.empty()) input_error(o.mesh, 0, "mesh has no triangles");
    mesh.vertices = std::move(gmsh->points);
    mesh.triangles = std::move(gmsh->faces);
  } else {
    mesh = read_surface_mesh(o.mesh);
  }
  return grade_surface(o, mesh, global);
}

}  // namespace

void add_quality_command(CLI::App& app, const GlobalOptions& global, int& exit_code) {
  add_command(app, "quality",
              "grade a triangle mesh (OFF, PLY, OBJ, STL, Gmsh, MSMS .vert/.face) or a tetrahedral one (TetGen "
              ".node/.ele, Gmsh)",
              global, exit_code, add_quality_options, run_quality);
}

}  // namespace skinmesh::app
