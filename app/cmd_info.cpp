// skinmesh info: what was read, the radii used, and the skin complex built on it.
#include "commands.hpp"
#include "exit_codes.hpp"
#include "molecule_options.hpp"
#include "quality_report.hpp"

#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/core/radii.hpp"
#include "skinmesh/core/skin_complex.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <iomanip>
#include <iostream>
#include <map>

namespace skinmesh::app {
namespace {

using json = nlohmann::json;

json describe(const Molecule& m, const MoleculeOptions& o) {
  json j;
  j["file"] = m.source;
  j["format"] = format_name(m.format);
  j["model"] = m.model;
  j["models_in_file"] = m.models_in_file;
  j["atoms"] = m.atoms.size();
  long skipped_total = 0;
  json skipped = json::object();
  for (const auto& [reason, count] : m.skipped) skipped[reason] = count, skipped_total += count;
  j["atoms_skipped"] = skipped_total;
  j["skipped_by_reason"] = skipped;

  std::map<std::string, std::pair<long, double>> radii;  // element -> (count, radius)
  for (const Atom& a : m.atoms) {
    auto& entry = radii[a.element.empty() ? "?" : a.element];
    ++entry.first;
    entry.second = a.radius;
  }
  json radii_json = json::array();
  const bool text_radii =
      m.format == MoleculeFormat::Pqr || m.format == MoleculeFormat::Xyzr || m.format == MoleculeFormat::Wpts;
  for (const auto& [element, entry] : radii) {
    json r{{"element", element}, {"atoms", entry.first}};
    if (text_radii) {
      r["source"] = "file";
    } else {
      r["radius"] = entry.second;
      r["source"] = m.unknown_elements.count(element) ? "unknown element: --unknown-radius" : "Bondi 1964";
    }
    radii_json.push_back(r);
  }
  j["radii"] = radii_json;
  json unknown = json::object();
  for (const auto& [element, count] : m.unknown_elements) unknown[element] = count;
  j["unknown_elements"] = unknown;

  Eigen::Vector3d lo = m.atoms.front().position, hi = lo;
  for (const Atom& a : m.atoms) lo = lo.cwiseMin(a.position), hi = hi.cwiseMax(a.position);
  j["bounding_box"] = {{"min", {lo.x(), lo.y(), lo.z()}}, {"max", {hi.x(), hi.y(), hi.z()}}};

  const auto t0 = Clock::now();
  const SkinComplex sc = build_skin_complex(balls_from_molecule(m, o.shrink, o.convention()), {o.shrink});
  const double seconds = seconds_since(t0);
  const auto counts = sc.cell_counts();
  j["shrink"] = o.shrink;
  j["weights"] = m.format == MoleculeFormat::Wpts ? "as given (weighted points)" : convention_name(o.convention());
  j["regular_triangulation_dimension"] = sc.triangulation_dimension();
  j["mixed_cells"] = {{"vertex", counts[0]}, {"edge", counts[1]}, {"triangle", counts[2]}, {"tetrahedron", counts[3]},
                      {"total", counts[0] + counts[1] + counts[2] + counts[3]}};
  j["degenerate_cells"] = sc.degenerate_cell_count();
  json hidden = json::array();
  for (int i : sc.hidden_balls()) {
    const Atom& a = m.atoms[static_cast<size_t>(i)];
    hidden.push_back({{"index", i}, {"atom", a.name}, {"residue", a.residue}, {"chain", a.chain},
                      {"residue_number", a.residue_number}, {"line", a.line}});
  }
  j["hidden_balls"] = hidden;
  j["complex_seconds"] = seconds;
  j["warnings"] = m.warnings;
  return j;
}

void print_text(const json& j, std::ostream& out) {
  out << j["file"].get<std::string>() << " (" << j["format"].get<std::string>() << ", model " << j["model"] << " of "
      << j["models_in_file"] << ")\n";
  out << "  atoms read:     " << j["atoms"] << "\n";
  out << "  atoms skipped:  " << j["atoms_skipped"];
  if (!j["skipped_by_reason"].empty()) {
    out << " (";
    bool first = true;
    for (auto it = j["skipped_by_reason"].begin(); it != j["skipped_by_reason"].end(); ++it) {
      out << (first ? "" : ", ") << it.value() << " " << it.key();
      first = false;
    }
    out << ")";
  }
  out << "\n  radii:";
  for (const auto& r : j["radii"]) {
    out << " " << r["element"].get<std::string>() << "x" << r["atoms"];
    if (r.contains("radius")) out << "=" << r["radius"].get<double>();
  }
  out << (j["radii"].front()["source"] == "file" ? "  (from the file)" : "  (Angstrom, Bondi 1964)") << "\n";
  if (!j["unknown_elements"].empty()) out << "  unknown elements: " << j["unknown_elements"].dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  const auto& lo = j["bounding_box"]["min"];
  const auto& hi = j["bounding_box"]["max"];
  out << std::fixed << std::setprecision(3) << "  bounding box:   [" << lo[0].get<double>() << ", "
      << lo[1].get<double>() << ", " << lo[2].get<double>() << "] - [" << hi[0].get<double>() << ", "
      << hi[1].get<double>() << ", " << hi[2].get<double>() << "] A\n";
  out << std::defaultfloat;
  out << "  skin:           s = " << j["shrink"].get<double>() << ", weights w = " << j["weights"].get<std::string>()
      << "\n";
  const auto& c = j["mixed_cells"];
  out << "  regular triangulation: dimension " << j["regular_triangulation_dimension"] << ", " << c["vertex"]
      << " vertices, " << c["edge"] << " edges, " << c["triangle"] << " triangles, " << c["tetrahedron"]
      << " tetrahedra\n";
  out << "  mixed cells:    " << c["total"] << " (" << c["vertex"] << " sphere, " << c["edge"] << " edge hyperboloid, "
      << c["triangle"] << " triangle hyperboloid, " << c["tetrahedron"] << " tetrahedron sphere)";
  if (j["degenerate_cells"].get<long>() > 0) out << ", " << j["degenerate_cells"] << " degenerate";
  out << "\n  hidden balls:   " << j["hidden_balls"].size();
  int shown = 0;
  for (const auto& h : j["hidden_balls"]) {
    if (shown++ == 5) {
      out << " ...";
      break;
    }
    out << (shown == 1 ? " (" : ", ") << h["atom"].get<std::string>() << " " << h["residue"].get<std::string>() << " "
        << h["chain"].get<std::string>() << h["residue_number"];
    if (h["line"].get<long>() > 0) out << " line " << h["line"];
  }
  if (shown > 0 && shown <= 5) out << ")";
  out << "\n  complex built in " << std::setprecision(3) << j["complex_seconds"].get<double>() * 1000 << " ms\n";
}

}  // namespace

void add_info_command(CLI::App& app, const GlobalOptions& global, int& exit_code) {
  auto options = std::make_shared<MoleculeOptions>();
  CLI::App* cmd = app.add_subcommand("info", "atoms, radii and the skin complex of a molecule");
  add_molecule_options(*cmd, *options, ModelChoice::one_or_all);
  cmd->callback([options, &global, &exit_code]() {
    std::vector<Molecule> molecules;
    if (options->all_models)
      molecules = read_all_models(options->path, options->read);
    else
      molecules.push_back(read_molecule(options->path, options->read));
    json all = json::array();
    for (const Molecule& m : molecules) {
      if (!global.quiet && !global.json)
        for (const std::string& w : m.warnings) std::cerr << "skinmesh: warning: " << w << "\n";
      all.push_back(describe(m, *options));
    }
    if (global.json) {
      std::cout << json_text((options->all_models ? all : all.front())) << "\n";
    } else {
      for (const json& j : all) print_text(j, std::cout);
    }
    exit_code = code(ExitCode::ok);
  });
}

}  // namespace skinmesh::app
