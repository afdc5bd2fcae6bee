// Primal active-set method (Nocedal & Wright, Numerical Optimization, 2nd ed.,
// Algorithm 16.3) on the simplex, over the balls of smallest power distance,
// followed by a check of the KKT conditions against every ball; balls that
// violate them join the candidates and the solve repeats.
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/core/cell_grid.hpp"
#include "skinmesh/core/error.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <optional>
#include <stdexcept>

namespace skinmesh {

double OracleResult::distance() const {
  if (std::isnan(value)) return INFINITY;  // no answer (a point that is not finite): never "on the skin"
  const double g = gradient.norm();
  return g > 0 ? std::abs(value) / g : std::abs(value) > 0 ? INFINITY : 0.0;
}

// Balls bucketed by centre in a uniform grid of about one ball per cell: the
// balls within a distance of a point are found without a pass over all of
// them. Only a speed-up: which balls a query visits never changes an
// answer's certificate (SkinOracle::evaluate bounds the rest).
class BallGrid {
 public:
  explicit BallGrid(const std::vector<Ball>& balls) : grid_(grid_of(balls)) {
    for (const Ball& b : balls) max_weight_ = std::max(max_weight_, b.weight);
  }
  double max_weight() const { return max_weight_; }
  // Calls visit(i) for every ball whose centre lies within `radius` of x (and
  // a few more). Returns false, visiting nothing, when the query would cover
  // most of the grid: the caller then passes over every ball.
  template <class Visit>
  bool within(const Eigen::Vector3d& x, double radius, Visit visit) const {
    const std::optional<CellGrid::Cells> cells = grid_.cells_met(x, radius);
    if (!cells) return !std::isnan(radius) && !std::isnan(x.sum());  // none near
    if (!(cells->count() * 2 < grid_.cells())) return false;
    grid_.any_in(*cells, [&](int i, const Eigen::Vector3d&) {
      visit(i);
      return false;
    });
    return true;
  }

 private:
  // Cells as wide as the balls' mean spacing, at most four a ball.
  static CellGrid grid_of(const std::vector<Ball>& balls) {
    std::vector<Eigen::Vector3d> centers;
    centers.reserve(balls.size());
    Eigen::AlignedBox3d box;
    for (const Ball& b : balls) box.extend(centers.emplace_back(b.center));
    const Eigen::Vector3d extent = box.sizes().cwiseMax(1e-9);
    CellGridOptions options;
    options.cell = std::max(std::cbrt(extent.prod() / static_cast<double>(balls.size())), 1e-3 * extent.maxCoeff());
    options.most_cells = 4.0 * static_cast<double>(balls.size()) + 64;
    return CellGrid(std::move(centers), {}, box, options);
  }
  CellGrid grid_;
  double max_weight_ = -INFINITY;
};

SkinOracle::SkinOracle(std::vector<Ball> balls, double shrink) : balls_(std::move(balls)), shrink_(shrink) {
  if (balls_.empty()) contract_error("SkinOracle needs at least one ball");
  if (!(shrink > 0 && shrink < 1)) contract_error("shrink factor must lie in (0,1)");
  grid_ = std::make_shared<const BallGrid>(balls_);
}

namespace {

struct Problem {
  const std::vector<Ball>& balls;
  double s;
  Eigen::Vector3d x;
  // Objective phi(l) = (1-s)|x - Z l|^2 + s sum l_i pi_i(x). On the simplex
  // x - Z l = -(Z - x 1^T) l, so we differentiate in centres relative to x,
  // which keeps every term the size of the local geometry instead of the
  // size of the coordinates (~100 A): gradient entry i is
  // g_i = -2(1-s) <x - Z l, z_i - x> + s pi_i(x).
  double gradient_entry(int i, const Eigen::Vector3d& r) const {
    const Ball& b = balls[static_cast<size_t>(i)];
    return -2 * (1 - s) * r.dot(b.center - x) + s * b.power(x);
  }
};

struct Solution {
  std::vector<int> support;
  std::vector<double> lambda;
};

// A support holds at most 4 balls with affinely independent centres, and one
// more enters before a step drops one: fixed-capacity matrices spare a heap
// allocation per matrix per iteration (with dynamic matrices, malloc and
// free took much of the oracle's time).
constexpr int kMaxSupport = 8;
using SupportVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxSupport + 1, 1>;
using SupportMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxSupport + 1, kMaxSupport + 1>;
using CentreMatrix = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxSupport>;
using AffineMatrix = Eigen::Matrix<double, 4, Eigen::Dynamic, 0, 4, kMaxSupport>;

// Whether the columns of A = [Z; 1^T] (centres relative to x, over a row of
// ones) are linearly dependent, that is the centres affinely dependent, by
// full pivoting (rank threshold 1e-10 of the largest pivot); then a kernel
// direction. Fixed-size at the usual support sizes (1-4 balls).
struct Dependence {
  bool singular = false;
  SupportVector direction;  // when singular: A d = 0, d != 0
};
template <class Matrix>
Dependence dependence_of(const Matrix& A) {
  Eigen::FullPivLU<Matrix> lu(A);
  lu.setThreshold(1e-10);
  Dependence out;
  out.singular = lu.rank() < A.cols();
  if (out.singular) out.direction = lu.kernel().col(0);
  return out;
}
Dependence affine_dependence(const AffineMatrix& A) {
  switch (A.cols()) {
    case 1: return dependence_of<Eigen::Matrix<double, 4, 1>>(A);
    case 2: return dependence_of<Eigen::Matrix<double, 4, 2>>(A);
    case 3: return dependence_of<Eigen::Matrix<double, 4, 3>>(A);
    case 4: return dependence_of<Eigen::Matrix<double, 4, 4>>(A);
    default: return dependence_of<AffineMatrix>(A);
  }
}

// M x = rhs for the KKT matrix of a support whose centres are affinely
// independent, which makes M nonsingular (the step below): partial
// pivoting suffices, and at the usual sizes (a support of 1-4 balls) a
// fixed-size solve, unrolled, costs a fraction of the general one.
template <int N>
SupportVector solve_fixed(const SupportMatrix& M, const SupportVector& rhs) {
  const Eigen::Matrix<double, N, N> m = M.template topLeftCorner<N, N>();
  const Eigen::Matrix<double, N, 1> b = rhs.template head<N>();
  return m.partialPivLu().solve(b);
}
SupportVector solve_nonsingular(const SupportMatrix& M, const SupportVector& rhs) {
  switch (M.rows()) {
    case 2: return solve_fixed<2>(M, rhs);
    case 3: return solve_fixed<3>(M, rhs);
    case 4: return solve_fixed<4>(M, rhs);
    case 5: return solve_fixed<5>(M, rhs);
    default: return M.partialPivLu().solve(rhs);
  }
}

// The candidate of least objective at a vertex of the simplex (l = e_i):
// where the active-set solves start.
int least_phi(const Problem& p, const std::vector<int>& candidates) {
  int start = candidates[0];
  double best = INFINITY;
  for (int i : candidates) {
    const Ball& b = p.balls[static_cast<size_t>(i)];
    const double phi = (1 - p.s) * (p.x - b.center).squaredNorm() + p.s * b.power(p.x);
    if (phi < best) best = phi, start = i;
  }
  return start;
}

// Active-set solve restricted to `candidates`. Returns the support and
// weights. `warm`: the working set starts as all the candidates, at equal
// weights (a mesh vertex's mixed-cell balls, which are the minimiser's
// support at a point inside the cell: one step there instead of a ball
// added per step); else as the candidate of least objective alone.
Solution solve_on(const Problem& p, const std::vector<int>& candidates, bool warm = false) {
  const double s = p.s;
  const bool start_on_all = warm && candidates.size() > 1;
  // A single ball's weight 1 is the minimiser on it, as are the weights
  // after a full step: the next solve's step is round-off, so go straight
  // to the multipliers.
  bool at_subproblem_minimum = !start_on_all;
  std::vector<int> S;
  std::vector<double> l;
  S.reserve(kMaxSupport);
  l.reserve(kMaxSupport);
  if (start_on_all) {
    S = candidates;
    l.assign(S.size(), 1.0 / static_cast<double>(S.size()));
  } else {
    S.push_back(least_phi(p, candidates));
    l.push_back(1.0);
  }
  for (int iteration = 0; iteration < 200; ++iteration) {
    const int k = static_cast<int>(S.size());
    Eigen::Vector3d y = Eigen::Vector3d::Zero();
    for (int a = 0; a < k; ++a) y += l[a] * p.balls[static_cast<size_t>(S[a])].center;
    const Eigen::Vector3d r = p.x - y;
    SupportVector g(k);
    // Centres relative to x: the objective only sees x - Z l, and with
    // coordinates ~100 A the absolute Gram matrix has entries ~1e4 that are
    // nearly equal, which makes the KKT system look singular when it is not.
    CentreMatrix Z(3, k);
    for (int a = 0; a < k; ++a) {
      g[a] = p.gradient_entry(S[a], r);
      Z.col(a) = p.balls[static_cast<size_t>(S[a])].center - p.x;
    }
    // The KKT system below is singular exactly when the centres of S are
    // affinely dependent: [Z; 1^T] d = 0 has a non-zero solution.
    AffineMatrix A(4, k);
    A.topRows(3) = Z;
    A.row(3).setOnes();
    const Dependence dependence = affine_dependence(A);
    const bool singular = dependence.singular;
    SupportVector step;
    double mu = 0;
    if (!singular) {
      // Equality-constrained step on S: [2(1-s) Z^T Z, -1; 1^T, 0] [step; mu] = [-g; 0].
      SupportMatrix M = SupportMatrix::Zero(k + 1, k + 1);
      M.topLeftCorner(k, k) = 2 * (1 - s) * Z.transpose() * Z;
      M.block(0, k, k, 1).setConstant(-1.0);
      M.block(k, 0, 1, k).setConstant(1.0);
      SupportVector rhs = SupportVector::Zero(k + 1);
      rhs.head(k) = -g;
      const SupportVector sol = solve_nonsingular(M, rhs);
      step = sol.head(k);
      mu = sol[k];
    } else {
      // Affinely dependent centres: along a direction d with sum d = 0 and
      // Z d = 0 the objective is linear; go downhill until a weight reaches 0.
      SupportVector d = dependence.direction;
      if (g.dot(d) > 0) d = -d;
      step = d * 1e30;  // unbounded along d: the ratio test below stops it
    }
    const double step_norm = step.cwiseAbs().maxCoeff();
    if (!singular && (at_subproblem_minimum || step_norm <= 1e-15)) {
      at_subproblem_minimum = false;
      // Stationary on S: check the multipliers of the inactive bounds.
      int entering = -1;
      double most_negative = -1e-13 * (1.0 + std::abs(mu));
      for (int i : candidates) {
        if (std::find(S.begin(), S.end(), i) != S.end()) continue;
        const double multiplier = p.gradient_entry(i, r) - mu;
        if (multiplier < most_negative) most_negative = multiplier, entering = i;
      }
      // (A support at capacity cannot happen, see kMaxSupport; were it to,
      // the caller's KKT check against every ball would leave x uncertified.)
      if (entering < 0 || k == kMaxSupport) return {std::move(S), std::move(l)};
      S.push_back(entering);
      l.push_back(0.0);
      continue;
    }
    // Ratio test: the largest alpha <= 1 keeping every weight >= 0.
    double alpha = 1.0;
    int blocking = -1;
    for (int a = 0; a < k; ++a)
      if (step[a] < 0) {
        const double limit = -l[a] / step[a];
        if (limit < alpha) alpha = limit, blocking = a;
      }
    for (int a = 0; a < k; ++a) l[a] += alpha * step[a];
    at_subproblem_minimum = blocking < 0;
    if (blocking >= 0) {
      S.erase(S.begin() + blocking);
      l.erase(l.begin() + blocking);
      const double sum = std::accumulate(l.begin(), l.end(), 0.0);
      for (double& v : l) v = std::max(v, 0.0) / sum;
    }
  }
  return {std::move(S), std::move(l)};
}

// What a solution on some candidates says at x: the residual r = x - Z l, the
// value, the multiplier mu of the simplex constraint, the scale KKT gaps are
// measured against (the size of the terms in g, so the test is relative), and
// the worst gap on the support.
struct Stationary {
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  double value = 0, mu = 0, scale = 1, violation = 0;
};
Stationary stationary(const Problem& p, const Solution& sol) {
  Eigen::Vector3d y = Eigen::Vector3d::Zero();
  double linear = 0;
  for (size_t a = 0; a < sol.support.size(); ++a) {
    const Ball& b = p.balls[static_cast<size_t>(sol.support[a])];
    y += sol.lambda[a] * b.center;
    linear += sol.lambda[a] * b.power(p.x);
  }
  Stationary st;
  st.r = p.x - y;
  st.value = (1 - p.s) * st.r.squaredNorm() + p.s * linear;
  // KKT: g_i = mu on the support, g_k >= mu for every ball.
  double wsum = 0;
  for (size_t a = 0; a < sol.support.size(); ++a) {
    st.mu += sol.lambda[a] * p.gradient_entry(sol.support[a], st.r);
    wsum += sol.lambda[a];
  }
  st.mu /= wsum;
  double reach = 1.0;
  for (int i : sol.support) reach = std::max(reach, (p.balls[static_cast<size_t>(i)].center - p.x).norm());
  st.scale = 1.0 + std::abs(st.mu) + 2 * (1 - p.s) * st.r.norm() * reach;
  for (int i : sol.support)
    st.violation = std::max(st.violation, std::abs(p.gradient_entry(i, st.r) - st.mu) / st.scale);
  return st;
}

// Copies a solution into a result: value, gradient 2 r, and the support
// with each candidate named by name(candidate).
template <class Result, class Name>
void take_solution(Result& out, const Stationary& st, const Solution& sol, Name name) {
  out.value = st.value;
  out.gradient = 2.0 * st.r;
  out.support.clear();
  for (size_t a = 0; a < sol.support.size(); ++a)
    if (sol.lambda[a] > 0) out.support.emplace_back(name(sol.support[a]), sol.lambda[a]);
}

}  // namespace

namespace {

// Beyond this distance from x no ball's multiplier g_k can fall below mu:
// g_k = -2(1-s) <r, z_k - x> + s (|z_k - x|^2 - w_k)
//     >= s d^2 - 2(1-s)|r| d - s w_max   (d = |z_k - x|),
// which passes mu for d beyond the larger root of s d^2 - b d - c.
double certification_radius(double s, const Eigen::Vector3d& r, double mu, double max_weight) {
  const double b = 2 * (1 - s) * r.norm(), c = s * max_weight + mu;
  const double discriminant = b * b + 4 * s * c;
  if (!(discriminant > 0)) return 0;
  return (b + std::sqrt(discriminant)) / (2 * s) * (1 + 1e-9) + 1e-9;
}

// Calls visit(k) for every ball whose centre lies within `radius` of x (and
// a few more), or for every ball when the grid cannot narrow it down.
template <class Visit>
void visit_near(const BallGrid& grid, const std::vector<Ball>& balls, const Eigen::Vector3d& x, double radius,
                Visit visit) {
  if (!std::isfinite(radius) || !grid.within(x, radius, visit))
    for (int k = 0; k < static_cast<int>(balls.size()); ++k) visit(k);
}

// The `count` balls of least power distance among those near x: only
// candidates (the caller certifies its answer against every ball). The
// (power, ball) pairs live in one array per thread: the oracle runs on
// every vertex of a mesh, and an allocation per call showed.
std::vector<int> least_power(const BallGrid& grid, const std::vector<Ball>& balls, const Eigen::Vector3d& x,
                             size_t count) {
  thread_local std::vector<std::pair<double, int>> buffer;
  std::vector<std::pair<double, int>>& by_power = buffer;  // one look-up of the thread's copy, not one per use
  const auto gather = [&](int k) { by_power.emplace_back(balls[static_cast<size_t>(k)].power(x), k); };
  by_power.clear();
  double radius = std::sqrt(std::max(grid.max_weight(), 0.0)) + 1.0;
  bool all = false;
  for (int growth = 0; growth < 128 && by_power.size() < count && !all; ++growth, radius *= 2) {
    by_power.clear();
    all = !grid.within(x, radius, gather);
  }
  if (all || by_power.empty()) {  // most of the grid, or x not a finite point
    by_power.clear();
    for (int k = 0; k < static_cast<int>(balls.size()); ++k) gather(k);
  }
  count = std::min(count, by_power.size());
  std::nth_element(by_power.begin(), by_power.begin() + static_cast<long>(count - 1), by_power.end());
  std::vector<int> out;
  out.reserve(count + 8);
  for (size_t a = 0; a < count; ++a) out.push_back(by_power[a].second);
  return out;
}

}  // namespace

OracleResult SkinOracle::evaluate(const Eigen::Vector3d& x) const {
  if (!x.allFinite()) return solve_from(x, {});
  return solve_from(x, least_power(*grid_, balls_, x, 12));
}

OracleResult SkinOracle::evaluate(const Eigen::Vector3d& x, const std::array<int, 4>& start) const {
  std::vector<int> candidates;
  for (int ball : start) {
    if (ball >= static_cast<int>(balls_.size())) contract_error("SkinOracle::evaluate: a start ball past the last ball");
    if (ball >= 0) candidates.push_back(ball);
  }
  if (candidates.empty()) return evaluate(x);
  const bool warm = candidates.size() <= 4;
  return solve_from(x, std::move(candidates), warm);
}

// The solve from `candidates` (not empty for a finite x), which grow by
// every ball the KKT check finds violating until none does.
OracleResult SkinOracle::solve_from(const Eigen::Vector3d& x, std::vector<int> candidates, bool warm) const {
  if (!x.allFinite()) {  // no answer to certify (the maxima below would pass NaN over)
    OracleResult none;
    none.value = NAN;
    none.kkt_violation = INFINITY;
    return none;
  }
  const Problem p{balls_, shrink_, x};
  OracleResult out;
  for (int round = 0; round < 50; ++round) {
    const Solution sol = solve_on(p, candidates, warm && round == 0);
    const Stationary st = stationary(p, sol);
    take_solution(out, st, sol, [](int ball) { return ball; });
    // The KKT check against every ball: those beyond the certification
    // radius pass it by the bound, the others are checked one by one.
    double violation = st.violation;
    std::vector<int> violators;
    const auto check = [&](int k) {
      const double gap = (st.mu - p.gradient_entry(k, st.r)) / st.scale;
      if (gap > 1e-12 && std::find(candidates.begin(), candidates.end(), k) == candidates.end())
        violators.push_back(k);
      violation = std::max(violation, gap);
    };
    const double reach = certification_radius(shrink_, st.r, st.mu, grid_->max_weight());
    visit_near(*grid_, balls_, x, reach, check);
    out.reach = std::isfinite(reach) ? reach : INFINITY;
    out.kkt_violation = violation;
    out.certified = violation < 1e-9;
    if (violators.empty()) break;
    candidates.insert(candidates.end(), violators.begin(), violators.end());
  }
  return out;
}

double MorphOracleResult::distance() const {
  const double g = gradient.norm();
  return g > 0 ? std::abs(value) / g : std::abs(value) > 0 ? INFINITY : 0.0;
}

MorphOracle::MorphOracle(std::vector<Ball> source, std::vector<Ball> target, double shrink)
    : source_(std::move(source), shrink), target_(std::move(target), shrink) {}

namespace {

// An end of the morph is the source's (or target's) own skin function.
MorphOracleResult end_result(const OracleResult& o, bool source_end) {
  MorphOracleResult out;
  out.value = o.value;
  out.gradient = o.gradient;
  for (const auto& [ball, weight] : o.support)
    out.support.push_back({source_end ? BallPair{ball, -1} : BallPair{-1, ball}, weight});
  out.kkt_violation = o.kkt_violation;
  out.certified = o.certified;
  return out;
}

// The least multiplier g_k = -2(1-s) <r, z_k - x> + s pi_k(x) over one
// side's balls: the least among the balls near x, certified for the rest by
// the bound of certification_radius (a ball with g_k below a value lies
// within that value's radius), so the pass is over the near balls only.
struct Least {
  int ball = -1;
  double g = INFINITY;
};
Least least_multiplier(const BallGrid& grid, const Problem& side, const Eigen::Vector3d& r) {
  Least least;
  const auto take = [&](int k) {
    const double g = side.gradient_entry(k, r);
    if (g < least.g) least = {k, g};
  };
  const double near = std::sqrt(std::max(grid.max_weight(), 0.0)) + 1.0;
  visit_near(grid, side.balls, side.x, near, take);
  // Balls beyond `reach` have g_k >= least.g; one more pass settles it
  // (least.g only falls, so the reach of its result is no larger).
  const double reach = certification_radius(side.s, r, least.g, grid.max_weight());
  if (!(reach <= near)) visit_near(grid, side.balls, side.x, reach, take);
  return least;
}

// The same from seeds, balls of this side such as the support's
// (each_seed(take) calls take(k) for each): the least of their
// multipliers bounds the least of all, and one pass over the balls within
// that value's reach finds it, where without seeds a first pass over the
// balls near x gives the bound and most calls need the second pass.
template <class EachSeed>
Least least_multiplier_from(const BallGrid& grid, const Problem& side, const Eigen::Vector3d& r, EachSeed each_seed) {
  Least least;
  const auto take = [&](int k) {
    const double g = side.gradient_entry(k, r);
    if (g < least.g) least = {k, g};
  };
  each_seed(take);
  if (least.ball < 0) return least_multiplier(grid, side, r);
  visit_near(grid, side.balls, side.x, certification_radius(side.s, r, least.g, grid.max_weight()), take);
  return least;
}


// The morph's minimisation in its own unknowns (docs/math.md section 4):
// weights l on the source's balls and u on the target's, one simplex each.
// Near t = 0 (or 1) the pair balls b_ij(t) of one source ball i differ by
// t |z_j - z_j'|, so the pair solve's Gram matrix is singular to round-off
// and its answer can miss the minimum; here the target's columns enter as
// t (z_j - x) and the step is solved in the scaled unknowns
// (1-t) dl and t du, whose system does not depend on t.
struct SplitSolution {
  std::vector<int> a, b;        // supports on the source's and target's candidates
  std::vector<double> l, u;     // their weights, each summing to 1
};
using SplitMatrix = Eigen::Matrix<double, 5, Eigen::Dynamic, 0, 5, kMaxSupport>;
using SplitKkt = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxSupport + 2, kMaxSupport + 2>;
using SplitVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxSupport + 2, 1>;

// x - (1-t) Z_A l - t Z_B u, summed relative to x (see Problem).
Eigen::Vector3d split_residual(const Problem& pa, const Problem& pb, double t, const SplitSolution& w) {
  Eigen::Vector3d y = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < w.a.size(); ++k) y += (1 - t) * w.l[k] * (pa.balls[static_cast<size_t>(w.a[k])].center - pa.x);
  for (size_t k = 0; k < w.b.size(); ++k) y += t * w.u[k] * (pb.balls[static_cast<size_t>(w.b[k])].center - pb.x);
  return -y;
}


// The most negative scaled multiplier among the candidates outside the
// supports: (1-t)(g_i - alpha) on the source's side, t (g_j - beta) on the
// target's (the objective's rate when weight moves onto that ball).
struct Entering {
  bool source_side = true;
  int ball = -1;
};
Entering split_entering(const Problem& pa, const Problem& pb, double t, const SplitSolution& w,
                        const Eigen::Vector3d& r, double alpha, double beta, const std::vector<int>& ca,
                        const std::vector<int>& cb) {
  Entering e;
  double most_negative = -1e-13 * (1.0 + std::abs((1 - t) * alpha + t * beta));
  for (int i : ca)
    if (std::find(w.a.begin(), w.a.end(), i) == w.a.end()) {
      const double m = (1 - t) * (pa.gradient_entry(i, r) - alpha);
      if (m < most_negative) most_negative = m, e = {true, i};
    }
  for (int j : cb)
    if (std::find(w.b.begin(), w.b.end(), j) == w.b.end()) {
      const double m = t * (pb.gradient_entry(j, r) - beta);
      if (m < most_negative) most_negative = m, e = {false, j};
    }
  return e;
}

// The equality-constrained step on the supports (ka source columns of Z
// and g, then kb target ones), in the scaled unknowns ((1-t) dl, t du), with
// the multipliers alpha and beta of the two simplex constraints; or, when
// [Z; 1_A; 1_B] has dependent columns (the scale of a column does not change
// that, so t does not enter the test), a downhill kernel direction, along
// which the objective is linear.
struct SplitStep {
  SplitVector scaled;
  double alpha = 0, beta = 0;
  bool singular = false;
};
SplitStep split_step(double s, const CentreMatrix& Z, const SplitVector& g, int ka, int kb) {
  const int k = ka + kb;
  SplitMatrix A = SplitMatrix::Zero(5, k);
  A.topRows(3) = Z;
  A.row(3).head(ka).setOnes();
  A.row(4).tail(kb).setOnes();
  Eigen::FullPivLU<SplitMatrix> dependence(A);
  dependence.setThreshold(1e-10);
  SplitStep out;
  out.singular = dependence.rank() < k;
  if (out.singular) {
    out.scaled = dependence.kernel().col(0);
    if (g.dot(out.scaled) > 0) out.scaled = -out.scaled;
    out.scaled *= 1e30;  // unbounded: the ratio test stops it
    return out;
  }
  SplitKkt M = SplitKkt::Zero(k + 2, k + 2);
  M.topLeftCorner(k, k) = 2 * (1 - s) * Z.transpose() * Z;
  M.block(0, k, ka, 1).setConstant(-1.0);
  M.block(ka, k + 1, kb, 1).setConstant(-1.0);
  M.block(k, 0, 1, ka).setConstant(1.0);
  M.block(k + 1, ka, 1, kb).setConstant(1.0);
  SplitVector rhs = SplitVector::Zero(k + 2);
  rhs.head(k) = -g;
  const SplitVector sol = M.fullPivLu().solve(rhs);
  out.scaled = sol.head(k);
  out.alpha = sol[k], out.beta = sol[k + 1];
  return out;
}

// Moves the weights along the step as far as they stay >= 0 (at most the
// full step) and drops a weight that reaches 0; true after a full step.
// Each side's step sums to 0 exactly: the round-off of the target's part,
// divided by a small t, would otherwise move its weights' sum.
bool take_split_step(SplitSolution& w, const SplitVector& scaled, double t) {
  const int ka = static_cast<int>(w.a.size()), kb = static_cast<int>(w.b.size()), k = ka + kb;
  SplitVector step(k);
  step.head(ka) = (scaled.head(ka).array() - scaled.head(ka).mean()) / (1 - t);
  step.tail(kb) = (scaled.tail(kb).array() - scaled.tail(kb).mean()) / t;
  double length = 1.0;
  int blocking = -1;
  for (int c = 0; c < k; ++c) {
    const double weight = c < ka ? w.l[static_cast<size_t>(c)] : w.u[static_cast<size_t>(c - ka)];
    if (step[c] < 0 && -weight / step[c] < length) length = -weight / step[c], blocking = c;
  }
  for (int c = 0; c < ka; ++c) w.l[static_cast<size_t>(c)] += length * step[c];
  for (int c = 0; c < kb; ++c) w.u[static_cast<size_t>(c)] += length * step[ka + c];
  if (blocking >= 0) {
    const bool on_a = blocking < ka;
    const long at = on_a ? blocking : blocking - ka;
    (on_a ? w.a : w.b).erase((on_a ? w.a : w.b).begin() + at);
    (on_a ? w.l : w.u).erase((on_a ? w.l : w.u).begin() + at);
  }
  for (std::vector<double>* weights : {&w.l, &w.u}) {
    const double sum = std::accumulate(weights->begin(), weights->end(), 0.0);
    for (double& v : *weights) v = std::max(v, 0.0) / sum;
  }
  return blocking < 0;
}

// Primal active-set method on the two simplices (as solve_on), t in (0,1).
SplitSolution solve_split(const Problem& pa, const Problem& pb, double t, const std::vector<int>& ca,
                          const std::vector<int>& cb) {
  SplitSolution w{{least_phi(pa, ca)}, {least_phi(pb, cb)}, {1.0}, {1.0}};
  bool at_subproblem_minimum = true;
  for (int iteration = 0; iteration < 400; ++iteration) {
    const int ka = static_cast<int>(w.a.size()), kb = static_cast<int>(w.b.size()), k = ka + kb;
    const Eigen::Vector3d r = split_residual(pa, pb, t, w);
    SplitVector g(k);
    CentreMatrix Z(3, k);
    for (int c = 0; c < k; ++c) {
      const Problem& p = c < ka ? pa : pb;
      const int ball = c < ka ? w.a[static_cast<size_t>(c)] : w.b[static_cast<size_t>(c - ka)];
      g[c] = p.gradient_entry(ball, r);
      Z.col(c) = p.balls[static_cast<size_t>(ball)].center - p.x;
    }
    const SplitStep step = split_step(pa.s, Z, g, ka, kb);
    if (!step.singular && (at_subproblem_minimum || step.scaled.cwiseAbs().maxCoeff() <= 1e-15)) {
      at_subproblem_minimum = false;
      const Entering e = split_entering(pa, pb, t, w, r, step.alpha, step.beta, ca, cb);
      if (e.ball < 0 || k == kMaxSupport) return w;
      (e.source_side ? w.a : w.b).push_back(e.ball);
      (e.source_side ? w.l : w.u).push_back(0.0);
      continue;
    }
    at_subproblem_minimum = take_split_step(w, step.scaled, t);
  }
  return w;
}

// The morph oracle's answer from the split solve, judged exactly as the pair
// solve's: its supports become the pairs (i, j) of weight l_i u_j (the same
// point and value), certified against every pair by each side's least
// multiplier. Candidates on each side grow by the balls that violate.
MorphOracleResult split_evaluate(const BallGrid& grid_a, const BallGrid& grid_b, const Problem& pa,
                                 const Problem& pb, double t) {
  std::vector<int> ca = least_power(grid_a, pa.balls, pa.x, 8), cb = least_power(grid_b, pb.balls, pb.x, 8);
  MorphOracleResult out;
  for (int round = 0; round < 50; ++round) {
    const SplitSolution w = solve_split(pa, pb, t, ca, cb);
    std::vector<BallPair> pairs;
    Solution sol;
    for (size_t i = 0; i < w.a.size(); ++i)
      for (size_t j = 0; j < w.b.size(); ++j)
        if (w.l[i] * w.u[j] > 0) {
          sol.support.push_back(static_cast<int>(pairs.size()));
          sol.lambda.push_back(w.l[i] * w.u[j]);
          pairs.push_back({w.a[i], w.b[j]});
        }
    const std::vector<Ball> balls = interpolated_balls(pa.balls, pb.balls, pairs, t);
    const Problem p{balls, pa.s, pa.x};
    const Stationary st = stationary(p, sol);
    take_solution(out, st, sol, [&](int candidate) { return pairs[static_cast<size_t>(candidate)]; });
    const Least a = least_multiplier(grid_a, pa, st.r), b = least_multiplier(grid_b, pb, st.r);
    out.kkt_violation = std::max(st.violation, (st.mu - ((1 - t) * a.g + t * b.g)) / st.scale);
    out.certified = out.kkt_violation < 1e-9;
    // Balls whose side multiplier lies below that side's mean on its support
    // by more than the pair test allows join the candidates.
    double alpha = 0, beta = 0;
    for (size_t i = 0; i < w.a.size(); ++i) alpha += w.l[i] * pa.gradient_entry(w.a[i], st.r);
    for (size_t j = 0; j < w.b.size(); ++j) beta += w.u[j] * pb.gradient_entry(w.b[j], st.r);
    const auto violators = [&](const BallGrid& grid, const Problem& side, double below, std::vector<int>& candidates) {
      std::vector<int> found;
      visit_near(grid, side.balls, side.x, certification_radius(side.s, st.r, below, grid.max_weight()), [&](int k) {
        if (side.gradient_entry(k, st.r) < below && std::find(candidates.begin(), candidates.end(), k) == candidates.end())
          found.push_back(k);
      });
      candidates.insert(candidates.end(), found.begin(), found.end());
      return !found.empty();
    };
    const bool more_a = violators(grid_a, pa, alpha - 1e-12 * st.scale / (1 - t), ca);
    const bool more_b = violators(grid_b, pb, beta - 1e-12 * st.scale / t, cb);
    if (!more_a && !more_b) break;
  }
  return out;
}

}  // namespace


MorphOracleResult MorphOracle::evaluate(const Eigen::Vector3d& x, double t) const {
  if (!(t >= 0 && t <= 1)) contract_error("MorphOracle: t must lie in [0, 1]");
  if (t == 0) return end_result(source_.evaluate(x), true);
  if (t == 1) return end_result(target_.evaluate(x), false);
  // Candidates: every pair of a few balls of least power on each side (four:
  // the pairs grow as the square, and fewer cost more rounds).
  std::vector<BallPair> pairs;
  for (int i : least_power(*source_.grid_, source_.balls(), x, 4))
    for (int j : least_power(*target_.grid_, target_.balls(), x, 4)) pairs.push_back({i, j});
  return solve_from(x, t, std::move(pairs));
}

MorphOracleResult MorphOracle::evaluate(const Eigen::Vector3d& x, double t, const std::vector<BallPair>& start) const {
  if (!(t >= 0 && t <= 1)) contract_error("MorphOracle: t must lie in [0, 1]");
  std::vector<BallPair> pairs;
  for (const BallPair& pair : start) {
    if (pair.source >= static_cast<int>(source_.balls().size()) || pair.target >= static_cast<int>(target_.balls().size()))
      contract_error("MorphOracle::evaluate: a start pair past a side's last ball");
    if (pair.source >= 0 && pair.target >= 0) pairs.push_back(pair);
  }
  if (pairs.empty() || t == 0 || t == 1 || !x.allFinite()) return evaluate(x, t);
  const bool warm = pairs.size() <= 4;
  return solve_from(x, t, std::move(pairs), warm);
}

// The pair solve from `pairs` (0 < t < 1), which grow by the violators the
// KKT check finds until none is left.
MorphOracleResult MorphOracle::solve_from(const Eigen::Vector3d& x, double t, std::vector<BallPair> pairs,
                                          bool warm) const {
  const double s = source_.shrink();
  const std::vector<Ball>& A = source_.balls();
  const std::vector<Ball>& B = target_.balls();
  const Problem side_a{A, s, x}, side_b{B, s, x};
  MorphOracleResult out;
  for (int round = 0; round < 50; ++round) {
    const std::vector<Ball> balls = interpolated_balls(A, B, pairs, t);
    const Problem p{balls, s, x};
    std::vector<int> all(pairs.size());
    std::iota(all.begin(), all.end(), 0);
    const Solution sol = solve_on(p, all, warm && round == 0);
    const Stationary st = stationary(p, sol);
    take_solution(out, st, sol, [&](int candidate) { return pairs[static_cast<size_t>(candidate)]; });
    // Pair (i, j)'s multiplier is (1-t) g_i + t g_j, least at the least of
    // each side, sought from the support's balls on that side.
    const Least a = least_multiplier_from(*source_.grid_, side_a, st.r, [&](const auto& take) {
      for (int k : sol.support) take(pairs[static_cast<size_t>(k)].source);
    });
    const Least b = least_multiplier_from(*target_.grid_, side_b, st.r, [&](const auto& take) {
      for (int k : sol.support) take(pairs[static_cast<size_t>(k)].target);
    });
    const double least = (1 - t) * a.g + t * b.g;
    out.kkt_violation = std::max(st.violation, (st.mu - least) / st.scale);
    out.certified = out.kkt_violation < 1e-9;
    if (!((st.mu - least) / st.scale > 1e-12)) break;  // no pair violates
    // Violators paired with the other side's least: on side A those with
    // g_i < (mu - t g_b) / (1-t), which lie within that value's reach.
    std::vector<BallPair> violators;
    auto add = [&](BallPair pair) {
      const double g = (1 - t) * side_a.gradient_entry(pair.source, st.r) + t * side_b.gradient_entry(pair.target, st.r);
      if ((st.mu - g) / st.scale > 1e-12 && std::find(pairs.begin(), pairs.end(), pair) == pairs.end() &&
          std::find(violators.begin(), violators.end(), pair) == violators.end())
        violators.push_back(pair);
    };
    const double below_a = (st.mu - t * b.g) / (1 - t), below_b = (st.mu - (1 - t) * a.g) / t;
    visit_near(*source_.grid_, A, x, certification_radius(s, st.r, below_a, source_.grid_->max_weight()),
               [&](int i) { add({i, b.ball}); });
    visit_near(*target_.grid_, B, x, certification_radius(s, st.r, below_b, target_.grid_->max_weight()),
               [&](int j) { add({a.ball, j}); });
    if (violators.empty()) break;
    pairs.insert(pairs.end(), violators.begin(), violators.end());
  }
  if (!out.certified) {  // near t = 0 or 1 the pair solve can miss the minimum: solve in the split unknowns
    MorphOracleResult split = split_evaluate(*source_.grid_, *target_.grid_, side_a, side_b, t);
    if (split.kkt_violation < out.kkt_violation) out = std::move(split);
  }
  return out;
}

}  // namespace skinmesh
