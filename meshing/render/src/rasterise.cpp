#include "skinmesh/core/error.hpp"
#include "skinmesh/render/render.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace skinmesh {
namespace {

constexpr int kSamples = 2;  // supersampling per axis: edges drawn at twice the resolution and averaged

// Per vertex: the mesh's normal, or the area-weighted mean of its triangles'.
std::vector<Eigen::Vector3d> vertex_normals(const SurfaceMesh& mesh) {
  if (mesh.normals.size() == mesh.vertices.size()) return mesh.normals;
  std::vector<Eigen::Vector3d> n(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[static_cast<size_t>(t[0])];
    const Eigen::Vector3d face = (mesh.vertices[static_cast<size_t>(t[1])] - a).cross(mesh.vertices[static_cast<size_t>(t[2])] - a);
    for (int v : t) n[static_cast<size_t>(v)] += face;
  }
  for (auto& v : n) v.normalize();
  return n;
}

struct Frame {  // the view: rotation, then the fit of the mesh's outline to the canvas
  Eigen::Matrix3d turn;
  Eigen::Vector2d centre;
  double scale = 1;  // canvas pixels per Angstrom
  int width = 0, height = 0;
  Eigen::Vector3d screen(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d q = turn * p;
    return {width / 2.0 + (q.x() - centre.x()) * scale, height / 2.0 - (q.y() - centre.y()) * scale, q.z()};
  }
};

Eigen::Matrix3d turn_of(const RenderOptions& o) {
  const double yaw = o.yaw * M_PI / 180, pitch = o.pitch * M_PI / 180;
  return (Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()))
      .toRotationMatrix();
}

Frame fit(const SurfaceMesh& mesh, const RenderOptions& o) {
  const ViewFit v = o.fit ? *o.fit : fit_view({&mesh}, o);
  Frame f;
  f.turn = turn_of(o);
  f.width = o.width * kSamples;
  f.height = o.height * kSamples;
  f.centre = {v.centre_x, v.centre_y};
  f.scale = v.pixels_per_angstrom * kSamples;
  return f;
}

// Lambert with an ambient term and a little specular light, for a unit
// normal in view coordinates (z towards the viewer).
float shade(const Eigen::Vector3d& n) {
  static const Eigen::Vector3d light = Eigen::Vector3d(-0.4, 0.5, 0.77).normalized();
  static const Eigen::Vector3d half = (light + Eigen::Vector3d::UnitZ()).normalized();
  const double diffuse = std::max(0.0, n.dot(light));
  const double specular = std::pow(std::max(0.0, n.dot(half)), 40.0);
  return static_cast<float>(0.28 + 0.72 * diffuse + 0.18 * specular);
}

}  // namespace

ViewFit fit_view(const std::vector<const SurfaceMesh*>& meshes, const RenderOptions& o) {
  const Eigen::Matrix3d turn = turn_of(o);
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const SurfaceMesh* mesh : meshes)
    for (const auto& p : mesh->vertices) {
      const Eigen::Vector3d q = turn * p;
      lo = lo.cwiseMin(q.head<2>());
      hi = hi.cwiseMax(q.head<2>());
    }
  if (lo.x() > hi.x()) contract_error("fit_view: no vertices to frame");
  const double margin = o.margin * std::min(o.width, o.height);
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(1e-9);
  const Eigen::Vector2d centre = (lo + hi) / 2;
  return {centre.x(), centre.y(), std::min((o.width - 2 * margin) / extent.x(), (o.height - 2 * margin) / extent.y())};
}

Image render_mesh(const SurfaceMesh& mesh, const RenderOptions& o, const std::vector<Colour>& colours) {
  if (o.width < 1 || o.height < 1 || o.width > 16384 || o.height > 16384)
    contract_error("render_mesh: the image must be 1 to 16384 pixels a side");
  if (!colours.empty() && colours.size() != mesh.vertices.size())
    contract_error("render_mesh: one colour per vertex, or none");
  const Frame f = fit(mesh, o);
  const std::vector<Eigen::Vector3d> normals = vertex_normals(mesh);
  const size_t canvas = static_cast<size_t>(f.width) * static_cast<size_t>(f.height);
  std::vector<float> depth(canvas, -std::numeric_limits<float>::infinity());
  std::vector<Colour> pixel(canvas, o.background);
  std::vector<char> hit(canvas, 0);
  for (const auto& t : mesh.triangles) {
    std::array<Eigen::Vector3d, 3> s;
    for (int k = 0; k < 3; ++k) s[static_cast<size_t>(k)] = f.screen(mesh.vertices[static_cast<size_t>(t[static_cast<size_t>(k)])]);
    const double area = (s[1].x() - s[0].x()) * (s[2].y() - s[0].y()) - (s[2].x() - s[0].x()) * (s[1].y() - s[0].y());
    if (std::abs(area) < 1e-12) continue;
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({s[0].x(), s[1].x(), s[2].x()}))));
    const int x1 = std::min(f.width - 1, static_cast<int>(std::ceil(std::max({s[0].x(), s[1].x(), s[2].x()}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({s[0].y(), s[1].y(), s[2].y()}))));
    const int y1 = std::min(f.height - 1, static_cast<int>(std::ceil(std::max({s[0].y(), s[1].y(), s[2].y()}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        const double w0 = ((s[1].x() - px) * (s[2].y() - py) - (s[2].x() - px) * (s[1].y() - py)) / area;
        const double w1 = ((s[2].x() - px) * (s[0].y() - py) - (s[0].x() - px) * (s[2].y() - py)) / area;
        const double w2 = 1 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        const float z = static_cast<float>(w0 * s[0].z() + w1 * s[1].z() + w2 * s[2].z());
        const size_t at = static_cast<size_t>(y) * static_cast<size_t>(f.width) + static_cast<size_t>(x);
        if (z <= depth[at]) continue;
        depth[at] = z;
        hit[at] = 1;
        const std::array<double, 3> w{w0, w1, w2};
        Eigen::Vector3d n = Eigen::Vector3d::Zero();
        Colour c{0, 0, 0};
        for (size_t k = 0; k < 3; ++k) {
          const size_t v = static_cast<size_t>(t[k]);
          n += w[k] * normals[v];
          const Colour& cv = colours.empty() ? o.colour : colours[v];
          for (size_t i = 0; i < 3; ++i) c[i] += static_cast<float>(w[k]) * cv[i];
        }
        const float light = shade((f.turn * n).normalized());
        for (size_t i = 0; i < 3; ++i) pixel[at][i] = std::min(1.0f, c[i] * light);
      }
  }
  Image image;
  image.width = o.width;
  image.height = o.height;
  image.pixels_per_angstrom = f.scale / kSamples;
  image.rgb.resize(static_cast<size_t>(o.width) * static_cast<size_t>(o.height) * 3);
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x) {
      Colour sum{0, 0, 0};
      int covered = 0;
      for (int dy = 0; dy < kSamples; ++dy)
        for (int dx = 0; dx < kSamples; ++dx) {
          const size_t at = static_cast<size_t>(y * kSamples + dy) * static_cast<size_t>(f.width) +
                            static_cast<size_t>(x * kSamples + dx);
          covered += hit[at];
          for (size_t i = 0; i < 3; ++i) sum[i] += pixel[at][i];
        }
      image.covered += covered * 2 >= kSamples * kSamples;
      for (size_t i = 0; i < 3; ++i)
        image.rgb[(static_cast<size_t>(y) * static_cast<size_t>(o.width) + static_cast<size_t>(x)) * 3 + i] =
            static_cast<std::uint8_t>(std::lround(255 * sum[i] / (kSamples * kSamples)));
    }
  return image;
}

}  // namespace skinmesh
