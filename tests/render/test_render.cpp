// Pictures (meshing/render): a sphere's silhouette against its closed form,
// the colours given per vertex where the mesh is drawn, and the PNG's header.
#include "test_support.hpp"

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/render/render.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <sstream>

using namespace skinmesh;

namespace {

SurfaceMesh sphere_mesh(const Eigen::Vector3d& centre, double radius) {
  const SkinMeshResult made = mesh_skin(build_skin_complex({{centre, 2 * radius * radius}}));  // s = 1/2
  REQUIRE(made.status == MeshingStatus::ok);
  return made.mesh;
}

}  // namespace

TEST_CASE("a sphere's picture covers pi r^2 at the scale it was fitted at, centred", "[render]") {
  const SurfaceMesh sphere = sphere_mesh(Eigen::Vector3d(3, -1, 2), 2.0);
  RenderOptions o;
  o.width = o.height = 400;
  o.yaw = o.pitch = 0;  // seen along -z
  const Image image = render_mesh(sphere, o);
  // The outline spans the image less its margins: 360 pixels for 4 A.
  CHECK(image.pixels_per_angstrom == Approx(360.0 / 4.0).epsilon(0.01));
  // The convex mesh's shadow along z: the triangles facing +z, projected.
  double shadow = 0;
  for (const auto& t : sphere.triangles) {
    const Eigen::Vector3d& a = sphere.vertices[static_cast<size_t>(t[0])];
    const double z = (sphere.vertices[static_cast<size_t>(t[1])] - a).cross(sphere.vertices[static_cast<size_t>(t[2])] - a).z() / 2;
    shadow += std::max(0.0, z);
  }
  const double scale2 = image.pixels_per_angstrom * image.pixels_per_angstrom;
  CHECK(static_cast<double>(image.covered) == Approx(shadow * scale2).epsilon(0.01));
  CHECK(static_cast<double>(image.covered) == Approx(M_PI * 4.0 * scale2).epsilon(0.05));  // the disc of radius 2
  // Background in the corners, the sphere's colour (lit) at the centre.
  const auto at = [&](int x, int y) { return image.rgb[static_cast<size_t>((y * image.width + x) * 3)]; };
  CHECK(at(2, 2) == 255);
  CHECK(at(200, 200) < 255);
}

TEST_CASE("per-vertex colours are drawn where their vertices are", "[render]") {
  SurfaceMesh two = sphere_mesh(Eigen::Vector3d(-3, 0, 0), 1.0);
  const size_t left = two.vertices.size();
  const SurfaceMesh right = sphere_mesh(Eigen::Vector3d(3, 0, 0), 1.0);
  for (size_t v = 0; v < right.vertices.size(); ++v) {
    two.vertices.push_back(right.vertices[v]);
    two.normals.push_back(right.normals[v]);
    two.cells.push_back(right.cells[v]);
  }
  for (auto t : right.triangles) two.triangles.push_back({t[0] + static_cast<int>(left), t[1] + static_cast<int>(left), t[2] + static_cast<int>(left)});
  std::vector<Colour> colours(two.vertices.size(), Colour{1, 0, 0});
  for (size_t v = left; v < colours.size(); ++v) colours[v] = Colour{0, 0, 1};
  RenderOptions o;
  o.yaw = o.pitch = 0;
  const Image image = render_mesh(two, o, colours);
  const auto pixel = [&](int x, int y) {
    const size_t i = static_cast<size_t>((y * image.width + x) * 3);
    return std::array<int, 3>{image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]};
  };
  const auto red = pixel(image.width / 6, image.height / 2), blue = pixel(5 * image.width / 6, image.height / 2);
  CHECK(red[0] > 100);
  CHECK(red[2] == 0);
  CHECK(blue[2] > 100);
  CHECK(blue[0] == 0);
  CHECK_THROWS_AS(render_mesh(two, o, std::vector<Colour>(3)), ContractError);
}

TEST_CASE("the PNG has the signature and the image's size", "[render]") {
  Image image;
  image.width = 3;
  image.height = 2;
  image.rgb.assign(18, 128);
  std::ostringstream out;
  write_png(out, image);
  const std::string png = out.str();
  REQUIRE(png.size() > 33);
  CHECK(png.substr(0, 8) == std::string("\x89PNG\r\n\x1a\n", 8));
  CHECK(png.substr(12, 4) == "IHDR");
  const auto be32 = [&](size_t at) {
    return (static_cast<unsigned char>(png[at]) << 24) | (static_cast<unsigned char>(png[at + 1]) << 16) |
           (static_cast<unsigned char>(png[at + 2]) << 8) | static_cast<unsigned char>(png[at + 3]);
  };
  CHECK(be32(16) == 3u);
  CHECK(be32(20) == 2u);
}
