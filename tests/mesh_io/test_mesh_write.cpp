// Every mesh format the tool writes is read back by the tool's own readers
// (which were written against the format descriptions, not against the writer).
#include "test_support.hpp"

#include "skinmesh/mesh_io/mesh_read.hpp"
#include "skinmesh/mesh_io/mesh_write.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <iterator>
#include <sstream>

#include <fstream>

using namespace skinmesh;
using namespace skinmesh::test;

namespace {

SurfaceMesh octahedron() {
  SurfaceMesh m;
  // Coordinates that float cannot hold exactly, to see the precision.
  const double a = 1.0 / 3.0 + 1e-12;
  m.vertices = {{a, 0, 0}, {-a, 0, 0}, {0, a, 0}, {0, -a, 0}, {0, 0, a}, {0, 0, -a}};
  m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (const auto& v : m.vertices) m.normals.push_back(v.normalized());
  m.cells = {0, 1, 2, 3, 4, 5};
  return m;
}

// A torus of n x n quads, each cut in two: a mesh whose files are many
// times the writers' 64 KiB chunks.
SurfaceMesh torus(int n) {
  SurfaceMesh m;
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = 2 * pi * i / n, v = 2 * pi * j / n;
      m.vertices.emplace_back((3 + std::cos(v)) * std::cos(u), (3 + std::cos(v)) * std::sin(u), std::sin(v));
      m.normals.emplace_back(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v));
      m.cells.push_back(i);
    }
  const auto at = [n](int i, int j) { return (i % n) * n + j % n; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

}  // namespace

TEST_CASE("written meshes read back with the same vertices and triangles", "[io]") {
  const SurfaceMesh m = octahedron();
  VertexAttributes attributes;
  attributes.patch = {0, 1, 2, 3, 0, 1};
  attributes.atom = {5, 4, 3, 2, 1, 0};
  for (const char* name : {"m.ply", "m.off", "m.obj", "m.stl", "m.msh"}) {
    INFO(name);
    TempFile file(name);
    {
      std::ofstream out(file.path(), std::ios::binary);
      write_mesh(out, m, mesh_format_from_path(name), &attributes);
    }
    const SurfaceMesh back = read_surface_mesh(file.path());
    REQUIRE(back.vertices.size() == m.vertices.size());
    REQUIRE(back.triangles.size() == m.triangles.size());
    const bool single = std::string(name) == "m.stl";  // STL holds 32-bit floats only
    double worst = 0;
    for (size_t t = 0; t < m.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, (back.vertices[static_cast<size_t>(back.triangles[t][static_cast<size_t>(k)])] -
                                 m.vertices[static_cast<size_t>(m.triangles[t][static_cast<size_t>(k)])])
                                    .norm());
    if (single)
      CHECK(worst < 1e-7);
    else
      CHECK(worst == 0.0);  // full double precision survives the file
  }
  {
    TempFile vert("m.vert");
    const std::string face = vert.path().substr(0, vert.path().size() - 5) + ".face";
    {
      std::ofstream out(vert.path());
      write_msms_vert(out, m, &attributes);
      std::ofstream out_face(face);
      write_msms_face(out_face, m, &attributes);
    }
    const SurfaceMesh back = read_surface_mesh(vert.path());
    // MSMS's columns: the closest atom (1-based) eighth, the face type
    // (1 contact, 2 toric, 3 spheric reentrant) ninth; a face's type fourth.
    const auto data_lines = [](const std::string& path) {
      std::ifstream in(path);
      std::vector<std::vector<std::string>> rows;
      std::string line;
      bool count_seen = false;
      while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        if (!count_seen) {
          count_seen = true;
          continue;
        }
        std::istringstream words(line);
        rows.emplace_back(std::istream_iterator<std::string>(words), std::istream_iterator<std::string>());
      }
      return rows;
    };
    const auto vertex_rows = data_lines(vert.path());
    REQUIRE(vertex_rows.size() == m.vertices.size());
    const int type_of_patch[] = {1, 2, 3, 3};
    for (size_t v = 0; v < vertex_rows.size(); ++v) {
      REQUIRE(vertex_rows[v].size() == 9);
      CHECK(vertex_rows[v][7] == std::to_string(attributes.atom[v] + 1));
      CHECK(vertex_rows[v][8] == std::to_string(type_of_patch[attributes.patch[v]]));
    }
    const auto face_rows = data_lines(face);
    REQUIRE(face_rows.size() == m.triangles.size());
    for (size_t f = 0; f < face_rows.size(); ++f) {
      REQUIRE(face_rows[f].size() == 5);
      CHECK(face_rows[f][3] == std::to_string(type_of_patch[attributes.patch[static_cast<size_t>(m.triangles[f][0])]]));
    }
    std::remove(face.c_str());
    REQUIRE(back.vertices.size() == m.vertices.size());
    CHECK(back.triangles == m.triangles);
    for (size_t v = 0; v < m.vertices.size(); ++v) CHECK(back.vertices[v] == m.vertices[v]);
  }
  {
    // Single precision is a choice: the PLY then holds floats.
    TempFile file("f.ply");
    {
      std::ofstream out(file.path(), std::ios::binary);
      MeshWriteOptions o;
      o.single_precision = true;
      write_mesh(out, m, MeshFormat::ply, &attributes, o);
    }
    const SurfaceMesh back = read_surface_mesh(file.path());
    CHECK(back.vertices[0][0] == static_cast<double>(static_cast<float>(m.vertices[0][0])));
  }
  CHECK_THROWS_AS(mesh_format_from_path("m.xyz"), ContractError);
}

// Numbers in text formats are written by std::to_chars; they must read as
// printf's "%.17g" (or "%.9g" in single precision) reads, which is what the
// formats' earlier stream output was and what the docs promise.
TEST_CASE("text formats write every real as printf's %.17g (or %.9g) would", "[io]") {
  SurfaceMesh m = octahedron();
  const std::vector<double> awkward{0.1, -0.0, 4.9e-324, 1.7976931348623157e308, 123456789.12345679,
                                    -2.5e-7, 1.0 / 3.0, 1e21, 100.0, -7.0, 1e-5, 0.30000000000000004,
                                    6.02214076e23, -1.0 / 7.0, 2.0, 1e16, 123.0, 0.5, 5e-324, 42.0};
  for (size_t k = 0; k < 18; ++k) m.vertices[k / 3][static_cast<long>(k % 3)] = awkward[k];
  m.normals[0] = {awkward[18], awkward[19], awkward[0]};
  const auto printf_text = [](double v, int digits) {
    char text[64];
    std::snprintf(text, sizeof(text), "%.*g", digits, v);
    return std::string(text);
  };
  for (const bool single : {false, true}) {
    const int digits = single ? 9 : 17;
    MeshWriteOptions options;
    options.single_precision = single;
    options.ascii = true;
    for (const MeshFormat format :
         {MeshFormat::ply, MeshFormat::off, MeshFormat::obj, MeshFormat::vtp, MeshFormat::gmsh, MeshFormat::msms}) {
      INFO("format " << static_cast<int>(format) << ", digits " << digits);
      std::ostringstream out;
      if (format == MeshFormat::msms)
        write_msms_vert(out, m, nullptr, options);
      else
        write_mesh(out, m, format, nullptr, options);
      const std::string text = out.str();
      for (const auto& v : m.vertices) {
        // The vertex's three numbers, one space apart, as printf writes them.
        const std::string row =
            printf_text(v[0], digits) + " " + printf_text(v[1], digits) + " " + printf_text(v[2], digits);
        CHECK(text.find(row) != std::string::npos);
      }
      if (format != MeshFormat::off && format != MeshFormat::gmsh) {
        const Eigen::Vector3d& n = m.normals[0];
        const std::string row =
            printf_text(n[0], digits) + " " + printf_text(n[1], digits) + " " + printf_text(n[2], digits);
        CHECK(text.find(row) != std::string::npos);
      }
    }
  }
}

// The writers gather their output and hand it to the stream in chunks: a
// mesh whose files hold many chunks reads back value for value, and the
// VTP's points are the vertices, in order.
TEST_CASE("meshes many times the writers' chunks read back exactly", "[io]") {
  const SurfaceMesh m = torus(120);  // 14,400 vertices, 28,800 triangles
  VertexAttributes attributes;
  for (size_t v = 0; v < m.vertices.size(); ++v) {
    attributes.patch.push_back(static_cast<int>(v % 4));
    attributes.atom.push_back(static_cast<int>(v % 1000));
  }
  for (const bool ascii : {false, true})
    for (const char* name : {"big.ply", "big.off", "big.obj", "big.stl"}) {
      INFO(name << (ascii ? " as text" : ""));
      TempFile file(name);
      MeshWriteOptions options;
      options.ascii = ascii;
      {
        std::ofstream out(file.path(), std::ios::binary);
        write_mesh(out, m, mesh_format_from_path(name), &attributes, options);
      }
      const SurfaceMesh back = read_surface_mesh(file.path());
      REQUIRE(back.triangles.size() == m.triangles.size());
      if (std::string(name) == "big.stl") {  // corners merged where equal, as floats
        CHECK(back.vertices.size() == m.vertices.size());
        continue;
      }
      REQUIRE(back.vertices.size() == m.vertices.size());
      CHECK(back.triangles == m.triangles);
      long differ = 0;
      for (size_t v = 0; v < m.vertices.size(); ++v) differ += back.vertices[v] != m.vertices[v];
      CHECK(differ == 0);
    }
  // VTP as text: the points one a line, in order.
  MeshWriteOptions text_options;
  text_options.ascii = true;
  std::ostringstream out;
  write_mesh(out, m, MeshFormat::vtp, &attributes, text_options);
  const std::string text = out.str();
  const std::string opening = "NumberOfComponents=\"3\" format=\"ascii\">\n";
  const size_t first = text.find(opening);
  REQUIRE(first != std::string::npos);
  std::istringstream points(text.substr(first + opening.size(), text.find("</DataArray>", first) - first - opening.size()));
  long differ = 0, read = 0;
  for (Eigen::Vector3d p; points >> p[0] >> p[1] >> p[2]; ++read)
    differ += static_cast<size_t>(read) >= m.vertices.size() || p != m.vertices[static_cast<size_t>(read)];
  CHECK(read == static_cast<long>(m.vertices.size()));
  CHECK(differ == 0);
  CHECK(text.size() > 16 * 65536);
}

namespace {

// RFC 4648 base64 decoded; throws on a character outside the alphabet.
std::string from_base64(const std::string& code) {
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string bytes;
  unsigned bits = 0;
  int held = 0;
  for (char c : code) {
    if (c == '=' || c == '\n') continue;
    const size_t k = alphabet.find(c);
    if (k == std::string::npos) throw std::runtime_error(std::string("not base64: ") + c);
    bits = (bits << 6) | static_cast<unsigned>(k);
    held += 6;
    if (held >= 8) {
      held -= 8;
      bytes.push_back(static_cast<char>((bits >> held) & 0xff));
    }
  }
  return bytes;
}

// The values of the binary data array named `name` ("" for the points) of
// a VTP file, as the VTK XML format lays them out: base64 of a UInt64 byte
// count followed by the values; checks the array's type name and count.
template <class T>
std::vector<T> vtp_array(const std::string& file, const std::string& name, const std::string& type) {
  const std::string named = name.empty() ? "" : " Name=\"" + name + "\"";
  const std::string opening = "<DataArray type=\"" + type + "\"" + named;
  const size_t at = file.find(opening);
  if (at == std::string::npos) throw std::runtime_error("no array " + opening);
  const size_t begin = file.find(">\n", at) + 2, end = file.find("</DataArray>", begin);
  const std::string bytes = from_base64(file.substr(begin, end - begin));
  uint64_t count = 0;
  std::memcpy(&count, bytes.data(), sizeof count);
  if (count != bytes.size() - sizeof count || count % sizeof(T) != 0) throw std::runtime_error("byte count of " + name);
  std::vector<T> values(count / sizeof(T));
  std::memcpy(values.data(), bytes.data() + sizeof count, count);
  return values;
}

}  // namespace

// The binary VTP read back value for value: points, normals, the vertex
// properties in their types, the triangles and their offsets.
TEST_CASE("a binary VTP holds the mesh's values exactly", "[io]") {
  const SurfaceMesh m = torus(40);
  VertexAttributes attributes;
  std::vector<int> small, big;
  for (size_t v = 0; v < m.vertices.size(); ++v) {
    attributes.patch.push_back(static_cast<int>(v % 4));
    attributes.atom.push_back(static_cast<int>(v % 1000) - 3);
    small.push_back(static_cast<int>(v % 256));
    big.push_back(static_cast<int>(v * 7919));
  }
  attributes.more = {{"flag", PropertyType::uint8, small}, {"serial", PropertyType::uint32, big}};
  for (const bool single : {false, true}) {
    INFO((single ? "single" : "double") << " precision");
    MeshWriteOptions options;
    options.single_precision = single;
    std::ostringstream out;
    write_mesh(out, m, MeshFormat::vtp, &attributes, options);
    const std::string file = out.str();
    CHECK(file.find("format=\"ascii\"") == std::string::npos);
    CHECK(file.find("header_type=\"UInt64\"") != std::string::npos);
    const auto reals = [&](const std::string& name) {
      std::vector<double> values;
      if (single)
        for (float x : vtp_array<float>(file, name, "Float32")) values.push_back(x);
      else
        values = vtp_array<double>(file, name, "Float64");
      return values;
    };
    for (const auto& [name, expected] : {std::pair{std::string(), &m.vertices}, std::pair{std::string("Normals"), &m.normals}}) {
      const std::vector<double> values = reals(name);
      REQUIRE(values.size() == 3 * expected->size());
      long differ = 0;
      for (size_t v = 0; v < expected->size(); ++v)
        for (int k = 0; k < 3; ++k) {
          const double want = single ? static_cast<float>((*expected)[v][k]) : (*expected)[v][k];
          differ += values[3 * v + static_cast<size_t>(k)] != want;
        }
      CHECK(differ == 0);
    }
    CHECK(vtp_array<int32_t>(file, "patch", "Int32") == std::vector<int32_t>(attributes.patch.begin(), attributes.patch.end()));
    CHECK(vtp_array<int32_t>(file, "atom", "Int32") == std::vector<int32_t>(attributes.atom.begin(), attributes.atom.end()));
    CHECK(vtp_array<uint8_t>(file, "flag", "UInt8") == std::vector<uint8_t>(small.begin(), small.end()));
    CHECK(vtp_array<uint32_t>(file, "serial", "UInt32") == std::vector<uint32_t>(big.begin(), big.end()));
    std::vector<int32_t> corners, offsets;
    for (size_t f = 0; f < m.triangles.size(); ++f) {
      for (int v : m.triangles[f]) corners.push_back(v);
      offsets.push_back(static_cast<int32_t>(3 * (f + 1)));
    }
    CHECK(vtp_array<int32_t>(file, "connectivity", "Int32") == corners);
    CHECK(vtp_array<int32_t>(file, "offsets", "Int32") == offsets);
  }
}
