#include "weilgen/analysis/prediction.hpp"

#include <cmath>
#include <limits>
#include <memory>

#include "weilgen/analysis/ballbar_model.hpp"
#include "weilgen/analysis/per_output_rms.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {

namespace {}  // namespace

Prediction predict_table(const Model& model, const ErrorParameterisation& param,
                         const std::vector<double>& theta, const MeasurementTable& table) {
  const Description& d = model.description();
  Prediction p;
  p.file = table.file;
  std::vector<const std::vector<double>*> coord;
  for (int b : d.axes()) {
    p.axes.push_back(d.bodies[static_cast<std::size_t>(b)].joint.coordinate);
    coord.push_back(&table.column(p.axes.back()));
  }
  ModelData md(model);
  std::vector<double> pose(p.axes.size());
  PerOutputRms<6> measured, difference;
  for (std::size_t r = 0; r < table.rows(); ++r) {
    bool complete = true;
    for (std::size_t a = 0; a < pose.size(); ++a) {
      pose[a] = (*coord[a])[r];
      complete = complete && std::isfinite(pose[a]);
    }
    if (!complete) continue;
    const std::array<double, 6> f = predict_deviation(model, md, param, theta, pose.data());
    std::array<double, 6> m;
    for (std::size_t o = 0; o < 6; ++o) {
      m[o] = table.has(kDeviationColumns[o]) ? table.column(kDeviationColumns[o])[r] : kNaN;
      if (!std::isfinite(m[o])) continue;
      ++p.compared[o];
      measured.add(o, m[o]);
      difference.add(o, m[o] - f[o]);
    }
    p.poses.push_back(pose);
    p.lines.push_back(table.lines[r]);
    p.predicted.push_back(f);
    p.measured.push_back(m);
  }
  if (p.poses.empty())
    throw InputError(SourceLoc{table.file, 0, 0},
                     "no row has every coordinate (" + join(p.axes) + "): nothing to predict");
  p.rms_measured = measured.rms_per_output();
  p.rms_difference = difference.rms_per_output();
  p.max_difference = difference.max_per_output();
  return p;
}

bool is_ballbar_table(const MeasurementTable& table) {
  return table.has("angle_deg") || table.has("dr_um") || !table.header_key("plane").empty();
}

BallbarPrediction predict_ballbar_table(const Model& model, const ErrorParameterisation& param,
                                        const std::vector<double>& theta,
                                        const MeasurementTable& table, const BallbarFlags& flags) {
  BallbarPrediction p;
  p.file = table.file;
  const BallbarMachine machine = ballbar_machine(model);
  p.circle = parse_ballbar_circle(table, machine, flags);
  auto md = std::make_shared<ModelData>(model);
  const DeviationFn fn = [&model, &param, &theta, md](const double* axes, double* out6) {
    param.errors_at(axes, theta.data(), md->errors.data());
    model.deviation(*md, axes, md->errors.data(), out6);
  };
  p.predicted = predict_ballbar(machine, p.circle, fn);
  p.predicted_evaluation = evaluate_ballbar(p.predicted, p.circle.radius_mm);
  if (table.has("dr_um")) {
    for (const BallbarTrace& measured : ballbar_traces(table, p.circle)) {
      const BallbarTrace at = predict_ballbar_at(machine, p.circle, fn, measured.angle_deg);
      p.compared.push_back(compare_ballbar(measured, at, p.circle.radius_mm));
    }
  }
  return p;
}

}  // namespace weilgen
