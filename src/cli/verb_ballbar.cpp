// weilgen ballbar: a ballbar trace evaluated on its own — ISO 230-4 G (least-squares and
// minimum-zone centre), F and H per run, and the usual causes (backlash, reversal spikes, lateral
// play, cyclic error, servo mismatch, squareness, straightness, scale mismatch) fitted on the
// trace and ranked; with --machine also through the machine's model. docs/ballbar.md.
#include <iostream>

#include "flags.hpp"
#include "study.hpp"
#include "verbs.hpp"
#include "weilgen/analysis/ballbar_request.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/report/ballbar_document.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_ballbar(const Args& args) {
  StudyFlags flags;
  BallbarRequest rq;
  po::options_description opts(
      "weilgen ballbar <trace.csv> [options]\n\n"
      "A ballbar circular test evaluated on its own: ISO 230-4's circular deviation G (least-\n"
      "squares and minimum-zone centre), radial deviation F, centre offset and radius deviation\n"
      "per run, the circular hysteresis H, and the usual causes fitted on the trace by least\n"
      "squares and ranked by their contribution: backlash, reversal spikes, lateral play and\n"
      "cyclic error per axis, servo mismatch, squareness, straightness per axis, scale mismatch.\n"
      "With --machine the circle is checked against the machine and the model's terms behind\n"
      "each geometric cause are named. docs/ballbar.md, docs/data-format.md.\n\nOptions");
  std::string json_path, plot_path, report_path;
  opts.add_options()("help,h", "show this help")(
      "machine", po::value<std::string>(&flags.request.machine),
      "a shipped machine or machine file: evaluate through its model (optional)")(
      "feedrate", po::value<std::string>(&rq.feedrate),
      "the programmed feed (e.g. '1000 mm/min'; mm/s, m/min, in/min): servo mismatch as a time "
      "lag (default: the header key feedrate)")(
      "alpha", ranged(&rq.alpha, NumberRange::open(0, 1))->default_value(rq.alpha),
      "family-wise false-positive rate of the causes' significance tests")(
      "min-contribution",
      ranged(&rq.min_contribution_um, NumberRange::closed(0, 1e3))
          ->default_value(rq.min_contribution_um),
      "the smallest contribution (um, max - min of its part of dr) a cause is named with")(
      "pdge", po::value<std::vector<std::string>>(&rq.pdge)->composing(),
      "with --machine: the PDGE basis of the model's terms (default poly:2)")(
      "json", po::value<std::string>(&json_path), "write the results as JSON to FILE")(
      "plot", po::value<std::string>(&plot_path),
      "draw the polar plot (both directions, minimum zone, diagnosis) to FILE.svg")(
      "report", po::value<std::string>(&report_path),
      "write the report as one self-contained HTML file")(
      "allow-unknown", "warn about unknown columns instead of failing")(
      "quiet,q", po::bool_switch(&flags.quiet), "no model messages on stderr");
  opts.add(ballbar_circle_options(rq.circle));
  opts.add(model_options(flags));
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("ballbar", args, opts, "trace", 1, vm)) return *stop;
  if (!vm.count("trace")) return usage_error("ballbar", "no trace file given");
  rq.trace = vm["trace"].as<std::string>();
  if (vm.count("pdge") && flags.request.machine.empty())
    return usage_error("ballbar", "--pdge: the model's terms need --machine");
  fill_measurement_request(vm, flags, rq);
  try {
    rq.validate();
  } catch (const std::invalid_argument& e) {
    return usage_error("ballbar", e.what());
  }
  rq.check_outputs(json_path, plot_path, report_path);

  const BallbarStudy st = run_ballbar(rq);
  if (!plot_path.empty()) write_file_atomically(plot_path, ballbar_polar_svg(st));
  if (!json_path.empty()) write_file_atomically(json_path, ballbar_json(st).dump(1) + "\n");
  if (!report_path.empty()) write_file_atomically(report_path, ballbar_html(st));
  std::cout << ballbar_text(st);
  for (const std::string* p : {&plot_path, &json_path, &report_path})
    if (!p->empty()) std::cout << "wrote " << *p << "\n";
  return 0;
}

}  // namespace weilgen::cli
