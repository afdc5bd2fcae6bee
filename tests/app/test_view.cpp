// skinmesh view and render's pictures and movies, from the command line: the
// page's parts and refusals (the page in a browser: tests/js/), a PNG's
// silhouette against the molecule, a movie's pictures by ffprobe.
#include "test_support.hpp"

#include "skinmesh/core/molecule.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <zlib.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;

struct Run {
  int code;
  std::string output;  // stdout and stderr together
};

Run shell(const std::string& command) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string output;
  std::array<char, 4096> buffer{};
  for (size_t n; (n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0;) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}
Run run(const std::string& args) { return shell(std::string(SKINMESH_BINARY) + " " + args); }

struct TempDir {
  fs::path path;
  TempDir() {
    char pattern[] = "/tmp/skinmesh-view-XXXXXX";
    path = mkdtemp(pattern);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

const char* kAtomHeader = "index\tchain\tresidue_number\tinsertion_code\tresidue_name\tatom_name\telement\tradius\n";

// An 8-bit RGB PNG, not interlaced (what skinmesh writes), decoded with zlib.
struct Picture {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};
Picture read_png(const std::string& path) {
  const std::string png = read_text(path);
  REQUIRE(png.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)) == 0);
  auto u32 = [&](size_t at) {
    return static_cast<unsigned>(static_cast<unsigned char>(png[at])) << 24 | static_cast<unsigned char>(png[at + 1]) << 16 |
           static_cast<unsigned char>(png[at + 2]) << 8 | static_cast<unsigned char>(png[at + 3]);
  };
  Picture p;
  std::string idat;
  for (size_t at = 8; at + 8 <= png.size();) {
    const unsigned length = u32(at);
    const std::string type = png.substr(at + 4, 4);
    if (type == "IHDR") {
      p.width = static_cast<int>(u32(at + 8));
      p.height = static_cast<int>(u32(at + 12));
      REQUIRE(png[at + 16] == 8);  // bit depth
      REQUIRE(png[at + 17] == 2);  // RGB
    }
    if (type == "IDAT") idat += png.substr(at + 8, length);
    at += 12 + length;
  }
  const size_t stride = static_cast<size_t>(p.width) * 3;
  std::vector<unsigned char> raw((stride + 1) * static_cast<size_t>(p.height));
  uLongf size = raw.size();
  REQUIRE(uncompress(raw.data(), &size, reinterpret_cast<const Bytef*>(idat.data()), idat.size()) == Z_OK);
  p.rgb.resize(stride * static_cast<size_t>(p.height));
  for (size_t y = 0; y < static_cast<size_t>(p.height); ++y) {
    const unsigned char filter = raw[y * (stride + 1)];
    REQUIRE(filter < 5);
    for (size_t x = 0; x < stride; ++x) {
      const int a = x >= 3 ? p.rgb[y * stride + x - 3] : 0, b = y ? p.rgb[(y - 1) * stride + x] : 0;
      const int c = x >= 3 && y ? p.rgb[(y - 1) * stride + x - 3] : 0;
      const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
      const int paeth = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      const int predictor[5] = {0, a, b, (a + b) / 2, paeth};
      p.rgb[y * stride + x] = static_cast<unsigned char>(raw[y * (stride + 1) + 1 + x] + predictor[filter]);
    }
  }
  return p;
}

}  // namespace

TEST_CASE("view writes one page holding the viewer and the mesh, or one that reads the files beside it", "[cli][view]") {
  TempDir dir;
  REQUIRE(run("--quiet mesh " + skinmesh::test::data_file("pept.pdb") + " -o " + dir / "pept.ply").code == 0);
  // The table mesh writes beside its mesh, or one of ours where it writes none.
  if (!fs::exists(dir / "pept.atoms.tsv")) std::ofstream(dir / "pept.atoms.tsv") << kAtomHeader << "0\tA\t1\t\tGLY\tN\tN\t1.55\n";
  const Run page = run("--json view " + dir / "pept.ply" + " -o " + dir / "pept.html");
  REQUIRE(page.code == 0);
  auto report = nlohmann::json::parse(page.output.substr(page.output.find('{')));
  CHECK(report["atom_tables"] == 1);
  const std::string html = read_text(dir / "pept.html");
  CHECK(html.find("data-file=\"pept.ply\"") != std::string::npos);
  CHECK(html.find("data-file=\"pept.atoms.tsv\"") != std::string::npos);
  CHECK(html.find("getContext('webgl2'") != std::string::npos);
  CHECK(html.find("@SKINMESH_") == std::string::npos);  // every place of the template filled
  CHECK(html.find("http://") == std::string::npos);
  CHECK(html.find("https://") == std::string::npos);
  CHECK(report["page_bytes"].get<size_t>() == html.size());
  // Without the table the page is made all the same, and holds none.
  fs::rename(dir / "pept.atoms.tsv", dir / "kept.tsv");
  const Run plain = run("--json view " + dir / "pept.ply" + " -o " + dir / "plain.html");
  REQUIRE(plain.code == 0);
  CHECK(nlohmann::json::parse(plain.output.substr(plain.output.find('{')))["atom_tables"] == 0);
  CHECK(read_text(dir / "plain.html").find("data-file=\"pept.atoms.tsv\"") == std::string::npos);
  fs::rename(dir / "kept.tsv", dir / "pept.atoms.tsv");
  // --no-embed: the page names the files by their addresses and holds none;
  // they must be in its folder or below, where a server of that folder finds them.
  REQUIRE(run("--quiet view " + dir / "pept.ply" + " -o " + dir / "index.html --no-embed").code == 0);
  const std::string served = read_text(dir / "index.html");
  CHECK(served.find("data-file=") == std::string::npos);
  CHECK(served.find("\"file\":\"pept.ply\"") != std::string::npos);
  CHECK(served.find("\"pept.atoms.tsv\"") != std::string::npos);
  fs::create_directory(dir / "site");
  const Run above = run("view " + dir / "pept.ply" + " -o " + dir / "site/index.html --no-embed");
  CHECK(above.code == 2);
  CHECK(above.output.find(dir / "index.html") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "site/index.html"));
}

TEST_CASE("view refuses a page too large to embed, a directory that is no morph and a bad atom table", "[cli][view][bad]") {
  TempDir dir;
  REQUIRE(run("--quiet mesh " + skinmesh::test::data_file("pept.pdb") + " -o " + dir / "pept.ply").code == 0);
  const Run large = run("view " + dir / "pept.ply" + " -o " + dir / "p.html --max-embedded-mb 0.001");
  CHECK(large.code == 2);
  CHECK(large.output.find("--no-embed") != std::string::npos);
  CHECK(large.output.find("http.server") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "p.html"));
  fs::create_directory(dir / "empty");
  const Run no_morph = run("view " + dir / "empty" + " -o " + dir / "p.html");
  CHECK(no_morph.code == 2);
  CHECK(no_morph.output.find("frames.jsonl") != std::string::npos);
  std::ofstream(dir / "pept.atoms.tsv") << "index\tchain\tresidue\n0\tA\t1\n";
  const Run table = run("view " + dir / "pept.ply" + " -o " + dir / "p.html");
  CHECK(table.code == 2);
  CHECK(table.output.find(dir / "pept.atoms.tsv") != std::string::npos);
  CHECK(table.output.find("residue_number") != std::string::npos);
  CHECK(run("view " + dir / "missing.ply -o " + dir / "p.html").code == 2);
  CHECK(run("view " + dir / "pept.ply -o " + dir / "p.html --max-embedded-mb 0").code == 2);
  CHECK_FALSE(fs::exists(dir / "p.html"));
}

TEST_CASE("render's picture of 1ubi has the molecule's silhouette at the scale it reports", "[cli][render]") {
  TempDir dir;
  const std::string ubi = skinmesh::test::data_file("1ubi.pdb");
  const Run r = run("--json render " + ubi + " -o " + dir / "1ubi.png --yaw 0 --pitch 0 --width 400 --height 300");
  REQUIRE(r.code == 0);
  const double scale = nlohmann::json::parse(r.output.substr(r.output.find('{')))["pixels_per_angstrom"];
  const Picture p = read_png(dir / "1ubi.png");
  REQUIRE(p.width == 400);
  REQUIRE(p.height == 300);
  int x0 = p.width, x1 = -1, y0 = p.height, y1 = -1;
  long drawn = 0;
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x) {
      const unsigned char* c = &p.rgb[(static_cast<size_t>(y) * static_cast<size_t>(p.width) + static_cast<size_t>(x)) * 3];
      if (c[0] + c[1] + c[2] > 3 * 250) continue;  // the white background
      ++drawn;
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  REQUIRE(drawn > 400 * 300 / 5);
  // Every van der Waals ball lies inside the skin, and the skin inside the
  // balls' convex hull: its extent along x and y is exactly the balls'.
  const skinmesh::Molecule m = skinmesh::read_molecule(ubi, {});
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (const auto& a : m.atoms)
    for (int k = 0; k < 2; ++k) {
      lo[k] = std::min(lo[k], a.position[k] - a.radius);
      hi[k] = std::max(hi[k], a.position[k] + a.radius);
    }
  INFO("silhouette " << x1 - x0 + 1 << " x " << y1 - y0 + 1 << " pixels, the balls' extent " << (hi[0] - lo[0]) * scale
                      << " x " << (hi[1] - lo[1]) * scale);
  CHECK(std::abs((x1 - x0 + 1) - (hi[0] - lo[0]) * scale) < 3);
  CHECK(std::abs((y1 - y0 + 1) - (hi[1] - lo[1]) * scale) < 3);
  CHECK((x1 - x0 + 1 == 400 - 2 * 15 || y1 - y0 + 1 == 300 - 2 * 15));  // fitted inside the margin (5% of 300)
}

TEST_CASE("render --movie of a morph: ffprobe finds every picture at the size asked, bad options write nothing",
          "[cli][render][movie]") {
  TempDir dir;
  const std::string k39 = skinmesh::test::data_file("2k39_3models.pdb");
  REQUIRE(run("--quiet morph " + k39 + " " + k39 + " --target-model 3 --frames 3 --pairs matched -o " + dir / "m").code == 0);
  for (const char* kind : {"mp4", "webm"}) {
    const std::string movie = dir / (std::string("m.") + kind);
    REQUIRE(run("--quiet render " + dir / "m" + " --movie " + movie + " --width 160 --height 120 --seconds 1 --fps 9").code == 0);
    const Run probe = shell("ffprobe -v error -count_frames -select_streams v:0 -show_entries "
                            "stream=nb_read_frames,width,height -of csv=p=0 " + movie);
    REQUIRE(probe.code == 0);
    CHECK(probe.output == "160,120,9\n");
  }
  // chain and element need the morph's atom tables: without them, refused.
  for (const char* side : {"source", "target"})
    fs::remove(dir / (std::string("m/") + side + "_atoms.tsv"));
  const std::string small = " --width 160 --height 120 --seconds 0.2";  // were one accepted, quick
  for (const std::string& bad : {"--movie " + dir / "x.avi" + small, "--movie " + dir / "x.mp4 --width 161 --height 120",
                                 "--movie " + dir / "x.mp4 --fps 0" + small, "--movie " + dir / "x.mp4 -o " + dir / "x.png" + small,
                                 "--movie " + dir / "x.mp4 --colour chain" + small}) {
    INFO(bad);
    CHECK(run("render " + dir / "m " + bad).code == 2);
  }
  CHECK(run("render " + skinmesh::test::data_file("pept.pdb") + " --movie " + dir / "x.mp4").code == 2);
  CHECK(run("render " + dir / "m -o " + dir / "x.png").code == 2);
  CHECK(run("render " + skinmesh::test::data_file("pept.pdb") + " -o " + dir / "x.png --fps 10").code == 2);
  CHECK(run("render " + skinmesh::test::data_file("pept.pdb") + " -o " + dir / "x.png --colour age").code == 2);
  const Run no_ffmpeg = shell("PATH=/nonexistent " + std::string(SKINMESH_BINARY) + " render " + dir / "m --movie " + dir / "x.mp4");
  CHECK(no_ffmpeg.code != 0);
  CHECK(no_ffmpeg.output.find("ffmpeg") != std::string::npos);
  for (const auto& e : fs::directory_iterator(dir.path)) CHECK(e.path().filename().string().rfind("x.", 0) != 0);
}
