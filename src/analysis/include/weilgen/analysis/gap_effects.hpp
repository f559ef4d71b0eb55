// The candidate unmodelled effects of the gap diagnosis (docs/gap.md, "Effect library"): each is
// a set of variants (hyper-parameters such as a period, a lag, an axis), and a variant gives
// extra design columns for every observation. Internal to gap.cpp and its tests.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "weilgen/analysis/gap.hpp"
#include "weilgen/model/numeric_chain.hpp"

namespace weilgen::gap_detail {

// What an effect's columns need to know: the data, the model and its parameterisation, the
// observation-to-row map, and a numeric chain for the linearised effects.
struct EffectContext {
  const GapData* data = nullptr;
  const Model* model = nullptr;
  const ErrorParameterisation* param = nullptr;
  std::shared_ptr<const NumericChain> chain;  // exact kinematics (higher_order, tool_offset)
};

struct Variant {
  struct Refine;
  Variant() = default;
  Variant(std::string l, std::vector<double> h, bool theta = false, std::vector<Refine> r = {})
      : label(std::move(l)), hyper(std::move(h)), needs_theta(theta), refine(std::move(r)) {}
  std::string label;          // "temperature T_1 lagged", "X, dy"
  std::vector<double> hyper;  // effect-specific numbers
  bool needs_theta = false;   // columns depend on the identified parameters
  // Continuous hyper-parameters refined around the grid value: (index, lo, hi) bounds.
  std::vector<Refine> refine;
  // A shape along one coordinate in one output (periodic, pdge_shape): GapData::axes index and
  // output 0..5; -1 for other effects. The diagnosis checks that the data can tell the shape
  // from any other along that coordinate.
  int shape_axis = -1, shape_output = -1;
  // needs_theta: refit θ jointly with the columns this many times before they are taken (the
  // columns at the first-order θ are biased when that θ has absorbed part of the effect).
  int theta_iterations = 0;
};

struct Variant::Refine {
  std::size_t index;
  double lo, hi;
};

struct Candidate {
  std::string name;
  std::vector<Variant> variants;
  // Columns (observations × q) of a variant; `theta` is the baseline parameters of the split
  // (only read when the variant needs_theta).
  std::function<Eigen::MatrixXd(const Variant&, const std::vector<double>& theta)> columns;
  // Fills summary/params/region of `fit` from the full-data coefficients c of the columns.
  std::function<void(const Variant&, const Eigen::VectorXd& c, EffectFit& fit)> describe;
};

// The library's candidates that apply to the data (e.g. reversal needs a direction column).
std::vector<Candidate> effect_candidates(const EffectContext& ctx,
                                         const std::vector<std::string>& names);

}  // namespace weilgen::gap_detail
