#include "weilgen/analysis/identify_request.hpp"

#include <stdexcept>

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

  IdentifyRun run;
  run.files = rq.data;
  const Description desc = rq.description();
  const PdgeBasisChoice choice = parse_pdge_flags(desc, rq.pdge);
  run.model = rq.open(desc);
  run.param = std::make_shared<const ErrorParameterisation>(run.model->description(), choice,
                                                            run.model->parameters());
  const ReadOptions ro = machine_read_options(desc, rq.allow_unknown);
  run.points = merged_point_data(rq.data, desc, ro, rq.warn);
  run.result = Identification(io).run(*run.model, *run.param, run.points);

  for (std::size_t i = 0; i < rq.predict.size(); ++i) {
    const MeasurementTable t = read_measurements(rq.predict[i], ro);
    FilePrediction fp;
    if (is_ballbar_table(t)) {
      if (i + 1 == rq.predict.size() && !rq.predict_out.empty())
        throw std::invalid_argument("--predict-out: " + rq.predict[i] +
                                    " is a ballbar trace; the JSON carries its predicted trace");
      fp.ballbar = predict_ballbar_table(*run.model, *run.param, run.result.theta, t, rq.circle);
    } else {
      fp.points = predict_table(*run.model, *run.param, run.result.theta, t);
    }
    run.predictions.push_back(std::move(fp));
  }
  return run;
}

}  // namespace weilgen
