// Least-squares fits of a position-dependent error y(x) (µm or µrad versus mm) on a basis
// (pdge_basis.hpp), with Zhang & Chen 2021's Table 4 metrics (e_max, R², SSE, RMSE), k-fold
// cross-validation to choose the order (contiguous blocks of positions, or leave-one-cycle-out),
// and a Fourier period search. Algorithm objects (LeastSquaresFit, PeriodSearch, PdgeFit: options
// in, run() const) are separate from the results they return (FitResult, PeriodSearchResult,
// PdgeFitResult: plain data carrying their metrics and CV curve). docs/fit-pdge.md.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "weilgen/machine/pdge_basis.hpp"

namespace weilgen {

// Zhang & Chen 2021's Table 4 metrics (eqs. (6)-(8)) of a fit's residuals r_i = y_i - ỹ_i, in the
// unit of y (SSE in its square).
struct FitMetrics {
  std::size_t n = 0;
  double e_max = NAN;  // max |r_i|
  double r2 = NAN;     // 1 - SSE / sum (y_i - ȳ)²; NaN when every y_i is equal
  double sse = NAN;    // sum r_i²
  double rmse = NAN;   // sqrt(SSE / n)
};
// Throws std::invalid_argument when the sizes differ or are zero.
FitMetrics fit_metrics(const std::vector<double>& y, const std::vector<double>& fitted);

// One least-squares fit on one basis.
struct FitResult {
  Basis basis;
  std::vector<double> coefficients;  // one per basis term, unit of y
  std::vector<double> std_errors;    // sigma * sqrt(diag (XᵀX)⁻¹); NaN when n == p
  double sigma = NAN;                // residual standard deviation sqrt(SSE / (n - p))
  std::size_t rank = 0;              // numerical rank of the design (== size() on success)
  double condition = NAN;  // |R₁₁| / |R_pp| of the pivoted QR: a conditioning estimate
  FitMetrics metrics;
  std::vector<double> fitted, residuals;  // per input row, in input order

  double predict(double x) const { return basis.value(coefficients.data(), x); }
  std::size_t params() const { return coefficients.size(); }
};

struct LeastSquaresOptions {
  // Columns whose pivoted-QR diagonal |R_kk| falls below rank_tolerance * |R₁₁| count as
  // dependent: the fit is refused as rank deficient.
  double rank_tolerance = 1e-9;
};

// Column-pivoted Householder QR (Eigen) of the design matrix X[i][k] = term_k(x_i).
class LeastSquaresFit {
 public:
  explicit LeastSquaresFit(LeastSquaresOptions options = {}) : options_(options) {}
  // Throws std::invalid_argument when x and y differ in size or hold NaN/infinities, when the
  // data has fewer distinct positions than the basis has coefficients ("poly:12 has 13
  // coefficients but the data has 9 distinct positions: the data cannot support this order (use
  // order <= 8)"), or when the design is numerically rank deficient.
  FitResult run(const std::vector<double>& x, const std::vector<double>& y,
                const Basis& basis) const;
  const LeastSquaresOptions& options() const { return options_; }

 private:
  LeastSquaresOptions options_;
};

// ---- Cross-validation ----

// Blocks: the distinct positions, sorted, cut into `folds` contiguous groups whose sizes differ by
// at most one; every row (every cycle) at a position belongs to its position's fold, so a fold is
// a stretch of the travel the fit has not seen. Cycles: one fold per distinct cycle id
// (leave-one-cycle-out; `folds` is ignored).
enum class CvScheme { Blocks, Cycles };
struct CvOptions {
  CvScheme scheme = CvScheme::Blocks;
  // Blocks of about (distinct positions - 2) / folds positions each: with 10 folds a held-out
  // stretch is a tenth of the travel, short enough for wave-shaped errors to be interpolated.
  int folds = 10;
  // Blocks: the rows at the first and last distinct positions are never held out (fold -1), so
  // every held-out row lies between training positions: the error of interpolating across a
  // gap, not of extrapolating beyond the travel (where a fitted PDGE is never used).
  bool keep_ends = true;
};
const char* cv_scheme_name(CvScheme s);  // "blocks", "cycles"

// The fold (0 .. K-1) of every row. Throws std::invalid_argument when folds < 2, when there
// are fewer distinct positions than folds, or (Cycles) when cycles is not one id per row or holds
// fewer than two distinct ids.
std::vector<int> cv_folds(const std::vector<double>& x, const std::vector<int>& cycles,
                          const CvOptions& options);

// Cross-validated squared prediction error: every row is predicted once, by the fit on the other
// folds. mse = sum of squared prediction errors / n (pooled); fold_mse the per-fold means;
// mse_se = sd(fold_mse) / sqrt(K), the standard error used by the one-standard-error rule.
struct CvScore {
  double mse = NAN, mse_se = NAN, rmse = NAN;
  std::vector<double> fold_mse;
};

// ---- Fourier period search ----

// The objective minimised over the period L with the order fixed:
//   Sse  the training SSE of the fit on all rows (the order is fixed, so every L has the same
//        number of coefficients and SSE compares them fairly; cheap and smooth in 1/L);
//   Cv   the cross-validated MSE on the folds given to run().
enum class PeriodObjective { Sse, Cv };
struct PeriodSearchOptions {
  PeriodObjective objective = PeriodObjective::Sse;
  // Search range of L (mm). NaN: from 2·n·Δx (the n-th harmonic at the Nyquist frequency of the
  // median spacing Δx of the distinct positions) to 2·(b - a).
  double min_mm = NAN, max_mm = NAN;
  // Grid spacing in frequency 1/L: 1 / (oversampling · n · (b - a)), a quarter of the spacing
  // at which the n-th harmonic's phase over the travel changes by a full turn.
  int oversampling = 4;
};
struct PeriodSearchResult {
  double period_mm = NAN, objective = NAN;
  std::vector<double> grid_period_mm, grid_objective;  // the coarse grid (NaN: rank deficient)
  int evaluations = 0;
  double min_mm = NAN, max_mm = NAN;  // the range searched
  bool at_bound = false;              // the period found is an end of the range
  FitResult fit;                      // on all rows at the period found
};

// Grid over the frequency 1/L, then Brent's minimiser (Boost) on the bracket around the best
// grid point. Integer multiples of a period fit as well when the order allows their harmonics,
// so L is identified up to them.
class PeriodSearch {
 public:
  explicit PeriodSearch(PeriodSearchOptions options = {}, LeastSquaresOptions least_squares = {})
      : options_(options), least_squares_(least_squares) {}
  // A Fourier basis of `order` >= 1 on [a, b]; `folds` (one per row) only for the Cv objective.
  // Throws std::invalid_argument for order 0, a bad range, or when no period on the grid gives
  // a full-rank fit.
  PeriodSearchResult run(const std::vector<double>& x, const std::vector<double>& y, int order,
                         double a, double b, const std::vector<int>& folds = {}) const;
  const PeriodSearchOptions& options() const { return options_; }

 private:
  PeriodSearchOptions options_;
  LeastSquaresOptions least_squares_;
};

// ---- Order selection ----

// OneStandardError: the smallest order whose CV MSE is within one standard error (mse_se) of the
// minimum CV MSE (Hastie, Tibshirani & Friedman, ESL 7.10). Minimum: the order with the minimum
// CV MSE. Either way the choice comes from held-out error, never from training error.
enum class OrderRule { OneStandardError, Minimum };
const char* order_rule_name(OrderRule r);  // "1se", "min"

struct PdgeFitOptions {
  int min_order = 0, max_order = 10;  // orders tried when the spec's order is auto
  OrderRule rule = OrderRule::OneStandardError;
  CvOptions cv;
  // Used when the spec's period is auto. Inside the cross-validation the period is searched
  // again on every training fold (objective Sse), so the CV error of an auto-period fit includes
  // the cost of choosing its period.
  PeriodSearchOptions period_search;
  LeastSquaresOptions least_squares;
  // 0 <= min_order <= max_order and CV folds >= 2 (std::invalid_argument naming the field).
  void validate() const;
};

// One order on the CV curve.
struct CvCurvePoint {
  int order = 0;
  std::size_t params = 0;   // coefficients (the searched period not counted)
  double period_mm = NAN;   // Fourier: the period of the fit on all rows
  bool feasible = false;    // every training fold and the full data support the order
  std::string reason;       // why not, when not feasible
  double train_rmse = NAN;  // RMSE of the fit on all rows
  CvScore cv;
};

struct PdgeFitResult {
  BasisSpec spec;                   // as asked
  FitResult fit;                    // the chosen order (and period) fitted on all rows
  std::string order_choice;         // "fixed", "1se" or "min"
  std::string period_choice;        // Fourier: "travel", "given" or "search"; else ""
  CvScore cv;                       // of the chosen order (NaN when its CV was not feasible)
  std::string cv_note;              // why cv is NaN, if it is
  int folds = 0;                    // folds used (Blocks: fewer than asked when positions are few)
  bool period_at_bound = false;     // Fourier search: the period is an end of the search range
  int min_cv_order = -1;            // the order with the least CV MSE (auto only)
  std::vector<CvCurvePoint> curve;  // every order tried (the fixed order alone when fixed)
};

// Fits `spec` (order fixed or auto, Fourier period travel/given/auto) to y(x) on [a, b].
// `cycles` is empty or one id per row (needed by CvScheme::Cycles). With CvScheme::Blocks and
// fewer candidate positions than folds, the folds are reduced to the number of candidate
// positions (leave-one-position-out); result.folds says how many were used.
class PdgeFit {
 public:
  explicit PdgeFit(PdgeFitOptions options = {});  // validates the options
  // Throws std::invalid_argument when the data cannot support any order tried (auto) or the
  // fixed order (fixed; the LeastSquaresFit message), or for bad options.
  PdgeFitResult run(const std::vector<double>& x, const std::vector<double>& y,
                    const std::vector<int>& cycles, const BasisSpec& spec, double a,
                    double b) const;
  const PdgeFitOptions& options() const { return options_; }

 private:
  PdgeFitOptions options_;
};

// Number of distinct values (exact comparison) and their median spacing (NaN for fewer than 2).
std::size_t distinct_count(const std::vector<double>& x);
double median_spacing(const std::vector<double>& x);

}  // namespace weilgen
