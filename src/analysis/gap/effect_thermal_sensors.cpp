// thermal_drift as a regularised model of every temperature sensor and the spindle speed
// (docs/gap.md, "Effect library"): each input through first-order lags spanning the run, a ridge
// regression per output with its penalty chosen by blocked cross-validation in time inside the
// training part. One sensor and one lag at a time (effect_thermal.cpp) misses a structure whose
// growth follows several heat sources with different time constants.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>

#include "effects.hpp"
#include "weilgen/base/format.hpp"

namespace weilgen::gap_detail {

namespace {

// The last fit on all observations, for the description.
struct RidgeSummary {
  std::vector<std::string> features;           // "T_5 lag 0.93 h"
  std::map<int, double> lambda;                // per output
  std::map<int, std::vector<double>> weights;  // per output: standardised coefficient per feature
};

struct RidgeInputs {
  std::vector<std::string> names;         // sensors, then rpm
  std::vector<double> lags_s;             // first-order lags (0 = as read)
  std::vector<std::vector<double>> rows;  // per table row: the features, input-major
};

// Ridge coefficients for every penalty at once from the eigen-decomposition of X^T X.
struct RidgePath {
  Eigen::VectorXd s;  // eigenvalues of X^T X
  Eigen::MatrixXd V;
  Eigen::VectorXd vty;  // V^T X^T y
  RidgePath(const MatrixXd& X, const VectorXd& y) {
    Eigen::SelfAdjointEigenSolver<MatrixXd> es(MatrixXd(X.transpose() * X));
    s = es.eigenvalues().cwiseMax(0.0);
    V = es.eigenvectors();
    vty = V.transpose() * (X.transpose() * y);
  }
  VectorXd beta(double lambda) const { return V * (vty.array() / (s.array() + lambda)).matrix(); }
};

}  // namespace

void add_thermal_sensors(const EffectContext& ctx, std::vector<Candidate>& out) {
  const GapData& d = *ctx.data;
  double t0 = INFINITY, t1 = -INFINITY;
  for (const auto& o : d.points.observations)
    if (std::isfinite(d.time_s[o.row]))
      t0 = std::min(t0, d.time_s[o.row]), t1 = std::max(t1, d.time_s[o.row]);
  if (!(t1 > t0)) return;
  auto in = std::make_shared<RidgeInputs>();
  std::vector<const std::vector<double>*> signals;
  for (const auto& [name, v] : d.temperature) in->names.push_back(name), signals.push_back(&v);
  if (d.covariate.count("rpm"))
    in->names.push_back("rpm"), signals.push_back(&d.covariate.at("rpm"));
  if (signals.size() < 2) return;  // one input: the single-sensor variants cover it
  // Direct observations only (a ballbar's dr mixes outputs).
  std::vector<int> outs;
  for (const auto& ob : d.points.observations)
    if (ob.output < kNumDeviationOutputs &&
        std::find(outs.begin(), outs.end(), ob.output) == outs.end())
      outs.push_back(ob.output);
  std::sort(outs.begin(), outs.end());
  if (outs.empty()) return;
  // Lags from as read to a sixth of the run, doubling: the time constants of spindle, headstock
  // and column.
  in->lags_s = {0};
  for (int k = 0; k < 6; ++k) in->lags_s.push_back((t1 - t0) / 200 * std::pow(2.0, k));
  const std::size_t nrows = d.time_s.size(), nf = signals.size() * in->lags_s.size();
  in->rows.assign(nrows, std::vector<double>(nf, 0.0));
  for (std::size_t s = 0; s < signals.size(); ++s)
    for (std::size_t l = 0; l < in->lags_s.size(); ++l) {
      const std::vector<double> f = first_order_lag(d, *signals[s], in->lags_s[l]);
      for (std::size_t r = 0; r < nrows; ++r)
        in->rows[r][s * in->lags_s.size() + l] = std::isfinite(f[r]) ? f[r] : 0.0;
    }
  auto summary = std::make_shared<RidgeSummary>();
  for (const std::string& n : in->names)
    for (double lag : in->lags_s)
      summary->features.push_back(n +
                                  (lag > 0 ? " lag " + format_short(lag / 3600, 2) + " h" : ""));

  Candidate c;
  c.name = "thermal_drift";
  c.variants.push_back({"multi-sensor ridge", {4}});
  c.fitted_columns = [&d, in, outs, summary](const Variant&, const std::vector<std::size_t>& train,
                                             const VectorXd& residual) {
    const auto& obs = d.points.observations;
    const auto nfeat = static_cast<Index>(in->rows.empty() ? 0 : in->rows[0].size());
    MatrixXd E = MatrixXd::Zero(static_cast<Index>(obs.size()), static_cast<Index>(outs.size()));
    const bool full = train.size() == obs.size();
    for (std::size_t k = 0; k < outs.size(); ++k) {
      // The training observations of this output, in time order.
      std::vector<std::size_t> pos;  // positions in `train`
      for (std::size_t i = 0; i < train.size(); ++i)
        if (obs[train[i]].output == outs[k]) pos.push_back(i);
      if (pos.size() < 20) continue;
      std::stable_sort(pos.begin(), pos.end(), [&](std::size_t a, std::size_t b) {
        return d.time_s[obs[train[a]].row] < d.time_s[obs[train[b]].row];
      });
      const auto n = static_cast<Index>(pos.size());
      MatrixXd X(n, nfeat);
      VectorXd y(n);
      for (Index i = 0; i < n; ++i) {
        const std::size_t o = train[pos[static_cast<std::size_t>(i)]];
        for (Index f = 0; f < nfeat; ++f)
          X(i, f) = in->rows[obs[o].row][static_cast<std::size_t>(f)];
        y[i] = residual[static_cast<Index>(pos[static_cast<std::size_t>(i)])];
      }
      // Standardised on the training rows; the intercept is not penalised.
      const Eigen::RowVectorXd mean = X.colwise().mean();
      Eigen::RowVectorXd sd = (X.rowwise() - mean).colwise().norm() / std::sqrt(double(n));
      for (Index f = 0; f < nfeat; ++f)
        if (!(sd[f] > 0)) sd[f] = 1;
      const MatrixXd Xs = (X.rowwise() - mean).array().rowwise() / sd.array();
      const double ym = y.mean();
      const VectorXd yc = y.array() - ym;
      // Penalty by 5 contiguous blocks in time (the held-out part of a drift is later, not
      // interleaved): lambda = n 10^(j/4), j = -24 .. 12.
      std::vector<double> lambdas;
      for (int j = -24; j <= 12; ++j) lambdas.push_back(double(n) * std::pow(10.0, j / 4.0));
      std::vector<double> cv(lambdas.size(), 0.0);
      const Index blocks = 5;
      for (Index b = 0; b < blocks; ++b) {
        const Index lo = n * b / blocks, hi = n * (b + 1) / blocks;
        MatrixXd Xt(n - (hi - lo), nfeat);
        VectorXd yt(n - (hi - lo));
        Xt << Xs.topRows(lo), Xs.bottomRows(n - hi);
        yt << yc.head(lo), yc.tail(n - hi);
        const double ytm = yt.mean();
        const Eigen::RowVectorXd xtm = Xt.colwise().mean();
        const RidgePath path(Xt.rowwise() - xtm, yt.array() - ytm);
        for (std::size_t j = 0; j < lambdas.size(); ++j) {
          const VectorXd beta = path.beta(lambdas[j]);
          const VectorXd pred = ((Xs.middleRows(lo, hi - lo).rowwise() - xtm) * beta).array() + ytm;
          cv[j] += (yc.segment(lo, hi - lo) - pred).squaredNorm();
        }
      }
      const std::size_t best =
          static_cast<std::size_t>(std::min_element(cv.begin(), cv.end()) - cv.begin());
      const VectorXd beta = RidgePath(Xs, yc).beta(lambdas[best]);
      if (full) {
        summary->lambda[outs[k]] = lambdas[best];
        summary->weights[outs[k]].assign(beta.data(), beta.data() + beta.size());
      }
      for (std::size_t i = 0; i < obs.size(); ++i) {
        if (obs[i].output != outs[k]) continue;
        double v = ym;
        for (Index f = 0; f < nfeat; ++f)
          v += (in->rows[obs[i].row][static_cast<std::size_t>(f)] - mean[f]) / sd[f] * beta[f];
        E(static_cast<Index>(i), static_cast<Index>(k)) = v;
      }
    }
    return E;
  };
  c.describe = [in, outs, summary](const Variant&, const VectorXd& coef, EffectFit& fit) {
    std::string per_output;
    std::vector<double> weight(summary->features.size(), 0.0);
    for (std::size_t k = 0; k < outs.size(); ++k) {
      const std::string o = output_name(static_cast<std::size_t>(outs[k]));
      if (k < static_cast<std::size_t>(coef.size()))
        per_output += (per_output.empty() ? "" : ", ") + o + " x" + format_short(coef[Index(k)], 3);
      if (summary->lambda.count(outs[k])) fit.params["lambda_" + o] = summary->lambda[outs[k]];
      for (std::size_t f = 0; f < weight.size() && summary->weights.count(outs[k]); ++f)
        weight[f] += std::abs(summary->weights[outs[k]][f]);
    }
    std::vector<std::size_t> order(weight.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return weight[a] > weight[b]; });
    std::string top;
    for (std::size_t k = 0; k < std::min<std::size_t>(4, order.size()); ++k) {
      top += (top.empty() ? "" : ", ") + summary->features[order[k]];
      fit.params["weight_" + std::to_string(k + 1) + "_" + summary->features[order[k]]] =
          weight[order[k]];
    }
    fit.params["inputs"] = static_cast<double>(in->names.size());
    fit.params["lags"] = static_cast<double>(in->lags_s.size());
    fit.summary = "thermal, ridge over " + std::to_string(in->names.size()) + " inputs x " +
                  std::to_string(in->lags_s.size()) + " lags (" + per_output +
                  "); carried most by " + top;
  };
  out.push_back(std::move(c));
}

}  // namespace weilgen::gap_detail
