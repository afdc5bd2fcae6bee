#include "skinmesh/mesh_io/mesh_read.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/file_names.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>

namespace skinmesh {
namespace {

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) input_error(path, 0, "cannot open mesh file");
  std::string text;
  char buffer[1 << 16];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) text.append(buffer, static_cast<size_t>(in.gcount()));
  if (text.empty()) input_error(path, 0, "file is empty");
  return text;
}

// Adds a polygon as a fan of triangles, checking its indices.
void add_polygon(SurfaceMesh& mesh, const std::vector<long>& corners, const std::string& path, long line) {
  if (corners.size() < 3) input_error(path, line, "face with fewer than 3 corners");
  for (long c : corners)
    if (c < 0 || c >= static_cast<long>(mesh.vertices.size()))
      input_error(path, line, "face refers to vertex " + std::to_string(c) + ", but there are " +
                                  std::to_string(mesh.vertices.size()));
  for (size_t k = 1; k + 1 < corners.size(); ++k)
    mesh.triangles.push_back({static_cast<int>(corners[0]), static_cast<int>(corners[k]), static_cast<int>(corners[k + 1])});
}

// Coordinates beyond this (Angstrom) are no molecular mesh, and their
// products (areas, volumes, cross products in the grader) overflow a double.
constexpr double kMaxCoordinate = 1e15;

Eigen::Vector3d checked_point(double x, double y, double z, const std::string& path, long line) {
  const Eigen::Vector3d p(x, y, z);
  if (!p.allFinite()) input_error(path, line, "non-finite vertex coordinate");
  if (p.cwiseAbs().maxCoeff() > kMaxCoordinate)
    input_error(path, line, "vertex coordinate beyond +-1e15 A: not a molecular mesh");
  return p;
}

// A whole number a mesh can index: finite and below 2^53 in magnitude, so
// that no cast from double is undefined or loses the value.
bool is_whole_number(double v) { return std::isfinite(v) && v == std::floor(v) && std::abs(v) <= 9007199254740992.0; }

// Tokens of a text file read in place, with the line each comes from; '#'
// starts a comment. The file is held once and no token is copied (a string
// per token took about 28 times the file's size in memory).
struct Tokens {
  std::string text;
  size_t pos = 0;   // at or before the next token
  long at_line = 1; // the line of pos
  std::string_view last;  // the token taken last
  const std::string* path = nullptr;

  static bool space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }
  void skip() {
    while (pos < text.size()) {
      const char c = text[pos];
      if (c == '#') {
        while (pos < text.size() && text[pos] != '\n') ++pos;
      } else if (space(c)) {
        at_line += c == '\n';
        ++pos;
      } else {
        return;
      }
    }
  }
  bool done() {
    skip();
    return pos >= text.size();
  }
  long line() {
    skip();
    return at_line;
  }
  void rewind() {
    pos = 0;
    at_line = 1;
  }
  std::string_view word() {
    if (done()) input_error(*path, at_line, "unexpected end of file");
    const size_t start = pos;
    while (pos < text.size() && !space(text[pos]) && text[pos] != '#') ++pos;
    last = std::string_view(text).substr(start, pos - start);
    return last;
  }
  // The line of the k-th token from here (0: the next), -1 past the end;
  // nothing is taken.
  long line_ahead(int k) {
    const size_t keep_pos = pos;
    const long keep_line = at_line;
    long found = -1;
    for (int i = 0; i <= k && !done(); ++i) {
      if (i == k) found = at_line;
      word();
    }
    pos = keep_pos;
    at_line = keep_line;
    return found;
  }
  double number() {
    const long at = line();
    const std::string_view w = word();
    char* end = nullptr;
    const double v = std::strtod(w.data(), &end);  // the token ends at a space, '#' or the string's end
    if (end != w.data() + w.size()) input_error(*path, at, "expected a number, found '" + std::string(w) + "'");
    return v;
  }
  long integer() {
    const long at = line();
    const double v = number();
    if (!is_whole_number(v)) input_error(*path, at, "expected an integer of at most 2^53, found " + std::string(last));
    return static_cast<long>(v);
  }
  // A count of items that follow: no more than the tokens the rest of the
  // file could hold (each takes a character and a separator).
  long count() {
    const long at = line();
    const long n = integer();
    if (n < 0) input_error(*path, at, "negative element count");
    if (static_cast<size_t>(n) > (text.size() - pos) / 2 + 1)
      input_error(*path, at, "a count of " + std::to_string(n) + " is more than the file holds");
    return n;
  }
};

Tokens tokenize(std::string text, const std::string& path) {
  Tokens t;
  t.text = std::move(text);
  t.path = &path;
  return t;
}

// Calls visit(line number, first word, the rest of the line's words) for
// every line that has a first word.
template <class Visit>
void for_each_tagged_line(const std::string& text, Visit visit) {
  long number = 0;
  for (size_t start = 0; start < text.size();) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    ++number;
    std::istringstream words(text.substr(start, end - start));  // one line at a time, never the whole text again
    start = end + 1;
    std::string tag;
    if (words >> tag) visit(number, tag, words);
  }
}

SurfaceMesh read_off(const std::string& path) {
  Tokens t = tokenize(read_all(path), path);
  const std::string head(t.word());
  if (head != "OFF" && head != "COFF" && head != "NOFF") input_error(path, 1, "not an OFF file (header '" + head + "')");
  const long counts_line = t.line();
  const long nv = t.count(), nf = t.count();
  t.integer();  // edges
  // A record a line, where COFF/NOFF vertices and coloured faces carry more
  // numbers to skip; or plain OFF in free format (records run on across
  // lines, the counts' line included), where nothing is skipped.
  const bool free_format =
      head == "OFF" && !t.done() &&
      (t.line() == counts_line || t.line_ahead(3) == t.line());
  auto skip_rest_of_line = [&](long at) {
    while (!free_format && !t.done() && t.line() == at) t.word();
  };
  SurfaceMesh mesh;
  for (long i = 0; i < nv; ++i) {
    const long at = t.line();
    const double x = t.number(), y = t.number(), z = t.number();
    mesh.vertices.push_back(checked_point(x, y, z, path, at));
    skip_rest_of_line(at);
  }
  for (long f = 0; f < nf; ++f) {
    const long at = t.line();
    const long n = t.count();
    std::vector<long> corners;
    for (long k = 0; k < n; ++k) corners.push_back(t.integer());
    add_polygon(mesh, corners, path, at);
    skip_rest_of_line(at);  // face colours
  }
  return mesh;
}

SurfaceMesh read_obj(const std::string& path) {
  SurfaceMesh mesh;
  for_each_tagged_line(read_all(path), [&](long number, const std::string& tag, std::istringstream& words) {
    if (tag == "v") {
      double x, y, z;
      if (!(words >> x >> y >> z)) input_error(path, number, "vertex needs x y z");
      mesh.vertices.push_back(checked_point(x, y, z, path, number));
    } else if (tag == "f") {
      std::vector<long> corners;
      std::string corner;
      while (words >> corner) {
        const long index = std::strtol(corner.c_str(), nullptr, 10);  // "7/3/2" -> 7
        if (index == 0) input_error(path, number, "bad face corner '" + corner + "'");
        corners.push_back(index > 0 ? index - 1 : static_cast<long>(mesh.vertices.size()) + index);
      }
      add_polygon(mesh, corners, path, number);
    }
  });
  return mesh;
}

// STL stores corners per triangle; identical coordinates become one vertex.
struct VertexMerger {
  std::map<std::array<double, 3>, int> index;
  int operator()(SurfaceMesh& mesh, const Eigen::Vector3d& p) {
    auto [it, inserted] = index.emplace(std::array<double, 3>{p.x(), p.y(), p.z()}, static_cast<int>(mesh.vertices.size()));
    if (inserted) mesh.vertices.push_back(p);
    return it->second;
  }
};

SurfaceMesh read_stl(const std::string& path) {
  const std::string data = read_all(path);
  SurfaceMesh mesh;
  VertexMerger merge;
  // A binary STL's 80-byte header may begin with "solid" and hold "facet"
  // (some writers put the ASCII keyword there): a file whose size is exactly
  // what its triangle count announces is binary whatever its header says.
  uint32_t count = 0;
  if (data.size() >= 84) std::memcpy(&count, data.data() + 80, 4);
  const bool sized_binary = data.size() >= 84 && data.size() == 84 + 50ull * count;
  const bool ascii = !sized_binary && data.compare(0, 5, "solid") == 0 && data.find("facet") != std::string::npos;
  if (!ascii) {
    if (data.size() < 84) input_error(path, 0, "binary STL shorter than its 84-byte header");
    if (data.size() < 84 + 50ull * count)
      input_error(path, 0, "binary STL announces " + std::to_string(count) + " triangles but is too short");
    for (uint32_t f = 0; f < count; ++f) {
      const char* rec = data.data() + 84 + 50ull * f + 12;
      std::array<int, 3> tri{};
      for (int k = 0; k < 3; ++k) {
        float c[3];
        std::memcpy(c, rec + 12 * k, 12);
        tri[k] = merge(mesh, checked_point(c[0], c[1], c[2], path, 0));
      }
      mesh.triangles.push_back(tri);
    }
    return mesh;
  }
  std::istringstream in(data);
  std::string line;
  long number = 0;
  std::vector<int> corners;
  while (std::getline(in, line)) {
    ++number;
    std::istringstream words(line);
    std::string tag;
    words >> tag;
    if (tag == "vertex") {
      double x, y, z;
      if (!(words >> x >> y >> z)) input_error(path, number, "vertex needs x y z");
      corners.push_back(merge(mesh, checked_point(x, y, z, path, number)));
    } else if (tag == "endfacet") {
      if (corners.size() != 3) input_error(path, number, "facet without exactly 3 vertices");
      mesh.triangles.push_back({corners[0], corners[1], corners[2]});
      corners.clear();
    }
  }
  return mesh;
}

// A PLY scalar type, parsed once from the header: the body's values are read
// by it (comparing type names per value was a quarter of `skinmesh quality`
// on a binary mesh).
enum class PlyType : unsigned char { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

PlyType ply_type(const std::string& t, const std::string& path) {
  if (t == "char" || t == "int8") return PlyType::int8;
  if (t == "uchar" || t == "uint8") return PlyType::uint8;
  if (t == "short" || t == "int16") return PlyType::int16;
  if (t == "ushort" || t == "uint16") return PlyType::uint16;
  if (t == "int" || t == "int32") return PlyType::int32;
  if (t == "uint" || t == "uint32") return PlyType::uint32;
  if (t == "float" || t == "float32") return PlyType::float32;
  if (t == "double" || t == "float64") return PlyType::float64;
  input_error(path, 0, "unknown PLY property type '" + t + "'");
}

size_t ply_type_size(PlyType t) {
  switch (t) {
    case PlyType::int8: case PlyType::uint8: return 1;
    case PlyType::int16: case PlyType::uint16: return 2;
    case PlyType::float64: return 8;
    default: return 4;
  }
}

struct PlyProperty {
  std::string name, type, count_type;  // count_type non-empty for lists
  PlyType value = PlyType::float64, count = PlyType::uint8;  // parsed type and count_type
};
struct PlyElement {
  std::string name;
  long count = 0;
  std::vector<PlyProperty> properties;
};
struct PlyHeader {
  std::string format;  // ascii, binary_little_endian or binary_big_endian
  std::vector<PlyElement> elements;
  size_t body = 0;     // offset of the first byte after the header
};

// Refuses element counts the body cannot hold before any is read: a record
// takes at least the bytes of its scalar properties and list counts (binary),
// or two characters a value (text). A header may otherwise declare 10^18
// records in a file of a hundred bytes.
void check_ply_counts(const PlyHeader& h, size_t body_bytes, const std::string& path) {
  const bool ascii = h.format == "ascii";
  double needed = 0;
  for (const PlyElement& e : h.elements) {
    if (e.count < 0) input_error(path, 0, "PLY element '" + e.name + "' has a negative count");
    size_t record = 0;
    for (const PlyProperty& p : e.properties)
      record += ascii ? 2 : ply_type_size(p.count_type.empty() ? p.value : p.count);
    needed += static_cast<double>(e.count) * static_cast<double>(record);
    if (needed - (ascii ? 1 : 0) > static_cast<double>(body_bytes))  // text: no separator after the last value
      input_error(path, 0, "PLY element '" + e.name + "' declares " + std::to_string(e.count) +
                               " records, more than the " + std::to_string(body_bytes) + " bytes after the header hold");
  }
}

PlyHeader read_ply_header(const std::string& data, const std::string& path) {
  const size_t end_header = data.find("end_header");
  if (data.compare(0, 3, "ply") != 0 || end_header == std::string::npos) input_error(path, 1, "not a PLY file");
  PlyHeader h;
  h.body = data.find('\n', end_header);
  h.body = h.body == std::string::npos ? data.size() : h.body + 1;
  for_each_tagged_line(data.substr(0, end_header), [&](long number, const std::string& tag, std::istringstream& w) {
    if (tag == "format") {
      w >> h.format;
    } else if (tag == "element") {
      PlyElement e;
      std::string count;
      w >> e.name >> count;
      char* end = nullptr;
      const double value = std::strtod(count.c_str(), &end);
      if (count.empty() || end != count.c_str() + count.size() || !is_whole_number(value) || value < 0)
        input_error(path, number, "PLY element '" + e.name + "' needs a count of 0 to 2^53, found '" + count + "'");
      e.count = static_cast<long>(value);
      h.elements.push_back(e);
    } else if (tag == "property") {
      if (h.elements.empty()) input_error(path, number, "property before any element");
      PlyProperty p;
      w >> p.type;
      if (p.type == "list") w >> p.count_type >> p.type;
      w >> p.name;
      // Checked in every format: an ASCII body is read as numbers whatever
      // the header says, so a wrong type would pass unseen.
      p.value = ply_type(p.type, path);
      if (!p.count_type.empty()) p.count = ply_type(p.count_type, path);
      if (!p.count_type.empty() && (p.count == PlyType::float32 || p.count == PlyType::float64))
        input_error(path, number, "PLY list '" + p.name + "' needs an integer count type, not " + p.count_type);
      h.elements.back().properties.push_back(p);
    }
  });
  if (h.format != "ascii" && h.format != "binary_little_endian" && h.format != "binary_big_endian")
    input_error(path, 2, "unknown PLY format '" + h.format + "'");
  check_ply_counts(h, data.size() - h.body, path);
  return h;
}

// The values of a PLY body one after another, as doubles, in its format.
class PlyValues {
 public:
  PlyValues(const std::string& data, const PlyHeader& header, const std::string& path)
      : data_(data), path_(path), ascii_(header.format == "ascii"), swap_(header.format == "binary_big_endian"),
        pos_(header.body), text_(ascii_ ? data.substr(header.body) : std::string()) {}

  double next(PlyType type) {
    if (ascii_) {
      double v;
      if (!(text_ >> v)) input_error(path_, 0, "PLY body ends early or holds a non-number");
      return v;
    }
    const size_t n = ply_type_size(type);
    if (pos_ + n > data_.size()) input_error(path_, 0, "PLY body ends early");
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, n);
    pos_ += n;
    if (swap_) std::reverse(b, b + n);
    switch (type) {
      case PlyType::float32: { float f; std::memcpy(&f, b, 4); return f; }
      case PlyType::float64: { double d; std::memcpy(&d, b, 8); return d; }
      case PlyType::int8: return static_cast<int8_t>(b[0]);
      case PlyType::uint8: return b[0];
      case PlyType::int16: { int16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::uint16: { uint16_t v; std::memcpy(&v, b, 2); return v; }
      case PlyType::int32: { int32_t v; std::memcpy(&v, b, 4); return v; }
      case PlyType::uint32: break;
    }
    uint32_t v;
    std::memcpy(&v, b, 4);
    return v;
  }

 private:
  const std::string& data_;
  const std::string& path_;
  bool ascii_, swap_;
  size_t pos_;
  std::istringstream text_;
};

// `properties`, when given, gets every scalar vertex property but x, y, z by name.
SurfaceMesh read_ply(const std::string& path, std::map<std::string, std::vector<double>>* properties = nullptr) {
  const std::string data = read_all(path);
  const PlyHeader header = read_ply_header(data, path);
  PlyValues values(data, header, path);
  SurfaceMesh mesh;
  for (const PlyElement& e : header.elements) {
    // A record without properties holds nothing: 10^15 of them fit in no
    // bytes at all, and counting through them would take days.
    if (e.properties.empty()) {
      if ((e.name == "vertex" || e.name == "face") && e.count > 0)
        input_error(path, 0, "PLY element '" + e.name + "' has no properties");
      continue;
    }
    // What each property is, decided once per element, not per record.
    const bool vertex = e.name == "vertex", face = e.name == "face";
    std::vector<int> role(e.properties.size(), -1);  // 0-2: x, y, z of a vertex; 3: a face's vertex indices
    for (size_t k = 0; k < role.size(); ++k) {
      const PlyProperty& p = e.properties[k];
      if (vertex && p.count_type.empty() && (p.name == "x" || p.name == "y" || p.name == "z")) role[k] = p.name[0] - 'x';
      if (face && !p.count_type.empty() && (p.name == "vertex_indices" || p.name == "vertex_index")) role[k] = 3;
    }
    std::vector<long> corners;
    for (long i = 0; i < e.count; ++i) {
      double xyz[3] = {NAN, NAN, NAN};
      corners.clear();
      for (size_t k = 0; k < role.size(); ++k) {
        const PlyProperty& p = e.properties[k];
        if (!p.count_type.empty()) {
          const double count = values.next(p.count);
          if (!is_whole_number(count) || count < 0)
            input_error(path, 0, "PLY " + e.name + " " + std::to_string(i) + ": bad list length");
          for (long c = 0; c < static_cast<long>(count); ++c) {
            const double v = values.next(p.value);
            if (role[k] != 3) continue;
            if (!is_whole_number(v)) input_error(path, 0, "PLY face " + std::to_string(i) + ": vertex index is not an integer");
            corners.push_back(static_cast<long>(v));
          }
        } else {
          const double v = values.next(p.value);
          if (role[k] >= 0) xyz[role[k]] = v;
          else if (vertex && properties) (*properties)[p.name].push_back(v);
        }
      }
      if (vertex) mesh.vertices.push_back(checked_point(xyz[0], xyz[1], xyz[2], path, 0));
      if (face) add_polygon(mesh, corners, path, 0);
    }
  }
  return mesh;
}

// MSMS: NAME.vert (header lines starting with '#', a count line, then
// "x y z nx ny nz ..." per vertex) and NAME.face ("v1 v2 v3 ..." 1-based).
SurfaceMesh read_msms(const std::string& path) {
  const std::string stem = path.substr(0, path.size() - 5);
  const std::string vert = stem + ".vert", face = stem + ".face";
  SurfaceMesh mesh;
  auto data_lines = [](const std::string& file, auto visit) {
    std::istringstream in(read_all(file));
    std::string line;
    long number = 0;
    bool count_seen = false;
    while (std::getline(in, line)) {
      ++number;
      if (line.empty() || line[0] == '#') continue;
      if (!count_seen) {
        count_seen = true;  // "count  spheres  density  probe"
        continue;
      }
      visit(number, line);
    }
  };
  data_lines(vert, [&](long number, const std::string& line) {
    std::istringstream w(line);
    double x, y, z, nx, ny, nz;
    if (!(w >> x >> y >> z)) input_error(vert, number, "vertex line needs x y z");
    mesh.vertices.push_back(checked_point(x, y, z, vert, number));
    if (w >> nx >> ny >> nz) mesh.normals.emplace_back(nx, ny, nz);
  });
  if (mesh.normals.size() != mesh.vertices.size()) mesh.normals.clear();
  data_lines(face, [&](long number, const std::string& line) {
    std::istringstream w(line);
    long a, b, c;
    if (!(w >> a >> b >> c)) input_error(face, number, "face line needs three vertex numbers");
    add_polygon(mesh, {a - 1, b - 1, c - 1}, face, number);
  });
  return mesh;
}

// Gmsh MSH 4.x ASCII: the nodes of every entity block; triangles (type 2)
// and quadrangles (type 3) with their entity tags, and tetrahedra (type 4)
// with theirs; other element types (points, lines, other volumes) are skipped.
struct GmshContent {
  SurfaceMesh surface;
  std::vector<int> triangle_entity;
  std::vector<std::array<int, 4>> tets;
  std::vector<int> tet_entity;
};

GmshContent read_gmsh_content(const std::string& path) {
  Tokens t = tokenize(read_all(path), path);
  auto seek = [&](const char* section) {
    while (!t.done() && t.word() != section) {
    }
    if (t.last != section) input_error(path, 0, std::string("no ") + section + " section");
  };
  seek("$MeshFormat");
  const long at = t.line();
  const std::string version(t.word());
  if (version.rfind("4", 0) != 0) input_error(path, at, "Gmsh format " + version + " (only 4.x is read)");
  if (t.integer() != 0) input_error(path, at, "binary Gmsh files are not read (save as ASCII)");
  t.rewind();
  seek("$Nodes");
  GmshContent out;
  SurfaceMesh& mesh = out.surface;
  std::map<long, int> index;
  const long node_blocks = t.integer();
  t.integer();  // number of nodes
  t.integer();  // smallest tag
  t.integer();  // largest tag
  for (long b = 0; b < node_blocks; ++b) {
    t.integer();  // entity dimension
    t.integer();  // entity tag
    const long parametric = t.integer(), count = t.integer();
    std::vector<long> tags;
    for (long i = 0; i < count; ++i) tags.push_back(t.integer());
    for (long i = 0; i < count; ++i) {
      const long line = t.line();
      const double x = t.number(), y = t.number(), z = t.number();
      if (parametric) while (!t.done() && t.line() == line) t.word();
      index[tags[static_cast<size_t>(i)]] = static_cast<int>(mesh.vertices.size());
      mesh.vertices.push_back(checked_point(x, y, z, path, line));
    }
  }
  seek("$Elements");
  const long element_blocks = t.integer();
  t.integer();
  t.integer();
  t.integer();
  const std::map<long, int> corners_of{{15, 1}, {1, 2}, {2, 3}, {3, 4}, {4, 4}, {5, 8}, {6, 6}, {7, 5}};
  for (long b = 0; b < element_blocks; ++b) {
    t.integer();  // entity dimension
    const long entity = t.integer();
    const long block_line = t.line();
    const long type = t.integer(), count = t.integer();
    const auto known = corners_of.find(type);
    if (known == corners_of.end()) input_error(path, block_line, "unsupported Gmsh element type " + std::to_string(type));
    for (long e = 0; e < count; ++e) {
      const long line = t.line();
      t.integer();  // element tag
      std::vector<long> corners;
      for (int k = 0; k < known->second; ++k) {
        const long tag = t.integer();
        const auto it = index.find(tag);
        if (it == index.end()) input_error(path, line, "element refers to node " + std::to_string(tag) + ", not in $Nodes");
        corners.push_back(it->second);
      }
      if (type == 2 || type == 3) {
        add_polygon(mesh, corners, path, line);
        out.triangle_entity.resize(mesh.triangles.size(), static_cast<int>(entity));
      } else if (type == 4) {
        out.tets.push_back({static_cast<int>(corners[0]), static_cast<int>(corners[1]), static_cast<int>(corners[2]),
                            static_cast<int>(corners[3])});
        out.tet_entity.push_back(static_cast<int>(entity));
      }
    }
  }
  return out;
}

SurfaceMesh read_gmsh(const std::string& path) { return read_gmsh_content(path).surface; }

// `count` node numbers of one TetGen item, shifted to zero-based and checked.
template <size_t count>
std::array<int, count> tetgen_corners(Tokens& t, long first, long nodes, const std::string& path, long line,
                                      const char* what) {
  std::array<int, count> out{};
  for (size_t k = 0; k < count; ++k) {
    const long v = t.integer() - first;
    if (v < 0 || v >= nodes) input_error(path, line, std::string(what) + " refers to node " + std::to_string(v + first));
    out[k] = static_cast<int>(v);
  }
  return out;
}

// TetGen's files: "<count> <fields...>" headers, one numbered item a line,
// '#' comments; `stem` is the name without .node/.ele/.face.
TetMesh read_tetgen(const std::string& stem) {
  TetMesh mesh;
  {
    const std::string path = stem + ".node";
    Tokens t = tokenize(read_all(path), path);
    const long n = t.integer(), dim = t.integer(), attributes = t.integer(), markers = t.integer();
    if (dim != 3) input_error(path, 1, "not a 3D .node file");
    if (n < 0 || attributes < 0 || markers < 0) input_error(path, 1, "negative count");
    std::vector<long> numbers;
    for (long i = 0; i < n; ++i) {
      const long line = t.line();
      numbers.push_back(t.integer());
      const double x = t.number(), y = t.number(), z = t.number();
      mesh.points.push_back(checked_point(x, y, z, path, line));
      for (long k = 0; k < attributes + markers; ++k) t.number();
    }
    // Indices may start at 0 or 1 (TetGen keeps the input's numbering).
    const long first = numbers.empty() ? 0 : *std::min_element(numbers.begin(), numbers.end());
    if (first != 0 && first != 1) input_error(path, 2, "node numbers start at " + std::to_string(first));
    const std::string ele = stem + ".ele";
    Tokens e = tokenize(read_all(ele), ele);
    const long m = e.integer(), corners = e.integer(), ele_attributes = e.integer();
    if (corners != 4) input_error(ele, 1, "only 4-node tetrahedra are read");
    for (long i = 0; i < m; ++i) {
      const long line = e.line();
      e.integer();
      mesh.tets.push_back(tetgen_corners<4>(e, first, n, ele, line, "tetrahedron"));
      double region = 0;
      for (long k = 0; k < ele_attributes; ++k) {
        const double a = e.number();
        if (k == 0) region = a;
      }
      mesh.tet_region.push_back(static_cast<int>(std::lround(region)));
    }
    const std::string face = stem + ".face";
    if (std::ifstream(face).good()) {
      Tokens f = tokenize(read_all(face), face);
      const long nf = f.integer(), with_markers = f.integer();
      for (long i = 0; i < nf; ++i) {
        const long line = f.line();
        f.integer();
        mesh.faces.push_back(tetgen_corners<3>(f, first, n, face, line, "face"));
        mesh.face_marker.push_back(with_markers ? static_cast<int>(f.integer()) : 0);
      }
    }
  }
  return mesh;
}

}  // namespace

SurfaceMesh read_surface_mesh(const std::string& path) {
  SurfaceMesh mesh;
  if (has_extension(path, ".off")) mesh = read_off(path);
  else if (has_extension(path, ".obj")) mesh = read_obj(path);
  else if (has_extension(path, ".stl")) mesh = read_stl(path);
  else if (has_extension(path, ".ply")) mesh = read_ply(path);
  else if (has_extension(path, ".vert") || has_extension(path, ".face")) mesh = read_msms(path);
  else if (has_extension(path, ".msh")) mesh = read_gmsh(path);
  else input_error(path, 0, "unknown mesh format (expected .off, .obj, .stl, .ply, .msh, or an MSMS .vert/.face pair)");
  if (mesh.triangles.empty()) input_error(path, 0, "mesh has no triangles");
  return mesh;
}

TetMesh read_gmsh_volume(const std::string& path) {
  GmshContent g = read_gmsh_content(path);
  TetMesh mesh;
  mesh.points = std::move(g.surface.vertices);
  mesh.tets = std::move(g.tets);
  mesh.tet_region = std::move(g.tet_entity);
  mesh.faces = std::move(g.surface.triangles);
  mesh.face_marker = std::move(g.triangle_entity);
  return mesh;
}

TetMesh read_tet_mesh(const std::string& path) {
  for (const char* ext : {".node", ".ele", ".face"})
    if (has_extension(path, ext)) return read_tetgen(path.substr(0, path.size() - std::string(ext).size()));
  if (!has_extension(path, ".msh")) input_error(path, 0, "unknown volume mesh format (expected .ele/.node/.face or .msh)");
  TetMesh mesh = read_gmsh_volume(path);
  if (mesh.tets.empty()) input_error(path, 0, "no tetrahedra in the file");
  return mesh;
}

PlyMesh read_ply_with_properties(const std::string& path) {
  PlyMesh ply;
  ply.mesh = read_ply(path, &ply.vertex_properties);
  return ply;
}

}  // namespace skinmesh
