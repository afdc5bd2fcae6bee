// Moving atoms (`--pairs matched`, morph/moving_balls.hpp) against per-frame
// reconstruction, side by side in one run, each column in its own forked
// child:
//   (b) each frame rebuilt from scratch by skinmesh's mesher from the moved
//       atoms (complex and mesh, at the frame criteria: 20 degrees);
//   (c) the moving-balls engine: the first frame meshed, every later frame
//       carried from the one before;
//   (c_cmd) `skinmesh trajectory` over the same frames written as the models
//       of an mmCIF file (a frame per model, coordinates in full): the
//       engine with the command's check of every frame and its output, as a
//       user runs it.
// Motions: 2k39 model 1 -> 3 (fitted by Kabsch), a hinge motion of 3mht's
// protein (residues 187-304 of chain A turned by 20 degrees), and 3mht's
// DNA (chains C and D of its 3,141 atoms) moved 6 A off the protein and
// turned by 20 degrees, and 1ubi's atoms in MD-like thermal motion (each
// atom fluctuating about its place, below), each over N frames (default 101).
// (b) costs about the same at every frame and averages a sample spread over
// the run, after one untimed rebuild of the first frame. Quality is measured
// with the clock stopped, by the commands' own check (check_guarantees):
// every frame graded (closed, manifold, oriented, self-intersections,
// angles, components, voids and Euler characteristic against the skin's)
// and every vertex measured by the static oracle of the frame's balls.
//
//   bench_moving [--frames N] [--sample K] [--timeout S] [--only TEXT] [--skip-command]
//                [--first-size-margin X]   (c only: MovingOptions::first_size_margin, default the engine's)
//                [--retry-around-faults on|off]   (c only: PatchPolicy::retry_around_faults)
//                [--neck-surgery on|off]   (c only: RepairPolicy::neck_surgery)
//                [--birth-surgery on|off]   (c only: RepairPolicy::birth_surgery)
//                [--edit-generations N]   (c only: EditPolicy::generations)
//                [--patch-share X]   (c only: PatchPolicy::max_failing_share, a share 0-1)
//                [--sample-share X]   (c only: PatchPolicy::max_sample_share, a share 0-1)
//                [--retry-after N]   (c only: EditPolicy::retry_after_frames)
//                [--frame-log FILE]   (c only: each later frame's FrameStats, a JSON line per frame)
#include "forked.hpp"
#include "skinmesh/core/allocator.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/morph/alignment.hpp"
#include "skinmesh/morph/moving_balls.hpp"
#include "skinmesh/quality/guarantees.hpp"

#include <Eigen/Geometry>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

using namespace skinmesh;

namespace {

constexpr double kShrink = 0.5;

std::string data(const std::string& name) { return std::string(SKINMESH_DATA_DIR) + "/" + name; }

// A motion: the balls at s in [0,1], and the atoms they are (in order),
// from which the command's column writes the motion as an mmCIF file.
struct Motion {
  std::string name;
  size_t atoms = 0;
  std::function<std::vector<Ball>(double)> at;
  std::vector<Atom> atom_records;
};

// 3mht's two DNA strands (chains C and D) moved 6 A away from the protein
// (along the line between the centroids) and turned by 20 degrees about an
// axis through their centroid, the rest kept: one subunit of a complex moving
// off its partner.
Motion dna_3mht() {
  const Molecule m = read_molecule(data("3mht.pdb"));
  const std::vector<Ball> start = balls_from_molecule(m, kShrink);
  std::vector<char> moving(m.atoms.size(), 0);
  Eigen::Vector3d protein = Eigen::Vector3d::Zero(), dna = Eigen::Vector3d::Zero();
  double np = 0, nd = 0;
  for (size_t i = 0; i < m.atoms.size(); ++i) {
    moving[i] = m.atoms[i].chain != "A";
    (moving[i] ? dna : protein) += m.atoms[i].position;
    (moving[i] ? nd : np) += 1;
  }
  protein /= np;
  dna /= nd;
  const Eigen::Vector3d away = (dna - protein).normalized();
  const Eigen::Vector3d axis = away.cross(Eigen::Vector3d(0, 0, 1)).normalized();
  return {"3mht DNA 6 A out, 20 deg", start.size(),
          [=](double s) {
            const Eigen::Matrix3d turn = Eigen::AngleAxisd(s * 20 * M_PI / 180, axis).toRotationMatrix();
            std::vector<Ball> balls = start;
            for (size_t i = 0; i < balls.size(); ++i)
              if (moving[i]) balls[i].center = dna + s * 6 * away + turn * (start[i].center - dna);
            return balls;
          },
          m.atoms};
}

// A hinge motion of 3mht's protein alone (chain A, 2,632 atoms as read):
// residues 187-304, a third of them, turned by 20 degrees about the axis
// through the CA atoms of residues 186 and 305, the rest kept.
Motion hinge_3mht() {
  const Molecule m = read_molecule(data("3mht.pdb"));
  const std::vector<Ball> all = balls_from_molecule(m, kShrink);
  std::vector<Ball> start;
  std::vector<Atom> chain_a;
  std::vector<char> moving;
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero(), end = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < m.atoms.size(); ++i) {
    const Atom& a = m.atoms[i];
    if (a.chain != "A") continue;
    start.push_back(all[i]);
    chain_a.push_back(a);
    moving.push_back(a.residue_number >= 187 && a.residue_number <= 304);
    if (a.name == "CA" && a.residue_number == 186) pivot = a.position;
    if (a.name == "CA" && a.residue_number == 305) end = a.position;
  }
  const Eigen::Vector3d axis = (end - pivot).normalized();
  return {"3mht protein hinge, 20 deg", start.size(),
          [=](double s) {
            const Eigen::Matrix3d turn = Eigen::AngleAxisd(s * 20 * M_PI / 180, axis).toRotationMatrix();
            std::vector<Ball> balls = start;
            for (size_t i = 0; i < balls.size(); ++i)
              if (moving[i]) balls[i].center = pivot + turn * (start[i].center - pivot);
            return balls;
          },
          chain_a};
}

Motion models_2k39() {
  ReadOptions read;
  const Molecule first = read_molecule(data("2k39_3models.pdb"), read);
  read.model = 3;
  Molecule third = read_molecule(data("2k39_3models.pdb"), read);
  const RigidMotion fit = align(first, third, AlignmentMethod::kabsch).motion;  // before third is moved from
  third = moved(std::move(third), fit);
  const std::vector<Ball> a = balls_from_molecule(first, kShrink), b = balls_from_molecule(third, kShrink);
  return {"2k39 model 1 -> 3", a.size(),
          [=](double s) {
            if (s == 1) return b;
            std::vector<Ball> balls = a;
            for (size_t i = 0; i < balls.size(); ++i) balls[i].center = (1 - s) * a[i].center + s * b[i].center;
            return balls;
          },
          first.atoms};
}

// 1ubi's atoms in thermal motion as an MD trajectory saved every few
// picoseconds shows it: each atom fluctuates about its place in the
// crystal structure (an Ornstein-Uhlenbeck process: rms 0.5 A, correlation
// 0.8 from one snapshot to the next, about 0.3 A rms between snapshots), 11
// snapshots, the frames spread evenly over them with the atoms on straight
// lines in between. Seeded, and Gaussian draws by Box-Muller from the
// 64-bit Mersenne twister (whose sequence the standard fixes), so every run
// and every machine sees the same motion.
Motion thermal_1ubi() {
  const Molecule ubi = read_molecule(data("1ubi.pdb"));
  const std::vector<Ball> rest = balls_from_molecule(ubi, kShrink);
  constexpr int kSnapshots = 11;
  constexpr double kRms = 0.5, kCorrelation = 0.8;
  std::mt19937_64 random(20261127);
  const auto gaussian = [&random] {
    const double u = (static_cast<double>(random() >> 11) + 0.5) / 9007199254740992.0;  // (0, 1)
    const double v = static_cast<double>(random() >> 11) / 9007199254740992.0;
    return std::sqrt(-2 * std::log(u)) * std::cos(2 * M_PI * v);
  };
  const double sigma = kRms / std::sqrt(3.0), renew = std::sqrt(1 - kCorrelation * kCorrelation);
  std::vector<std::vector<Eigen::Vector3d>> offsets(kSnapshots, std::vector<Eigen::Vector3d>(rest.size()));
  for (size_t i = 0; i < rest.size(); ++i)
    for (int k = 0; k < 3; ++k) offsets[0][i][k] = sigma * gaussian();
  for (int m = 1; m < kSnapshots; ++m)
    for (size_t i = 0; i < rest.size(); ++i)
      for (int k = 0; k < 3; ++k) offsets[m][i][k] = kCorrelation * offsets[m - 1][i][k] + renew * sigma * gaussian();
  return {"1ubi thermal motion, 11 snapshots", rest.size(),
          [=](double s) {
            const double at = s * (kSnapshots - 1);
            const int m = std::min(static_cast<int>(at), kSnapshots - 2);
            const double w = at - m;
            std::vector<Ball> balls = rest;
            for (size_t i = 0; i < balls.size(); ++i)
              balls[i].center += (1 - w) * offsets[m][i] + w * offsets[m + 1][i];
            return balls;
          },
          ubi.atoms};
}

struct Column {
  double frames = 0, seconds = 0, seconds_first = 0;
  double seconds_complex = 0, seconds_transport = 0, seconds_relax = 0, seconds_judge = 0, seconds_repair = 0;
  double seconds_edits = 0, seconds_patch = 0, patch_attempts = 0, patched_frames = 0;
  double triangles = 0, min_angle = 180, max_error = 0, invalid_frames = 0;
  double remeshed = 0, full_rebuilds = 0, steps = 0, min_ids_kept = 1, mean_ids_kept = 0, max_kept_move = 0;
  double max_atom_move = 0;

  // The commands' own check (check_guarantees): a vertex the static oracle
  // cannot certify is measured on the complex of the frame's balls built
  // from scratch; a frame is invalid when it is not a closed, oriented
  // manifold without self-intersections or its topology is not the skin's.
  void grade(const SurfaceMesh& mesh, const std::vector<Ball>& balls) {
    GuaranteeOptions o;
    o.min_angle = 20;
    const GuaranteeReport g = check_guarantees(mesh, balls, kShrink, o);
    const MeshQuality& q = g.quality;
    frames += 1;
    triangles += static_cast<double>(q.triangles);
    min_angle = std::min(min_angle, q.min_angle);
    invalid_frames += !(g.closed_oriented_manifold && g.no_self_intersections.value_or(false) && g.topology.value_or(false));
    max_error = std::max(max_error, g.surface_error.max);
  }
};

double s_of(int k, int frames) { return static_cast<double>(k) / (frames - 1); }

// A frame's stats as one JSON line: where its time went and what its repair did.
void log_frame(std::FILE* log, const std::string& motion, int k, const FrameStats& s) {
  const nlohmann::json j = {{"motion", motion}, {"frame", k}, {"seconds", s.seconds},
                            {"complex", s.seconds_complex}, {"transport", s.seconds_transport},
                            {"relax", s.seconds_relax}, {"judge", s.seconds_judge}, {"repair", s.seconds_repair},
                            {"edits", s.seconds_edits}, {"patch", s.seconds_patch},
                            {"patch_attempts", s.patch_attempts}, {"steps", s.steps},
                            {"triangles", s.triangles}, {"moved", s.moved},
                            {"relocated", s.relocated}, {"settled", s.settled}, {"carried", s.carried},
                            {"bad_triangles", s.bad_triangles},
                            {"events", s.events}, {"necks", s.necks}, {"births", s.births}, {"surgeries_undone", s.surgeries_undone}, {"split", s.split}, {"flipped", s.flipped},
                            {"contracted", s.contracted}, {"patch_triangles", s.patch_triangles},
                            {"inserted", s.inserted}, {"removed", s.removed}, {"remeshed", s.remeshed},
                            {"full_rebuild", s.full_rebuild}, {"because", s.remeshed_because}};
  std::fprintf(log, "%s\n", j.dump().c_str());
  std::fflush(log);
}

Column run_engine(const Motion& motion, int frames, const MovingOptions& options, const std::string& frame_log) {
  keep_large_blocks_for_reuse();  // as `skinmesh trajectory` does
  Column c;
  std::FILE* log = frame_log.empty() ? nullptr : std::fopen(frame_log.c_str(), "a");
  if (!frame_log.empty() && log == nullptr) throw std::runtime_error("cannot open " + frame_log);
  std::vector<Ball> before = motion.at(0);
  const auto start = Clock::now();
  MovingBalls moving(before, options);
  c.seconds_first = seconds_since(start);
  c.seconds += c.seconds_first;
  c.grade(moving.frame().mesh, before);
  for (int k = 1; k < frames; ++k) {
    const std::vector<Ball> balls = motion.at(s_of(k, frames));
    for (size_t i = 0; i < balls.size(); ++i) c.max_atom_move = std::max(c.max_atom_move, (balls[i].center - before[i].center).norm());
    // Told the frame after, as `skinmesh trajectory` tells it.
    const MorphFrame& f =
        moving.advance_to(balls, s_of(k, frames), k + 1 < frames ? motion.at(s_of(k + 1, frames)) : std::vector<Ball>{});
    const FrameStats& s = f.stats;
    c.seconds += s.seconds;
    c.seconds_complex += s.seconds_complex;
    c.seconds_transport += s.seconds_transport;
    c.seconds_relax += s.seconds_relax;
    c.seconds_judge += s.seconds_judge;
    c.seconds_repair += s.seconds_repair;
    c.seconds_edits += s.seconds_edits;
    c.seconds_patch += s.seconds_patch;
    c.patch_attempts += static_cast<double>(s.patch_attempts);
    c.patched_frames += s.patch_attempts > 0;
    c.remeshed += s.remeshed;
    c.full_rebuilds += s.full_rebuild;
    c.steps += static_cast<double>(s.steps);
    c.min_ids_kept = std::min(c.min_ids_kept, s.ids_kept);
    c.mean_ids_kept += s.ids_kept / (frames - 1);
    c.max_kept_move = std::max(c.max_kept_move, s.max_kept_move);
    if (log != nullptr) log_frame(log, motion.name, k, s);
    c.grade(f.mesh, balls);
    before = balls;
  }
  if (log != nullptr) std::fclose(log);
  return c;
}

Column run_rebuilds(const Motion& motion, int frames, int sample) {
  Column c;
  MeshingOptions criteria;
  criteria.min_angle = 20;
  // A fresh process's first rebuild pays for its first page faults and cold
  // caches (on 2k39 0.11 s against 0.085-0.09 s for the next ones); c's
  // first frame, a rebuild too, is left out of its mean as well.
  if (mesh_skin(build_skin_complex(motion.at(0), {kShrink}), criteria).status != MeshingStatus::ok)
    throw std::runtime_error("the first frame cannot be meshed");
  for (int j = 0; j < sample; ++j) {
    const double s = s_of(1 + j * (frames - 2) / std::max(1, sample - 1), frames);
    const std::vector<Ball> balls = motion.at(s);
    const auto start = Clock::now();
    const SkinMeshResult made = mesh_skin(build_skin_complex(balls, {kShrink}), criteria);
    c.seconds += seconds_since(start);
    if (made.status != MeshingStatus::ok) throw std::runtime_error(made.message);
    c.full_rebuilds += 1;
    c.grade(made.mesh, balls);
  }
  return c;
}

// A value as mmCIF writes it: ? when empty, quoted when it holds a blank,
// a quote or a character CIF reserves (O5' of a nucleotide).
std::string cif_text(const std::string& text) {
  if (text.empty()) return "?";
  if (text.find_first_of("'\" \t#$_[];") == std::string::npos) return text;
  return text.find('"') == std::string::npos ? "\"" + text + "\"" : "'" + text + "'";
}

// The motion's frames as the models of one mmCIF file, each coordinate
// with the 17 significant digits that give back its double, so that the
// command's frames are c's (a PDB file's 1e-3 A would jitter every moving
// atom and open and close small voids the engine then has to mend).
void write_models(const std::string& path, const Motion& motion, int frames) {
  std::FILE* out = std::fopen(path.c_str(), "w");
  if (!out) throw std::runtime_error("cannot write " + path);
  std::fprintf(out, "data_bench_moving\nloop_\n");
  for (const char* field : {"group_PDB", "id", "type_symbol", "label_atom_id", "label_alt_id", "label_comp_id",
                            "label_asym_id", "label_seq_id", "pdbx_PDB_ins_code", "Cartn_x", "Cartn_y", "Cartn_z",
                            "occupancy", "B_iso_or_equiv", "auth_seq_id", "auth_comp_id", "auth_asym_id",
                            "auth_atom_id", "pdbx_PDB_model_num"})
    std::fprintf(out, "_atom_site.%s\n", field);
  long serial = 0;
  for (int k = 0; k < frames; ++k) {
    const std::vector<Ball> balls = motion.at(s_of(k, frames));
    for (size_t i = 0; i < balls.size(); ++i) {
      const Atom& a = motion.atom_records[i];
      const std::string name = cif_text(a.name), residue = cif_text(a.residue), chain = cif_text(a.chain);
      const std::string code = a.insertion_code == ' ' ? "?" : std::string(1, a.insertion_code);
      std::fprintf(out, "ATOM %ld %s %s . %s %s %d %s %.17g %.17g %.17g 1 0 %d %s %s %s %d\n", ++serial,
                   cif_text(a.element).c_str(), name.c_str(), residue.c_str(), chain.c_str(), a.residue_number,
                   code.c_str(), balls[i].center.x(), balls[i].center.y(), balls[i].center.z(), a.residue_number,
                   residue.c_str(), chain.c_str(), name.c_str(), k + 1);
    }
  }
  if (std::fclose(out) != 0) throw std::runtime_error("cannot write " + path);
}

// (c_cmd): `skinmesh trajectory` over those models, a frame per model, as a
// user runs it on an MD trajectory saved as models (binary PLY frames; the
// default adds VTP): wall time less the first frame's meshing, per later
// frame. Every frame is checked by the command before it is written.
Column run_command(const Motion& motion, int frames) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("bench_moving_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string models = (dir / "models.cif").string(), out = (dir / "frames").string();
  write_models(models, motion, frames);
  const std::string command = std::string("'") + SKINMESH_BINARY + "' --quiet trajectory '" + models + "' -o '" + out +
                              "' --frames-per-step 1 --align none --format ply";
  const auto start = Clock::now();
  const int status = std::system(command.c_str());
  Column c;
  c.seconds = seconds_since(start);
  std::ifstream jsonl(std::filesystem::path(out) / "frames.jsonl");
  for (std::string line; std::getline(jsonl, line);) {
    const nlohmann::json f = nlohmann::json::parse(line);
    if (c.frames == 0) c.seconds_first = f["seconds"].get<double>();
    c.frames += 1;
    c.triangles += f["triangles"].get<double>();
    c.min_angle = std::min(c.min_angle, f["min_angle"].get<double>());
    c.max_error = std::max(c.max_error, f["max_onsurf_error"].get<double>());
    c.remeshed += f["remeshed"].get<bool>();
    c.full_rebuilds += f["full_rebuild"].get<bool>();
    if (c.frames > 1) {
      c.min_ids_kept = std::min(c.min_ids_kept, f["ids_kept"].get<double>());
      c.mean_ids_kept += f["ids_kept"].get<double>() / (frames - 1);
      c.max_kept_move = std::max(c.max_kept_move, f["max_kept_move"].get<double>());
    }
  }
  std::filesystem::remove_all(dir);
  if (status != 0 || c.frames != frames) throw std::runtime_error("the command failed: " + command);
  return c;
}

struct Row {
  std::string motion, column;
  size_t atoms = 0;
  bench::Forked<Column> run;
};

double later_ms(const Column& c, double seconds) { return c.frames > 1 ? 1e3 * seconds / (c.frames - 1) : 0.0; }

// Seconds a frame: (b) its mean; (c) the later frames' mean (the first is a rebuild).
double per_frame(const Row& r) {
  const Column& c = r.run.result;
  return r.column[0] == 'c' ? (c.seconds - c.seconds_first) / std::max(1.0, c.frames - 1)
                            : c.seconds / std::max(1.0, c.frames);
}

void print_json(const Row& r) {
  const Column& c = r.run.result;
  std::printf(
      "{\"motion\": \"%s\", \"atoms\": %zu, \"column\": \"%s\", \"status\": \"%s\", \"frames\": %.0f, "
      "\"seconds_per_frame\": %.4f, \"seconds_first_frame\": %.3f, \"peak_mb\": %.1f, \"mean_triangles\": %.0f, "
      "\"min_angle\": %.3f, \"max_on_surface_error\": %.3e, \"invalid_frames\": %.0f, \"remeshed_frames\": %.0f, "
      "\"full_rebuilds\": %.0f, \"steps\": %.0f, \"min_ids_kept\": %.4f, \"mean_ids_kept\": %.4f, "
      "\"max_kept_move\": %.3f, \"max_atom_move_per_frame\": %.3f, \"later_frame_ms\": {\"complex\": %.3f, "
      "\"transport\": %.3f, \"relax\": %.3f, \"judge\": %.3f, \"repair\": %.3f, \"of_repair_edits\": %.3f, "
      "\"of_repair_patch\": %.3f}, \"patched_frames\": %.0f, \"patch_attempts\": %.0f}\n",
      r.motion.c_str(), r.atoms, r.column.c_str(), r.run.status.c_str(), c.frames, per_frame(r), c.seconds_first,
      r.run.peak_mb, c.triangles / std::max(1.0, c.frames), c.min_angle, c.max_error, c.invalid_frames, c.remeshed,
      c.full_rebuilds, c.steps, c.min_ids_kept, c.mean_ids_kept, c.max_kept_move, c.max_atom_move,
      later_ms(c, c.seconds_complex), later_ms(c, c.seconds_transport), later_ms(c, c.seconds_relax),
      later_ms(c, c.seconds_judge), later_ms(c, c.seconds_repair), later_ms(c, c.seconds_edits),
      later_ms(c, c.seconds_patch), c.patched_frames, c.patch_attempts);
  std::fflush(stdout);
}

void print_table(const std::vector<Row>& rows) {
  std::printf("\n| motion | column | frames | s/frame | b/c | peak MB | triangles | min angle | max error A | "
              "invalid | remeshed | ids kept min / mean | largest kept move A |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    const Column& c = r.run.result;
    if (r.run.status != "ok") {
      std::printf("| %s | %s | %s | | | | | | | | | | |\n", r.motion.c_str(), r.column.c_str(), r.run.status.c_str());
      continue;
    }
    double ratio = NAN;
    for (const Row& b : rows)
      if (b.motion == r.motion && b.column[0] == 'b' && r.column[0] == 'c' && b.run.status == "ok")
        ratio = per_frame(b) / per_frame(r);
    std::printf("| %s | %s | %.0f | %.4f | %.1f | %.0f | %.0f | %.2f | %.1e | %.0f | %.0f | %.3f / %.3f | %.2f |\n",
                r.motion.c_str(), r.column.c_str(), c.frames, per_frame(r), ratio, r.run.peak_mb,
                c.triangles / std::max(1.0, c.frames), c.min_angle, c.max_error, c.invalid_frames, c.remeshed,
                c.min_ids_kept, c.mean_ids_kept, c.max_kept_move);
  }
}

// Per motion: b/c, b/c_cmd and c_cmd/c (the command's frame against the engine's).
void print_ratios(const std::vector<Row>& rows) {
  std::printf("\n| motion | b/c | b/c_cmd | c_cmd/c |\n|---|---|---|---|\n");
  for (const Row& b : rows) {
    if (b.column[0] != 'b' || b.run.status != "ok") continue;
    const Row *c = nullptr, *cmd = nullptr;
    for (const Row& r : rows)
      if (r.motion == b.motion && r.run.status == "ok") {
        if (r.column.rfind("c moving", 0) == 0) c = &r;
        if (r.column.rfind("c_cmd", 0) == 0) cmd = &r;
      }
    const auto ratio = [](const Row* x, const Row* y) { return x && y ? per_frame(*x) / per_frame(*y) : NAN; };
    std::printf("| %s | %.1f | %.1f | %.2f |\n", b.motion.c_str(), ratio(&b, c), ratio(&b, cmd), ratio(cmd, c));
  }
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 101, sample = 5, timeout = 3600;
  std::string only;  // run the motions whose name holds this text
  std::string frame_log;
  bool skip_command = false;
  MovingOptions engine_options;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--only" && i + 1 < argc) only = argv[++i];
    else if (a == "--skip-command") skip_command = true;
    else if (a == "--frames" && i + 1 < argc) frames = std::atoi(argv[++i]);
    else if (a == "--sample" && i + 1 < argc) sample = std::atoi(argv[++i]);
    else if (a == "--timeout" && i + 1 < argc) timeout = std::atoi(argv[++i]);
    else if (a == "--first-size-margin" && i + 1 < argc) engine_options.first_size_margin = std::atof(argv[++i]);
    else if (a == "--frame-log" && i + 1 < argc) frame_log = argv[++i];
    else if (a == "--retry-around-faults" && i + 1 < argc)
      engine_options.repair.patch.retry_around_faults = std::string(argv[++i]) == "on";
    else if (a == "--neck-surgery" && i + 1 < argc) engine_options.repair.neck_surgery = std::string(argv[++i]) == "on";
    else if (a == "--birth-surgery" && i + 1 < argc) engine_options.repair.birth_surgery = std::string(argv[++i]) == "on";
    else if (a == "--edit-generations" && i + 1 < argc) engine_options.repair.edits.generations = std::atoi(argv[++i]);
    else if (a == "--patch-share" && i + 1 < argc) engine_options.repair.patch.max_failing_share = std::atof(argv[++i]);
    else if (a == "--retry-after" && i + 1 < argc) engine_options.repair.edits.retry_after_frames = std::atoi(argv[++i]);
    else if (a == "--sample-share" && i + 1 < argc) engine_options.repair.patch.max_sample_share = std::atof(argv[++i]);
    else {
      std::fprintf(stderr,
                   "usage: bench_moving [--frames N] [--sample K] [--timeout S] [--only TEXT] [--skip-command] "
                   "[--first-size-margin X] [--retry-around-faults on|off] [--neck-surgery on|off] "
                   "[--birth-surgery on|off] [--edit-generations N] [--patch-share X] [--sample-share X] [--retry-after N] "
                   "[--frame-log FILE]\n");
      return 2;
    }
  }
  if (frames < 3 || sample < 1) {
    std::fprintf(stderr, "bench_moving: --frames must be at least 3 and --sample at least 1\n");
    return 2;
  }
  std::vector<Row> rows;
  for (const Motion& motion : {models_2k39(), hinge_3mht(), dna_3mht(), thermal_1ubi()}) {
    if (motion.name.find(only) == std::string::npos) continue;
    Row b{motion.name, "b rebuild (skinmesh mesher)", motion.atoms,
          bench::run_forked<Column>(timeout, [&] { return run_rebuilds(motion, frames, sample); })};
    print_json(b);
    rows.push_back(b);
    Row c{motion.name, "c moving balls", motion.atoms,
          bench::run_forked<Column>(timeout, [&] { return run_engine(motion, frames, engine_options, frame_log); })};
    print_json(c);
    rows.push_back(c);
    if (skip_command) continue;
    Row cmd{motion.name, "c_cmd skinmesh trajectory", motion.atoms,
            bench::run_forked<Column>(timeout, [&] { return run_command(motion, frames); })};
    print_json(cmd);
    rows.push_back(cmd);
  }
  print_table(rows);
  print_ratios(rows);
  return 0;
}
