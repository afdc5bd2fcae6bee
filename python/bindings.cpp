// skinmesh for Python (pybind11): molecules or balls in, numpy arrays out
// (docs/python.md). Vertices are (n, 3) float64 arrays that take over the
// library's memory without a copy; triangles (m, 3) int64; per-vertex
// attributes a dict of arrays; reports dicts (the JSON the command writes).
// Long calls release the GIL; errors are Python exceptions, InputError
// keeping the file and the line.
#include "morph_frames.hpp"
#include "output_file.hpp"
#include "quality_report.hpp"

#include "skinmesh/core/error.hpp"
#include "skinmesh/core/interpolation.hpp"
#include "skinmesh/core/molecule.hpp"
#include "skinmesh/core/skin_complex.hpp"
#include "skinmesh/core/skin_topology.hpp"
#include "skinmesh/core/stopwatch.hpp"
#include "skinmesh/mesher/skin_mesher.hpp"
#include "skinmesh/morph/alignment.hpp"
#include "skinmesh/morph/matched_motion.hpp"
#include "skinmesh/morph/morph.hpp"
#include "skinmesh/morph/moving_balls.hpp"
#include "skinmesh/mesh_io/mesh_write.hpp"
#include "skinmesh/quality/guarantees.hpp"
#include "skinmesh/quality/mesh_quality.hpp"
#include "skinmesh/volume/volume_mesh.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace py = pybind11;
using namespace skinmesh;

namespace {

// ---- arrays ----------------------------------------------------------------

// The vertices handed over to numpy: the vector moves into a capsule that
// numpy frees with the array (Eigen::Vector3d is three packed doubles).
py::array_t<double> vertex_array(std::vector<Eigen::Vector3d> points) {
  auto* held = new std::vector<Eigen::Vector3d>(std::move(points));
  const py::capsule owner(held, [](void* p) { delete static_cast<std::vector<Eigen::Vector3d>*>(p); });
  const auto n = static_cast<py::ssize_t>(held->size());
  return py::array_t<double>({n, py::ssize_t{3}}, {py::ssize_t{3 * sizeof(double)}, py::ssize_t{sizeof(double)}},
                             held->empty() ? nullptr : held->front().data(), owner);
}

py::array_t<std::int64_t> triangle_array(const std::vector<std::array<int, 3>>& triangles) {
  py::array_t<std::int64_t> out({static_cast<py::ssize_t>(triangles.size()), py::ssize_t{3}});
  auto view = out.mutable_unchecked<2>();
  for (size_t f = 0; f < triangles.size(); ++f)
    for (size_t k = 0; k < 3; ++k) view(static_cast<py::ssize_t>(f), static_cast<py::ssize_t>(k)) = triangles[f][k];
  return out;
}

template <class T, class Out = T>
py::array_t<Out> array_of(const std::vector<T>& values) {
  py::array_t<Out> out(static_cast<py::ssize_t>(values.size()));
  auto view = out.template mutable_unchecked<1>();
  for (size_t i = 0; i < values.size(); ++i) view(static_cast<py::ssize_t>(i)) = static_cast<Out>(values[i]);
  return out;
}

std::vector<Eigen::Vector3d> points_from(const py::array_t<double, py::array::c_style | py::array::forcecast>& a,
                                         const char* what) {
  if (a.ndim() != 2 || a.shape(1) != 3) throw py::value_error(std::string(what) + " must be an (n, 3) array");
  std::vector<Eigen::Vector3d> out(static_cast<size_t>(a.shape(0)));
  const auto view = a.unchecked<2>();
  for (py::ssize_t i = 0; i < a.shape(0); ++i) out[static_cast<size_t>(i)] = {view(i, 0), view(i, 1), view(i, 2)};
  return out;
}

SurfaceMesh mesh_from(const py::array_t<double, py::array::c_style | py::array::forcecast>& vertices,
                      const py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>& triangles) {
  SurfaceMesh mesh;
  mesh.vertices = points_from(vertices, "vertices");
  if (triangles.ndim() != 2 || triangles.shape(1) != 3) throw py::value_error("triangles must be an (m, 3) array");
  const auto view = triangles.unchecked<2>();
  for (py::ssize_t f = 0; f < triangles.shape(0); ++f) {
    std::array<int, 3> t{};
    for (py::ssize_t k = 0; k < 3; ++k) {
      const std::int64_t v = view(f, k);
      if (v < 0 || v >= static_cast<std::int64_t>(mesh.vertices.size()))
        throw py::value_error("triangle " + std::to_string(f) + " uses vertex " + std::to_string(v) +
                              ", not one of the " + std::to_string(mesh.vertices.size()));
      t[static_cast<size_t>(k)] = static_cast<int>(v);
    }
    mesh.triangles.push_back(t);
  }
  return mesh;
}

py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

// ---- options ---------------------------------------------------------------

// Keyword options with the command line's names (dashes as underscores)
// and defaults; an unknown name is an error, as on the command line.
struct Options {
  py::dict given;
  std::vector<std::string> used;
  template <class T>
  T get(const char* name, T fallback) {
    used.emplace_back(name);
    return given.contains(name) ? given[name].cast<T>() : fallback;
  }
  void finish() const {
    for (const auto& item : given) {
      const std::string key = item.first.cast<std::string>();
      if (std::find(used.begin(), used.end(), key) == used.end()) throw py::type_error("unknown option '" + key + "'");
    }
  }
};

struct BallSource {
  std::vector<Ball> balls;
  std::optional<Molecule> molecule;  // when read from a file
};

WeightConvention convention_of(const std::string& weights) {
  if (weights == "grow") return WeightConvention::GrowBySkin;
  if (weights == "raw") return WeightConvention::Raw;
  throw py::value_error("weights must be 'grow' or 'raw', not '" + weights + "'");
}

// A path, or a tuple (centres (n, 3), radii (n,)).
BallSource balls_from(const py::object& source, Options& o, double shrink) {
  const WeightConvention convention = convention_of(o.get<std::string>("weights", "grow"));
  BallSource out;
  if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__")) {
    ReadOptions read;
    read.model = o.get<int>("model", 1);
    read.keep_hydrogens = o.get<bool>("keep_hydrogens", false);
    read.keep_waters = o.get<bool>("keep_waters", false);
    read.chains = o.get<std::vector<std::string>>("chain", {});
    read.unknown_radius = o.get<double>("unknown_radius", read.unknown_radius);
    const std::string path = py::str(py::module_::import("os").attr("fspath")(source));
    out.molecule = read_molecule(path, read);
    if (out.molecule->atoms.empty()) input_error(path, 0, "no atoms left to mesh");
    out.balls = balls_from_molecule(*out.molecule, shrink, convention);
    return out;
  }
  const auto pair = source.cast<py::tuple>();
  if (pair.size() != 2) throw py::value_error("source must be a path or a tuple (centres, radii)");
  const std::vector<Eigen::Vector3d> centres = points_from(pair[0].cast<py::array_t<double, py::array::c_style | py::array::forcecast>>(), "centres");
  const auto radii = pair[1].cast<py::array_t<double, py::array::c_style | py::array::forcecast>>();
  if (radii.ndim() != 1 || static_cast<size_t>(radii.shape(0)) != centres.size())
    throw py::value_error("radii must be an (n,) array, one per centre");
  for (size_t i = 0; i < centres.size(); ++i) {
    const double r = radii.at(static_cast<py::ssize_t>(i));
    out.balls.push_back({centres[i], convention == WeightConvention::GrowBySkin ? r * r / shrink : r * r});
  }
  return out;
}

MeshingOptions meshing_options(Options& o, double default_angle) {
  MeshingOptions m;
  m.min_angle = o.get<double>("min_angle", default_angle);
  m.sizing.epsilon = o.get<double>("epsilon", m.sizing.epsilon);
  m.edge_length = o.get<double>("edge_length", 0.0);
  m.tolerance = o.get<double>("tolerance", m.tolerance);
  m.max_triangles = o.get<long>("max_triangles", m.max_triangles);
  m.threads = o.get<int>("threads", 0);
  return m;
}

// A Python callable as the mesher's progress callback, called with the
// stage, the vertices so far and the expected count (the GIL taken back).
std::function<void(const MeshingProgress&)> progress_from(const py::object& progress) {
  if (progress.is_none()) return {};
  return [progress](const MeshingProgress& p) {
    py::gil_scoped_acquire gil;
    progress(std::string(p.stage), p.vertices, p.expected_vertices);
  };
}

// ---- results ---------------------------------------------------------------

struct MeshResult {
  py::array_t<double> vertices;
  py::array_t<std::int64_t> triangles;
  py::dict attributes;
  py::object report;
};

struct Frame {
  py::array_t<double> vertices;
  py::array_t<std::int64_t> triangles;
  py::array_t<std::int64_t> ids;
  py::dict attributes;
  py::object report;
};

nlohmann::json stats_json(const FrameStats& s) {
  return {{"t", s.t},
          {"vertices", s.vertices},
          {"triangles", s.triangles},
          {"moved", s.moved},
          {"relocated", s.relocated},
          {"inserted", s.inserted},
          {"removed", s.removed},
          {"steps", s.steps},
          {"steps_built_ahead", s.built_ahead},
          {"reidentified", s.reidentified},
          {"settled", s.settled},
          {"carried", s.carried},
          {"ids_kept", s.ids_kept},
          {"max_kept_move", s.max_kept_move},
          {"repaired", s.repaired},
          {"remeshed", s.remeshed},
          {"remeshed_because", s.remeshed_because},
          {"full_rebuild", s.full_rebuild},
          {"topology_certified", s.topology_certified},
          {"seconds", s.seconds}};
}

// A frame: mesh arrays, ids, per-vertex atoms, and its stats and grade.
Frame frame_of(const MorphFrame& f, const std::vector<int>& atom, const std::vector<int>& patch, double min_angle,
               const std::vector<Ball>* balls, double shrink) {
  Frame out;
  out.triangles = triangle_array(f.mesh.triangles);
  out.ids = array_of<long, std::int64_t>(f.ids);
  out.attributes["atom"] = array_of<int, std::int64_t>(atom);
  out.attributes["patch"] = array_of<int, std::int64_t>(patch);
  out.attributes["normals"] = vertex_array(f.mesh.normals);
  nlohmann::json report = stats_json(f.stats);
  if (balls) {
    GuaranteeOptions bounds;
    bounds.min_angle = min_angle;
    bounds.on_skin_tolerance = 1e-8;
    const GuaranteeReport g = check_guarantees(f.mesh, *balls, shrink, bounds);
    report["quality"] = app::to_json(g.quality);
    report["on_surface_error"] = app::to_json(g.surface_error);
    report["guarantees"] = {
        {"min_angle_at_least_bound", g.angle},
        {"vertices_on_skin", g.on_skin},
        {"on_skin_tolerance", bounds.on_skin_tolerance},
        {"closed_oriented_manifold", g.closed_oriented_manifold},
        {"no_self_intersections", g.no_self_intersections.value_or(false)},
        {"topology", g.topology.value_or(false)}};
  }
  out.vertices = vertex_array(f.mesh.vertices);
  out.report = json_to_python(report);
  return out;
}

// ---- calls -----------------------------------------------------------------

std::string json_source(const py::object& source) {
  return py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>();
}

MeshResult mesh(const py::object& source, const py::kwargs& kwargs) {
  Options o{kwargs.cast<py::dict>(), {}};
  const double shrink = o.get<double>("shrink", 0.5);
  BallSource in = balls_from(source, o, shrink);
  MeshingOptions m = meshing_options(o, 30.0);
  const bool self_intersections = !o.get<bool>("no_self_intersections", false);
  const bool outer_only = o.get<bool>("outer_only", false);
  const py::object progress = o.get<py::object>("progress", py::none());
  o.finish();
  m.progress = progress_from(progress);
  SkinMeshResult made;
  GuaranteeReport g;
  SkinArea area;
  size_t dropped = 0;
  std::vector<int> atom, patch;
  nlohmann::json seconds;
  {
    py::gil_scoped_release release;
    const auto start = Clock::now();
    const SkinComplex complex = build_skin_complex(in.balls, {shrink});
    seconds["complex"] = seconds_since(start);
    made = mesh_skin(complex, m);
    seconds["meshing"] = made.stats.seconds_total;
    if (made.status == MeshingStatus::ok && outer_only) {
      const size_t before = surface_components(made.mesh).enclosed_volume.size();
      made.mesh = outer_surface(made.mesh);
      dropped = before - surface_components(made.mesh).enclosed_volume.size();
    }
    if (made.status == MeshingStatus::ok) {
      GuaranteeOptions bounds;
      bounds.min_angle = m.min_angle;
      bounds.self_intersections = self_intersections ? SelfIntersectionCheck::exact : SelfIntersectionCheck::skip;
      bounds.topology = !outer_only;  // the voids' surfaces are dropped: not the skin's topology
      g = check_guarantees(made.mesh, in.balls, shrink, bounds);
      area = skin_area(complex, made.mesh);
      for (size_t v = 0; v < made.mesh.vertices.size(); ++v) {
        patch.push_back(complex.cell(made.mesh.cells[v]).dim);
        atom.push_back(complex.owning_ball(made.mesh.vertices[v], made.mesh.cells[v]));
      }
    }
  }
  if (made.status == MeshingStatus::empty_skin) throw py::value_error(made.message);
  if (made.status != MeshingStatus::ok) throw std::runtime_error(made.message);
  if (!g.all_hold()) throw std::runtime_error("the mesh fails a guarantee: " + app::guarantees_json(g).dump());
  nlohmann::json report = {{"skinmesh_version", SKINMESH_VERSION},
                           {"molecule", in.molecule ? nlohmann::json(json_source(source)) : nlohmann::json(nullptr)},
                           {"atoms", in.balls.size()},
                           {"shrink", shrink},
                           {"weights", convention_name(convention_of(o.get<std::string>("weights", "grow")))},
                           {"options", app::options_json(m)},
                           {"refinement", app::refinement_json(made.stats)},
                           {"estimated_triangles", std::llround(made.estimated_triangles)},
                           {"quality", app::to_json(g.quality)},
                           {"outer_only", outer_only},
                           {"components_dropped", dropped},
                           {"skin_area", app::skin_area_json(area, g.quality.area)},
                           {"on_surface_error", app::to_json(g.surface_error)},
                           {"guarantees", app::guarantees_json(g)},
                           {"seconds", seconds}};
  MeshResult out;
  out.triangles = triangle_array(made.mesh.triangles);
  out.attributes["atom"] = array_of<int, std::int64_t>(atom);
  out.attributes["patch"] = array_of<int, std::int64_t>(patch);
  out.attributes["normals"] = vertex_array(std::move(made.mesh.normals));
  out.vertices = vertex_array(std::move(made.mesh.vertices));
  out.report = json_to_python(report);
  return out;
}

py::object grade(const py::array_t<double, py::array::c_style | py::array::forcecast>& vertices,
                 const py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>& triangles) {
  const SurfaceMesh m = mesh_from(vertices, triangles);
  MeshQuality q;
  {
    py::gil_scoped_release release;
    q = grade_mesh(m);
  }
  return json_to_python(app::to_json(q));
}

// The mixed complex of a molecule or ball set: its counts and topology.
py::dict complex_counts(const py::object& source, const py::kwargs& kwargs) {
  Options o{kwargs.cast<py::dict>(), {}};
  const double shrink = o.get<double>("shrink", 0.5);
  const BallSource in = balls_from(source, o, shrink);
  o.finish();
  std::array<long, 4> counts{};
  SkinTopology topology;
  size_t hidden = 0;
  {
    py::gil_scoped_release release;
    const SkinComplex complex = build_skin_complex(in.balls, {shrink});
    counts = complex.cell_counts();
    hidden = complex.hidden_balls().size();
    topology = skin_topology(in.balls);
  }
  py::dict out;
  out["balls"] = in.balls.size();
  out["hidden_balls"] = hidden;
  out["cells"] = py::make_tuple(counts[0], counts[1], counts[2], counts[3]);
  out["components"] = topology.components;
  out["voids"] = topology.voids;
  out["euler"] = topology.euler;
  return out;
}

// The balls of B(t) of a morph (docs/math.md section 4): the live pairs', or all m x n.
py::tuple interpolate(const py::object& source, const py::object& target, double t, const py::kwargs& kwargs) {
  Options o{kwargs.cast<py::dict>(), {}};
  const double shrink = o.get<double>("shrink", 0.5);
  const bool all = o.get<bool>("all_pairs", false);
  Options for_target{o.given, o.used};
  const BallSource a = balls_from(source, o, shrink), b = balls_from(target, for_target, shrink);
  o.finish();
  if (!(t >= 0 && t <= 1)) throw py::value_error("t must lie in [0, 1]");
  std::vector<Ball> balls;
  {
    py::gil_scoped_release release;
    balls = interpolated_balls(a.balls, b.balls, all ? all_pairs(a.balls.size(), b.balls.size()) : live_pairs(a.balls, b.balls), t);
  }
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> weights;
  for (const Ball& ball : balls) {
    centres.push_back(ball.center);
    weights.push_back(ball.weight);
  }
  return py::make_tuple(vertex_array(std::move(centres)), array_of<double>(weights));
}

struct VolumeResult {
  py::array_t<double> points;
  py::array_t<std::int64_t> tetrahedra, faces;
  py::array_t<std::int64_t> tetrahedron_region, face_marker;
};

// A tetrahedral mesh bounded by the skin mesh (TetGen; `skinmesh volume`).
VolumeResult volume(const py::object& source, const py::kwargs& kwargs) {
  Options o{kwargs.cast<py::dict>(), {}};
  const double shrink = o.get<double>("shrink", 0.5);
  const BallSource in = balls_from(source, o, shrink);
  MeshingOptions m = meshing_options(o, 30.0);
  VolumeOptions v;
  const std::string domain = o.get<std::string>("domain", "interior");
  if (domain != "interior" && domain != "exterior" && domain != "both")
    throw py::value_error("domain must be interior, exterior or both");
  v.domain = domain == "interior" ? VolumeDomain::interior : domain == "exterior" ? VolumeDomain::exterior : VolumeDomain::both;
  v.box_margin = o.get<double>("box_margin", v.box_margin);
  v.max_volume = o.get<double>("max_volume", 0.0);
  v.cavities = o.get<bool>("drop_cavities", false) ? Cavities::fill : Cavities::keep;
  const py::object progress = o.get<py::object>("progress", py::none());
  o.finish();
  m.progress = progress_from(progress);
  VolumeMeshResult made;
  {
    py::gil_scoped_release release;
    const SkinMeshResult surface = mesh_skin(build_skin_complex(in.balls, {shrink}), m);
    if (surface.status != MeshingStatus::ok) throw std::runtime_error(surface.message);
    made = tetrahedralize(surface.mesh, v);
  }
  if (made.status != VolumeStatus::ok) throw std::runtime_error(made.message);
  VolumeResult out;
  out.points = vertex_array(std::move(made.mesh.points));
  py::array_t<std::int64_t> tets({static_cast<py::ssize_t>(made.mesh.tets.size()), py::ssize_t{4}});
  auto view = tets.mutable_unchecked<2>();
  for (size_t k = 0; k < made.mesh.tets.size(); ++k)
    for (size_t j = 0; j < 4; ++j) view(static_cast<py::ssize_t>(k), static_cast<py::ssize_t>(j)) = made.mesh.tets[k][j];
  out.tetrahedra = tets;
  out.faces = triangle_array(made.mesh.faces);
  out.tetrahedron_region = array_of<int, std::int64_t>(made.mesh.tet_region);
  out.face_marker = array_of<int, std::int64_t>(made.mesh.face_marker);
  return out;
}

// Moving balls fed centres call by call (morph/moving_balls.hpp): the first
// call meshes, every later one carries the mesh on.
class PyMovingBalls {
 public:
  PyMovingBalls(const py::array_t<double, py::array::c_style | py::array::forcecast>& radii, const py::kwargs& kwargs) {
    Options o{kwargs.cast<py::dict>(), {}};
    options_.shrink = o.get<double>("shrink", 0.5);
    const WeightConvention convention = convention_of(o.get<std::string>("weights", "grow"));
    options_.first = meshing_options(o, 30.0);
    options_.frames = options_.first;
    options_.frames.min_angle = std::min(options_.first.min_angle, 20.0);
    options_.first.min_angle = 30.0;
    options_.max_step = o.get<double>("max_step", options_.max_step);
    options_.first.progress = progress_from(o.get<py::object>("progress", py::none()));  // the first frame's mesh
    check_ = o.get<bool>("check", true);
    o.finish();
    if (radii.ndim() != 1) throw py::value_error("radii must be an (n,) array");
    for (py::ssize_t i = 0; i < radii.shape(0); ++i) {
      const double r = radii.at(i);
      weights_.push_back(convention == WeightConvention::GrowBySkin ? r * r / options_.shrink : r * r);
    }
  }
  // `next`: the centres the call after this one will pass, or None
  // (MovingBalls::advance_to builds that call's first complex beside this
  // call's repair; the frames are the same).
  Frame advance_to(const py::array_t<double, py::array::c_style | py::array::forcecast>& centres, double t,
                   const py::object& next) {
    std::vector<Ball> balls = balls_at(centres, "centres");
    std::vector<Ball> ahead;
    if (!next.is_none())
      ahead = balls_at(next.cast<py::array_t<double, py::array::c_style | py::array::forcecast>>(), "next");
    std::vector<int> atom, patch;
    {
      py::gil_scoped_release release;
      if (!engine_) engine_ = std::make_unique<MovingBalls>(std::move(balls), options_, t);
      else engine_->advance_to(std::move(balls), t, std::move(ahead));
      atom = engine_->vertex_balls();
      for (int c : engine_->frame().mesh.cells) patch.push_back(engine_->complex().cell(c).dim);
    }
    const std::vector<Ball>& now = engine_->balls();
    return frame_of(engine_->frame(), atom, patch, options_.frames.min_angle, check_ ? &now : nullptr,
                    options_.shrink);
  }

 private:
  std::vector<Ball> balls_at(const py::array_t<double, py::array::c_style | py::array::forcecast>& centres,
                             const char* name) const {
    const std::vector<Eigen::Vector3d> points = points_from(centres, name);
    if (points.size() != weights_.size())
      throw py::value_error(std::string(name) + " has " + std::to_string(points.size()) + " rows, radii " +
                            std::to_string(weights_.size()));
    std::vector<Ball> balls(points.size());
    for (size_t i = 0; i < balls.size(); ++i) balls[i] = {points[i], weights_[i]};
    return balls;
  }

  MovingOptions options_;
  std::vector<double> weights_;
  bool check_ = true;
  std::unique_ptr<MovingBalls> engine_;
};

// A morph from a source to a target: pairs "matched" (atoms travel) or
// "all" (the m x n blend), "auto" as the command decides.
class PyMorph {
 public:
  PyMorph(const py::object& source, const py::object& target, const py::kwargs& kwargs) {
    Options o{kwargs.cast<py::dict>(), {}};
    shrink_ = o.get<double>("shrink", 0.5);
    const std::string pairs = o.get<std::string>("pairs", "auto");
    const std::string how = o.get<std::string>("align", "auto");
    MorphOptions m;
    m.shrink = shrink_;
    m.first = meshing_options(o, 30.0);
    m.frames = m.first;
    m.frames.min_angle = std::min(m.first.min_angle, 20.0);
    m.first.min_angle = 30.0;
    min_angle_ = m.frames.min_angle;
    m.first.progress = progress_from(o.get<py::object>("progress", py::none()));  // the first frame's mesh
    check_ = o.get<bool>("check", true);
    const WeightConvention convention = convention_of(o.get<std::string>("weights", "grow"));
    Options target_options{o.given, o.used};
    BallSource a = balls_from(source, o, shrink_);
    BallSource b = balls_from(target, target_options, shrink_);
    o.finish();
    if (a.molecule && b.molecule) {
      const std::map<std::string, AlignmentMethod> methods{{"auto", AlignmentMethod::automatic},
                                                           {"none", AlignmentMethod::none},
                                                           {"centroid", AlignmentMethod::centroid},
                                                           {"kabsch", AlignmentMethod::kabsch}};
      if (!methods.count(how)) throw py::value_error("align must be auto, none, centroid or kabsch");
      const RigidMotion fit = align(*a.molecule, *b.molecule, methods.at(how)).motion;  // before it is moved from
      *b.molecule = moved(std::move(*b.molecule), fit);
      snap_unmoved(*a.molecule, *b.molecule);
      b.balls = balls_from_molecule(*b.molecule, shrink_, convention);
      a.balls = balls_from_molecule(*a.molecule, shrink_, convention);
    }
    matched_ = pairs == "matched" || (pairs == "auto" && a.molecule && b.molecule && same_molecule(*a.molecule, *b.molecule));
    if (matched_ && !(a.molecule && b.molecule)) throw py::value_error("pairs='matched' needs two molecule files");
    py::gil_scoped_release release;
    if (matched_) {
      motion_ = match_motion(*a.molecule, a.balls, *b.molecule, b.balls);
      for (const auto& track : motion_.tracks) ball_atoms_.push_back({track.source, track.target});
      moving_ = std::make_unique<MovingBalls>(motion_.balls_at(0), moving_options(m), 0.0);
    } else {
      morph_ = std::make_unique<Morph>(prepare_morph(a.balls, b.balls, 0.0, m));
      source_ = a.balls;
      target_ = b.balls;
    }
  }
  Frame frame() { return current(); }
  Frame advance_to(double t) {
    {
      py::gil_scoped_release release;
      if (matched_) moving_->advance_to(motion_.balls_at(t), t);
      else morph_->advance_to(t);
    }
    return current();
  }
  bool matched() const { return matched_; }

 private:
  static MovingOptions moving_options(const MorphOptions& m) {
    MovingOptions o;
    o.shrink = m.shrink;
    o.first = m.first;
    o.frames = m.frames;
    return o;
  }
  // Per vertex its atoms as `skinmesh morph` writes them (frame_attributes):
  // atom and atomid the source atom where there is one, the target atom
  // otherwise; source_atom, target_atom (0 where the side lacks the atom)
  // with has_source_atom, has_target_atom.
  Frame current() {
    std::vector<std::array<int, 2>> sides;
    std::vector<int> patch;
    const MorphFrame& made = matched_ ? moving_->frame() : morph_->frame();
    const SkinComplex& complex = matched_ ? moving_->complex() : morph_->complex();
    if (matched_)
      for (int ball : moving_->vertex_balls()) sides.push_back(ball_atoms_[static_cast<size_t>(ball)]);
    else
      sides = morph_->vertex_atoms();
    for (int c : made.mesh.cells) patch.push_back(complex.cell(c).dim);
    std::vector<int> atom;
    for (const auto& [source, target] : sides) atom.push_back(source >= 0 ? source : target);
    const VertexAttributes a = app::frame_attributes(patch, atom, made.ids, sides);
    std::vector<Ball> balls;
    if (matched_) {
      balls = moving_->balls();
    } else {  // the blend's balls as a static set: the ends' own, the live pairs' in between
      const double t = morph_->t();
      balls = t == 0 ? source_ : t == 1 ? target_ : interpolated_balls(source_, target_, morph_->pairs(), t);
    }
    Frame f = frame_of(made, atom, patch, min_angle_, check_ ? &balls : nullptr, shrink_);
    for (const VertexProperty& column : a.more)
      if (column.name != "id") f.attributes[column.name.c_str()] = array_of<int, std::int64_t>(column.values);
    return f;
  }

  double shrink_ = 0.5, min_angle_ = 20;
  bool check_ = true, matched_ = false;
  MatchedMotion motion_;
  std::vector<std::array<int, 2>> ball_atoms_;
  std::unique_ptr<MovingBalls> moving_;
  std::unique_ptr<Morph> morph_;
  std::vector<Ball> source_, target_;
};

// Frames (Morph's or MovingBalls') written as a morph directory, as
// `skinmesh morph` writes one (docs/morph.md): frame_NNNN.{ply,vtp} with
// per-vertex id, atom, patch (and a morph's atomid, source_atom,
// has_source_atom, target_atom, has_target_atom), frames.pvd, frames.jsonl
// of the frames' reports. All files or none; the directory is made when
// missing.
void write_frames(const std::string& directory, const py::iterable& frames, const std::vector<std::string>& formats) {
  if (formats.empty()) throw py::value_error("formats: at least one of ply, vtp, off, obj, stl");
  for (const std::string& f : formats)
    if (f != "ply" && f != "vtp" && f != "off" && f != "obj" && f != "stl")
      throw py::value_error("formats: '" + f + "' is none of ply, vtp, off, obj, stl");
  const py::object dumps = py::module_::import("json").attr("dumps");
  app::OutputDirectory dir(directory);
  app::OutputSet outputs;
  std::ostringstream lines;
  std::vector<double> times;
  size_t k = 0;
  for (const py::handle item : frames) {
    const Frame& f = item.cast<const Frame&>();
    SurfaceMesh mesh = mesh_from(f.vertices, f.triangles);
    mesh.normals = points_from(f.attributes["normals"].cast<py::array_t<double, py::array::c_style | py::array::forcecast>>(), "normals");
    VertexAttributes a;
    const auto ints = [&](const char* name) {
      const auto arr = f.attributes[name].cast<py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>>();
      return std::vector<int>(arr.data(), arr.data() + arr.size());
    };
    a.patch = ints("patch");
    a.atom = ints("atom");
    std::vector<int> ids(f.ids.data(), f.ids.data() + f.ids.size());
    a.more = {{"id", PropertyType::int32, ids}};
    // A morph's frame: its atom columns, typed as `skinmesh morph` writes them.
    for (const auto& [name, type] : {std::pair{"atomid", PropertyType::uint32}, {"source_atom", PropertyType::uint32},
                                     {"has_source_atom", PropertyType::uint8}, {"target_atom", PropertyType::uint32},
                                     {"has_target_atom", PropertyType::uint8}})
      if (f.attributes.contains(name)) a.more.push_back({name, type, ints(name)});
    for (const std::string& format : formats) {
      const std::string name = app::frame_name(k, format);
      outputs.add(dir.file(name), [&](std::ostream& out) { write_mesh(out, mesh, mesh_format_from_path(name), &a); });
    }
    const py::dict report = f.report.cast<py::dict>();
    times.push_back(report.contains("t") ? report["t"].cast<double>() : static_cast<double>(k));
    lines << dumps(report).cast<std::string>() << "\n";
    ++k;
  }
  if (k == 0) throw py::value_error("no frames to write");
  if (std::find(formats.begin(), formats.end(), "vtp") != formats.end())
    outputs.add(dir.file("frames.pvd"), [&](std::ostream& out) { app::write_pvd(out, times); });
  outputs.add(dir.file("frames.jsonl"), [&](std::ostream& out) { out << lines.str(); });
  outputs.commit();
  dir.keep();
}

}  // namespace

PYBIND11_MODULE(_skinmesh, m) {
  m.doc() = "skinmesh: quality meshes of molecular skin surfaces, and morphs (docs/python.md)";
  m.attr("__version__") = SKINMESH_VERSION;
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<InputError> input(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      py::object instance = py::reinterpret_borrow<py::object>(input.ptr())(e.what());
      instance.attr("file") = e.file();
      instance.attr("line") = e.line();
      PyErr_SetObject(input.ptr(), instance.ptr());
    } catch (const ContractError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    }
  });

  py::class_<MeshResult>(m, "Mesh")
      .def_readonly("vertices", &MeshResult::vertices)
      .def_readonly("triangles", &MeshResult::triangles)
      .def_readonly("attributes", &MeshResult::attributes)
      .def_readonly("report", &MeshResult::report);
  py::class_<Frame>(m, "Frame")
      .def_readonly("vertices", &Frame::vertices)
      .def_readonly("triangles", &Frame::triangles)
      .def_readonly("ids", &Frame::ids)
      .def_readonly("attributes", &Frame::attributes)
      .def_readonly("report", &Frame::report);
  m.def("mesh", &mesh, py::arg("source"),
        "Quality mesh of the skin of a molecule file or of (centres, radii); options as on the command line.");
  py::class_<VolumeResult>(m, "VolumeMesh")
      .def_readonly("points", &VolumeResult::points)
      .def_readonly("tetrahedra", &VolumeResult::tetrahedra)
      .def_readonly("faces", &VolumeResult::faces)
      .def_readonly("tetrahedron_region", &VolumeResult::tetrahedron_region)
      .def_readonly("face_marker", &VolumeResult::face_marker);
  m.def("complex", &complex_counts, py::arg("source"),
        "The mixed complex's cell counts (vertex, edge, triangle, tetrahedron cells) and the skin's topology.");
  m.def("interpolate", &interpolate, py::arg("source"), py::arg("target"), py::arg("t"),
        "The balls of B(t) as (centres, weights); all_pairs=True for the m x n set.");
  m.def("volume", &volume, py::arg("source"),
        "Tetrahedra bounded by the skin mesh (TetGen): points, tetrahedra, faces, regions and markers.");
  m.def("write_frames", &write_frames, py::arg("directory"), py::arg("frames"),
        py::arg("formats") = std::vector<std::string>{"ply", "vtp"},
        "Frames written as a morph directory: frame_NNNN.ply/.vtp with per-vertex id, atom, patch, frames.pvd, frames.jsonl.");
  m.def("grade", &grade, py::arg("vertices"), py::arg("triangles"), "The quality report of any triangle mesh.");
  py::class_<PyMovingBalls>(m, "MovingBalls")
      .def(py::init<const py::array_t<double, py::array::c_style | py::array::forcecast>&, const py::kwargs&>(),
           py::arg("radii"))
      .def("advance_to", &PyMovingBalls::advance_to, py::arg("centres"), py::arg("t") = 0.0,
           py::arg("next") = py::none(),
           "The frame of the balls at these centres (the first call meshes, later ones carry the mesh on); "
           "`next`, the centres of the call after, lets the engine prepare that call beside this one.");
  py::class_<PyMorph>(m, "Morph")
      .def(py::init<const py::object&, const py::object&, const py::kwargs&>(), py::arg("source"), py::arg("target"))
      .def_property_readonly("frame", &PyMorph::frame)
      .def_property_readonly("matched", &PyMorph::matched)
      .def("advance_to", &PyMorph::advance_to, py::arg("t"));
}
