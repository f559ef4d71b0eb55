// weilgen iso230-2: the ISO 230-2 positioning figures of one axis from a measurement CSV, with the
// Stejskal et al. 2017's thermal-drift-eliminated evaluation side by side. Definitions, the drift
// method, the anomaly criterion and the JSON schema: docs/iso230-2.md; the CSV:
// docs/data-format.md.
#include <iostream>

#include "comp_table.hpp"
#include "flags.hpp"
#include "iso_flags.hpp"
#include "verbs.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/measure/iso230_2_study.hpp"
#include "weilgen/report/iso230_2_document.hpp"
#include "weilgen/report/iso230_2_html.hpp"
#include "weilgen/report/measurement_document.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_iso230_2(const Args& args) {
  po::options_description opts(
      "weilgen iso230-2 <data.csv> [options]\n\n"
      "ISO 230-2:2014 positioning figures of one axis (B, B mean, R up/down/bi, E up/down/bi, M,\n"
      "A up/down/bi; coverage factor 2, and the Student-t widened set for few cycles), and the\n"
      "thermal-drift-eliminated evaluation of Stejskal et al. (2017): adjacent-position\n"
      "differences, the chart rebuilt from a reference position and cycle, anomalous positions,\n"
      "the drift per cycle. The CSV needs the axis column (mm), dir or dir_<axis> (+1/-1), cycle\n"
      "and the deviation along the axis (dx_um for X ...); t_s gives the drift rate in um/h.\n"
      "docs/iso230-2.md, docs/data-format.md.\n\nOptions");
  std::string axis, column, json_path, plot_path, csv_path;
  double alpha = 0.01, tolerance = 1e-6, reference_position = 0;
  long reference_cycle = 0;
  opts.add_options()("help,h", "show this help")(
      "axis", po::value<std::string>(&axis),
      "the coordinate column of the axis (default: '# axis:' header key, else the only coordinate "
      "column, else the only one that varies)")(
      "column", po::value<std::string>(&column),
      "the deviation column (default: dx_um for X, dy_um for Y, dz_um for Z, da_urad, db_urad, "
      "dc_urad for A, B, C)")("reference-position", ranged(&reference_position, NumberRange{}),
                              "drift elimination: the reference target (mm; default the lowest)")(
      "reference-cycle", ranged(&reference_cycle, NumberRange::whole_numbers(-1e15, 1e15)),
      "drift elimination: the reference cycle id (default the lowest; Stejskal et al. 2017 suggest "
      "one "
      "measured after at least 2 h)")("alpha",
                                      ranged(&alpha, NumberRange::open(0, 1))->default_value(alpha),
                                      "family-wise false-positive rate of the anomaly test")(
      "target-tolerance",
      ranged(&tolerance, NumberRange::positive(1e3))->default_value(tolerance, "1e-6"),
      "positions closer than this (mm) are the same target")(
      "allow-unknown", "warn about unknown columns instead of failing")(
      "json", po::value<std::string>(&json_path), "write the results as JSON to FILE")(
      "csv", po::value<std::string>(&csv_path),
      "write the per-target table to FILE (CSV; units in the column names)")(
      "plot", po::value<std::string>(&plot_path),
      "draw the deviation charts to FILE.png or FILE.svg (gnuplot)");
  CompTableFlags comp;
  opts.add(comp_table_options(comp, false));
  IsoFlags iso;
  opts.add(iso_options(iso));
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("iso230-2", args, opts, "data", 1, vm)) return *stop;
  if (!vm.count("data")) return usage_error("iso230-2", "no data file given");
  const std::string data = vm["data"].as<std::string>();
  check_output_paths({{"data file", data}}, {{"--json", json_path},
                                             {"--plot", plot_path},
                                             {"--csv", csv_path},
                                             {"--report", iso.report},
                                             {"--comp-table", comp.path}});
  if (!plot_path.empty()) check_plot_target(plot_path);
  check_comp_table_flags(comp, vm, false);
  ImportOptions io;
  io.read.allow_unknown = vm.count("allow-unknown") > 0;
  io.axis = axis;

  Iso230_2StudyOptions so;
  so.axis = axis;
  so.column = column;
  so.target_tolerance_mm = tolerance;
  so.drift.alpha = alpha;
  if (vm.count("reference-position")) so.drift.reference_position_mm = reference_position;
  if (vm.count("reference-cycle")) so.drift.reference_cycle = reference_cycle;
  apply_iso_flags(iso, vm, so, io);
  const ImportResult imported = read_instrument_file(data, io);
  for (const auto& w : imported.table.warnings) std::cerr << w << "\n";
  const Iso230_2StudyResult r = Iso230_2Study(so).run(imported.table);
  for (const auto& w : r.normalisation.warnings) std::cerr << "warning: " << w << "\n";
  const std::string format = to_string(imported.format);
  const CompTable comp_table =
      comp.path.empty() ? CompTable{} : comp_table_from_iso(r, comp.options.table);
  // The plot first: the step most likely to fail; then JSON, then stdout.
  if (!plot_path.empty())
    write_plot(plot_path, iso230_2_panels(r), "ISO 230-2, " + r.columns.axis + ": " + data);
  if (!json_path.empty())
    write_file_atomically(json_path, iso230_2_json(data, r, format).dump(1) + "\n");
  if (!csv_path.empty()) write_file_atomically(csv_path, iso230_2_csv(r));
  if (!iso.report.empty()) write_file_atomically(iso.report, iso230_2_html(data, r, format));
  if (imported.format != InstrumentFormat::Tidy)
    std::cout << import_summary(data, imported) << "\n";
  std::cout << iso230_2_text(data, r);
  if (!plot_path.empty()) std::cout << "wrote " << plot_path << "\n";
  if (!json_path.empty()) std::cout << "wrote " << json_path << "\n";
  if (!csv_path.empty()) std::cout << "wrote " << csv_path << "\n";
  if (!iso.report.empty()) std::cout << "wrote " << iso.report << "\n";
  if (!comp.path.empty()) std::cout << write_comp_table(comp, comp_table);
  return 0;
}

}  // namespace weilgen::cli
