#include "quality_report.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <cmath>
#include <string>
#include <utility>

namespace skinmesh::app {

std::string json_text(const nlohmann::json& j, JsonLayout layout) {
  return j.dump(layout == JsonLayout::indented ? 2 : -1, ' ', false, nlohmann::json::error_handler_t::replace);
}

nlohmann::json to_json(const MeshQuality& q) {
  using json = nlohmann::json;
  json valence = json::object();
  for (const auto& [k, n] : q.valence) valence[std::to_string(k)] = n;
  auto finite = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  return {{"vertices", q.vertices},
          {"triangles", q.triangles},
          {"edges", q.edges},
          {"min_angle_deg", q.min_angle},
          {"max_angle_deg", q.max_angle},
          {"mean_min_angle_deg", q.mean_min_angle},
          {"share_min_angle_below_20", q.share_below_20},
          {"share_min_angle_below_10", q.share_below_10},
          {"max_radius_edge_ratio", finite(q.max_radius_edge)},
          {"max_aspect_ratio", finite(q.max_aspect)},
          {"edge_length", {{"min", q.min_edge}, {"mean", q.mean_edge}, {"max", q.max_edge}}},
          {"valence", valence},
          {"area", q.area},
          {"volume", q.volume},
          {"components", q.components},
          {"cavities", q.cavities},
          {"euler_characteristic", q.euler},
          {"genus", q.genus >= 0 ? json(q.genus) : json(nullptr)},
          {"closed", q.closed},
          {"manifold", q.manifold},
          {"consistently_oriented", q.oriented},
          {"boundary_edges", q.boundary_edges},
          {"nonmanifold_edges", q.nonmanifold_edges},
          {"nonmanifold_vertices", q.nonmanifold_vertices},
          {"inconsistent_edges", q.inconsistent_edges},
          {"degenerate_triangles", q.degenerate_triangles},
          {"unused_vertices", q.unused_vertices},
          {"self_intersections_checked", q.self_intersections_checked},
          {"self_intersecting_pairs", q.self_intersections_checked ? json(q.self_intersecting_pairs) : json(nullptr)},
          {"self_intersection_box_pairs", q.self_intersection_box_pairs},
          {"self_intersections_over_bound", q.self_intersections_over_bound},
          {"min_angle_histogram", {{"lo_deg", q.min_angle_histogram.lo},
                                   {"hi_deg", q.min_angle_histogram.hi},
                                   {"counts", q.min_angle_histogram.counts}}}};
}

void write_svg(std::ostream& out, const MeshQuality& q, const std::string& title) {
  const auto& h = q.min_angle_histogram;
  const long peak = std::max<long>(1, *std::max_element(h.counts.begin(), h.counts.end()));
  const int width = 640, height = 360, left = 60, bottom = 300, plot_h = 240;
  const double bar = (width - left - 20.0) / h.counts.size();
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  out << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  out << "<text x=\"" << left << "\" y=\"24\" font-size=\"14\">Smallest angle per triangle: " << title << "</text>\n";
  for (size_t i = 0; i < h.counts.size(); ++i) {
    const double hgt = plot_h * static_cast<double>(h.counts[i]) / peak;
    const double lo = h.lo + (h.hi - h.lo) * i / h.counts.size();
    out << "<rect x=\"" << left + bar * i + 1 << "\" y=\"" << bottom - hgt << "\" width=\"" << bar - 2
        << "\" height=\"" << hgt << "\" fill=\"" << (lo < 20 ? "#d95f02" : "#1b9e77") << "\"><title>" << lo << "-"
        << lo + (h.hi - h.lo) / h.counts.size() << " deg: " << h.counts[i] << "</title></rect>\n";
    out << "<text x=\"" << left + bar * i << "\" y=\"" << bottom + 16 << "\">" << lo << "</text>\n";
  }
  out << "<line x1=\"" << left << "\" y1=\"" << bottom << "\" x2=\"" << width - 20 << "\" y2=\"" << bottom
      << "\" stroke=\"black\"/>\n";
  out << "<text x=\"" << left << "\" y=\"" << bottom + 36 << "\">degrees (orange: below 20); " << q.triangles
      << " triangles, min " << q.min_angle << " deg; tallest bar " << peak << "</text>\n";
  out << "</svg>\n";
}


nlohmann::json to_json(const SurfaceError& e) {
  return {{"max", e.max}, {"mean", e.mean}, {"uncertified", e.uncertified}};
}

nlohmann::json guarantees_json(const GuaranteeReport& g) {
  using json = nlohmann::json;
  return {{"min_angle_at_least_bound", g.angle},
          {"vertices_on_skin_within_1e-9", g.on_skin},
          {"closed_oriented_manifold", g.closed_oriented_manifold},
          {"no_self_intersections", g.no_self_intersections ? json(*g.no_self_intersections) : json(nullptr)},
          {"topology_of_skin", g.topology ? json(*g.topology) : json(nullptr)}};
}

void print_quality_summary(std::ostream& out, const std::string& name, const MeshQuality& q) {
  out << name << ": " << q.vertices << " vertices, " << q.triangles << " triangles\n"
      << "  angles:      min " << q.min_angle << ", max " << q.max_angle << " deg; " << 100 * q.share_below_20
      << "% of triangles under 20 deg, " << 100 * q.share_below_10 << "% under 10\n"
      << "  ratios:      radius-edge max " << q.max_radius_edge << ", aspect max " << q.max_aspect << "\n"
      << "  edges:       " << q.min_edge << " / " << q.mean_edge << " / " << q.max_edge << " A (min/mean/max)\n"
      << "  size:        area " << q.area << " A^2, volume " << q.volume << " A^3\n"
      << "  topology:    " << q.components << " component(s) (" << q.cavities << " cavities), Euler characteristic "
      << q.euler << ", genus "
      << (q.genus >= 0 ? std::to_string(q.genus) : std::string("n/a")) << "\n"
      << "  defects:     " << q.boundary_edges << " boundary edges, " << q.nonmanifold_edges
      << " non-manifold edges, " << q.nonmanifold_vertices << " non-manifold vertices, " << q.inconsistent_edges
      << " inconsistently oriented edges, " << q.degenerate_triangles << " zero-area triangles\n"
      << "  self-intersections: "
      << (q.self_intersections_checked     ? std::to_string(q.self_intersecting_pairs) + " pairs"
          : q.self_intersections_over_bound ? "not checked (stopped after " + std::to_string(q.self_intersection_box_pairs) +
                                                  " pairs of overlapping boxes)"
                                            : std::string("not checked (needs a manifold, oriented mesh)"))
      << "\n";
}

nlohmann::json tet_report(const TetMesh& mesh, const TetQuality& q) {
  // The faces a solver sees as boundaries: faces of exactly one tetrahedron,
  // and faces between tetrahedra of different regions. They should be the
  // mesh's marked faces, no more and no fewer.
  std::map<std::array<int, 3>, std::vector<int>> owners;
  for (size_t i = 0; i < mesh.tets.size(); ++i) {
    const auto& t = mesh.tets[i];
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f{};
      int k = 0;
      for (int j = 0; j < 4; ++j)
        if (j != skip) f[static_cast<size_t>(k++)] = t[static_cast<size_t>(j)];
      std::sort(f.begin(), f.end());
      owners[f].push_back(mesh.tet_region[i]);
    }
  }
  std::set<std::array<int, 3>> boundary, marked;
  for (const auto& [f, regions] : owners)
    if (regions.size() == 1 || regions[0] != regions[1]) boundary.insert(f);
  for (auto f : mesh.faces) {
    std::sort(f.begin(), f.end());
    marked.insert(f);
  }
  long unmarked = 0, stray = 0;
  for (const auto& f : boundary) unmarked += !marked.count(f);
  for (const auto& f : marked) stray += !boundary.count(f);
  std::map<int, long> counts;
  for (int r : mesh.tet_region) ++counts[r];
  nlohmann::json regions = nlohmann::json::object();
  for (const auto& [r, n] : counts) {
    const std::string name = r == kRegionInterior ? "interior"
                             : r == kRegionSolvent ? "solvent"
                             : r == kRegionCavity  ? "cavity"
                                                   : std::to_string(r);
    regions[name] = {{"tetrahedra", n}, {"volume", region_volume(mesh, r)}};
  }
  return {{"points", q.points},
          {"tetrahedra", q.tets},
          {"volume", q.volume},
          {"min_dihedral_deg", q.min_dihedral},
          {"max_dihedral_deg", q.max_dihedral},
          {"max_radius_edge_ratio", q.max_radius_edge},
          {"max_radius_edge_ratio_off_boundary", q.max_radius_edge_off_boundary},
          {"min_dihedral_deg_off_boundary", q.min_dihedral_off_boundary},
          {"inverted", q.inverted},
          {"regions", regions},
          {"boundary_faces", static_cast<long>(boundary.size())},
          {"boundary_faces_not_marked", unmarked},
          {"marked_faces_not_on_boundary", stray}};
}

void print_tet_quality(std::ostream& out, const TetQuality& q) {
  out << "  dihedral angles: " << q.min_dihedral << " - " << q.max_dihedral << " deg ("
      << q.min_dihedral_off_boundary << " min away from the surface)\n"
      << "  radius-edge:     max " << q.max_radius_edge << " (" << q.max_radius_edge_off_boundary
      << " away from the surface); " << q.inverted << " inverted\n";
}

nlohmann::json skin_area_json(const SkinArea& skin, double mesh_area) {
  return {{"skin", skin.area},
          {"uncertainty", skin.uncertainty},
          {"mesh", mesh_area},
          {"mesh_relative_error", skin.area > 0 ? (mesh_area - skin.area) / skin.area : 0.0},
          {"converged", skin.converged}};
}

nlohmann::json options_json(const MeshingOptions& m) {
  return {{"min_angle_deg", m.min_angle},
          {"epsilon", m.edge_length > 0 ? nlohmann::json(nullptr) : nlohmann::json(m.sizing.epsilon)},
          {"edge_length", m.edge_length > 0 ? nlohmann::json(m.edge_length) : nlohmann::json(nullptr)},
          {"min_size", m.sizing.min_size},
          {"max_size", m.sizing.max_size},
          {"tolerance", m.tolerance},
          {"contract_below", m.contract_below},
          {"max_triangles", m.max_triangles}};
}

nlohmann::json refinement_json(const MeshingStats& s) {
  return {{"seeds", s.seeds},
          {"inserted_for_size", s.inserted_size},
          {"inserted_for_distance", s.inserted_distance},
          {"inserted_for_angle", s.inserted_shape},
          {"inserted_for_topology", s.inserted_topology},
          {"passes", s.passes},
          {"contracted_edges", s.contracted},
          {"contraction_attempts", s.contraction_attempts}};
}

}  // namespace skinmesh::app
