// A property test of the command line (issue 39, "Also"): morph, interpolate
// and volume with option values drawn at random (seeded, so a failure
// repeats) from their documented ranges, their ends included, on small
// inputs and near-degenerate pairs (pept against pept moved by 1e-6 A, an
// atom against itself twice). Whatever is drawn, every run must end within
// its CPU-time and memory limits with exit code 0, 2 or 3 (never a crash, a
// signal or a stall); on 0 its outputs exist (a morph's frames.jsonl one
// line a frame), otherwise nothing is left where it was to write.
#include "cli_run.hpp"
#include "test_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using skinmesh::test::Run;

constexpr int kCpuSeconds = 20;    // per run: the largest drawn takes a few seconds
constexpr long kMemoryMb = 2000;   // per run

std::string hostile(const std::string& name) { return std::string(SKINMESH_HOSTILE_INPUTS) + "/" + name; }

// Pairs of small inputs: a molecule with itself, with itself moved by up to
// 1e-6 A (PQR keeps the jitter), with itself and one atom twice; one atom
// with itself twice, either way.
std::vector<std::pair<std::string, std::string>> input_pairs() {
  const std::string pept = skinmesh::test::data_file("pept.pdb");
  return {{pept, pept},
          {pept, hostile("pept-jitter.pqr")},
          {hostile("pept-jitter.cif"), pept},
          {pept, hostile("pept-duplicate.pdb")},
          {hostile("one-atom.xyzr"), hostile("one-atom-twice.xyzr")},
          {hostile("one-atom-twice.xyzr"), hostile("one-atom.xyzr")}};
}

class Draw {
 public:
  explicit Draw(unsigned seed) : random_(seed) {}
  template <typename T>
  const T& one_of(const std::vector<T>& values) {
    return values[std::uniform_int_distribution<size_t>(0, values.size() - 1)(random_)];
  }
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random_); }
  bool coin() { return uniform(0, 1) < 0.5; }
  // An increasing list of 2 to 5 times in [0, 1], often next to its ends.
  std::vector<double> times() {
    std::vector<double> t;
    const int n = std::uniform_int_distribution<int>(2, 5)(random_);
    while (static_cast<int>(t.size()) < n) {
      t.push_back(one_of<double>({0.0, 1e-9, 1e-5, uniform(0, 1), uniform(0, 1), 1 - 1e-5, 1 - 1e-9, 1.0}));
      std::sort(t.begin(), t.end());
      t.erase(std::unique(t.begin(), t.end()), t.end());
    }
    return t;
  }

 private:
  std::mt19937 random_;
};

std::string number(double x) {
  std::ostringstream out;
  out.precision(17);
  out << x;
  return out.str();
}

std::string joined(const std::vector<double>& t) {
  std::string s;
  for (double x : t) s += (s.empty() ? "" : ",") + number(x);
  return s;
}

long lines_of(const std::string& path) {
  std::ifstream in(path);
  long n = 0;
  for (std::string line; std::getline(in, line);) n += !line.empty();
  return n;
}

// One run into a fresh folder: the exit code is 0, 2 or 3; on 0 `made`
// says whether the outputs are there, otherwise the folder must be empty.
void check_run(const std::string& args, const std::function<bool(const std::string&)>& made) {
  skinmesh::test::TempFile holder("x");
  const std::string folder = holder.path() + "-runs";
  std::filesystem::create_directory(folder);
  std::string command = args;
  for (size_t at; (at = command.find("@OUT")) != std::string::npos;) command.replace(at, 4, folder);
  const Run r = skinmesh::test::run_within(kCpuSeconds, "--quiet " + command, kMemoryMb);
  INFO(command << "\n" << r.output);
  CHECK((r.code == 0 || r.code == 2 || r.code == 3));
  if (r.code == 0) CHECK(made(folder));
  else CHECK(std::filesystem::is_empty(folder));
  std::filesystem::remove_all(folder);
}

}  // namespace

TEST_CASE("property: morph with drawn times, pairs and options ends cleanly", "[cli][property][large]") {
  Draw draw(3901);
  for (int i = 0; i < 10; ++i) {
    const auto [source, target] = draw.one_of(input_pairs());
    std::string args = "morph " + source + " " + target + " -o @OUT/m";
    long frames = 0;
    if (draw.coin()) {
      const std::vector<double> t = draw.times();
      args += " --t " + joined(t);
      frames = static_cast<long>(t.size());
    } else {
      frames = draw.one_of<long>({2, 3, 4});
      args += " --frames " + std::to_string(frames) + " --spacing " + draw.one_of<std::string>({"uniform", "change"});
    }
    args += " --pairs " + draw.one_of<std::string>({"auto", "matched", "all"});
    args += " --align " + draw.one_of<std::string>({"auto", "none", "centroid", "kabsch"});
    args += " --max-step " + number(draw.one_of<double>({0.05, 0.5, 1e6}));
    args += " --min-angle " + number(draw.one_of<double>({1, 20, 30}));
    args += " --epsilon " + number(draw.one_of<double>({0.3, 0.8, 1e3}));
    args += " --tolerance " + number(draw.one_of<double>({0.02, 0.1, 1e3}));
    args += " --shrink " + number(draw.one_of<double>({0.5, 0.5, 0.3, 0.8}));
    args += " --format " + draw.one_of<std::string>({"ply", "off", "glb"});
    check_run(args, [&](const std::string& folder) { return lines_of(folder + "/m/frames.jsonl") == frames; });
  }
}

TEST_CASE("property: interpolate with drawn times and pairs ends cleanly", "[cli][property]") {
  Draw draw(3902);
  for (int i = 0; i < 10; ++i) {
    const auto [source, target] = draw.one_of(input_pairs());
    std::string args = "interpolate " + source + " " + target + " -o @OUT/b.wpts --t " +
                       number(draw.one_of<double>({0.0, 1e-9, 1e-5, draw.uniform(0, 1), 1 - 1e-9, 1.0}));
    if (draw.coin()) args += " --all-pairs";
    if (draw.coin()) args += " --centre";
    args += " --shrink " + number(draw.one_of<double>({1e-6, 0.5, 0.999999}));
    check_run(args, [](const std::string& folder) { return lines_of(folder + "/b.wpts") > 0; });
  }
}

TEST_CASE("property: volume with drawn domains, boxes and bounds ends cleanly", "[cli][property][volume]") {
  Draw draw(3903);
  const std::vector<std::string> molecules = {skinmesh::test::data_file("pept.pdb"), hostile("pept-jitter.pqr"),
                                              hostile("one-atom.xyzr"), hostile("one-atom-twice.xyzr")};
  for (int i = 0; i < 8; ++i) {
    std::string args = "volume " + draw.one_of(molecules) + " -o @OUT/v --max-seconds 4";
    args += " --domain " + draw.one_of<std::string>({"interior", "exterior", "both"});
    args += " --box-margin " + number(draw.one_of<double>({1e-3, 10, 40, 1e9}));
    args += " --max-radius-edge " + number(draw.one_of<double>({1, 2, 10}));
    args += " --min-dihedral " + number(draw.one_of<double>({0, 5, 16}));
    args += " --max-volume " + number(draw.one_of<double>({0, 0, 1e-4, 5}));
    args += " --max-tetrahedra " + std::to_string(draw.one_of<long>({1, 200000, 10000000}));
    if (draw.coin()) args += " --drop-cavities";
    check_run(args, [](const std::string& folder) {
      for (const char* ext : {".vtu", ".msh", ".node", ".ele", ".face"})
        if (!std::filesystem::exists(folder + "/v" + ext)) return false;
      return true;
    });
  }
}
