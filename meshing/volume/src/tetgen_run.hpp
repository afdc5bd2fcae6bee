// TetGen's library (Debian's libtet1.5-dev) called in memory, private to
// the volume module. TetGen 1.5.0 cannot be called in-process safely when
// it stops on an error: terminatetetgen() frees its mesh and throws, and the
// stack's tetgenmesh frees it again while the exception unwinds (a double
// free that ends the process with SIGSEGV or SIGABRT; reproduced here on two
// interpenetrating tetrahedra, and reported against TetGen by meshpy,
// libigl and pyvista users). So TetGen runs in a forked child of this
// process: the input is the child's copy of the caller's memory, the
// output comes back through a pipe in binary, and an error or a crash of
// TetGen becomes a message, never the end of the caller. No shell, no
// program, no temporary files.
#pragma once

#include "skinmesh/core/tet_mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace skinmesh::detail {

struct Marked {
  Eigen::Vector3d point;
  int region;
};

// What TetGen meshes: a piecewise linear complex of marked triangles, with
// hole points (nothing meshed around them) and region points.
struct Plc {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> facets;
  std::vector<int> markers;  // kFace* per facet
  std::vector<Eigen::Vector3d> holes;
  std::vector<Marked> regions;
};

struct TetgenRun {
  std::string error;  // empty when TetGen finished
  TetMesh mesh;       // its points, tetrahedra (as TetGen orients them), first region attribute, boundary faces
};

// Bounds on TetGen's child: the memory it may take beyond what it starts
// with (its address space), and its run time; 0: none. Past them TetGen
// stops with an error that says which bound.
struct TetgenLimits {
  double max_memory_bytes = 0;
  double max_seconds = 0;
};

// tetrahedralize(switches, plc) (switches without '-', always with z:
// zero-based). With d, the faces are those TetGen found meeting another.
TetgenRun run_tetgen(const Plc& plc, const std::string& switches, const TetgenLimits& limits = {});

}  // namespace skinmesh::detail
