// The planner's internals shared by plan.cpp (count and target modes) and plan_budget.cpp (the
// time budget): the planning model, the frame of the exchange and the exact evaluation.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "weilgen/analysis/plan.hpp"
#include "weilgen/uq/dense.hpp"
#include "weilgen/uq/lsq.hpp"

namespace weilgen::plan_detail {

using Eigen::MatrixXd;
using Eigen::VectorXd;

std::uint64_t mix(std::uint64_t z);
// The noise (µm, µrad) of an observation of `kind` made by a unit of set-up `setup`.
double noise_of(const PlanInput& in, std::size_t setup, int kind);

// The model the planner works with: every unit's rows (noise-weighted) over the free parameters
// and the nuisance columns of set-up references shared by several units (a 6D line's reference
// over the positions of its axis, an R-test's zeros over the poses of its nest); a reference
// within one unit (a ballbar circle's centre) is projected out of that unit's rows.
class PlanModel {
 public:
  PlanModel(const PlanInput& in, const std::vector<std::size_t>& cols) : in_(in), cols_(cols) {}

  // The blocks of `units` (k_j × (free + nuisance) each). New nuisance keys are added when
  // `grow` (the candidates define them).
  std::vector<MatrixXd> blocks(const std::vector<PlanUnit>& units, bool grow);

  std::size_t nuisance() const { return nuisance_count_; }

 private:
  const PlanInput& in_;
  std::vector<std::size_t> cols_;
  std::map<std::string, std::size_t> nuisance_;
  std::size_t nuisance_count_ = 0;
};

// The frame of the exchange: every column scaled by its RMS over the candidates, then the
// candidates' estimable space (their right singular vectors above the rank tolerance).
struct Frame {
  VectorXd scale;           // per column (free parameters, then nuisance)
  MatrixXd Q;               // columns × r
  MatrixXd W;               // r × r: the I criterion's weight
  std::vector<MatrixXd> Z;  // the candidates in the frame
  MatrixXd to_frame(const MatrixXd& block) const {
    const Eigen::Index w = scale.size();
    MatrixXd b = MatrixXd::Zero(block.rows(), w);
    b.leftCols(std::min(w, block.cols())) = block.leftCols(std::min(w, block.cols()));
    return b * scale.cwiseInverse().asDiagonal() * Q;
  }
};

Frame make_frame(const std::vector<MatrixXd>& blocks, double rank_tol, Eigen::Index max_rank);

// dx, dy, dz observations (values 0) at each pose.
PointData volumetric_rows(std::vector<std::vector<double>> poses);
// The volumetric prediction rows: dx, dy, dz at a 5-level grid over every axis's travel.
PointData prediction_grid(const Description& d);

struct Context {
  const PlanInput& in;
  const PlanOptions& o;
  std::vector<std::size_t> cols;  // free parameters
  MatrixXd Wg;                    // the grid's Gram over the free parameters, per row
  PlanModel model;
  Frame frame;
  Context(const PlanInput& i, const PlanOptions& opt, std::vector<std::size_t> c)
      : in(i), o(opt), cols(std::move(c)), model(i, cols) {}
};

// The figures of a layout as identify will estimate from it; its information in the frame from
// `frame_blocks` (the units' rows there) or computed; `keep_svd`, `cov_out`: identify's SVD and
// the parameters' covariance (free parameters); `in_frame` false: no frame figures.
LayoutFigures evaluate(Context& cx, const std::string& name, const std::vector<PlanUnit>& units,
                       const std::vector<MatrixXd>* frame_blocks,
                       EquilibratedSvd* keep_svd = nullptr, MatrixXd* cov_out = nullptr,
                       bool in_frame = true);
std::vector<MatrixXd> frame_blocks_of(const Context& cx, const std::vector<std::size_t>& idx);
std::vector<PlanUnit> units_of(const PlanCandidates& c, const std::vector<std::size_t>& idx);
LayoutFigures evaluate_candidates(Context& cx, const std::string& name,
                                  const std::vector<std::size_t>& idx);
// Greedy rank building in the frame: units in turn, each adding the most new directions, until
// the frame's rank. Returns how many units it took.
std::size_t greedy_rank_units(const Frame& f, const std::vector<std::size_t>& forced);

// The time budget (plan_budget.cpp): the set-ups and units within o.budget_s.
void plan_budget(Context& cx, PlanResult& R);

}  // namespace weilgen::plan_detail
