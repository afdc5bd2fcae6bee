// skinmesh view: one HTML page that shows a mesh or a morph in a browser,
// with no server and no network: the viewer (app/viewer/, WebGL2 written for
// the project, no library) and the data, gzip-compressed and base64-encoded,
// inside the page. --no-embed writes a page that reads the files by their
// relative addresses instead, for a morph too large to embed.
#include "commands.hpp"
#include "exit_codes.hpp"
#include "output_file.hpp"
#include "quality_report.hpp"
#include "view_input.hpp"
#include "viewer_assets.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/mesh_io/mesh_read.hpp"

#include <nlohmann/json.hpp>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <sstream>

namespace skinmesh::app {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct ViewOptions {
  std::string input;                // a mesh file, or a morph directory
  std::string output;               // the HTML page
  std::string title;                // the page's title; default: the input's name
  bool no_embed = false;            // the page reads its files by relative address (serve its folder)
  double max_embedded_mb = 64;      // MiB of compressed data a page may embed
};

void add_view_options(CLI::App& cmd, ViewOptions& o) {
  cmd.add_option("input", o.input, "a mesh file (PLY keeps the per-vertex atoms), or a morph or trajectory directory")
      ->required();
  cmd.add_option("--output,-o", o.output, "the HTML page")->required();
  cmd.add_option("--title", o.title, "the page's title (default: the input's name)");
  cmd.add_flag("--no-embed", o.no_embed,
               "write a page that reads the frames and atom tables by their addresses relative to it (serve its "
               "folder, e.g. python3 -m http.server) instead of holding them");
  cmd.add_option("--max-embedded-mb", o.max_embedded_mb,
                 "MiB of compressed data a page may hold; beyond it the page is refused (use --no-embed)")
      ->check(finite_number())
      ->check(positive_number());
}

// A PLY of what the page needs, small: float positions, no normals or
// colours (the page makes its own), every other vertex property as int,
// uint or float.
std::string compact_ply(const std::string& path) {
  PlyMesh ply;
  if (fs::path(path).extension() == ".ply") ply = read_ply_with_properties(path);
  else ply.mesh = read_surface_mesh(path);
  const SurfaceMesh& m = ply.mesh;
  if (m.triangles.empty()) input_error(path, 0, "no triangles to show");
  std::vector<std::pair<std::string, const char*>> columns;  // name, PLY type
  for (const auto& [name, values] : ply.vertex_properties) {
    // Normals are computed in the page, colours chosen there.
    if (name == "nx" || name == "ny" || name == "nz" || name == "red" || name == "green" || name == "blue" || name == "alpha")
      continue;
    double lo = 0, hi = 0;
    bool whole = true;
    for (double v : values) {
      whole = whole && std::isfinite(v) && v == std::floor(v);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    const char* type = !whole ? "float" : lo >= INT32_MIN && hi <= INT32_MAX ? "int" : lo >= 0 && hi <= UINT32_MAX ? "uint" : "float";
    columns.emplace_back(name, type);
  }
  std::ostringstream out;
  out << "ply\nformat binary_little_endian 1.0\ncomment skinmesh view: " << fs::path(path).filename().string()
      << "\nelement vertex " << m.vertices.size() << "\nproperty float x\nproperty float y\nproperty float z\n";
  for (const auto& [name, type] : columns) out << "property " << type << " " << name << "\n";
  out << "element face " << m.triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  // Little-endian bytes of v as T, whatever the host.
  auto put = [&out](auto v) {
    std::uint8_t b[sizeof v];
    std::memcpy(b, &v, sizeof v);
    const std::uint16_t probe = 1;
    if (*reinterpret_cast<const std::uint8_t*>(&probe) != 1) std::reverse(b, b + sizeof v);
    out.write(reinterpret_cast<const char*>(b), sizeof v);
  };
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    for (int c = 0; c < 3; ++c) put(static_cast<float>(m.vertices[i][c]));
    for (const auto& [name, type] : columns) {
      const double v = ply.vertex_properties.at(name)[i];
      if (std::strcmp(type, "int") == 0) put(static_cast<std::int32_t>(v));
      else if (std::strcmp(type, "uint") == 0) put(static_cast<std::uint32_t>(v));
      else put(static_cast<float>(v));
    }
  }
  for (const auto& t : m.triangles) {
    put(static_cast<std::uint8_t>(3));
    for (int v : t) put(static_cast<std::int32_t>(v));
  }
  return out.str();
}

std::string gzip(const std::string& data) {
  z_stream z{};
  if (deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY) != Z_OK)
    throw Error("zlib: cannot start compressing");
  std::string out(deflateBound(&z, data.size()), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  z.avail_in = static_cast<uInt>(data.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int status = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  if (status != Z_STREAM_END) throw Error("zlib: compressing failed");
  return out;
}

std::string base64(const std::string& data) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((data.size() + 2) / 3 * 4);
  for (size_t i = 0; i < data.size(); i += 3) {
    const size_t n = std::min<size_t>(3, data.size() - i);
    std::uint32_t v = 0;
    for (size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? static_cast<std::uint8_t>(data[i + k]) : 0);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? digits[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) input_error(path, 0, "cannot be read");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string html_escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

// JSON inside a <script> element: "</" would end the element.
std::string script_json(const json& j) {
  std::string text = j.dump(-1, ' ', false, json::error_handler_t::replace);
  for (size_t at = text.find("</"); at != std::string::npos; at = text.find("</", at)) text.replace(at, 2, "<\\/");
  return text;
}

// A file the page names, and how it reaches it: by its address relative to
// the page, or embedded (its bytes compressed).
struct PageFile {
  std::string name;
  std::string compressed;  // empty when not embedded
};

struct Page {
  json manifest;
  std::vector<PageFile> files;
  size_t embedded_bytes = 0;  // compressed
};

// The name the page knows a file by: embedded, a short one of its own; else
// its address relative to the page, which must lie in the page's folder or
// below it (a server of that folder serves nothing above it).
std::string page_name(const std::string& path, const ViewOptions& o, size_t k) {
  if (!o.no_embed) return (k == SIZE_MAX ? fs::path(path).filename().string() : "frame_" + std::to_string(k) + ".ply");
  const fs::path folder = fs::absolute(o.output).parent_path();
  const std::string name = fs::relative(fs::absolute(path), folder).generic_string();
  if (name.empty() || name.rfind("..", 0) == 0)
    unusable_output(o.output, "a --no-embed page reads its files from its own folder or below, and " + path +
                                  " is not there: write the page into the folder that holds them (e.g. " +
                                  (fs::path(path).parent_path() / "index.html").string() + ")");
  return name;
}

// Refused when the page would hold more than --max-embedded-mb, as soon as
// the files compressed so far pass it.
struct TooLarge {
  size_t bytes;
};

Page make_page(const ViewInput& input, const ViewOptions& o) {
  Page page;
  page.manifest = {{"kind", input.morph ? "morph" : "mesh"},
                   {"title", o.title.empty() ? fs::path(o.input).lexically_normal().filename().string() : o.title},
                   {"embedded", !o.no_embed},
                   {"skinmesh_version", version_text()}};
  if (page.manifest["title"] == "") page.manifest["title"] = fs::path(o.input).lexically_normal().parent_path().filename().string();
  auto add = [&](const std::string& name, const std::function<std::string()>& bytes) {
    PageFile f{name, o.no_embed ? std::string() : gzip(bytes())};
    page.embedded_bytes += f.compressed.size();
    if (static_cast<double>(page.embedded_bytes) > o.max_embedded_mb * 1048576) throw TooLarge{page.embedded_bytes};
    page.files.push_back(std::move(f));
  };
  json frames = json::array();
  for (size_t k = 0; k < input.frames.size(); ++k) {
    const ViewFrame& f = input.frames[k];
    if (o.no_embed && fs::path(f.path).extension() != ".ply")
      input_error(f.path, 0, "--no-embed pages read PLY files only: convert the mesh, or leave --no-embed out");
    const std::string name = page_name(f.path, o, input.morph ? k : SIZE_MAX);
    add(name, [&] { return compact_ply(f.path); });
    frames.push_back({{"t", f.t}, {"file", name}});
  }
  page.manifest["frames"] = frames;
  json atoms = json::object();
  for (const auto& [side, file] : atom_table_names(o.input, input.morph)) {
    const auto found = input.atoms.find(side);
    if (found == input.atoms.end()) {
      atoms[side] = nullptr;
      continue;
    }
    const std::string name = page_name(found->second, o, SIZE_MAX);
    add(name, [&] { return read_bytes(found->second); });
    atoms[side] = name;
  }
  page.manifest["atoms"] = atoms;
  return page;
}

// The template with its four places filled (each once, from the template:
// what is put in is never searched again).
std::string page_html(const Page& page) {
  std::string files;
  for (const PageFile& f : page.files)
    if (!f.compressed.empty())
      files += "<script type=\"application/gzip;base64\" data-file=\"" + html_escaped(f.name) + "\">" + base64(f.compressed) +
               "</script>\n";
  const std::pair<const char*, std::string> places[] = {
      {"@SKINMESH_TITLE@", html_escaped(page.manifest["title"].get<std::string>())},
      {"@SKINMESH_MANIFEST@", script_json(page.manifest)},
      {"@SKINMESH_FILES@", files},
      {"@SKINMESH_SCRIPT@", viewer_assets::script}};
  std::string html = viewer_assets::html, out;
  size_t from = 0;
  for (const auto& [place, text] : places) {
    const size_t at = html.find(place, from);
    if (at == std::string::npos) throw Error(std::string("the viewer's template lacks ") + place);
    out += html.substr(from, at - from) + text;
    from = at + std::strlen(place);
  }
  return out + html.substr(from);
}

ExitCode run_view(const ViewOptions& o, const GlobalOptions& global) {
  check_writable({o.output});
  const ViewInput input = find_view_input(o.input);
  Page page;
  try {
    page = make_page(input, o);
  } catch (const TooLarge& large) {
    const fs::path folder = input.morph ? fs::path(o.input) : fs::path(o.input).parent_path();
    std::cerr << "skinmesh: error: " << o.input << ": at least " << large.bytes / 1048576.0
              << " MiB compressed, more than a page may embed (--max-embedded-mb " << o.max_embedded_mb
              << "); nothing written. Write a page that reads the files beside it instead: skinmesh view " << o.input
              << " -o " << (folder / "index.html").string()
              << " --no-embed, then serve that folder (python3 -m http.server) and open the page from there "
                 "(docs/viewing.md)\n";
    return ExitCode::bad_input;
  }
  const std::string html = page_html(page);
  write_file_atomically(o.output, [&](std::ostream& out) { out << html; });
  const json report = {{"input", o.input},
                       {"output", o.output},
                       {"kind", page.manifest["kind"]},
                       {"frames", input.frames.size()},
                       {"atom_tables", input.atoms.size()},
                       {"embedded", !o.no_embed},
                       {"page_bytes", html.size()},
                       {"embedded_compressed_bytes", page.embedded_bytes}};
  if (global.json) std::cout << json_text(report) << "\n";
  else if (!global.quiet)
    std::cout << o.output << ": " << (input.morph ? std::to_string(input.frames.size()) + " frames" : "a mesh") << ", "
              << input.atoms.size() << " atom table(s), " << html.size() / 1024 << " KiB"
              << (o.no_embed ? " (reads its files beside it: serve the folder)" : "") << "\n";
  return ExitCode::ok;
}

}  // namespace

void add_view_command(CLI::App& app, const GlobalOptions& global, int& exit_code) {
  add_command(app, "view", "an HTML page that shows a mesh or a morph in a browser, offline, in one file", global,
              exit_code, add_view_options, run_view);
}

}  // namespace skinmesh::app
