// A machine error model at run time: an immutable Model (what the machine is: its description,
// parameter values and compiled functions) and a ModelData workspace (scratch for one thread).
// Evaluations through a Model allocate nothing once a ModelData exists.
//
// Three engines stand behind the same interface (model_loader.hpp chooses):
//   BuiltIn       a generated header compiled into weilgen (the shipped machines);
//   Compiled      a generated header compiled at run time with the system C++ compiler and
//                 loaded as a shared object (cached by content key);
//   NumericChain  no compiler available: the exact Eigen chain (numeric_chain.hpp), with
//                 coefficients by central differences. Exact kinematics (not truncated at the
//                 algebra order) and ~600x slower.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "weilgen/machine/description.hpp"
#include "weilgen/model/model_abi.hpp"

namespace weilgen {

class NumericChain;
class ModelData;

enum class ModelEngine { BuiltIn, Compiled, NumericChain };
const char* engine_name(ModelEngine engine);

class Model {
 public:
  // A compiled model: `abi` must outlive the Model (`keep_alive` holds the shared object).
  Model(Description desc, const WeilgenModelAbi* abi, ModelEngine engine, std::string origin,
        std::shared_ptr<void> keep_alive);
  // The numeric-chain fallback.
  Model(Description desc, int order, std::string origin);
  ~Model();
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  const Description& description() const { return desc_; }
  const std::string& name() const { return desc_.name; }
  int order() const { return order_; }
  ModelEngine engine() const { return engine_; }
  // Human-readable provenance: "built-in", "compiled (<path>)", "numeric chain (...)".
  const std::string& origin() const { return origin_; }
  std::size_t num_axes() const { return num_axes_; }
  std::size_t num_errors() const { return desc_.errors.size(); }
  std::size_t num_params() const { return params_.size(); }

  // Parameter values (Description::parameters order; mm / deg); defaults until set.
  const std::vector<double>& parameters() const { return params_; }
  void set_parameters(std::vector<double> values);

  // (dx, dy, dz) in mm and (da, db, dc) in rad; axes in their units (mm, deg), errors in base
  // units (mm, rad).
  void deviation(ModelData& data, const double* axes, const double* errors, double* out6) const;
  // `count` deviations at one pose in one call: errors row-major [count][num_errors()],
  // position [count][3] (mm) and orientation [count][3] (rad), either may be null (not
  // computed, where the engine allows). Compiled models loop inside the compiled code.
  void deviation_batch(ModelData& data, const double* axes, std::size_t count, const double* errors,
                       double* position, double* orientation) const;
  // d(output)/d(error) at zero error, row-major [6][num_errors] (mm or rad per base unit).
  void coefficients(ModelData& data, const double* axes, double* coeff) const;
  // deviation(errors) into out6 and coefficients into coeff at one pose in one call: compiled
  // models share the sin/cos and common terms (the generated DeviationAndCoefficients), at about
  // the cost of the deviation alone. Either output may be null (not computed).
  void deviation_and_coefficients(ModelData& data, const double* axes, const double* errors,
                                  double* out6, double* coeff) const;

 private:
  friend class ModelData;
  Description desc_;
  int order_;
  ModelEngine engine_;
  std::string origin_;
  std::size_t num_axes_;
  std::vector<double> params_;
  const WeilgenModelAbi* abi_ = nullptr;
  std::shared_ptr<void> keep_alive_;
  std::unique_ptr<NumericChain> chain_;
};

// Per-thread scratch for Model evaluations (one per thread; never shared concurrently).
class ModelData {
 public:
  explicit ModelData(const Model& model);
  std::vector<double> axes, errors, out;  // free for callers: sized num_axes, num_errors, 6
  std::vector<double> coeff;              // sized 6 * num_errors

 private:
  friend class Model;
  std::vector<double> chain_axes_, chain_errors_;
};

}  // namespace weilgen
