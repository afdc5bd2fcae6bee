#include "skinmesh/volume/tet_estimate.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <vector>

namespace skinmesh {
namespace {

// Tetrahedra per boundary triangle at the default bounds (radius-edge 2,
// dihedral 5 degrees), measured: the interior's per skin triangle (pept 3.2,
// 1ubi 3.6, 3al1 3.0), the solvent's per skin triangle and per box triangle
// (fitted over pept at margins 5-160 A, 1ubi at 10 and 30, 3al1 at 10 and 40:
// the counts 1.0-1.2 times the fit).
constexpr double kPerInteriorTriangle = 3.3;
constexpr double kPerExteriorTriangle = 2.6;
constexpr double kPerBoxTriangle = 3.2;
// A volume bound adds about one tetrahedron per max_volume of the domain
// (measured 0.8-1.35 on pept).
constexpr double kPerMaxVolume = 1.1;
// Peak memory of the run: per tetrahedron, and per box triangle (TetGen
// keeps each facet of the input with its own lists; measured 1.4-1.65 KB a
// box triangle on pept's exterior at margins 40-160 A).
constexpr double kBytesPerTet = 200;
constexpr double kBytesPerBoxTriangle = 1500;

// How many more tetrahedra the quality bounds TetGen is given ask for than
// the defaults', measured on pept's interior (25,862 tetrahedra at the
// defaults) at the ratios (rows) and dihedral angles (columns) TetGen gets
// (tetgen_ratio, tetgen_dihedral). The last row was measured up to 10%
// above the one before it; it is kept at that one's, so that the factor
// never grows as the ratio loosens.
constexpr std::array<double, 4> kRatios = {1.2, 1.6, 2.4, 8.0};
constexpr std::array<double, 5> kDihedrals = {5, 10, 15, 17, 18};
constexpr double kQualityFactor[4][5] = {
    {1.64, 1.76, 2.40, 3.19, 8.30},  // ratio 1.2 (--max-radius-edge 1.5 or less)
    {0.89, 1.00, 1.28, 1.61, 1.85},  // ratio 1.6 (the defaults: 2 and 5 degrees asked, 1.6 and 10 given)
    {0.64, 0.77, 1.09, 1.39, 1.70},  // ratio 2.4
    {0.54, 0.73, 1.09, 1.39, 1.70},  // ratio 8 (--max-radius-edge 10)
};

// The factor at the grid's point on the side of looser bounds (the next
// larger ratio, the next smaller angle): the count grows steeply towards
// the tightest bounds, so interpolating would overshoot between the points.
double quality_factor(double ratio, double dihedral) {
  size_t r = 0, d = 0;
  while (r + 1 < kRatios.size() && kRatios[r] < ratio - 1e-9) ++r;
  while (d + 1 < kDihedrals.size() && kDihedrals[d + 1] <= dihedral + 1e-9) ++d;
  return kQualityFactor[r][d];
}

}  // namespace

TetDomain tet_domain(const SurfaceMesh& surface, double enclosed) {
  TetDomain d;
  d.skin_triangles = static_cast<double>(surface.triangles.size());
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const auto& t : surface.triangles)
    for (int v : t) {
      lo = lo.cwiseMin(surface.vertices[static_cast<size_t>(v)]);
      hi = hi.cwiseMax(surface.vertices[static_cast<size_t>(v)]);
    }
  if (!surface.triangles.empty()) d.extent = hi - lo;
  d.enclosed = enclosed;
  return d;
}

double box_triangles(const Eigen::Vector3d& extent, double margin) {
  std::array<double, 3> cells{};
  for (int k = 0; k < 3; ++k) cells[static_cast<size_t>(k)] = std::max(1.0, std::ceil((extent[k] + 2 * margin) / kBoxSpacing));
  return 4 * (cells[0] * cells[1] + cells[1] * cells[2] + cells[2] * cells[0]);
}

TetEstimate estimate_tetrahedra(const TetDomain& domain, const VolumeOptions& options) {
  TetEstimate e;
  const bool interior = options.domain != VolumeDomain::exterior;
  const bool exterior = options.domain != VolumeDomain::interior;
  double per_boundary = 0;
  if (interior) per_boundary += kPerInteriorTriangle * domain.skin_triangles;
  if (exterior) {
    e.box_triangles = box_triangles(domain.extent, options.box_margin);
    per_boundary += kPerExteriorTriangle * domain.skin_triangles + kPerBoxTriangle * e.box_triangles;
  }
  const Eigen::Vector3d box = domain.extent + Eigen::Vector3d::Constant(2 * options.box_margin);
  e.volume = options.domain == VolumeDomain::interior ? domain.enclosed
             : options.domain == VolumeDomain::both  ? box.prod()
                                                      : box.prod() - domain.enclosed;
  const double by_volume = options.max_volume > 0 ? e.volume / options.max_volume : 0;
  e.tetrahedra = quality_factor(tetgen_ratio(options.bounds), tetgen_dihedral(options.bounds)) * per_boundary +
                 kPerMaxVolume * by_volume;
  e.low = std::max(e.tetrahedra / kTetEstimateSpread, by_volume);
  e.peak_bytes = kBytesPerTet * e.tetrahedra + kBytesPerBoxTriangle * e.box_triangles;
  e.low_bytes = kBytesPerTet * e.low + kBytesPerBoxTriangle * e.box_triangles / kTetEstimateSpread;
  return e;
}

namespace {

bool fits(const TetEstimate& e, const VolumeOptions& options) {
  return e.low <= static_cast<double>(options.max_tetrahedra) &&
         !(options.max_memory_bytes > 0 && e.low_bytes > options.max_memory_bytes);
}

// The value of one option, between `from` (today's, too much) and `to`
// (the loosest), at which the estimate fits: bisection on a log scale (the
// count is monotone in each). 0 when even `to` does not fit.
template <typename Set>
double value_that_fits(const TetDomain& domain, const VolumeOptions& options, double from, double to, Set set) {
  VolumeOptions o = options;
  set(o, to);
  if (!fits(estimate_tetrahedra(domain, o), o)) return 0;
  for (int i = 0; i < 100; ++i) {
    const double mid = std::sqrt(from * to);
    set(o, mid);
    (fits(estimate_tetrahedra(domain, o), o) ? to : from) = mid;
  }
  return to;
}

// A count as an integer while it reads as one, else in powers of ten.
std::string count(double n) {
  std::ostringstream out;
  if (n < 1e15) out << std::llround(n);
  else out << std::setprecision(3) << n;
  return out.str();
}

// Three significant digits, rounded towards `down` or up, so that a value
// printed as fitting still fits.
std::string rounded(double x, bool down) {
  const double unit = std::pow(10.0, std::floor(std::log10(x)) - 2);
  std::ostringstream out;
  out << std::setprecision(3) << (down ? std::floor(x / unit) : std::ceil(x / unit)) * unit;
  return out.str();
}

// What the estimate was made from, as the message names it.
std::string estimate_terms(const TetDomain& domain, const VolumeOptions& options, const TetEstimate& e) {
  std::vector<std::string> from;
  if (domain.skin_triangles > 0) from.push_back(count(domain.skin_triangles) + " skin triangles");
  std::ostringstream term;
  term.precision(3);
  if (e.box_triangles > 0) term << count(e.box_triangles) << " box triangles at --box-margin " << options.box_margin;
  if (e.box_triangles > 0) from.push_back(term.str()), term.str("");
  if (options.max_volume > 0) term << e.volume << " A^3 to fill over --max-volume " << options.max_volume;
  if (options.max_volume > 0) from.push_back(term.str());
  std::string joined;
  for (const std::string& f : from) joined += (joined.empty() ? "" : ", ") + f;
  return joined;
}

// The box margin and the volume bound that would fit, each alone.
std::vector<std::string> options_that_fit(const TetDomain& domain, const VolumeOptions& options) {
  std::vector<std::string> fitting;
  if (options.domain != VolumeDomain::interior)
    if (const double m = value_that_fits(domain, options, options.box_margin, 1e-3,
                                         [](VolumeOptions& o, double v) { o.box_margin = v; }))
      fitting.push_back("--box-margin " + rounded(m, true));
  if (options.max_volume > 0)
    if (const double v = value_that_fits(domain, options, options.max_volume, 1e30,
                                         [](VolumeOptions& o, double x) { o.max_volume = x; }))
      fitting.push_back("a --max-volume of at least " + rounded(v, false) + " A^3");
  return fitting;
}

}  // namespace

std::string tet_budget_refusal(const TetDomain& domain, const VolumeOptions& options) {
  const TetEstimate e = estimate_tetrahedra(domain, options);
  if (fits(e, options)) return "";
  std::ostringstream out;
  out.precision(3);
  out << "TetGen would make about " << count(e.tetrahedra) << " tetrahedra (at least " << count(e.low) << ", from "
      << estimate_terms(domain, options, e) << ") and take about " << e.peak_bytes / 1e9 << " GB, more than ";
  if (e.low > static_cast<double>(options.max_tetrahedra)) out << "--max-tetrahedra " << options.max_tetrahedra;
  else out << "the memory allowed (" << options.max_memory_bytes / 1e9 << " GB, --max-memory)";
  const std::vector<std::string> fitting = options_that_fit(domain, options);
  if (domain.skin_triangles == 0 && !fitting.empty())
    // The box alone, the skin not meshed yet: a necessary bound, not one that fits.
    out << "; the box alone (the skin not meshed yet) needs a --box-margin under " << fitting[0].substr(13);
  else if (fitting.empty())
    out << "; no --box-margin or --max-volume alone fits: loosen --min-dihedral or --max-radius-edge";
  else
    out << "; this would fit: " << fitting[0] << (fitting.size() > 1 ? ", or " + fitting[1] : "");
  out << " (or raise --max-tetrahedra or --max-memory)";
  return out.str();
}

}  // namespace skinmesh
