// weilgen fit-pdge: parametric fits of position-dependent errors (polynomial, Fourier, Legendre,
// Chebyshev), compared by Zhang & Chen 2021's Table 4 metrics, the order chosen by
// cross-validation. Bases, CV rule, period search, metrics and the JSON schema: docs/fit-pdge.md;
// the 6D line variant of the CSV: docs/data-format.md.
#include <iostream>

#include "flags.hpp"
#include "verbs.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/measure/pdge_fit_study.hpp"
#include "weilgen/report/pdge_fit_document.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_fit_pdge(const Args& args) {
  po::options_description opts(
      "weilgen fit-pdge <data.csv> [options]\n\n"
      "Fits each position-dependent error profile y(x) on polynomial, Fourier, Legendre and\n"
      "Chebyshev bases and compares them by the 6D-laser seed's Table 4 metrics (e_max, R2, SSE,\n"
      "RMSE) and by cross-validated RMSE; with --order auto (the default) the order of each basis\n"
      "is chosen by cross-validation, never by training error.\n"
      "Profiles: a 6D line file ('# format: line6d') gives its six errors converted to ISO names\n"
      "(E_XX ... E_CX, Table 2 signs, straightness line removed); any other measurement CSV gives\n"
      "its deviation columns (dx_um ... dc_urad) against the axis column.\n"
      "docs/fit-pdge.md, docs/data-format.md.\n\nOptions");
  std::vector<std::string> basis_flags, column_flags;
  std::string order = "auto", period = "travel", cv = "blocks", rule = "1se", axis, travel;
  std::string json_path, csv_path, plot_path, angular = "mean";
  int max_order = 10, min_order = 0, folds = 10;
  bool keep_line = false, curves = false;
  opts.add_options()("help,h", "show this help")(
      "basis", po::value<std::vector<std::string>>(&basis_flags)->composing(),
      "bases, comma-separated or repeated: all (default) or KIND[:ORDER[:PERIOD]] with KIND "
      "poly|fourier|legendre|chebyshev, e.g. fourier:3,poly:7 or fourier:auto:auto")(
      "order", po::value<std::string>(&order)->default_value("auto"),
      "order of the bases given without one: a whole number, or auto (cross-validation)")(
      "min-order", ranged(&min_order, NumberRange::whole_numbers(0, 50))->default_value(0),
      "smallest order tried by auto")(
      "max-order", ranged(&max_order, NumberRange::whole_numbers(0, 50))->default_value(10),
      "largest order tried by auto")(
      "period", po::value<std::string>(&period)->default_value("travel"),
      "Fourier period of the bases given without one: travel (b - a), a length in mm, or "
      "auto (searched: grid over 1/L, then Brent, on the training SSE at each order)")(
      "cv", po::value<std::string>(&cv)->default_value("blocks"),
      "cross-validation: blocks (contiguous stretches of positions; the end positions always "
      "train) or cycles (leave one cycle out; needs a cycle column)")(
      "folds", ranged(&folds, NumberRange::whole_numbers(2, 1000))->default_value(10),
      "number of blocks (--cv blocks; fewer when the data has fewer interior positions)")(
      "rule", po::value<std::string>(&rule)->default_value("1se"),
      "order choice: 1se (smallest order within one standard error of the least CV error) | "
      "min (least CV error)")("column",
                              po::value<std::vector<std::string>>(&column_flags)->composing(),
                              "profiles to fit, comma-separated or repeated (E_BX, E_BX_urad, "
                              "dx_um ...; default: every profile)")(
      "axis", po::value<std::string>(&axis),
      "position column of a non-6D file (default: '# axis:' header key, else the only "
      "coordinate column that varies)")(
      "travel", po::value<std::string>(&travel),
      "basis travel a:b in mm (default: the data's smallest to largest position)")(
      "keep-line", po::bool_switch(&keep_line),
      "6D files: keep the straightness reference line (default: removed, eq. (1))")(
      "angular-reference", po::value<std::string>(&angular)->default_value("mean"),
      "6D files: mean (remove each angular profile's mean) | none")(
      "curves", po::bool_switch(&curves), "print the CV curve (error per order) of every fit")(
      "json", po::value<std::string>(&json_path), "write every number to FILE (JSON)")(
      "csv", po::value<std::string>(&csv_path),
      "write one row per profile and basis (order, metrics, CV error) to FILE (CSV)")(
      "plot", po::value<std::string>(&plot_path),
      "draw data, fitted curves and residuals to FILE (.png or .svg, gnuplot)");
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("fit-pdge", args, opts, "data", 1, vm)) return *stop;
  if (!vm.count("data")) return usage_error("fit-pdge", "no data file given");
  const std::string data_path = vm["data"].as<std::string>();
  check_output_paths({{"data file", data_path}},
                     {{"--json", json_path}, {"--csv", csv_path}, {"--plot", plot_path}});
  PdgeFitStudyOptions so;
  so.bases = basis_flags;
  so.order = order;
  so.period = period;
  so.cv = cv;
  so.rule = rule;
  so.min_order = min_order;
  so.max_order = max_order;
  so.folds = folds;
  so.columns = column_flags;
  so.axis = axis;
  so.travel = travel;
  so.keep_line = keep_line;
  so.angular = angular;
  try {
    so.validate();
  } catch (const std::invalid_argument& e) {
    return usage_error("fit-pdge", e.what());
  }
  const PdgeFitStudy study(so);
  if (!plot_path.empty()) check_plot_target(plot_path);
  const PdgeFitStudyResult r = study.run(data_path);
  for (const std::string& w : r.warnings) std::cerr << w << "\n";
  std::cout << pdge_fit_text(so, r, curves);
  if (!json_path.empty()) write_file_atomically(json_path, pdge_fit_json(so, r).dump(1) + "\n");
  if (!csv_path.empty()) write_file_atomically(csv_path, pdge_fit_csv(r));
  if (!plot_path.empty())
    write_plot(plot_path, pdge_fit_panels(r), "weilgen fit-pdge: " + data_path);
  // A basis the data cannot support is reported and the others still fitted; exit status 1.
  return r.failed ? 1 : 0;
}

}  // namespace weilgen::cli
