// weilgen import: a laser calibration export (Renishaw XL-80/CARTO wide CSV, weilgen's generic
// wide form, or a tidy file) read and printed as the tidy measurement CSV every verb reads. The
// reader and the mapping: weilgen/measure/instrument_import.hpp, docs/data-format.md.
#include <iostream>

#include "flags.hpp"
#include "verbs.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/measure/instrument_import.hpp"
#include "weilgen/report/measurement_document.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_import(const Args& args) {
  po::options_description opts(
      "weilgen import <file> [options]\n\n"
      "Reads a laser calibration export and prints it as the tidy measurement CSV (one row per\n"
      "observation: target, dir, cycle, deviation, environment): the wide per-run CSV of a\n"
      "Renishaw XL-80 / CARTO linear test ('Target Position (mm)', 'Direction', 'Run 1 (um)',\n"
      "... with 'Key,Value' lines before the table), weilgen's generic wide form ('# format:\n"
      "wide', columns dx_um@1, dx_um@2 ...), or a tidy file (checked and printed as read). The\n"
      "mapping of every source column is printed as comments. docs/data-format.md.\n\nOptions");
  std::string format = "auto", axis, out;
  opts.add_options()("help,h", "show this help")(
      "format", po::value<std::string>(&format)->default_value(format),
      "auto, tidy, carto or wide")(
      "axis", po::value<std::string>(&axis),
      "the axis (X, Y, Z, A, B, C ...) when the file does not name it")(
      "allow-unknown", "skip (CARTO) or keep (tidy, wide) unknown columns with a warning")(
      "out", po::value<std::string>(&out), "write the tidy CSV to FILE instead of stdout");
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("import", args, opts, "file", 1, vm)) return *stop;
  if (!vm.count("file")) return usage_error("import", "no file given");
  const std::string file = vm["file"].as<std::string>();
  ImportOptions io;
  if (lower(format) != "auto") io.format = parse_instrument_format(format);
  io.axis = axis;
  io.read.allow_unknown = vm.count("allow-unknown") > 0;
  check_output_paths({{"data file", file}}, {{"--out", out}});
  const ImportResult r = read_instrument_file(file, io);
  for (const auto& w : r.table.warnings) std::cerr << w << "\n";
  const std::string csv = measurement_csv(r.table, import_comments(file, r));
  if (out.empty()) {
    std::cout << csv;
    return 0;
  }
  write_file_atomically(out, csv);
  std::cout << import_summary(file, r) << "wrote " << out << "\n";
  return 0;
}

}  // namespace weilgen::cli
