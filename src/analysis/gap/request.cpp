#include <stdexcept>

#include "weilgen/analysis/gap_request.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {

GapOptions GapRequest::options() const {
  GapOptions go;
  for (const std::string& e : effects)
    for (const std::string& n : split(e, ',')) go.effects.push_back(trim(n));
  go.alpha = alpha;
  go.threads = threads;
  return go;
}

void GapRequest::validate() const {
  check_machine();
  if (data.empty()) throw std::invalid_argument("no --data file given");
  options().validate();
  parse_holdout(holdout);
}

GapRun run_gap(const GapRequest& rq) {
  rq.validate();
  GapOptions go = rq.options();
  const std::optional<HoldoutScheme> given = parse_holdout(rq.holdout);
  const Description desc = rq.description();
  go.fixed = parse_fixed_coordinates(desc, rq.at);
  GapRun run;
  run.model = rq.open(desc);
  const ErrorParameterisation param(run.model->description(), parse_pdge_flags(desc, rq.pdge),
                                    run.model->parameters());
  const MeasurementTable table =
      read_measurements(rq.data, machine_read_options(desc, rq.allow_unknown));
  if (rq.warn)
    for (const auto& w : table.warnings) rq.warn(w);
  run.data = gap_data(table, desc, go.fixed, rq.circle, run.model->parameters());
  const HoldoutScheme scheme = given ? *given : default_holdout(run.data);
  run.result = GapDiagnosis(go).run(*run.model, param, run.data, scheme,
                                    holdout_reason(scheme, given.has_value()));
  return run;
}

}  // namespace weilgen
