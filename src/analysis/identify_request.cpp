#include "weilgen/analysis/identify_request.hpp"

#include <stdexcept>

#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {

IdentifyOptions IdentifyRequest::options() const {
  IdentifyOptions io;
  io.rank_tolerance = rank_tolerance;
  io.fixed = fixed;
  return io;
}

void IdentifyRequest::validate() const {
  check_machine();
  if (data.empty()) throw std::invalid_argument("no --data file given");
  options().validate();
  if (!predict_out.empty() && predict.empty())
    throw std::invalid_argument("--predict-out needs a --predict file");
}

IdentifyRun run_identify(const IdentifyRequest& rq) {
  rq.validate();
  const IdentifyOptions io = rq.options();

  // Every input read and checked before the model is opened and fitted, so that nothing fails
  // after the work.
  IdentifyRun run;
  run.files = rq.data;
  const Description desc = rq.description();
  const PdgeBasisChoice choice = parse_pdge_flags(desc, rq.pdge);
  for (const std::string& f : rq.fixed) select_errors(desc, f, "--fix " + quoted(f));
  const ReadOptions ro = machine_read_options(desc, rq.allow_unknown);
  run.points = merged_point_data(rq.data, desc, ro, rq.warn, rq.circle, rq.parameters(desc));
  std::vector<MeasurementTable> tables;
  for (const std::string& p : rq.predict) {
    tables.push_back(read_measurements(p, ro));
    if (rq.warn)
      for (const auto& w : tables.back().warnings) rq.warn(w);
  }
  if (!rq.predict_out.empty() && is_ballbar_table(tables.back()))
    throw std::invalid_argument("--predict-out: " + rq.predict.back() +
                                " is a ballbar trace; the JSON carries its predicted trace");

  run.model = rq.open(desc);
  run.param = std::make_shared<const ErrorParameterisation>(run.model->description(), choice,
                                                            run.model->parameters());
  run.result = Identification(io).run(*run.model, *run.param, run.points);
  for (const MeasurementTable& t : tables) {
    FilePrediction fp;
    if (is_ballbar_table(t))
      fp.ballbar = predict_ballbar_table(*run.model, *run.param, run.result.theta, t, rq.circle);
    else
      fp.points = predict_table(*run.model, *run.param, run.result.theta, t);
    run.predictions.push_back(std::move(fp));
  }
  return run;
}

}  // namespace weilgen
