// Shared helpers for the tests: data paths, temporary files, sampling.
#pragma once

#include "skinmesh/core/balls.hpp"
#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/surface_mesh.hpp"

#include <Eigen/Core>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <unistd.h>
#include <vector>

namespace skinmesh::test {

inline std::string data_file(const std::string& name) { return std::string(SKINMESH_DATA_DIR) + "/" + name; }

// A file in a fresh temporary directory, removed with the object.
class TempFile {
 public:
  explicit TempFile(const std::string& name, const std::string& contents = "") {
    char pattern[] = "/tmp/skinmesh-test-XXXXXX";
    dir_ = mkdtemp(pattern);
    path_ = dir_ + "/" + name;
    std::ofstream(path_, std::ios::binary) << contents;
  }
  ~TempFile() {
    std::remove(path_.c_str());
    ::rmdir(dir_.c_str());
  }
  const std::string& path() const { return path_; }

 private:
  std::string dir_, path_;
};

// Points near the skin without using the skin: a random ball, a random
// direction, at the ball's own skin radius sqrt(s w) plus up to +-`spread` A.
// Many land inside the body (buried cells), many in the shell around it.
inline std::vector<Eigen::Vector3d> sample_near_balls(const std::vector<Ball>& balls, double s, int count,
                                                      double spread, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<size_t> pick(0, balls.size() - 1);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> offset(-spread, spread);
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<size_t>(count));
  while (static_cast<int>(points.size()) < count) {
    const Ball& b = balls[pick(rng)];
    Eigen::Vector3d u(normal(rng), normal(rng), normal(rng));
    if (u.norm() < 1e-9) continue;
    const double r = std::sqrt(std::max(0.0, s * b.weight)) + offset(rng);
    points.push_back(b.center + u.normalized() * std::abs(r));
  }
  return points;
}

// Model `model` of a molecule file as balls (w = r^2/s, s = 1/2), centred.
inline std::vector<Ball> centred_model(const std::string& path, int model) {
  ReadOptions read;
  read.model = model;
  std::vector<Ball> balls = balls_from_molecule(read_molecule(path, read), 0.5);
  centre_balls(balls);
  return balls;
}

// How many failing triangles a morph step's patch was allowed (its local
// share) when the step was remeshed whole for having more, from
// FrameStats::remeshed_because ("... the local share (S)"); -1 when it was
// not remeshed for that.
inline long remeshed_for_share(const std::string& because) {
  const std::string marker = "the local share (";
  const size_t open = because.find(marker);
  return open == std::string::npos ? -1L : std::stol(because.substr(open + marker.size()));
}

// The exact B(1/2) of two ball sets, live pairs only (docs/math.md section 4).
inline std::vector<Ball> midway(const std::vector<Ball>& a, const std::vector<Ball>& b) {
  return interpolated_balls(a, b, live_pairs(a, b), 0.5);
}

// Equal balls (lone skin radius 1.5 A at s = 1/2) in cospherical and coplanar
// arrangements: a cube's corners, a square, a regular hexagon with two on its
// axis, a regular octahedron. The square's half side is 1.4 A, not 1.5: at
// 1.5 its centre is exactly where the skin pinches (the square's orthogonal
// ball has size w - 2 * 1.5^2 = 0), a topology that 1e-9 A of jitter decides
// either way, and CGAL's reference mesh did differently under clang -O1
// than under GCC; 1.4 leaves a disc of skin across each face.
inline std::vector<std::pair<std::string, std::vector<Ball>>> symmetric_ball_sets() {
  const double w = 1.5 * 1.5 / 0.5, h = 1.4;
  std::vector<Ball> cube, square, hexagon, octahedron;
  for (int i = 0; i < 8; ++i) cube.push_back({Eigen::Vector3d(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h), w});
  for (int i = 0; i < 4; ++i) square.push_back({Eigen::Vector3d(i & 1 ? h : -h, i & 2 ? h : -h, 0), w});
  for (int i = 0; i < 6; ++i) hexagon.push_back({Eigen::Vector3d(2.5 * std::cos(i * M_PI / 3), 2.5 * std::sin(i * M_PI / 3), 0), w});
  hexagon.push_back({Eigen::Vector3d(0, 0, 1.8), w});
  hexagon.push_back({Eigen::Vector3d(0, 0, -1.8), w});
  for (int k = 0; k < 3; ++k)
    for (int sign = -1; sign <= 1; sign += 2) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      p[k] = 2.2 * sign;
      octahedron.push_back({p, w});
    }
  return {{"cube", cube}, {"square", square}, {"hexagon with two on its axis", hexagon}, {"octahedron", octahedron}};
}

// Two closed unit tetrahedra, the second shifted 0.2 A along (1,1,1) into
// the first: a closed oriented manifold that intersects itself.
inline SurfaceMesh two_interpenetrating_tetrahedra() {
  SurfaceMesh two;
  for (const Eigen::Vector3d& shift : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.2, 0.2, 0.2)}) {
    const int base = static_cast<int>(two.vertices.size());
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0),
                                     Eigen::Vector3d(0, 0, 1)})
      two.vertices.push_back(p + shift);
    for (const std::array<int, 3>& t : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}})
      two.triangles.push_back({base + t[0], base + t[1], base + t[2]});
  }
  return two;
}

// `copies` closed unit-edge tetrahedra, oriented outward, their centres
// drawn (seeded) in a cube of side `side` A: a closed oriented manifold (by
// index) whose triangles, when the cube is small, nearly all cross each
// other, so that its self-intersecting pairs grow as the square of its size.
inline SurfaceMesh pile_of_tetrahedra(int copies, double side, unsigned seed) {
  SurfaceMesh pile;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> at(0, side);
  const double h = 0.5 / std::sqrt(2.0);
  for (int i = 0; i < copies; ++i) {
    const Eigen::Vector3d c(at(random), at(random), at(random));
    const int base = static_cast<int>(pile.vertices.size());
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(h, h, h), Eigen::Vector3d(h, -h, -h), Eigen::Vector3d(-h, h, -h),
                                     Eigen::Vector3d(-h, -h, h)})
      pile.vertices.push_back(c + p);
    for (const std::array<int, 3>& t : {std::array<int, 3>{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}})
      pile.triangles.push_back({base + t[0], base + t[1], base + t[2]});
  }
  return pile;
}

}  // namespace skinmesh::test
