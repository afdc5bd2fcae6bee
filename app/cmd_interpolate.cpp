// skinmesh interpolate: the ball set B(t) = {(1-t) a_i + t b_j} between a
// source and a target molecule (docs/math.md sections 1 and 4), live pairs only or
// all m*n, written as weighted points (.wpts) that every command reads like a
// molecule, so an intermediate skin can be meshed and inspected as a static one.
#include "commands.hpp"
#include "exit_codes.hpp"
#include "molecule_options.hpp"
#include "quality_report.hpp"
#include "output_file.hpp"

#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/core/error.hpp"
#include "skinmesh/core/file_names.hpp"
#include "skinmesh/core/interpolation.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <sstream>

namespace skinmesh::app {
namespace {

std::vector<Ball> read_balls(const std::string& path, ReadOptions read, int model, const MoleculeOptions& o,
                             bool centre, bool warn) {
  read.model = model;
  const Molecule m = read_molecule(path, read);
  if (warn)
    for (const std::string& w : m.warnings) std::cerr << "skinmesh: warning: " << w << "\n";
  std::vector<Ball> balls = balls_from_molecule(m, o.shrink, o.convention());
  if (centre) centre_balls(balls);
  return balls;
}

}  // namespace

void add_interpolate_command(CLI::App& app, const GlobalOptions& global, int& exit_code) {
  struct Options {
    MoleculeOptions molecule;  // settings shared by both inputs; path unused
    std::string source, target, output;
    int source_model = 1, target_model = 1;
    double t = 0.5;
    bool all = false, centre = false;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("interpolate", "the interpolated ball set B(t) of a morph, as weighted points");
  cmd->add_option("source", o->source, "source molecule (any format a molecule is read from)")->required();
  cmd->add_option("target", o->target, "target molecule")->required();
  cmd->add_option("--t,-t", o->t, "time in [0, 1]: 0 is the source, 1 the target")
      ->check(finite_number())->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--output,-o", o->output, "output weighted points file (.wpts: x y z w per line)")->required();
  cmd->add_flag("--all-pairs", o->all, "keep all m*n pairs (default: live pairs only, hidden ones dropped)");
  cmd->add_flag("--centre,--center", o->centre, "move each molecule's centroid to the origin first");
  cmd->add_option("--source-model", o->source_model, "1-based model of the source file")->check(finite_number())->check(positive_number());
  cmd->add_option("--target-model", o->target_model, "1-based model of the target file")->check(finite_number())->check(positive_number());
  add_molecule_settings(*cmd, o->molecule, ModelChoice::none);
  cmd->callback([o, &global, &exit_code]() {
    if (!has_extension(lowercase(o->output), ".wpts"))
      contract_error(o->output + ": interpolated weights can be negative, which XYZR cannot hold; "
                                  "write weighted points, OUT.wpts");
    check_writable({o->output});
    const auto t0 = Clock::now();
    const bool warn = !global.quiet && !global.json;
    const std::vector<Ball> a = read_balls(o->source, o->molecule.read, o->source_model, o->molecule, o->centre, warn);
    std::vector<Ball> b = read_balls(o->target, o->molecule.read, o->target_model, o->molecule, o->centre, warn);
    // Balls the motion leaves nearer than kUnmovedWithin are the same ball:
    // that near but not equal, B(t) is too nearly degenerate to mesh.
    const long unmoved = snap_unmoved_balls(a, b);
    // All m*n pairs take 40 bytes each (the pair and its ball): refuse what
    // would not fit rather than die in the allocation.
    constexpr double kMaxAllPairs = 2e7;
    const double product = static_cast<double>(a.size()) * static_cast<double>(b.size());
    if (o->all && product > kMaxAllPairs)
      contract_error("--all-pairs would make " + std::to_string(a.size()) + " x " + std::to_string(b.size()) +
                     " balls (about " + std::to_string(static_cast<long long>(product * 40 / 1e6)) +
                     " MB); at most " + std::to_string(static_cast<long long>(kMaxAllPairs)) +
                     " are written. The live pairs (without --all-pairs) give the same skin");
    const std::vector<BallPair> pairs = o->all ? all_pairs(a.size(), b.size()) : live_pairs(a, b);
    const std::vector<Ball> balls = interpolated_balls(a, b, pairs, o->t);
    long negative = 0;
    for (const Ball& ball : balls) negative += ball.weight < 0;
    std::ostringstream comment;
    comment << "B(t) at t = " << o->t << " between " << o->source << " (model " << o->source_model << ", "
            << a.size() << " balls) and " << o->target << " (model " << o->target_model << ", " << b.size()
            << " balls); " << (o->all ? "all pairs" : "live pairs") << (o->centre ? ", both centred" : "")
            << "; shrink " << o->molecule.shrink << ", weights "
            << convention_name(o->molecule.convention()) << "; " << unmoved << " target balls within "
            << kUnmovedWithin << " A of a source ball of the same weight put on it";
    write_file_atomically(o->output, [&](std::ostream& out) { write_wpts(out, balls, comment.str()); });
    const double seconds = seconds_since(t0);
    nlohmann::json report{{"source", o->source},  {"target", o->target},         {"t", o->t},
                          {"source_balls", a.size()}, {"target_balls", b.size()}, {"all_pairs", a.size() * b.size()},
                          {"balls", balls.size()}, {"negative_weights", negative}, {"live_pairs_only", !o->all},
                          {"unmoved_balls", unmoved},
                          {"output", o->output},   {"seconds", seconds}};
    if (global.json) std::cout << json_text(report) << "\n";
    else if (!global.quiet)
      std::cout << o->output << ": " << balls.size() << " weighted points at t = " << o->t << " ("
                << (o->all ? "all" : "live") << " pairs of " << a.size() << " x " << b.size() << " = "
                << a.size() * b.size() << "; " << negative << " negative weights; " << unmoved
                << " target balls unmoved), " << seconds << " s\n";
    exit_code = code(ExitCode::ok);
  });
}

}  // namespace skinmesh::app
