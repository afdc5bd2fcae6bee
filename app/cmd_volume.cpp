// skinmesh volume: a tetrahedral mesh of the molecule's interior, of the
// solvent between its skin and a box, or of both, bounded by the quality skin
// mesh; written as TetGen's files, VTK (.vtu) and Gmsh (.msh), with a report.
#include "commands.hpp"
#include "molecule_options.hpp"
#include "output_file.hpp"
#include "quality_report.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/meshing/mesh_quality.hpp"
#include "skinmesh/meshing/skin_mesher.hpp"
#include "skinmesh/meshing/volume_mesh.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <iostream>

namespace skinmesh::app {

void add_volume_command(CLI::App& app, const GlobalOptions& global, int& exit_code) {
  struct Options {
    MoleculeOptions molecule;
    std::string output, report;
    MeshingOptions meshing;
    VolumeOptions volume;
    std::string domain = "interior";
    bool drop_cavities = false;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("volume", "tetrahedral mesh of the molecule's interior and/or the solvent (TetGen)");
  add_molecule_options(*cmd, o->molecule);
  cmd->add_option("--output,-o", o->output, "output stem: writes STEM.vtu, STEM.msh, STEM.node/.ele/.face")->required();
  cmd->add_option("--report", o->report, "write the report as JSON");
  cmd->add_option("--domain", o->domain, "interior, exterior (solvent up to a box) or both")
      ->check(CLI::IsMember({"interior", "exterior", "both"}))
      ->capture_default_str();
  cmd->add_option("--box-margin", o->volume.box_margin, "Angstrom between the skin's bounding box and the outer box")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--max-radius-edge", o->volume.max_radius_edge, "largest circumradius / shortest edge of a tetrahedron")
      ->check(CLI::Range(1.0, 10.0))
      ->capture_default_str();
  cmd->add_option("--min-dihedral", o->volume.min_dihedral, "smallest dihedral angle, degrees")
      ->check(CLI::Range(0.0, 16.0))
      ->capture_default_str();
  cmd->add_option("--max-volume", o->volume.max_volume, "largest tetrahedron, A^3 (0: no bound)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--drop-cavities", o->drop_cavities, "fill enclosed voids instead of keeping their surfaces");
  cmd->add_option("--epsilon", o->meshing.sizing.epsilon, "surface: edge length / local radius of curvature")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--edge-length", o->meshing.edge_length, "surface: largest edge length, A")->check(CLI::PositiveNumber);
  cmd->callback([o, &global, &exit_code]() {
    const bool progress = !global.quiet && !global.json;
    const Molecule m = read_molecule(o->molecule.path, o->molecule.read);
    if (m.atoms.empty()) throw InputError(o->molecule.path, 0, "no atoms left to mesh");
    const auto balls = balls_from_molecule(m, o->molecule.shrink, o->molecule.convention());
    const SkinComplex complex = build_skin_complex(balls, {o->molecule.shrink});
    if (progress) std::cerr << "skinmesh: meshing the skin\n";
    SkinMeshResult surface;
    try {
      surface = mesh_skin(complex, o->meshing);
    } catch (const MeshingError& e) {
      std::cerr << "skinmesh: error: " << o->molecule.path << ": " << e.what() << "\n";
      exit_code = 3;
      return;
    }
    const MeshQuality sq = grade_mesh(surface.mesh);
    if (!(sq.closed && sq.manifold && sq.oriented && sq.self_intersecting_pairs == 0)) {
      std::cerr << "skinmesh: error: " << o->molecule.path << ": the skin mesh is not a closed, oriented, "
                << "self-intersection-free manifold; no volume mesh\n";
      exit_code = 3;
      return;
    }
    VolumeOptions volume = o->volume;
    volume.domain = o->domain == "both"       ? VolumeDomain::both
                    : o->domain == "exterior" ? VolumeDomain::exterior
                                              : VolumeDomain::interior;
    volume.keep_cavities = !o->drop_cavities;
    if (progress) std::cerr << "skinmesh: " << surface.mesh.triangles.size() << " skin triangles; running TetGen\n";
    TetMesh tets;
    TetImprovement smoothing;
    try {
      tets = tetrahedralize(surface.mesh, volume, &smoothing);
    } catch (const VolumeMeshError& e) {
      std::cerr << "skinmesh: error: " << o->molecule.path << ": " << e.what() << "\n";
      exit_code = 3;
      return;
    }
    const TetQuality q = grade_tet_mesh(tets);
    const long tetgen_pairs = tetgen_self_intersections(surface.mesh, volume.tetgen);
    // The interior's tetrahedra fill exactly what the skin encloses (its
    // outer components minus kept cavities): the grader's signed volume.
    const double enclosed = sq.volume;
    const double interior = region_volume(tets, kRegionInterior);
    nlohmann::json report = tet_report(tets, q);
    report["molecule"] = o->molecule.path;
    report["domain"] = o->domain;
    report["surface"] = to_json(sq);
    report["surface_self_intersections"] = {{"cgal_exact", sq.self_intersecting_pairs}, {"tetgen", tetgen_pairs}};
    report["enclosed_volume"] = enclosed;
    const bool bounds_met = q.max_radius_edge <= volume.max_radius_edge && q.min_dihedral >= volume.min_dihedral;
    report["bounds"] = {{"max_radius_edge", volume.max_radius_edge}, {"min_dihedral", volume.min_dihedral}};
    report["bounds_met"] = bounds_met;
    report["smoothing"] = {{"out_of_bounds_from_tetgen", smoothing.bad_before},
                           {"out_of_bounds_after", smoothing.bad_after},
                           {"points_moved", smoothing.moved}, {"edges_removed", smoothing.flips}};
    report["outputs"] = {o->output + ".vtu", o->output + ".msh", o->output + ".node", o->output + ".ele",
                         o->output + ".face"};
    const nlohmann::json& regions = report["regions"];
    if (volume.domain != VolumeDomain::exterior)
      report["interior_volume_relative_difference"] = std::abs(interior - enclosed) / enclosed;
    write_file_atomically(o->output + ".vtu", [&](std::ostream& out) { write_vtu(out, tets); });
    write_file_atomically(o->output + ".msh", [&](std::ostream& out) { write_gmsh(out, tets); });
    write_file_atomically(o->output + ".node", [&](std::ostream& out) { write_tetgen_node(out, tets); });
    write_file_atomically(o->output + ".ele", [&](std::ostream& out) { write_tetgen_ele(out, tets); });
    write_file_atomically(o->output + ".face", [&](std::ostream& out) { write_tetgen_face(out, tets); });
    if (!o->report.empty())
      write_file_atomically(o->report, [&](std::ostream& out) { out << report.dump(2) << "\n"; });
    if (global.json) {
      std::cout << report.dump(2) << "\n";
    } else if (!global.quiet) {
      std::cout << o->output << ".{vtu,msh,node,ele,face}: " << q.tets << " tetrahedra, " << q.points << " points ("
                << o->domain << ")\n";
      print_tet_quality(std::cout, q);
      std::cout << "  bounds (radius-edge <= " << volume.max_radius_edge << ", dihedral >= " << volume.min_dihedral
                << " deg): " << (bounds_met ? "met" : "NOT met") << "; TetGen left " << smoothing.bad_before
                << " tetrahedra outside, " << smoothing.moved << " of its points moved, " << smoothing.flips << " edges removed, " << smoothing.bad_after
                << " left\n";
      for (const auto& [name, r] : regions.items())
        std::cout << "  region " << name << ": " << r["tetrahedra"].get<long>() << " tetrahedra, volume "
                  << r["volume"].get<double>() << " A^3\n";
      std::cout << "  skin: " << sq.triangles << " triangles, closed oriented manifold, "
                << sq.self_intersecting_pairs << " self-intersecting pairs (CGAL, exact), " << tetgen_pairs
                << " (TetGen -d); encloses " << enclosed << " A^3\n";
    }
    exit_code = 0;
  });
}

}  // namespace skinmesh::app
