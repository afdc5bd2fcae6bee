// Queries on the mixed complex: location by walking, the skin function (the
// per-cell quadric of docs/math.md section 3), projection, segment crossings
// and curvature.
#include "skinmesh/core/skin_complex.hpp"

#include "skinmesh/core/quadratic.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cstdint>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_set>
#include <vector>

namespace skinmesh {
namespace {

constexpr double kBaryTolerance = 1e-12;   // dimensionless
constexpr double kPlaneTolerance = 1e-11;  // Angstrom
constexpr int kMaxWalkSteps = 400;
constexpr int kWalkMemory = 8;       // cells a walk remembers to notice a cycle
constexpr size_t kNearCells = 512;   // cells searched around a cycle before a search of all

// What is wrong with "x in mu_c": the worst violated constraint and the cell
// across it. amount <= 0: x is in the cell.
struct Violation {
  double amount = -std::numeric_limits<double>::infinity();
  int target = -1;
};

// Q_X at y = x - z_X with py = P y (docs/math.md section 3):
//   Q_X(x) = (1-s)|(I-P)(x-z)|^2 - s|P(x-z)|^2 + s(1-s) R2.
// The one place Q_X is written.
double quadric_at(const MixedCell& cell, double s, const Eigen::Vector3d& y, const Eigen::Vector3d& py) {
  return (1 - s) * (y - py).squaredNorm() - s * py.squaredNorm() + s * (1 - s) * cell.R2;
}

// The cell's quadric along the line x = a + t dir: A t^2 + B t + C, with
// C = Q_X(a).
struct LineQuadric {
  double A = 0, B = 0, C = 0;
};
LineQuadric quadric_on_line(const MixedCell& cell, double s, const Eigen::Vector3d& a, const Eigen::Vector3d& dir) {
  const Eigen::Vector3d y0 = a - cell.center;
  const Eigen::Vector3d pd = cell.P * dir, py = cell.P * y0;
  LineQuadric q;
  q.A = (1 - s) * (dir - pd).squaredNorm() - s * pd.squaredNorm();
  q.B = 2.0 * ((1 - s) * (y0 - py).dot(dir - pd) - s * py.dot(pd));
  q.C = quadric_at(cell, s, y0, py);
  return q;
}

// grad F = grad Q_X / (1-s) = 2 (I-P) y - 2s/(1-s) P y; its Hessian,
// constant on the cell, is 2 (I-P) - 2s/(1-s) P.
Eigen::Vector3d skin_gradient(double s, const Eigen::Vector3d& y, const Eigen::Vector3d& py) {
  return 2.0 * (y - py) - (2.0 * s / (1 - s)) * py;
}

}  // namespace

double PrincipalCurvatures::max_abs() const { return std::max(std::abs(k1), std::abs(k2)); }

std::array<long, 4> SkinComplex::cell_counts() const {
  std::array<long, 4> counts{{0, 0, 0, 0}};
  for (const MixedCell& c : cells_) ++counts[static_cast<size_t>(c.dim)];
  return counts;
}

long SkinComplex::degenerate_cell_count() const {
  return std::count_if(cells_.begin(), cells_.end(), [](const MixedCell& c) { return c.degenerate; });
}

double SkinComplex::quadric(int c, const Eigen::Vector3d& x) const {
  const MixedCell& cell = cells_[static_cast<size_t>(c)];
  const Eigen::Vector3d y = x - cell.center;
  return quadric_at(cell, shrink_, y, cell.P * y);
}

Eigen::Vector3d SkinComplex::gradient(int c, const Eigen::Vector3d& x) const {
  const MixedCell& cell = cells_[static_cast<size_t>(c)];
  const Eigen::Vector3d y = x - cell.center;
  return skin_gradient(shrink_, y, cell.P * y);
}

int SkinComplex::owning_ball(const Eigen::Vector3d& x, int cell) const {
  const MixedCell& c = cells_[static_cast<size_t>(cell)];
  int best = c.balls[0];
  for (int k = 1; k <= c.dim; ++k) {
    const int b = c.balls[static_cast<size_t>(k)];
    if (balls_[static_cast<size_t>(b)].power(x) < balls_[static_cast<size_t>(best)].power(x)) best = b;
  }
  return best;
}

// The four ids folded into 64 bits, then splitmix64's finaliser (Steele,
// Lea and Flood 2014), whose low bits depend on every input bit: the mask
// keeps only low bits, and nearby ball ids must not crowd one run of slots.
size_t SkinComplex::slot_of(const std::array<int, 4>& tuple) const {
  uint64_t h = 0;
  for (int v : tuple) h = h * 0x9E3779B97F4A7C15ull + static_cast<uint64_t>(static_cast<uint32_t>(v));
  h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
  h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
  h ^= h >> 31;
  return static_cast<size_t>(h) & (cell_table_.size() - 1);
}

void SkinComplex::index_cells() {
  size_t size = 16;
  while (4 * size < 5 * cells_.size()) size *= 2;  // at most four fifths full
  cell_table_.assign(size, CellSlot{{{-1, -1, -1, -1}}, -1});
  for (size_t c = 0; c < cells_.size(); ++c) {
    size_t at = slot_of(cells_[c].balls);
    while (cell_table_[at].cell >= 0) at = (at + 1) & (size - 1);
    cell_table_[at] = CellSlot{cells_[c].balls, static_cast<int>(c)};
  }
}

int SkinComplex::find_cell(std::array<int, 4> balls) const {
  if (cell_table_.empty()) return -1;
  const std::array<int, 4> tuple = ball_tuple(balls);
  return find_cell_from(tuple, slot_of(tuple));
}

int SkinComplex::find_cell_from(const std::array<int, 4>& tuple, size_t slot) const {
  for (size_t at = slot;; at = (at + 1) & (cell_table_.size() - 1)) {
    const CellSlot& entry = cell_table_[at];
    // Compared one id at a time: std::array's == calls memcmp here.
    if (entry.cell < 0 || (entry.balls[0] == tuple[0] && entry.balls[1] == tuple[1] &&
                           entry.balls[2] == tuple[2] && entry.balls[3] == tuple[3]))
      return entry.cell;
  }
}

std::array<int, 4> SkinComplex::ball_tuple(std::array<int, 4> ids) {
  // An insertion sort: std::sort on four ints draws a false -Warray-bounds
  // from GCC 12. a goes after b when a is unused, or both are used and a > b.
  for (size_t i = 1; i < ids.size(); ++i)
    for (size_t j = i; j > 0; --j) {
      const int a = ids[j - 1], b = ids[j];
      if (!(a < 0 ? b >= 0 : b >= 0 && b < a)) break;
      std::swap(ids[j - 1], ids[j]);
    }
  return ids;
}

std::array<int, 3> SkinComplex::grid_cell_of(const Eigen::Vector3d& x) const {
  std::array<int, 3> g{};
  for (int k = 0; k < 3; ++k)
    g[static_cast<size_t>(k)] = std::clamp(static_cast<int>(std::floor((x[k] - grid_origin_[k]) / grid_step_)), 0,
                                           grid_size_[static_cast<size_t>(k)] - 1);
  return g;
}

// pi_k(v) - pi_0(v), the power of v from ball k less that from ball 0, as
// <z_0 - z_k, 2v - z_0 - z_k> + w_0 - w_k. The plain difference of the two
// powers loses to cancellation what matters when the balls are close: for
// centres 1e-9 A apart (a morph's B(t) between nearly equal conformations)
// its rounding, ~1e-16 of |v|^2 (1e-13 A^2 at 30 A), over twice the gap can
// move the bisector by 1e-4 A. Here z_0 - z_k and w_0 - w_k are exact when
// the balls are close (Sterbenz), and the product keeps its relative accuracy.
// The loops over a cell's cofaces (a vertex cell has one per neighbouring
// ball) call it tens of millions of times a morph: 2v - z_0 is worked out
// once per cell, and the call is inlined.
class PowerGain {
 public:
  PowerGain(const Ball& b0, const Eigen::Vector3d& v) : b0_(b0), two_v_less_z0_(2.0 * v - b0.center) {}
  double operator()(const Ball& bk) const {
    return (b0_.center - bk.center).dot(two_v_less_z0_ - bk.center) + (b0_.weight - bk.weight);
  }

 private:
  const Ball& b0_;
  const Eigen::Vector3d two_v_less_z0_;
};

// x = (1-s) d + s v with d = z + P(x-z)/(1-s) in aff(delta_X) and v = z + (I-P)(x-z)/s
// in aff(nu_X); x is in mu_X iff d is in delta_X (barycentric coordinates >= 0)
// and v is in nu_X (no ball of a coface has smaller power at v).
static Violation worst_violation(const SkinComplex& sc, int c, const Eigen::Vector3d& x) {
  const MixedCell& cell = sc.cell(c);
  const double s = sc.shrink();
  const Eigen::Vector3d y = x - cell.center;
  const Eigen::Vector3d py = cell.P * y;
  Violation worst;
  // A flat simplex (affinely dependent balls, from cospherical input split
  // by CGAL's symbolic perturbation) has a mixed cell of zero volume: it holds
  // no point, and a walk goes on through one of its faces.
  if (cell.degenerate) return {std::numeric_limits<double>::max(), *sc.faces_begin(c)};
  const Ball& b0 = sc.balls()[static_cast<size_t>(cell.balls[0])];
  if (cell.dim > 0) {
    const Eigen::Vector3d d = cell.center + py / (1 - s);
    const Eigen::Vector3d affine = cell.to_affine * (d - b0.center);
    double bary0 = 1.0;
    for (int j = 0; j < cell.dim; ++j) bary0 -= affine[j];
    const int* faces = sc.faces_begin(c);
    for (int j = 0; j <= cell.dim; ++j) {
      const double bary = j == 0 ? bary0 : affine[j - 1];
      if (-bary > kBaryTolerance && -bary > worst.amount) worst = {-bary, faces[j]};
    }
    if (worst.target >= 0) return worst;
  }
  const PowerGain power_gain(b0, cell.center + (y - py) / s);  // at v
  for (auto it = sc.cofaces_begin(c); it != sc.cofaces_end(c); ++it) {
    // A flat coface's ball is co-orthogonal with X's along aff(nu_X): its
    // bound is void (rounding noise); the cells beyond it bound nu_X instead.
    if (it->flat) continue;
    const Ball& bk = sc.balls()[static_cast<size_t>(it->ball)];
    const double gain = power_gain(bk);
    if (!(gain < 0)) continue;  // v on X's side: no violation, and no square root to take (most cofaces)
    const double gap = (bk.center - b0.center).norm();
    const double slack = gain / (2 * std::max(gap, 1e-300));  // signed distance to the bisector
    if (-slack > kPlaneTolerance && -slack > worst.amount) worst = {-slack, it->cell};
  }
  return worst;
}

double SkinComplex::membership_violation(int c, const Eigen::Vector3d& x) const {
  const Violation v = worst_violation(*this, c, x);
  return v.target < 0 ? 0.0 : v.amount;
}

int SkinComplex::start_cell(const Eigen::Vector3d& x) const {
  const std::array<int, 3> b = grid_cell_of(x);
  int best = -1;
  double best_power = std::numeric_limits<double>::infinity();
  const int max_ring = std::max({grid_size_[0], grid_size_[1], grid_size_[2]});
  for (int ring = 0, found_ring = -1; ring <= max_ring; ++ring) {
    if (found_ring >= 0 && ring > found_ring + 1) break;
    for (int i = b[0] - ring; i <= b[0] + ring; ++i)
      for (int j = b[1] - ring; j <= b[1] + ring; ++j)
        for (int k = b[2] - ring; k <= b[2] + ring; ++k) {
          if (std::max({std::abs(i - b[0]), std::abs(j - b[1]), std::abs(k - b[2])}) != ring) continue;
          if (i < 0 || j < 0 || k < 0 || i >= grid_size_[0] || j >= grid_size_[1] || k >= grid_size_[2]) continue;
          const size_t bucket = grid_bucket({i, j, k});
          for (int p = grid_offset_[bucket]; p < grid_offset_[bucket + 1]; ++p) {
            const int ball = grid_balls_[static_cast<size_t>(p)];
            const double power = balls_[static_cast<size_t>(ball)].power(x);
            if (power < best_power) {
              best_power = power;
              best = ball;
            }
          }
        }
    if (best >= 0 && found_ring < 0) found_ring = ring;
  }
  return vertex_cell_[static_cast<size_t>(best)];
}

int SkinComplex::locate_by_search(const Eigen::Vector3d& x) const {
  int best = 0;
  double best_amount = std::numeric_limits<double>::infinity();
  for (int c = 0; c < static_cast<int>(cells_.size()); ++c) {
    const Violation v = worst_violation(*this, c, x);
    const double amount = v.target < 0 ? 0.0 : v.amount;
    if (amount < best_amount) {
      best_amount = amount;
      best = c;
      if (amount <= 0) break;
    }
  }
  return best;
}

int SkinComplex::locate_near(const Eigen::Vector3d& x, int from) const {
  std::vector<int> queue{from};
  std::unordered_set<int> seen{from};
  for (size_t next = 0; next < queue.size() && queue.size() < kNearCells; ++next) {
    const int c = queue[next];
    if (worst_violation(*this, c, x).target < 0) return c;
    auto visit = [&](int d) {
      if (seen.insert(d).second) queue.push_back(d);
    };
    std::for_each(faces_begin(c), faces_end(c), visit);
    for (auto it = cofaces_begin(c); it != cofaces_end(c); ++it) visit(it->cell);
  }
  return -1;
}

int SkinComplex::locate(const Eigen::Vector3d& x, int hint) const {
  int c = (hint >= 0 && hint < static_cast<int>(cells_.size())) ? hint : start_cell(x);
  std::array<int, kWalkMemory> recent;
  recent.fill(-1);
  for (int step = 0; step < kMaxWalkSteps; ++step) {
    const Violation v = worst_violation(*this, c, x);
    if (v.target < 0) return c;
    // A walk goes round in a cycle where a cell of (numerically) zero size
    // sits between x and its cell: on B(t) of a morph, a triangle whose two
    // tetrahedra have the same orthocentre (five co-orthogonal balls) is
    // such a cell, and its coface test points to the wrong tetrahedron by
    // ~1e-9 A. The cell holding x is then a near neighbour of the cycle.
    if (std::find(recent.begin(), recent.end(), c) != recent.end()) {
      const int near = locate_near(x, c);
      return near >= 0 ? near : locate_by_search(x);
    }
    recent[static_cast<size_t>(step) % kWalkMemory] = c;
    c = v.target;
  }
  return locate_by_search(x);  // a walk this long is not expected; kept as a safety net
}

SkinEval SkinComplex::evaluate(const Eigen::Vector3d& x, int hint) const {
  SkinEval e;
  e.cell = locate(x, hint);
  const MixedCell& cell = cells_[static_cast<size_t>(e.cell)];
  const Eigen::Vector3d y = x - cell.center;
  const Eigen::Vector3d py = cell.P * y;
  e.value = quadric_at(cell, shrink_, y, py) / (1 - shrink_);  // F = Q_X / (1-s) on mu_X
  e.gradient = skin_gradient(shrink_, y, py);
  return e;
}

std::optional<SegmentCrossing> SkinComplex::nearest_crossing_on_rays(const Eigen::Vector3d& x0, double reach,
                                                                     int hint) const {
  constexpr int kDirections = 64;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  std::optional<SegmentCrossing> best;
  for (int i = 0; i < kDirections; ++i) {
    // Fibonacci sphere: nearly uniform directions.
    const double z = 1.0 - (2.0 * i + 1.0) / kDirections;
    const double rho = std::sqrt(1.0 - z * z);
    const Eigen::Vector3d u(rho * std::cos(golden * i), rho * std::sin(golden * i), z);
    const double limit = best ? (best->point - x0).norm() : reach;
    const auto hits = intersect_segment(x0, x0 + limit * u, hint);
    if (!hits.empty()) best = hits.front();
  }
  return best;
}

Projection SkinComplex::project_onto(const Eigen::Vector3d& x0, int hint, double tolerance) const {
  constexpr int kMaxIterations = 60;
  constexpr double kMaxStep = 2.0;    // Angstrom: a Newton step longer than this is damped
  constexpr double kMaxReach = 6.0;   // Angstrom: how far along the gradient line to look
  Projection out;
  out.point = x0;
  out.cell = hint;
  const SkinEval start = evaluate(x0, hint);
  out.cell = start.cell;
  const double g0 = start.gradient.norm();
  if (g0 > 1e-12) {
    out.distance = std::abs(start.value) / g0;
    if (out.distance <= tolerance) {
      out.converged = true;
      return out;
    }
    // The skin is a quadric in each cell, so the crossing of the gradient line
    // is exact; Newton's iteration on a saddle-shaped patch can wander instead.
    const Eigen::Vector3d toward = (start.value > 0 ? -1.0 : 1.0) * start.gradient / g0;
    const double reach = std::min(kMaxReach, std::max(0.5, 4.0 * out.distance));
    const auto hits = intersect_segment(x0, x0 + reach * toward, start.cell);
    if (!hits.empty()) {
      out.point = hits.front().point;
      out.cell = hits.front().cell;
    } else {
      // Inside the body F can have a saddle or a maximum below zero along the
      // gradient line, and Newton's iteration then runs to a critical point
      // of F. Cast rays in evenly spread directions and start from the
      // nearest crossing instead. Inside, look as far as kMaxReach (a point
      // deeper in a packed interior stays unprojected: converged = false);
      // outside, stay local, or a far point would snap onto any other piece.
      const double ray_reach = start.value < 0 ? kMaxReach : reach;
      if (const auto nearest = nearest_crossing_on_rays(x0, ray_reach, start.cell)) {
        out.point = nearest->point;
        out.cell = nearest->cell;
      }
    }
  }
  // Newton polish (one step on an exact crossing), or the whole way when the
  // gradient line missed the skin: damped so that |F| decreases every step.
  SkinEval e = evaluate(out.point, out.cell);
  for (int it = 0; it < kMaxIterations; ++it) {
    out.cell = e.cell;
    const double g2 = e.gradient.squaredNorm();
    out.iterations = it + 1;
    if (g2 < 1e-24) return out;  // at a critical point of F: no direction to go
    out.distance = std::abs(e.value) / std::sqrt(g2);
    if (out.distance <= tolerance) {
      out.converged = true;
      return out;
    }
    Eigen::Vector3d step = -(e.value / g2) * e.gradient;
    const double length = step.norm();
    if (length > kMaxStep) step *= kMaxStep / length;
    SkinEval trial;
    for (int halving = 0; halving < 30; ++halving, step *= 0.5) {
      trial = evaluate(out.point + step, e.cell);
      if (std::abs(trial.value) < std::abs(e.value)) break;
    }
    out.point += step;
    e = trial;
  }
  return out;
}

Projection SkinComplex::project(const Eigen::Vector3d& x0, int hint, double tolerance) const {
  // First onto the skin, then towards the closest point: move tangentially
  // towards x0 and back onto the skin until x0 - p is parallel to the normal at p
  // (the first-order condition of the closest point).
  Projection p = project_onto(x0, hint, tolerance);
  if (!p.converged) return p;
  int total = p.iterations;
  for (int it = 0; it < 30; ++it) {
    const SkinEval e = evaluate(p.point, p.cell);
    const Eigen::Vector3d n = e.gradient.normalized();
    const Eigen::Vector3d offset = x0 - p.point;
    const Eigen::Vector3d tangential = offset - offset.dot(n) * n;
    if (tangential.norm() <= 1e-10 * (1.0 + offset.norm())) break;
    Projection next = project_onto(p.point + tangential, p.cell, tolerance);
    total += next.iterations;
    if (!next.converged || (next.point - x0).norm() >= (p.point - x0).norm()) break;
    p = next;
  }
  p.iterations = total;
  return p;
}

// Where the segment a + t dir (t >= t_floor) leaves mu_c, and the cell across:
// every membership constraint of worst_violation is affine in t.
struct CellExit {
  double t = std::numeric_limits<double>::infinity();
  int next = -1;
  bool beyond = false;  // `next` is past a flat coface, not adjacent
};
static CellExit segment_exit(const SkinComplex& sc, int c, const Eigen::Vector3d& a, const Eigen::Vector3d& dir,
                             double t_floor) {
  const MixedCell& cell = sc.cell(c);
  const double s = sc.shrink();
  const Ball& b0 = sc.balls()[static_cast<size_t>(cell.balls[0])];
  const Eigen::Vector3d y0 = a - cell.center;
  CellExit exit;
  auto consider = [&](double value0, double slope, int target, bool beyond) {
    if (slope >= 0) return;
    const double crossing = std::max(t_floor, -value0 / slope);
    if (crossing < exit.t) exit = {crossing, target, beyond};
  };
  if (cell.dim > 0) {
    const Eigen::Vector3d d0 = cell.center + cell.P * y0 / (1 - s) - b0.center;
    const Eigen::Vector3d d1 = cell.P * dir / (1 - s);
    const Eigen::Vector3d A0 = cell.to_affine * d0, A1 = cell.to_affine * d1;
    double bary0 = 1.0, slope0 = 0.0;
    for (int j = 0; j < cell.dim; ++j) {
      bary0 -= A0[j];
      slope0 -= A1[j];
    }
    const int* faces = sc.faces_begin(c);
    const bool past_flat_coface = false;  // a face is always adjacent
    consider(bary0, slope0, faces[0], past_flat_coface);
    for (int j = 1; j <= cell.dim; ++j) consider(A0[j - 1], A1[j - 1], faces[j], past_flat_coface);
  }
  const Eigen::Vector3d v0 = cell.center + (y0 - cell.P * y0) / s;
  const Eigen::Vector3d v1 = (dir - cell.P * dir) / s;
  const PowerGain power_gain(b0, v0);
  for (auto it = sc.cofaces_begin(c); it != sc.cofaces_end(c); ++it) {
    if (it->flat) continue;  // void bound (see worst_violation)
    const Ball& bk = sc.balls()[static_cast<size_t>(it->ball)];
    // pi_k(v) - pi_0(v) = -2 <v, z_k - z_0> + |z_k|^2 - w_k - |z_0|^2 + w_0
    const double slope = -2.0 * v1.dot(bk.center - b0.center);
    if (slope >= 0) continue;  // the segment does not approach this bisector (consider's own first test)
    consider(power_gain(bk), slope, it->cell, it->beyond);
  }
  return exit;
}

std::vector<SegmentCrossing> SkinComplex::intersect_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                            int hint) const {
  std::vector<SegmentCrossing> out;
  intersect_segment(a, b, hint, &out);
  return out;
}

void SkinComplex::intersect_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int hint,
                                    std::vector<SegmentCrossing>* crossings) const {
  std::vector<SegmentCrossing>& out = *crossings;
  out.clear();
  const Eigen::Vector3d dir = b - a;
  if (dir.squaredNorm() == 0.0) return;
  int c = locate(a, hint);
  double t = 0.0;        // crossings are searched from here
  double t_floor = 0.0;  // exits are searched from here (past a point stepped over)
  int stalled = 0;
  // Each further skip doubles: a stretch of cells of nearly no size (balls
  // 1e-9 to 1e-5 A apart) is then crossed in a few dozen steps, not in
  // thousands of 1e-9 crawls that each locate x again.
  constexpr double kFirstSkip = 1e-9;
  double skip = kFirstSkip;
  const int max_cells = 20000;
  for (int visit = 0; visit < max_cells; ++visit) {
    if (cells_[static_cast<size_t>(c)].degenerate) {  // holds nothing: continue from the cell really there
      c = locate(a + t * dir, *faces_begin(c));
      continue;
    }
    const CellExit exit = segment_exit(*this, c, a, dir, t_floor);
    // Roots of Q_c(a + t dir) on [t, min(t_exit, 1)]: the skin is a quadric in the cell.
    const double hi = std::min(exit.t, 1.0);
    const LineQuadric q = quadric_on_line(cells_[static_cast<size_t>(c)], shrink_, a, dir);
    double roots[2];
    const int count = quadratic_roots(q.A, q.B, q.C, 1e-15, roots);
    const double eps = 1e-13;
    for (int r = 0; r < count; ++r) {
      const double u = roots[r];
      if (u < t - eps || u > hi + eps || u < -eps || u > 1 + eps) continue;
      const double uc = std::clamp(u, 0.0, 1.0);
      if (!out.empty() && std::abs(out.back().t - uc) < 1e-10) continue;
      out.push_back({uc, a + uc * dir, c, 2 * q.A * u + q.B < 0});
    }
    if (exit.t >= 1.0 || exit.next < 0) break;

    // Zero-length steps go round a face where several cells meet (many of
    // them of zero size where balls are cospherical); after a few, locate
    // slightly further along and go on from there. Crossings are still
    // searched from t, with the quadric of the cell found, which equals the
    // skin function there by continuity, so none is lost in the step.
    if (exit.t <= t_floor) {
      if (++stalled > 2) {
        t_floor = std::min(1.0, t_floor + skip);
        skip *= 2;
        c = locate(a + t_floor * dir, c);
        stalled = 0;
        continue;
      }
    } else {
      stalled = 0;
      skip = kFirstSkip;
    }
    t = t_floor = exit.t;
    // A cell past a flat coface is not adjacent: find the one really there.
    c = exit.beyond ? locate(a + t * dir, exit.next) : exit.next;
  }
}

double SkinComplex::max_abs_curvature(const Eigen::Vector3d& x, int c) const {
  const MixedCell& cell = cells_[static_cast<size_t>(c)];
  const double s = shrink_;
  const Eigen::Vector3d y = x - cell.center;
  const Eigen::Vector3d py = cell.P * y;
  const Eigen::Vector3d g = skin_gradient(s, y, py);
  const double gn = g.norm();
  if (gn == 0.0) return 0.0;
  // As curvature(): S = T^T H T / |g| with H = 2 I - (2 + h) P, T an
  // orthonormal basis of the tangent plane. Its eigenvalues are
  // (2 - (2 + h) mu) / |g|, mu those of T^T P T. Where P is the orthogonal
  // projector of a simplex that is not flat, they follow from its rank and
  // q = n^T P n alone (P g = -h P y, so q = h^2 |P y|^2 / |g|^2): mu is
  // {0, 0} for a vertex, {0, 1 - q} for an edge, {1, 1 - q} for a
  // triangle and {1, 1} for a tetrahedron.
  const double h = 2.0 * s / (1 - s);
  if (!cell.degenerate) {
    const double bent = std::abs(2.0 - (2.0 + h) * (1.0 - h * h * py.squaredNorm() / (gn * gn)));
    switch (cell.dim) {
      case 0: return 2.0 / gn;
      case 1: return std::max(2.0, bent) / gn;
      case 2: return std::max(h, bent) / gn;
      default: break;
    }
    if (cell.P == Eigen::Matrix3d::Identity()) return h / gn;
  }
  // A flat simplex's P (a pseudo-inverse's) has a rank below its
  // dimension: the 2x2 shape operator in closed form, no directions.
  const Eigen::Vector3d n = g / gn;
  const Eigen::Vector3d t1 = n.unitOrthogonal();
  const Eigen::Vector3d t2 = n.cross(t1);
  auto shape = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    return (2.0 * u.dot(v) - (2.0 + h) * u.dot(cell.P * v)) / gn;
  };
  const double a = shape(t1, t1), b = shape(t1, t2), d = shape(t2, t2);
  const double m = 0.5 * (a + d);
  return std::abs(m) + std::hypot(0.5 * (a - d), b);
}

PrincipalCurvatures SkinComplex::curvature(const Eigen::Vector3d& x, int c) const {
  const MixedCell& cell = cells_[static_cast<size_t>(c)];
  const double s = shrink_;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  // F = Q/(1-s): the gradient of skin_gradient, and its constant Hessian.
  const Eigen::Vector3d y = x - cell.center;
  const Eigen::Vector3d g = skin_gradient(s, y, cell.P * y);
  const Eigen::Matrix3d H = 2.0 * (I - cell.P) - (2.0 * s / (1 - s)) * cell.P;
  PrincipalCurvatures pc;
  const double gn = g.norm();
  if (gn == 0.0) return pc;
  pc.normal = g / gn;
  // Tangent frame, then the shape operator T^T H T / |g| of the level set.
  Eigen::Vector3d t1 = pc.normal.unitOrthogonal();
  Eigen::Vector3d t2 = pc.normal.cross(t1);
  Eigen::Matrix<double, 3, 2> T;
  T << t1, t2;
  const Eigen::Matrix2d S = T.transpose() * H * T / gn;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(S);
  pc.k1 = eig.eigenvalues()[1];
  pc.k2 = eig.eigenvalues()[0];
  pc.d1 = T * eig.eigenvectors().col(1);
  pc.d2 = T * eig.eigenvectors().col(0);
  return pc;
}

}  // namespace skinmesh
