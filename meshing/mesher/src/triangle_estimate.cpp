// The skin's area by radius of curvature, and the mesher's output estimated
// from it (see triangle_estimate.hpp).
#include "skinmesh/mesher/triangle_estimate.hpp"

#include "criteria_constants.hpp"

#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>

namespace skinmesh {
namespace {

constexpr int kDecades = 15;  // radii of curvature from 1e-6 to 1e9 A
constexpr size_t kBins = static_cast<size_t>(kDecades * SkinAreaProfile::kBinsPerDecade);

size_t bin_of(double rho) {
  const double b = std::floor(SkinAreaProfile::kBinsPerDecade * std::log10(rho / SkinAreaProfile::kSmallestRadius));
  if (!(b > 0)) return 0;
  return std::min(kBins - 1, static_cast<size_t>(b));
}

// n points spread evenly on the unit sphere (the Fibonacci lattice).
std::vector<Eigen::Vector3d> fibonacci_sphere(int n) {
  std::vector<Eigen::Vector3d> points;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    points.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return points;
}

// A rotation drawn from the cell's balls alone (uniform over rotations, K.
// Shoemake, "Uniform random rotations", Graphics Gems III, 1992): not from its
// index, which depends on the order CGAL built the complex in, so the profile
// is the same on every run and thread count.
Eigen::Matrix3d rotation_of_cell(const MixedCell& cell) {
  uint64_t h = 0;
  for (int ball : cell.balls) h = (h ^ static_cast<uint64_t>(ball + 1)) * 0x100000001B3ull;
  auto next = [&h] {  // splitmix64
    uint64_t z = (h += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return static_cast<double>((z ^ (z >> 31)) >> 11) / 9007199254740992.0;
  };
  const double u1 = next(), u2 = next(), u3 = next();
  const Eigen::Quaterniond q(std::sqrt(u1) * std::cos(2 * M_PI * u3), std::sqrt(1 - u1) * std::sin(2 * M_PI * u2),
                             std::sqrt(1 - u1) * std::cos(2 * M_PI * u2), std::sqrt(u1) * std::sin(2 * M_PI * u3));
  return q.normalized().toRotationMatrix();
}

struct PartialProfile {
  std::vector<SkinAreaBin> sphere = std::vector<SkinAreaBin>(kBins), hyperboloid = std::vector<SkinAreaBin>(kBins);
  double area = 0;
  long cells_with_skin = 0;
};

// One cell's share. Its quadric is Q(x) = (x-z)^T M (x-z) + s(1-s) R2 with
// M = (1-s)(I-P) - s P (docs/math.md section 3). The point with outward
// normal d is z + alpha M^-1 d, alpha^2 = -s(1-s) R2 / (d^T M^-1 d), and the
// Gaussian curvature there is K = det(M) (d^T M^-1 d) / alpha^2 (R. Goldman,
// "Curvature formulas for implicit curves and surfaces", CAGD 22 (2005), eq.
// for K with grad = 2 alpha d, Hessian 2M), so the area element over the
// solid angle is 1/|K|.
void add_cell(const SkinComplex& complex, int c, const std::vector<Eigen::Vector3d>& directions,
              PartialProfile& out) {
  const MixedCell& cell = complex.cell(c);
  if (cell.degenerate) return;  // a flat cell holds no point
  if ((cell.dim == 0 && cell.R2 >= 0) || (cell.dim == 3 && cell.R2 <= 0)) return;  // no skin on its sphere
  const double s = complex.shrink();
  const double det_m = std::pow(1 - s, 3 - cell.dim) * std::pow(-s, cell.dim);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d m_inverse = (I - cell.P) / (1 - s) - cell.P / s;
  const Eigen::Matrix3d turn = rotation_of_cell(cell);
  const double solid_angle = 4 * M_PI / static_cast<double>(directions.size());
  auto& bins = (cell.dim == 0 || cell.dim == 3) ? out.sphere : out.hyperboloid;
  bool hit = false;
  for (const Eigen::Vector3d& d0 : directions) {
    const Eigen::Vector3d d = turn * d0;
    const Eigen::Vector3d u = m_inverse * d;
    const double kappa = d.dot(u);
    const double alpha2 = -s * (1 - s) * cell.R2 / kappa;
    if (!(alpha2 > 0) || !std::isfinite(alpha2)) continue;
    const Eigen::Vector3d x = cell.center + std::sqrt(alpha2) * u;
    if (complex.membership_violation(c, x) > 0) continue;
    const double area = solid_angle * alpha2 / std::abs(det_m * kappa);
    const double k = complex.max_abs_curvature(x, c);
    const double rho = k > 0 ? 1.0 / k : std::numeric_limits<double>::max();
    SkinAreaBin& bin = bins[bin_of(rho)];
    bin.area += area;
    bin.area_rho += area * rho;
    out.area += area;
    hit = true;
  }
  if (hit) ++out.cells_with_skin;
}

}  // namespace

SkinAreaProfile skin_area_profile(const SkinComplex& complex, const SkinAreaOptions& options) {
  if (options.directions_per_cell < 1) contract_error("skin_area_profile: at least one direction per cell");
  const int cells = static_cast<int>(complex.cells().size());
  const long per_cell = std::max<long>(options.directions_per_cell, options.directions_in_all / std::max(cells, 1));
  const std::vector<Eigen::Vector3d> directions = fibonacci_sphere(static_cast<int>(std::min(per_cell, 1L << 20)));
  tbb::combinable<PartialProfile> partial;
  tbb::parallel_for(tbb::blocked_range<int>(0, cells, 256), [&](const tbb::blocked_range<int>& range) {
    PartialProfile& mine = partial.local();
    for (int c = range.begin(); c != range.end(); ++c) add_cell(complex, c, directions, mine);
  });
  SkinAreaProfile profile;
  profile.sphere.resize(kBins);
  profile.hyperboloid.resize(kBins);
  partial.combine_each([&](const PartialProfile& p) {
    profile.area += p.area;
    profile.cells_with_skin += p.cells_with_skin;
    for (size_t b = 0; b < kBins; ++b) {
      profile.sphere[b].area += p.sphere[b].area;
      profile.sphere[b].area_rho += p.sphere[b].area_rho;
      profile.hyperboloid[b].area += p.hyperboloid[b].area;
      profile.hyperboloid[b].area_rho += p.hyperboloid[b].area_rho;
    }
  });
  return profile;
}

namespace {

// Fitted (docs/benchmarks.md, "Knowing the size before meshing"; bench_estimate on
// pept, 2k39 and 3al1 at five sets of sizes, least squares on the relative
// error): triangles per unit of skin area over the square of the largest
// allowed surface-ball radius (its spanned cap over pi on a curved patch),
// where the size bound binds and where the distance bound does; triangles per
// mixed cell holding skin (small patches take a few triangles whatever their
// size); and the refiner's peak memory per output triangle.
constexpr double kTrianglesPerSizeArea = 1.3;
constexpr double kTrianglesPerDistanceArea = 1.0;
constexpr double kTrianglesPerCell = 1.7;
constexpr double kBytesPerTriangle = 560;  // bytes; bench_estimate's peaks on meshes above 100,000 triangles, rounded up
// Creases: where a hyperboloid patch bends more sharply than the sizes go
// (radius of curvature under kCreaseRadius, far below the default size floor
// of 0.05 A), the refinement for topology (one crossing per normal line,
// every vertex star a disk) resolves the neck, not the size bound. On a neck
// of waist radius a the smallest radius of curvature is rho = (1-s) a / s
// (docs/math.md section 3), so its area over rho^2 counts its length over
// rho, which grows as s / (1-s), whatever the size options. The constant is
// fitted on pept, 3al1 and 1ubi at s = 0.99-0.9999 (docs/benchmarks.md);
// kCreaseRadius is where the measured counts begin to pass the area terms
// (s = 0.99, whose necks bend at about 0.01 A).
constexpr double kCreaseRadius = 0.01;  // Angstrom
constexpr double kTrianglesPerCreaseArea = 0.086;

struct BallBound {
  double radius = 0;
  bool by_distance = false;  // the distance tolerance binds, not the size
};

// The largest surface Delaunay ball radius the criteria allow at a skin point
// whose radius of curvature is rho (triangle_defect): size, then distance,
// whose bound is the sagitta of a triangle on a sphere of radius rho.
BallBound largest_ball_radius(double rho, bool sphere_patch, const MeshingOptions& o) {
  double length = std::clamp(o.sizing.epsilon * rho, o.sizing.min_size, o.sizing.max_size);
  if (o.edge_length > 0) length = std::min(length, o.edge_length);
  if (sphere_patch) length = std::min(length, o.sizing.epsilon * rho);  // no floor (target_edge_length)
  BallBound bound{length / std::sqrt(3.0), false};
  const double h = detail::kToleranceMargin * o.tolerance;
  if (h < rho) {
    const double by_distance = std::sqrt(2 * rho * h - h * h);
    if (by_distance < bound.radius) bound = {by_distance, true};
  }
  return bound;
}

// The skin area a triangle of surface-ball radius r stands for, up to the
// fitted constants: pi r^2 on a flat patch, the spherical cap over the
// ball's circle on a curved one (2 pi rho^2 (1 - cos theta), sin theta = r /
// rho), which is what a coarse triangle on a small sphere spans.
// On a hyperboloid the largest curvature is across a neck only: a triangle
// wider than the neck's radius spans at least its flat area along it.
double area_spanned(double r, double rho) {
  const double sine = std::min(1.0, r / rho);
  const double cap = 2 * M_PI * rho * rho * (sine * sine / (1 + std::sqrt(1 - sine * sine)));  // 1 - cos, no cancellation
  return std::max(cap, M_PI * r * r * (sine < 1 ? 0.0 : 1.0));
}

}  // namespace

TriangleEstimate estimate_triangles(const SkinAreaProfile& profile, const MeshingOptions& options) {
  TriangleEstimate estimate;
  auto add = [&](const std::vector<SkinAreaBin>& bins, bool sphere_patch) {
    for (const SkinAreaBin& bin : bins) {
      if (!(bin.area > 0)) continue;
      const double rho = bin.area_rho / bin.area;
      const BallBound bound = largest_ball_radius(rho, sphere_patch, options);
      const double radius2 = area_spanned(bound.radius, rho) / M_PI;  // r^2 on a flat patch
      if (bound.by_distance) estimate.distance_bound += kTrianglesPerDistanceArea * bin.area / radius2;
      else estimate.size_bound += kTrianglesPerSizeArea * bin.area / radius2;
      if (!sphere_patch && rho < kCreaseRadius) estimate.creases += kTrianglesPerCreaseArea * bin.area / (rho * rho);
    }
  };
  add(profile.sphere, true);
  add(profile.hyperboloid, false);
  estimate.per_cell = kTrianglesPerCell * static_cast<double>(profile.cells_with_skin);
  estimate.triangles = estimate.size_bound + estimate.distance_bound + estimate.per_cell + estimate.creases;
  estimate.peak_bytes = kBytesPerTriangle * estimate.triangles;
  return estimate;
}

double affordable_triangles(const MeshingOptions& options) {
  double triangles = static_cast<double>(options.max_triangles);
  if (options.max_memory_bytes > 0) triangles = std::min(triangles, options.max_memory_bytes / kBytesPerTriangle);
  return triangles;
}

const char* size_option_name(SizeOption option) {
  switch (option) {
    case SizeOption::tolerance: return "tolerance";
    case SizeOption::epsilon: return "epsilon";
    case SizeOption::edge_length: return "edge_length";
    case SizeOption::max_size: return "max_size";
    case SizeOption::min_size: return "min_size";
  }
  return "unknown";
}

namespace {

double& option_value(MeshingOptions& o, SizeOption option) {
  switch (option) {
    case SizeOption::tolerance: return o.tolerance;
    case SizeOption::epsilon: return o.sizing.epsilon;
    case SizeOption::edge_length: return o.edge_length;
    case SizeOption::max_size: return o.sizing.max_size;
    case SizeOption::min_size: return o.sizing.min_size;
  }
  return o.tolerance;
}

// x rounded up to two significant digits: a value a user can type that still fits.
double round_up_two_digits(double x) {
  const double unit = std::pow(10.0, std::floor(std::log10(x)) - 1);
  return std::ceil(x / unit * (1 - 1e-12)) * unit;
}


// The smallest x in [today, ceiling] with fits(x), rounded up to two digits
// when that still fits; none when even the ceiling does not fit. fits is
// monotone: coarser sizes, fewer triangles.
std::optional<double> smallest_fitting(double today, double ceiling, const std::function<bool(double)>& fits) {
  if (!(ceiling > today) || !fits(ceiling)) return std::nullopt;
  double lo = today, hi = ceiling;  // fits at hi; lo does not or is today's value
  for (int step = 0; step < 60 && hi > lo * (1 + 1e-3); ++step) {
    const double mid = std::sqrt(lo * hi);
    (fits(mid) ? hi : lo) = mid;
  }
  const double rounded = round_up_two_digits(hi);
  return rounded <= ceiling && fits(rounded) ? rounded : hi;
}

// Far beyond any useful mesh of a molecule; the minimum size may not pass the maximum.
double ceiling_of(SizeOption option, const MeshingOptions& o) {
  switch (option) {
    case SizeOption::min_size: return o.sizing.max_size;
    case SizeOption::epsilon: return 100.0;
    case SizeOption::tolerance: return 1e3;
    default: return 1e6;
  }
}

constexpr SizeOption kSizeOptions[] = {SizeOption::epsilon, SizeOption::tolerance, SizeOption::edge_length,
                                       SizeOption::max_size, SizeOption::min_size};

}  // namespace

std::vector<FittingSize> sizes_that_fit(const SkinAreaProfile& profile, const MeshingOptions& options,
                                        double triangles) {
  auto fits_with = [&](const MeshingOptions& trial) {
    return estimate_triangles(profile, trial).triangles * kTriangleEstimateSpread <= triangles;
  };
  std::vector<FittingSize> fits;
  for (SizeOption option : kSizeOptions) {
    MeshingOptions trial = options;
    double& value = option_value(trial, option);
    if (!(value > 0)) continue;  // an edge length that is not set cannot be loosened
    const auto found = smallest_fitting(value, ceiling_of(option, options), [&](double v) {
      value = v;
      return fits_with(trial);
    });
    if (found) fits.push_back({{{option, *found}}});
  }
  if (!fits.empty()) return fits;
  auto scaled = [&](double f) {
    MeshingOptions trial = options;
    for (SizeOption option : kSizeOptions) option_value(trial, option) *= option == SizeOption::tolerance ? f * f : f;
    return trial;
  };
  const auto factor = smallest_fitting(1.0, 1e3, [&](double f) { return fits_with(scaled(f)); });
  if (!factor) return fits;
  MeshingOptions coarse = scaled(*factor);
  FittingSize together;  // each rounded up: coarser still, so it still fits
  for (SizeOption option : kSizeOptions)
    if (const double value = option_value(coarse, option); value > 0)
      together.changes.push_back({option, round_up_two_digits(value)});
  fits.push_back(together);
  return fits;
}

double shrink_that_fits(const TriangleEstimate& estimate, double shrink, double triangles) {
  if (!(estimate.creases > 0) || !(shrink > 0 && shrink < 1)) return 0;
  const double others = estimate.size_bound + estimate.distance_bound + estimate.per_cell;
  const double room = triangles / kCreaseEstimateSpread - others;
  if (!(room > 0)) return 0;
  // The crease term grows as s / (1-s) (kTrianglesPerCreaseArea); the other
  // terms barely change with s near 1.
  const double ratio = shrink / (1 - shrink) * room / estimate.creases;
  const double fitting = ratio / (1 + ratio);
  if (!(fitting < shrink)) return 0;
  const double rounded = 1 - round_up_two_digits(1 - fitting);  // typeable, and smaller still
  return rounded > 0 ? rounded : 0;
}

}  // namespace skinmesh
