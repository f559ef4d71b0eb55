#include "weilgen/measure/iso230_2_study.hpp"

#include <stdexcept>

namespace weilgen {

void Iso230_2StudyOptions::validate() const {
  if (!(drift.alpha > 0 && drift.alpha < 1))
    throw std::invalid_argument("--alpha must be in (0, 1)");
  if (!(target_tolerance_mm > 0)) throw std::invalid_argument("--target-tolerance must be > 0");
}

Iso230_2Study::Iso230_2Study(Iso230_2StudyOptions options) : options_(std::move(options)) {
  options_.validate();
}

Iso230_2StudyResult Iso230_2Study::run(const MeasurementTable& table) const {
  Iso230_2StudyResult r;
  r.columns = iso_columns(table, options_.axis, options_.column);
  r.runs =
      group_iso_runs(iso_observations(table, r.columns), table.file, options_.target_tolerance_mm);
  r.classical = Iso230_2Evaluation().run(r.runs);
  if (r.runs.targets() >= 2) {
    DriftOptions d = options_.drift;
    d.tolerance_mm = options_.target_tolerance_mm;
    r.drift = DriftElimination(d).run(r.runs);
  } else if (options_.drift.reference_position_mm || options_.drift.reference_cycle) {
    throw std::invalid_argument("--reference-position/--reference-cycle need >= 2 targets");
  }
  return r;
}

}  // namespace weilgen
