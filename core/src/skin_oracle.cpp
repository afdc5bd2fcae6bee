// Primal active-set method (Nocedal & Wright, Numerical Optimization, 2nd ed.,
// Algorithm 16.3) on the simplex, over the balls of smallest power distance,
// followed by a check of the KKT conditions against every ball; balls that
// violate them join the candidates and the solve repeats.
#include "skinmesh/core/skin_oracle.hpp"
#include "skinmesh/core/error.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace skinmesh {

double OracleResult::distance() const {
  const double g = gradient.norm();
  return g > 0 ? std::abs(value) / g : std::abs(value) > 0 ? INFINITY : 0.0;
}

SkinOracle::SkinOracle(std::vector<Ball> balls, double shrink) : balls_(std::move(balls)), shrink_(shrink) {
  if (balls_.empty()) contract_error("SkinOracle needs at least one ball");
  if (!(shrink > 0 && shrink < 1)) contract_error("shrink factor must lie in (0,1)");
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

// Active-set solve restricted to `candidates`. Returns the support and weights.
Solution solve_on(const Problem& p, const std::vector<int>& candidates) {
  const double s = p.s;
  // Start at the best vertex of the simplex.
  int start = candidates[0];
  double best = INFINITY;
  for (int i : candidates) {
    const Ball& b = p.balls[static_cast<size_t>(i)];
    const double phi = (1 - s) * (p.x - b.center).squaredNorm() + s * b.power(p.x);
    if (phi < best) best = phi, start = i;
  }
  std::vector<int> S{start};
  std::vector<double> l{1.0};
  // After a full step the weights sit at the minimiser on S: the next solve's
  // step is round-off, so go straight to the multipliers.
  bool at_subproblem_minimum = true;
  for (int iteration = 0; iteration < 200; ++iteration) {
    const int k = static_cast<int>(S.size());
    Eigen::Vector3d y = Eigen::Vector3d::Zero();
    for (int a = 0; a < k; ++a) y += l[a] * p.balls[static_cast<size_t>(S[a])].center;
    const Eigen::Vector3d r = p.x - y;
    Eigen::VectorXd g(k);
    // Centres relative to x: the objective only sees x - Z l, and with
    // coordinates ~100 A the absolute Gram matrix has entries ~1e4 that are
    // nearly equal, which makes the KKT system look singular when it is not.
    Eigen::MatrixXd Z(3, k);
    for (int a = 0; a < k; ++a) {
      g[a] = p.gradient_entry(S[a], r);
      Z.col(a) = p.balls[static_cast<size_t>(S[a])].center - p.x;
    }
    // The KKT system below is singular exactly when the centres of S are
    // affinely dependent: [Z; 1^T] d = 0 has a non-zero solution.
    Eigen::MatrixXd A(4, k);
    A.topRows(3) = Z;
    A.row(3).setOnes();
    Eigen::FullPivLU<Eigen::MatrixXd> dependence(A);
    dependence.setThreshold(1e-10);
    const bool singular = dependence.rank() < k;
    Eigen::VectorXd step;
    double mu = 0;
    if (!singular) {
      // Equality-constrained step on S: [2(1-s) Z^T Z, -1; 1^T, 0] [step; mu] = [-g; 0].
      Eigen::MatrixXd M = Eigen::MatrixXd::Zero(k + 1, k + 1);
      M.topLeftCorner(k, k) = 2 * (1 - s) * Z.transpose() * Z;
      M.block(0, k, k, 1).setConstant(-1.0);
      M.block(k, 0, 1, k).setConstant(1.0);
      Eigen::VectorXd rhs = Eigen::VectorXd::Zero(k + 1);
      rhs.head(k) = -g;
      const Eigen::VectorXd sol = M.fullPivLu().solve(rhs);
      step = sol.head(k);
      mu = sol[k];
    } else {
      // Affinely dependent centres: along a direction d with sum d = 0 and
      // Z d = 0 the objective is linear; go downhill until a weight reaches 0.
      Eigen::VectorXd d = dependence.kernel().col(0);
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
      if (entering < 0) return {S, l};
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
  return {S, l};
}

}  // namespace

OracleResult SkinOracle::evaluate(const Eigen::Vector3d& x) const {
  const Problem p{balls_, shrink_, x};
  const int n = static_cast<int>(balls_.size());
  // Candidates: the balls of smallest power distance at x.
  std::vector<double> power(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) power[static_cast<size_t>(i)] = balls_[static_cast<size_t>(i)].power(x);
  std::vector<int> order(static_cast<size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  const int first = std::min(n, 24);
  std::nth_element(order.begin(), order.begin() + (first - 1), order.end(),
                   [&](int a, int b) { return power[static_cast<size_t>(a)] < power[static_cast<size_t>(b)]; });
  std::vector<int> candidates(order.begin(), order.begin() + first);

  OracleResult out;
  for (int round = 0; round < 50; ++round) {
    const Solution sol = solve_on(p, candidates);
    Eigen::Vector3d y = Eigen::Vector3d::Zero();
    double linear = 0;
    for (size_t a = 0; a < sol.support.size(); ++a) {
      const Ball& b = balls_[static_cast<size_t>(sol.support[a])];
      y += sol.lambda[a] * b.center;
      linear += sol.lambda[a] * b.power(x);
    }
    const Eigen::Vector3d r = x - y;
    out.value = (1 - shrink_) * r.squaredNorm() + shrink_ * linear;
    out.gradient = 2.0 * r;
    out.support.clear();
    for (size_t a = 0; a < sol.support.size(); ++a)
      if (sol.lambda[a] > 0) out.support.emplace_back(sol.support[a], sol.lambda[a]);

    // KKT: g_i = mu on the support, g_k >= mu for every ball. Scale: the size
    // of the terms in g, so the test is relative.
    double mu = 0, wsum = 0;
    for (size_t a = 0; a < sol.support.size(); ++a) {
      mu += sol.lambda[a] * p.gradient_entry(sol.support[a], r);
      wsum += sol.lambda[a];
    }
    mu /= wsum;
    double reach = 1.0;
    for (int i : sol.support) reach = std::max(reach, (balls_[static_cast<size_t>(i)].center - x).norm());
    const double scale = 1.0 + std::abs(mu) + 2 * (1 - shrink_) * r.norm() * reach;
    double violation = 0;
    for (int i : sol.support) violation = std::max(violation, std::abs(p.gradient_entry(i, r) - mu) / scale);
    std::vector<int> violators;
    for (int k = 0; k < n; ++k) {
      const double gap = (mu - p.gradient_entry(k, r)) / scale;
      if (gap > 1e-12 && std::find(candidates.begin(), candidates.end(), k) == candidates.end())
        violators.push_back(k);
      violation = std::max(violation, gap);
    }
    out.kkt_violation = violation;
    out.certified = violation < 1e-9;
    if (violators.empty()) break;
    candidates.insert(candidates.end(), violators.begin(), violators.end());
  }
  return out;
}

}  // namespace skinmesh
