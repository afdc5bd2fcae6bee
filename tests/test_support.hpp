// Shared helpers for the tests: data paths, temporary files, sampling.
#pragma once

#include "skinmesh/core/balls.hpp"

#include <Eigen/Core>

#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <unistd.h>
#include <vector>

namespace skinmesh::test {

inline std::string data_file(const std::string& name) { return std::string(SKINMESH_DATA_DIR) + "/" + name; }
inline std::string shared_pdb(const std::string& name) { return std::string(SKINMESH_SHARED_PDB_DIR) + "/" + name; }

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

}  // namespace skinmesh::test
