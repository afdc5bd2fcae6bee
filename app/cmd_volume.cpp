// skinmesh volume: a tetrahedral mesh of the molecule's interior, of the
// solvent between its skin and a box, or of both, bounded by the quality skin
// mesh; written as TetGen's files, VTK (.vtu) and Gmsh (.msh), with a report.
#include "commands.hpp"
#include "exit_codes.hpp"
#include "meshing_feedback.hpp"
#include "molecule_options.hpp"
#include "output_file.hpp"
#include "quality_report.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/mesh_io/tet_write.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/quality/guarantees.hpp"
#include "skinmesh/quality/tet_quality.hpp"
#include "skinmesh/volume/tet_estimate.hpp"
#include "skinmesh/volume/volume_mesh.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <iostream>

namespace skinmesh::app {
namespace {

using json = nlohmann::json;

struct VolumeCommandOptions {
  MoleculeOptions molecule;
  std::string output, report;
  MeshingOptions meshing;
  double max_memory_gb = 0;  // 0: the memory available when the command starts
  VolumeOptions volume = [] {
    VolumeOptions v;
    v.max_seconds = 3600;  // an hour: quality bounds near their limits can keep TetGen's refinement going for good
    return v;
  }();
  std::string domain = "interior";
  bool drop_cavities = false;
};

void add_volume_options(CLI::App& cmd, VolumeCommandOptions& o) {
  add_molecule_options(cmd, o.molecule);
  cmd.add_option("--output,-o", o.output, "output stem: writes STEM.vtu, STEM.msh, STEM.node/.ele/.face")->required();
  cmd.add_option("--report", o.report, "write the report as JSON");
  cmd.add_option("--domain", o.domain, "interior, exterior (solvent up to a box) or both")
      ->check(CLI::IsMember({"interior", "exterior", "both"}))
      ->capture_default_str();
  cmd.add_option("--box-margin", o.volume.box_margin, "Angstrom between the skin's bounding box and the outer box")
      ->check(finite_number())->check(positive_number())
      ->capture_default_str();
  cmd.add_option("--max-radius-edge", o.volume.bounds.max_radius_edge, "largest circumradius / shortest edge of a tetrahedron")
      ->check(finite_number())->check(CLI::Range(1.0, 10.0))
      ->capture_default_str();
  cmd.add_option("--min-dihedral", o.volume.bounds.min_dihedral, "smallest dihedral angle, degrees")
      ->check(finite_number())->check(CLI::Range(0.0, 16.0))
      ->capture_default_str();
  cmd.add_option("--max-volume", o.volume.max_volume, "largest tetrahedron, A^3 (0: no bound)")
      ->check(finite_number())->check(non_negative_number())
      ->capture_default_str();
  cmd.add_option("--max-tetrahedra", o.volume.max_tetrahedra,
                 "refuse at once a job whose estimate of TetGen's tetrahedra passes this")
      ->check(positive_number())
      ->capture_default_str();
  cmd.add_flag("--drop-cavities", o.drop_cavities, "fill enclosed voids instead of keeping their surfaces");
  cmd.add_option("--epsilon", o.meshing.sizing.epsilon, "surface: edge length / local radius of curvature")
      ->check(finite_number())->check(positive_number())
      ->capture_default_str();
  cmd.add_option("--edge-length", o.meshing.edge_length, "surface: largest edge length, A (0: none, curvature only)")->check(finite_number())->check(non_negative_number())->capture_default_str();
  cmd.add_option("--max-memory", o.max_memory_gb,
                 "refuse at once a skin mesh or a TetGen run whose estimated memory passes this many GB, and stop "
                 "TetGen past it (0: the memory available now)")
      ->check(finite_number())->check(non_negative_number())
      ->capture_default_str();
  cmd.add_option("--max-seconds", o.volume.max_seconds, "stop TetGen past this many seconds (0: no bound)")
      ->check(finite_number())->check(non_negative_number())
      ->capture_default_str();
}

VolumeOptions volume_options(const VolumeCommandOptions& o) {
  VolumeOptions volume = o.volume;
  volume.domain = o.domain == "both"       ? VolumeDomain::both
                  : o.domain == "exterior" ? VolumeDomain::exterior
                                           : VolumeDomain::interior;
  volume.cavities = o.drop_cavities ? Cavities::fill : Cavities::keep;
  return volume;
}

json volume_report(const VolumeCommandOptions& o, const VolumeOptions& volume, const VolumeMeshResult& made,
                   const TetQuality& q, const MeshQuality& sq, long tetgen_triangles) {
  json report = tet_report(made.mesh, q);
  report["molecule"] = o.molecule.path;
  report["domain"] = o.domain;
  report["surface"] = to_json(sq);
  report["surface_self_intersections"] = {{"cgal_exact", sq.self_intersecting_pairs},
                                          {"tetgen_triangles", tetgen_triangles >= 0 ? json(tetgen_triangles) : json(nullptr)}};
  // The interior's tetrahedra fill exactly what the skin encloses (its
  // outer components minus kept cavities): the grader's signed volume.
  report["enclosed_volume"] = sq.volume;
  report["estimated_tetrahedra"] = {{"expected", std::llround(made.estimated_tetrahedra)},
                                    {"low", std::llround(made.estimated_low)}};
  const bool bounds_met =
      q.max_radius_edge <= volume.bounds.max_radius_edge && q.min_dihedral >= volume.bounds.min_dihedral;
  report["bounds"] = {{"max_radius_edge", volume.bounds.max_radius_edge}, {"min_dihedral", volume.bounds.min_dihedral}};
  report["bounds_met"] = bounds_met;
  const TetImprovement& smoothing = made.improvement;
  report["smoothing"] = {{"out_of_bounds_from_tetgen", smoothing.bad_before},
                         {"out_of_bounds_after", smoothing.bad_after},
                         {"points_moved", smoothing.moved},
                         {"edges_removed", smoothing.flips}};
  report["outputs"] = {o.output + ".vtu", o.output + ".msh", o.output + ".node", o.output + ".ele",
                       o.output + ".face"};
  if (volume.domain != VolumeDomain::exterior)
    report["interior_volume_relative_difference"] =
        std::abs(region_volume(made.mesh, kRegionInterior) - sq.volume) / sq.volume;
  return report;
}

void print_volume_summary(const VolumeCommandOptions& o, const VolumeOptions& volume, const TetQuality& q,
                          const json& report) {
  const json& smoothing = report["smoothing"];
  const json& surface = report["surface"];
  const json& tetgen = report["surface_self_intersections"]["tetgen_triangles"];
  std::cout << o.output << ".{vtu,msh,node,ele,face}: " << q.tets << " tetrahedra, " << q.points << " points ("
            << o.domain << ")\n";
  print_tet_quality(std::cout, q);
  std::cout << "  bounds (radius-edge <= " << volume.bounds.max_radius_edge << ", dihedral >= "
            << volume.bounds.min_dihedral << " deg): " << (report["bounds_met"].get<bool>() ? "met" : "NOT met")
            << "; TetGen left " << smoothing["out_of_bounds_from_tetgen"] << " tetrahedra outside, "
            << smoothing["points_moved"] << " of its points moved, " << smoothing["edges_removed"]
            << " edges removed, " << smoothing["out_of_bounds_after"] << " left\n";
  for (const auto& [name, r] : report["regions"].items())
    std::cout << "  region " << name << ": " << r["tetrahedra"].get<long>() << " tetrahedra, volume "
              << r["volume"].get<double>() << " A^3\n";
  std::cout << "  skin: " << surface["triangles"] << " triangles, closed oriented manifold, "
            << surface["self_intersecting_pairs"] << " self-intersecting pairs (CGAL, exact), "
            << (tetgen.is_null() ? std::string("not checked") : tetgen.dump() + " triangles") << " (TetGen -d); encloses "
            << report["enclosed_volume"].get<double>() << " A^3\n";
}

// The five volume files and the report, all or none.
void write_volume_files(const VolumeCommandOptions& o, const TetMesh& mesh, const json& report) {
  OutputSet outputs;
  outputs.add(o.output + ".vtu", [&](std::ostream& out) { write_vtu(out, mesh); });
  outputs.add(o.output + ".msh", [&](std::ostream& out) { write_gmsh(out, mesh); });
  outputs.add(o.output + ".node", [&](std::ostream& out) { write_tetgen_node(out, mesh); });
  outputs.add(o.output + ".ele", [&](std::ostream& out) { write_tetgen_ele(out, mesh); });
  outputs.add(o.output + ".face", [&](std::ostream& out) { write_tetgen_face(out, mesh); });
  if (!o.report.empty()) outputs.add(o.report, [&](std::ostream& out) { out << json_text(report) << "\n"; });
  outputs.commit();
}

// The outer box alone, before the skin is meshed: the atoms' centres lie
// inside the skin, so their bounding box is inside the skin's, and the box's
// estimate without the skin's triangles or the volume bound is a low end of
// the full one. A margin whose box TetGen could not hold is refused at once,
// however long the molecule would take to mesh. Empty when it fits.
std::string box_refusal(const std::vector<Ball>& balls, const VolumeOptions& volume) {
  if (volume.domain == VolumeDomain::interior) return "";
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const Ball& b : balls)
    if (b.weight > 0) lo = lo.cwiseMin(b.center), hi = hi.cwiseMax(b.center);
  if (!(lo.x() <= hi.x())) return "";
  TetDomain box;
  box.extent = hi - lo;
  VolumeOptions without_volume_bound = volume;
  without_volume_bound.max_volume = 0;
  return tet_budget_refusal(box, without_volume_bound);
}

ExitCode run_volume(const VolumeCommandOptions& o, const GlobalOptions& global) {
  const bool progress = !global.quiet && !global.json;
  std::vector<std::string> outputs_to_write;
  for (const char* ext : {".vtu", ".msh", ".node", ".ele", ".face"}) outputs_to_write.push_back(o.output + ext);
  if (!o.report.empty()) outputs_to_write.push_back(o.report);
  check_writable(outputs_to_write);
  const Molecule m = read_molecule(o.molecule.path, o.molecule.read);
  if (m.atoms.empty()) input_error(o.molecule.path, 0, "no atoms left to mesh");
  const auto balls = balls_from_molecule(m, o.molecule.shrink, o.molecule.convention());
  VolumeOptions volume = volume_options(o);
  volume.max_memory_bytes = memory_limit_bytes(o.max_memory_gb);
  if (const std::string too_big = box_refusal(balls, volume); !too_big.empty()) {
    std::cerr << "skinmesh: error: " << o.molecule.path << ": " << too_big << "\n";
    return ExitCode::not_met;
  }
  const SkinComplex complex = build_skin_complex(balls, {o.molecule.shrink});
  MeshingOptions meshing = o.meshing;
  meshing.max_memory_bytes = memory_limit_bytes(o.max_memory_gb);
  const auto line = std::make_shared<ProgressLine>(progress);
  if (progress) meshing.progress = meshing_progress_line(line);
  const SkinMeshResult surface = mesh_skin(complex, meshing);
  line->finish();
  if (surface.status == MeshingStatus::empty_skin) input_error(o.molecule.path, 0, surface.message);
  if (surface.status != MeshingStatus::ok) {
    std::cerr << "skinmesh: error: " << o.molecule.path << ": " << surface.message << "\n";
    if (surface.status == MeshingStatus::over_budget) std::cerr << "skinmesh: " << over_budget_hint(surface, true) << "\n";
    return ExitCode::not_met;
  }
  GuaranteeOptions bounds;
  bounds.min_angle = o.meshing.min_angle;
  const GuaranteeReport g = check_guarantees(surface.mesh, balls, o.molecule.shrink, bounds);
  if (!g.all_hold()) {
    std::cerr << "skinmesh: error: " << o.molecule.path << ": the skin mesh fails a guarantee; no volume mesh\n"
              << json_text(guarantees_json(g)) << "\n";
    return ExitCode::not_met;
  }
  if (progress) std::cerr << "skinmesh: " << surface.mesh.triangles.size() << " skin triangles; running TetGen\n";
  const VolumeMeshResult made = tetrahedralize(surface.mesh, volume);
  if (made.status != VolumeStatus::ok) {
    std::cerr << "skinmesh: error: " << o.molecule.path << ": " << made.message << "\n";
    return ExitCode::not_met;
  }
  const TetQuality q = grade_tet_mesh(made.mesh);
  const long tetgen_triangles = tetgen_self_intersections(surface.mesh);
  const json report = volume_report(o, volume, made, q, g.quality, tetgen_triangles);
  write_volume_files(o, made.mesh, report);
  if (global.json) std::cout << json_text(report) << "\n";
  else if (!global.quiet) print_volume_summary(o, volume, q, report);
  return ExitCode::ok;
}

}  // namespace

void add_volume_command(CLI::App& app, const GlobalOptions& global, int& exit_code) {
  add_command(app, "volume", "tetrahedral mesh of the molecule's interior and/or the solvent (TetGen)", global,
              exit_code, add_volume_options, run_volume);
}

}  // namespace skinmesh::app
