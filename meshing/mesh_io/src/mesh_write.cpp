#include "skinmesh/mesh_io/mesh_write.hpp"
#include "skinmesh/core/error.hpp"

#include "skinmesh/core/file_names.hpp"
#include "skinmesh/mesh_io/glb_write.hpp"

#include <Eigen/Geometry>

#include <charconv>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace skinmesh {
namespace {

int digits(const MeshWriteOptions& o) { return o.single_precision ? 9 : 17; }

// What a writer makes, gathered and handed to the stream 64 KiB at a
// time: a stream call per value took most of the time of writing a frame.
class Sink {
 public:
  explicit Sink(std::ostream& out) : out_(out), bytes_(kChunk) {}
  Sink(const Sink&) = delete;
  Sink& operator=(const Sink&) = delete;
  ~Sink() { flush(); }
  // A value's bytes (little endian on every machine we build for: checked by write_ply).
  template <class T>
  void put(T value) {
    if (used_ + sizeof(T) > kChunk) flush();
    std::memcpy(bytes_.data() + used_, &value, sizeof(T));
    used_ += sizeof(T);
  }
  void text(const char* begin, size_t size) {
    if (used_ + size > kChunk) flush();
    if (size > kChunk) {
      out_.write(begin, static_cast<std::streamsize>(size));
      return;
    }
    std::memcpy(bytes_.data() + used_, begin, size);
    used_ += size;
  }
  void flush() {
    if (used_ > 0) out_.write(bytes_.data(), static_cast<std::streamsize>(used_));
    used_ = 0;
  }

 private:
  static constexpr size_t kChunk = size_t{1} << 16;
  std::ostream& out_;
  std::vector<char> bytes_;
  size_t used_ = 0;
};

Sink& operator<<(Sink& out, const char* text) {
  out.text(text, std::strlen(text));
  return out;
}
Sink& operator<<(Sink& out, const std::string& text) {
  out.text(text.data(), text.size());
  return out;
}
Sink& operator<<(Sink& out, char c) {
  out.text(&c, 1);
  return out;
}
template <class T, std::enable_if_t<std::is_integral_v<T>, int> = 0>
Sink& operator<<(Sink& out, T value) {
  char text[24];
  const auto end = std::to_chars(text, text + sizeof(text), value).ptr;
  out.text(text, static_cast<size_t>(end - text));
  return out;
}

// A real as `out << std::setprecision(digits) << value` writes it (printf's
// %.*g), formatted by std::to_chars: the stream's own formatting was most
// of the time of writing a morph's frames.
struct Real {
  double value;
  int digits;
};
Sink& operator<<(Sink& out, Real r) {
  char text[64];
  const auto end = std::to_chars(text, text + sizeof(text), r.value, std::chars_format::general, r.digits).ptr;
  out.text(text, static_cast<size_t>(end - text));
  return out;
}
// A point or normal as its three Reals, one space apart.
struct Reals3 {
  const Eigen::Vector3d& value;
  int digits;
};
Sink& operator<<(Sink& out, Reals3 r) {
  return out << Real{r.value[0], r.digits} << ' ' << Real{r.value[1], r.digits} << ' ' << Real{r.value[2], r.digits};
}
// An integer as `out << value` writes it.
struct Integer {
  long long value;
};
Sink& operator<<(Sink& out, Integer i) { return out << i.value; }

Eigen::Vector3d normal_of(const SurfaceMesh& mesh, size_t v) {
  return v < mesh.normals.size() ? mesh.normals[v] : Eigen::Vector3d::Zero();
}

bool has(const VertexAttributes* a, const SurfaceMesh& mesh) {
  if (!a) return false;
  if (a->patch.size() != mesh.vertices.size() || a->atom.size() != mesh.vertices.size()) return false;
  for (const auto& column : a->more) {
    if (column.values.size() != mesh.vertices.size())
      contract_error("vertex property " + column.name + ": one value per vertex expected");
    if (column.type != PropertyType::int32)
      for (int v : column.values)
        if (v < 0 || (column.type == PropertyType::uint8 && v > 255))
          contract_error("vertex property " + column.name + ": " + std::to_string(v) + " does not fit its unsigned type");
  }
  return true;
}

bool has_colours(const VertexAttributes* a, const SurfaceMesh& mesh) {
  return a && !a->colours.empty() && a->colours.size() == mesh.vertices.size();
}

const char* ply_type(PropertyType t) {
  return t == PropertyType::uint8 ? "uchar" : t == PropertyType::uint32 ? "uint" : "int";
}

void write_ply_header(std::ostream& out, const SurfaceMesh& mesh, const VertexAttributes* attributes,
                      const MeshWriteOptions& options) {
  const bool normals = mesh.normals.size() == mesh.vertices.size();
  const char* real = options.single_precision ? "float" : "double";
  out << "ply\nformat " << (options.ascii ? "ascii" : "binary_little_endian") << " 1.0\n"
      << "comment skinmesh: molecular skin surface\n";
  out << "element vertex " << mesh.vertices.size() << "\n";
  for (const char* c : {"x", "y", "z"}) out << "property " << real << " " << c << "\n";
  if (normals)
    for (const char* c : {"nx", "ny", "nz"}) out << "property " << real << " " << c << "\n";
  if (has(attributes, mesh)) {
    out << "property uchar patch\nproperty int atom\n";
    for (const auto& column : attributes->more) out << "property " << ply_type(column.type) << " " << column.name << "\n";
  }
  if (has_colours(attributes, mesh))
    for (const char* c : {"red", "green", "blue"}) out << "property uchar " << c << "\n";
  out << "element face " << mesh.triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
}

// The vertex's values in the header's order, as text or binary.
template <class Put>
void write_ply_body(const SurfaceMesh& mesh, const VertexAttributes* attributes, Put& put_value) {
  const bool normals = mesh.normals.size() == mesh.vertices.size();
  const bool attrs = has(attributes, mesh), colours = has_colours(attributes, mesh);
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    for (int k = 0; k < 3; ++k) put_value.real(mesh.vertices[v][k]);
    if (normals)
      for (int k = 0; k < 3; ++k) put_value.real(mesh.normals[v][k]);
    if (attrs) {
      put_value.integer(PropertyType::uint8, attributes->patch[v]);
      put_value.integer(PropertyType::int32, attributes->atom[v]);
      for (const auto& column : attributes->more) put_value.integer(column.type, column.values[v]);
    }
    if (colours)
      for (int k = 0; k < 3; ++k) put_value.integer(PropertyType::uint8, attributes->colours[v][static_cast<size_t>(k)]);
    put_value.end_line();
  }
  for (const auto& t : mesh.triangles) {
    put_value.integer(PropertyType::uint8, 3);
    for (int k = 0; k < 3; ++k) put_value.integer(PropertyType::int32, t[static_cast<size_t>(k)]);
    put_value.end_line();
  }
}

struct BinaryPly {
  Sink& out;
  bool single;
  void real(double v) {
    if (single) out.put(static_cast<float>(v));
    else out.put(v);
  }
  void integer(PropertyType type, int v) {
    if (type == PropertyType::uint8) out.put(static_cast<uint8_t>(v));
    else if (type == PropertyType::uint32) out.put(static_cast<uint32_t>(v));
    else out.put(static_cast<int32_t>(v));
  }
  void end_line() {}
};

struct TextPly {
  Sink& out;
  int digits;
  bool first = true;
  void separate() {
    if (!first) out << ' ';
    first = false;
  }
  void real(double v) {
    separate();
    out << Real{v, digits};
  }
  void integer(PropertyType, int v) {
    separate();
    out << Integer{v};
  }
  void end_line() {
    out << '\n';
    first = true;
  }
};

void write_ply(std::ostream& out, const SurfaceMesh& mesh, const VertexAttributes* attributes,
               const MeshWriteOptions& options) {
  static_assert(sizeof(float) == 4 && sizeof(double) == 8, "IEEE floating point expected");
  const uint16_t probe = 1;
  if (*reinterpret_cast<const uint8_t*>(&probe) != 1) contract_error("the PLY writer needs a little-endian host");
  write_ply_header(out, mesh, attributes, options);
  if (options.ascii) {
    Sink sink(out);
    TextPly text{sink, digits(options)};
    write_ply_body(mesh, attributes, text);
    sink.flush();
  } else {
    Sink sink(out);
    BinaryPly binary{sink, options.single_precision};
    write_ply_body(mesh, attributes, binary);
    sink.flush();
  }
}

void write_off(std::ostream& stream, const SurfaceMesh& mesh, const MeshWriteOptions& options) {
  Sink out(stream);
  const int d = digits(options);
  out << "OFF\n" << mesh.vertices.size() << " " << mesh.triangles.size() << " 0\n";
  for (const auto& v : mesh.vertices) out << Reals3{v, d} << "\n";
  for (const auto& t : mesh.triangles) out << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
}

void write_obj(std::ostream& stream, const SurfaceMesh& mesh, const MeshWriteOptions& options) {
  Sink out(stream);
  const bool normals = mesh.normals.size() == mesh.vertices.size();
  const int d = digits(options);
  out << "# skinmesh: molecular skin surface\n";
  for (const auto& v : mesh.vertices) out << "v " << Reals3{v, d} << "\n";
  if (normals)
    for (const auto& n : mesh.normals) out << "vn " << Reals3{n, d} << "\n";
  for (const auto& t : mesh.triangles) {
    out << "f";
    for (int k = 0; k < 3; ++k) {
      const int i = t[static_cast<size_t>(k)] + 1;
      out << " " << i;
      if (normals) out << "//" << i;
    }
    out << "\n";
  }
}

// Binary STL holds 32-bit floats only, whatever the options say.
void write_stl(std::ostream& out, const SurfaceMesh& mesh) {
  char header[80] = {};
  std::strncpy(header, "skinmesh: molecular skin surface (binary STL, single precision)", sizeof(header) - 1);
  out.write(header, sizeof(header));
  Sink sink(out);
  sink.put(static_cast<uint32_t>(mesh.triangles.size()));
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[static_cast<size_t>(t[0])];
    const Eigen::Vector3d& b = mesh.vertices[static_cast<size_t>(t[1])];
    const Eigen::Vector3d& c = mesh.vertices[static_cast<size_t>(t[2])];
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    for (int k = 0; k < 3; ++k) sink.put(static_cast<float>(n[k]));
    for (const Eigen::Vector3d* p : {&a, &b, &c})
      for (int k = 0; k < 3; ++k) sink.put(static_cast<float>((*p)[k]));
    sink.put(static_cast<uint16_t>(0));
  }
  sink.flush();
}

// Base64 (RFC 4648) into a Sink, three bytes to four characters, with '='
// padding at the end.
class Base64 {
 public:
  explicit Base64(Sink& out) : out_(out) {}
  void bytes(const void* data, size_t size) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) {
      group_[held_++] = b[i];
      if (held_ == 3) emit();
    }
  }
  template <class T>
  void value(T v) {
    bytes(&v, sizeof v);
  }
  void finish() {
    if (held_ > 0) emit();
  }

 private:
  void emit() {
    static const char* const kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (size_t k = held_; k < 3; ++k) group_[k] = 0;
    const unsigned w = (unsigned{group_[0]} << 16) | (unsigned{group_[1]} << 8) | unsigned{group_[2]};
    const char text[4] = {kAlphabet[(w >> 18) & 63], kAlphabet[(w >> 12) & 63],
                          held_ > 1 ? kAlphabet[(w >> 6) & 63] : '=', held_ > 2 ? kAlphabet[w & 63] : '='};
    out_.text(text, 4);
    held_ = 0;
  }
  Sink& out_;
  unsigned char group_[3] = {0, 0, 0};
  size_t held_ = 0;
};

// One VTK XML data array: `count` values of `type` (a VTK type name) that
// `each(put)` hands over in order, put(value) with value of the type's C++
// type. Binary: base64 of a UInt64 byte count followed by the values, one
// stream (the layout VTK's reader expects of uncompressed inline data,
// header_type UInt64); text: one value a line, or three with `components` 3.
struct VtpArrays {
  Sink& out;
  bool ascii;
  int digits;

  template <class T, class Each>
  void array(const char* type, const std::string& name, int components, size_t count, Each each) {
    out << "<DataArray type=\"" << type << "\"";
    if (!name.empty()) out << " Name=\"" << name << "\"";
    if (components > 1) out << " NumberOfComponents=\"" << static_cast<long long>(components) << "\"";
    out << " format=\"" << (ascii ? "ascii" : "binary") << "\">\n";
    if (ascii) {
      size_t k = 0;
      each([&](T v) {
        if constexpr (std::is_floating_point_v<T>)
          out << Real{static_cast<double>(v), digits};
        else
          out << Integer{static_cast<long long>(v)};
        out << (++k % static_cast<size_t>(components) == 0 ? '\n' : ' ');
      });
    } else {
      Base64 code(out);
      code.value(static_cast<uint64_t>(count * sizeof(T)));
      each([&](T v) { code.value(v); });
      code.finish();
      out << '\n';
    }
    out << "</DataArray>\n";
  }

  // The vertices' points or normals, as doubles or floats.
  void reals3(const std::string& name, const std::vector<Eigen::Vector3d>& values, bool single) {
    const auto each = [&](auto put) {
      for (const auto& v : values)
        for (int k = 0; k < 3; ++k) put(v[k]);
    };
    if (single && !ascii)
      array<float>("Float32", name, 3, 3 * values.size(),
                   [&](auto put) { each([&](double x) { put(static_cast<float>(x)); }); });
    else  // text rounds the doubles to `digits` itself
      array<double>(single ? "Float32" : "Float64", name, 3, 3 * values.size(), each);
  }

  void integers(PropertyType type, const std::string& name, const std::vector<int>& values) {
    const auto each = [&](auto put) {
      for (int v : values) put(v);
    };
    if (type == PropertyType::uint8)
      array<uint8_t>("UInt8", name, 1, values.size(), [&](auto put) { each([&](int v) { put(static_cast<uint8_t>(v)); }); });
    else if (type == PropertyType::uint32)
      array<uint32_t>("UInt32", name, 1, values.size(), [&](auto put) { each([&](int v) { put(static_cast<uint32_t>(v)); }); });
    else
      array<int32_t>("Int32", name, 1, values.size(), [&](auto put) { each([&](int v) { put(static_cast<int32_t>(v)); }); });
  }

  // The triangles' corners and the offsets past each triangle's last.
  template <class Index>
  void polys(const char* type, const std::vector<std::array<int, 3>>& triangles) {
    array<Index>(type, "connectivity", 1, 3 * triangles.size(), [&](auto put) {
      for (const auto& t : triangles)
        for (int v : t) put(static_cast<Index>(v));
    });
    array<Index>(type, "offsets", 1, triangles.size(), [&](auto put) {
      for (size_t i = 0; i < triangles.size(); ++i) put(static_cast<Index>(3 * (i + 1)));
    });
  }
};

// VTK XML PolyData (version 1.0, 64-bit byte counts): opens in ParaView
// with normals and attributes. Arrays are binary (base64) unless text is
// asked for: formatting doubles as text took most of a morph frame's writing.
void write_vtp(std::ostream& stream, const SurfaceMesh& mesh, const VertexAttributes* attributes,
               const MeshWriteOptions& options) {
  Sink out(stream);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n<PolyData>\n<Piece NumberOfPoints=\""
      << mesh.vertices.size() << "\" NumberOfPolys=\"" << mesh.triangles.size() << "\">\n";
  VtpArrays arrays{out, options.ascii, digits(options)};
  out << "<Points>\n";
  arrays.reals3("", mesh.vertices, options.single_precision);
  out << "</Points>\n<PointData";
  const bool normals = mesh.normals.size() == mesh.vertices.size();
  if (normals) out << " Normals=\"Normals\"";
  out << ">\n";
  if (normals) arrays.reals3("Normals", mesh.normals, options.single_precision);
  if (has(attributes, mesh)) {
    std::vector<VertexProperty> columns{{"patch", PropertyType::int32, attributes->patch},
                                        {"atom", PropertyType::int32, attributes->atom}};
    columns.insert(columns.end(), attributes->more.begin(), attributes->more.end());
    for (const auto& [name, type, values] : columns) arrays.integers(type, name, values);
  }
  out << "</PointData>\n<Polys>\n";
  // Offsets reach three times the triangles: Int32 while that fits.
  if (3 * mesh.triangles.size() <= static_cast<size_t>(std::numeric_limits<int32_t>::max()))
    arrays.polys<int32_t>("Int32", mesh.triangles);
  else
    arrays.polys<int64_t>("Int64", mesh.triangles);
  out << "</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
}

}  // namespace

// Gmsh MSH 4.1 ASCII: one surface entity, physical group 1 named "skin".
void write_gmsh_surface(std::ostream& stream, const SurfaceMesh& mesh, const MeshWriteOptions& options) {
  Sink out(stream);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const auto& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  if (mesh.vertices.empty()) lo = hi = Eigen::Vector3d::Zero();
  const int d = digits(options);
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 1 \"skin\"\n$EndPhysicalNames\n";
  out << "$Entities\n0 0 1 0\n1 " << Reals3{lo, d} << ' ' << Reals3{hi, d} << " 1 1 0\n$EndEntities\n";
  const size_t n = mesh.vertices.size(), m = mesh.triangles.size();
  out << "$Nodes\n1 " << n << " 1 " << n << "\n2 1 0 " << n << "\n";
  for (size_t i = 0; i < n; ++i) out << i + 1 << "\n";
  for (const auto& v : mesh.vertices) out << Reals3{v, d} << "\n";
  out << "$EndNodes\n$Elements\n1 " << m << " 1 " << m << "\n2 1 2 " << m << "\n";
  for (size_t i = 0; i < m; ++i) {
    const auto& t = mesh.triangles[i];
    out << i + 1 << ' ' << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << "\n";
  }
  out << "$EndElements\n";
}

MeshFormat mesh_format_from_path(const std::string& path) {
  if (has_extension(path, ".ply")) return MeshFormat::ply;
  if (has_extension(path, ".off")) return MeshFormat::off;
  if (has_extension(path, ".obj")) return MeshFormat::obj;
  if (has_extension(path, ".stl")) return MeshFormat::stl;
  if (has_extension(path, ".vtp")) return MeshFormat::vtp;
  if (has_extension(path, ".vert")) return MeshFormat::msms;
  if (has_extension(path, ".msh")) return MeshFormat::gmsh;
  if (has_extension(path, ".glb")) return MeshFormat::glb;
  contract_error(path + ": unknown mesh format (use .ply, .off, .obj, .stl, .vtp, .msh, .glb, or .vert for MSMS)");
}

const char* mesh_format_name(MeshFormat format) {
  switch (format) {
    case MeshFormat::ply: return "ply";
    case MeshFormat::off: return "off";
    case MeshFormat::obj: return "obj";
    case MeshFormat::stl: return "stl";
    case MeshFormat::vtp: return "vtp";
    case MeshFormat::msms: return "msms";
    case MeshFormat::gmsh: return "gmsh";
    case MeshFormat::glb: return "glb";
  }
  return "?";
}

void write_mesh(std::ostream& out, const SurfaceMesh& mesh, MeshFormat format, const VertexAttributes* attributes,
                const MeshWriteOptions& options) {
  switch (format) {
    case MeshFormat::ply: write_ply(out, mesh, attributes, options); break;
    case MeshFormat::off: write_off(out, mesh, options); break;
    case MeshFormat::gmsh: write_gmsh_surface(out, mesh, options); break;
    case MeshFormat::obj: write_obj(out, mesh, options); break;
    case MeshFormat::stl: write_stl(out, mesh); break;
    case MeshFormat::vtp: write_vtp(out, mesh, attributes, options); break;
    case MeshFormat::glb: write_glb(out, {glb_frame(mesh, attributes ? attributes->colours : std::vector<Rgb>{})}); break;
    case MeshFormat::msms: contract_error("MSMS is two files: use write_msms_vert and write_msms_face");
  }
  if (!out) output_error("", "writing the mesh failed");
}

// MSMS's face types (its man page): 1 a contact face (on one atom), 2 a
// toric reentrant face (two atoms), 3 a spheric reentrant face (three). The
// skin's patches by the dimension of their Delaunay simplex: a vertex's
// sphere patch is convex on its atom (1), an edge's hyperboloid is the
// saddle between two atoms (2), a triangle's hyperboloid and a
// tetrahedron's sphere patch are concave between three or four (3).
namespace {
int msms_face_type(int patch) { return patch <= 0 ? 1 : patch == 1 ? 2 : 3; }
}  // namespace

void write_msms_vert(std::ostream& stream, const SurfaceMesh& mesh, const VertexAttributes* attributes,
                     const MeshWriteOptions& options) {
  Sink out(stream);
  const bool attrs = has(attributes, mesh);
  out << "# MSMS-format vertices written by skinmesh (molecular skin surface)\n"
      << "#vertex #sphere density probe_r\n"
      << mesh.vertices.size() << " " << 0 << " " << 0 << " " << 0 << "\n";
  const int d = digits(options);
  // As MSMS writes them: x y z nx ny nz, the analytic face (0: the skin has
  // none numbered), the closest atom (1-based; 0 unknown), the face type.
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Eigen::Vector3d& p = mesh.vertices[v];
    const Eigen::Vector3d n = normal_of(mesh, v);
    out << Reals3{p, d} << " " << Reals3{n, d} << " 0 "
        << (attrs ? attributes->atom[v] + 1 : 0) << " " << msms_face_type(attrs ? attributes->patch[v] : 0) << "\n";
  }
  out.flush();
  if (!stream) output_error("", "writing the MSMS vertices failed");
}

// As MSMS writes them: three 1-based corners, the face type (of the
// triangle's first corner), the analytic face (0: none numbered).
void write_msms_face(std::ostream& stream, const SurfaceMesh& mesh, const VertexAttributes* attributes) {
  Sink out(stream);
  const bool attrs = has(attributes, mesh);
  out << "# MSMS-format triangles written by skinmesh (molecular skin surface)\n"
      << "#faces #sphere density probe_r\n"
      << mesh.triangles.size() << " 0 0 0\n";
  for (const auto& t : mesh.triangles)
    out << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << " "
        << msms_face_type(attrs ? attributes->patch[static_cast<size_t>(t[0])] : 0) << " 0\n";
  out.flush();
  if (!stream) output_error("", "writing the MSMS triangles failed");
}

}  // namespace skinmesh
