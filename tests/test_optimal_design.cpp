// The exchange algorithm (weilgen/uq/optimal_design.hpp) against exhaustive enumeration and the
// classical optimal designs, and the observability indices against their definitions.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <random>

#include "weilgen/uq/optimal_design.hpp"

using namespace weilgen;
using Eigen::MatrixXd;

namespace {

// Polynomial regression of degree `degree` on the points: one row (1, x, ..., x^degree) each.
DesignProblem polynomial(const std::vector<double>& x, int degree) {
  DesignProblem p;
  for (double v : x) {
    MatrixXd row(1, degree + 1);
    for (int k = 0; k <= degree; ++k) row(0, k) = std::pow(v, k);
    p.units.push_back(row);
  }
  return p;
}

std::vector<double> grid(double a, double b, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(a + (b - a) * i / (n - 1));
  return v;
}

MatrixXd information(const DesignProblem& p, const std::vector<std::size_t>& sel) {
  const auto r = p.units.front().cols();
  MatrixXd M = MatrixXd::Zero(r, r);
  for (std::size_t j : sel) M += p.units[j].transpose() * p.units[j];
  return M;
}

// The best subset of `size` units by enumeration (criterion as ExchangeResult::value; larger is
// better for D and E).
double best_by_enumeration(const DesignProblem& p, std::size_t size, DesignCriterion c,
                           std::vector<std::size_t>* best_set = nullptr) {
  const bool larger = c == DesignCriterion::D || c == DesignCriterion::E;
  double best = larger ? -INFINITY : INFINITY;
  std::vector<std::size_t> sel;
  std::function<void(std::size_t)> rec = [&](std::size_t from) {
    if (sel.size() == size) {
      const double v = design_criterion(information(p, sel), c, p.weight);
      if (larger ? v > best : v < best) {
        best = v;
        if (best_set) *best_set = sel;
      }
      return;
    }
    for (std::size_t j = from; j < p.units.size(); ++j) {
      sel.push_back(j);
      rec(j + 1);
      sel.pop_back();
    }
  };
  rec(0);
  return best;
}

// Three responses per unit: random 3 × r blocks (a pose measured in dx, dy, dz).
DesignProblem random_blocks(std::size_t n, Eigen::Index r, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0, 1);
  DesignProblem p;
  for (std::size_t j = 0; j < n; ++j) {
    MatrixXd b(3, r);
    for (Eigen::Index i = 0; i < b.size(); ++i) b.data()[i] = g(rng);
    p.units.push_back(b);
  }
  MatrixXd L(r, r);
  for (Eigen::Index i = 0; i < L.size(); ++i) L.data()[i] = g(rng);
  p.weight = L * L.transpose() / static_cast<double>(r);
  return p;
}

}  // namespace

TEST_CASE("exchange: the classical D-optimal designs of polynomial regression on [-1, 1]") {
  // Quadratic, 3 points: {-1, 0, 1}; cubic, 4 points: {-1, ±1/√5, 1} (Guest 1958; the roots of
  // (1 − x²) P'_3(x)), here the nearest candidates of a 0.05 grid, ±0.45.
  const std::vector<double> x = grid(-1, 1, 41);
  ExchangeOptions o;
  o.size = 3;
  ExchangeResult r = ExchangeDesign(o).run(polynomial(x, 2));
  CHECK(r.selected == std::vector<std::size_t>{0, 20, 40});
  CHECK(r.value == doctest::Approx(std::log(4.0)));  // det of the 3-point design: 4
  o.size = 4;
  r = ExchangeDesign(o).run(polynomial(x, 3));
  CHECK(r.selected == std::vector<std::size_t>{0, 11, 29, 40});  // -1, -0.45, 0.45, 1
}

TEST_CASE("exchange: every criterion reaches the enumerated optimum on small problems") {
  for (const DesignCriterion c :
       {DesignCriterion::D, DesignCriterion::A, DesignCriterion::E, DesignCriterion::I}) {
    for (unsigned seed : {1u, 2u, 3u}) {
      const std::string name = design_criterion_name(c);
      CAPTURE(name);
      CAPTURE(seed);
      const DesignProblem p = random_blocks(14, 5, seed);
      ExchangeOptions o;
      o.criterion = c;
      o.size = 4;
      o.restarts = 10;
      const ExchangeResult r = ExchangeDesign(o).run(p);
      const double best = best_by_enumeration(p, 4, c);
      // The exchange is a local search: restarts make the enumerated optimum its usual result.
      CHECK(r.value == doctest::Approx(best).epsilon(1e-9));
      CHECK(r.value == doctest::Approx(design_criterion(information(p, r.selected), c, p.weight)));
    }
  }
}

TEST_CASE("exchange: forced units stay, the result does not depend on the threads") {
  const DesignProblem base = random_blocks(60, 8, 7);
  DesignProblem p = base;
  p.forced = {5, 17};
  ExchangeOptions o;
  o.size = 6;
  o.restarts = 6;
  o.criterion = DesignCriterion::I;
  o.threads = 1;
  const ExchangeResult one = ExchangeDesign(o).run(p);
  o.threads = 3;
  const ExchangeResult three = ExchangeDesign(o).run(p);
  CHECK(one.selected == three.selected);
  CHECK(one.restart_values == three.restart_values);
  CHECK(std::count(one.selected.begin(), one.selected.end(), 5u) == 1);
  CHECK(std::count(one.selected.begin(), one.selected.end(), 17u) == 1);
  // A different seed changes the random restarts, not the quality reached here.
  o.seed = 99;
  const ExchangeResult other = ExchangeDesign(o).run(p);
  CHECK(other.value <= one.value * (1 + 0.05));
}

TEST_CASE("exchange: budget mode keeps within the budget and finds the enumerated optimum") {
  DesignProblem p = random_blocks(12, 4, 11);
  std::mt19937 rng(3);
  for (std::size_t j = 0; j < p.units.size(); ++j)
    p.cost.push_back(1 + std::uniform_int_distribution<int>(0, 3)(rng));
  p.budget = 9;
  ExchangeOptions o;
  o.restarts = 12;
  const ExchangeResult r = ExchangeDesign(o).run(p);
  CHECK(r.cost <= p.budget);
  // Enumerate every subset within the budget.
  double best = -INFINITY;
  for (unsigned mask = 0; mask < (1u << 12); ++mask) {
    std::vector<std::size_t> sel;
    double cost = 0;
    for (std::size_t j = 0; j < 12; ++j)
      if (mask & (1u << j)) sel.push_back(j), cost += p.cost[j];
    if (cost > p.budget) continue;
    best = std::max(best, design_criterion(information(p, sel), DesignCriterion::D, p.weight));
  }
  CHECK(r.value == doctest::Approx(best).epsilon(1e-9));
}

TEST_CASE("exchange: a singular start reaches full rank, bad problems are refused") {
  // Candidates that span only in pairs: a random start of 3 units is often singular.
  DesignProblem p;
  for (int j = 0; j < 30; ++j) {
    MatrixXd b = MatrixXd::Zero(1, 3);
    b(0, j % 3) = 1 + 0.01 * j;
    p.units.push_back(b);
  }
  ExchangeOptions o;
  o.size = 3;
  o.restarts = 5;
  const ExchangeResult r = ExchangeDesign(o).run(p);
  CHECK(std::isfinite(r.value));
  o.size = 31;
  CHECK_THROWS_WITH(ExchangeDesign(o).run(p), "exchange: 31 units asked of 30 candidates");
  CHECK_THROWS_WITH(parse_design_criterion("G"), "--criterion: 'G' (expected D, A, E or I)");
  o.restarts = 0;
  CHECK_THROWS_WITH(ExchangeDesign{o}, "--restarts must be at least 1");
}

TEST_CASE("observability indices: the definitions on known singular values") {
  Eigen::VectorXd s(3);
  s << 4, 2, 1;
  const ObservabilityIndices o = observability_indices(s, 8);
  CHECK(o.o1 == doctest::Approx(2.0 / std::sqrt(8.0)));  // (4·2·1)^(1/3) / √8
  CHECK(o.o2 == doctest::Approx(0.25));
  CHECK(o.o3 == doctest::Approx(1.0));
  CHECK(o.o4 == doctest::Approx(0.25));
  CHECK(o.o5 == doctest::Approx(1 / 1.75));
  s[2] = 0;
  CHECK(observability_indices(s, 8).o3 == 0);
}
