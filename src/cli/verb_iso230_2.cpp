// weilgen iso230-2: the ISO 230-2 positioning figures of one axis from a measurement CSV, with the
// drift seed's thermal-drift-eliminated evaluation side by side. Definitions, the drift method,
// the anomaly criterion and the JSON schema: docs/iso230-2.md; the CSV: docs/data-format.md.
#include <iostream>

#include "comp_table.hpp"
#include "verbs.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/measure/iso230_2_study.hpp"
#include "weilgen/report/iso230_2_document.hpp"

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
  std::string axis, column, json_path, plot_path;
  double alpha = 0.01, tolerance = 1e-6;
  opts.add_options()("help,h", "show this help")(
      "axis", po::value<std::string>(&axis),
      "the coordinate column of the axis (default: '# axis:' header key, else the only coordinate "
      "column, else the only one that varies)")(
      "column", po::value<std::string>(&column),
      "the deviation column (default: dx_um for X, dy_um for Y, dz_um for Z, da_urad, db_urad, "
      "dc_urad for A, B, C)")("reference-position", po::value<double>(),
                              "drift elimination: the reference target (mm; default the lowest)")(
      "reference-cycle", po::value<long>(),
      "drift elimination: the reference cycle id (default the lowest; the seed suggests one "
      "measured after at least 2 h)")("alpha", po::value<double>(&alpha)->default_value(alpha),
                                      "family-wise false-positive rate of the anomaly test")(
      "target-tolerance", po::value<double>(&tolerance)->default_value(tolerance, "1e-6"),
      "positions closer than this (mm) are the same target")(
      "allow-unknown", "warn about unknown columns instead of failing")(
      "json", po::value<std::string>(&json_path), "write the results as JSON to FILE")(
      "plot", po::value<std::string>(&plot_path),
      "draw the deviation charts to FILE.png or FILE.svg (gnuplot)");
  CompTableFlags comp;
  opts.add(comp_table_options(comp, false));
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("iso230-2", args, opts, "data", 1, vm)) return *stop;
  if (!vm.count("data")) return usage_error("iso230-2", "no data file given");
  if (!(alpha > 0 && alpha < 1)) return usage_error("iso230-2", "--alpha must be in (0, 1)");
  if (!(tolerance > 0)) return usage_error("iso230-2", "--target-tolerance must be > 0");
  const std::string data = vm["data"].as<std::string>();
  if (!plot_path.empty()) check_plot_target(plot_path);
  check_comp_table_flags(comp, vm, {data}, false);

  Iso230_2StudyOptions so;
  so.axis = axis;
  so.column = column;
  so.target_tolerance_mm = tolerance;
  so.drift.alpha = alpha;
  if (vm.count("reference-position"))
    so.drift.reference_position_mm = vm["reference-position"].as<double>();
  if (vm.count("reference-cycle")) so.drift.reference_cycle = vm["reference-cycle"].as<long>();
  ReadOptions ro;
  ro.allow_unknown = vm.count("allow-unknown") > 0;
  const MeasurementTable table = read_measurements(data, ro);
  for (const auto& w : table.warnings) std::cerr << w << "\n";
  const Iso230_2StudyResult r = Iso230_2Study(so).run(table);
  const CompTable comp_table =
      comp.path.empty() ? CompTable{} : comp_table_from_iso(r, comp.options.table);
  // The plot first: the step most likely to fail; then JSON, then stdout.
  if (!plot_path.empty())
    write_plot(plot_path, iso230_2_panels(r), "ISO 230-2, " + r.columns.axis + ": " + data);
  if (!json_path.empty()) write_file_atomically(json_path, iso230_2_json(data, r).dump(1) + "\n");
  std::cout << iso230_2_text(data, r);
  if (!plot_path.empty()) std::cout << "wrote " << plot_path << "\n";
  if (!json_path.empty()) std::cout << "wrote " << json_path << "\n";
  if (!comp.path.empty()) std::cout << write_comp_table(comp, comp_table);
  return 0;
}

}  // namespace weilgen::cli
