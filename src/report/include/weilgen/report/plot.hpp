// Figures through gnuplot (Debian package gnuplot-nox): bar charts (with optional error bars),
// heat maps and line plots, one or several panels per figure. The data and a gnuplot script are
// written to a temporary directory, gnuplot draws into a temporary file next to the target, and
// the file is renamed over the target only when gnuplot succeeded: a failure never leaves a
// partial figure and leaves an existing target untouched. docs/study-inputs.md, "Plotting".
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace weilgen {

// One bar per category; lo/hi empty = no error bars, else the bar's interval (same size as value).
struct BarSeries {
  std::string label;
  std::vector<double> value, lo, hi;
};
struct BarChart {
  std::string title, ylabel;
  std::vector<std::string> categories;
  std::vector<BarSeries> series;  // grouped side by side per category
};
// z[iy * x.size() + ix] at (x[ix], y[iy]); NaN cells stay blank. zmin/zmax NaN: autoscaled.
// annotate: print the values in the cells when the grid is small (at most kMaxAnnotatedCells).
struct HeatMap {
  std::string title, xlabel, ylabel, zlabel;
  std::vector<double> x, y;
  std::vector<double> z;
  double zmin = NAN, zmax = NAN;
  bool annotate = true;
};
enum class LineStyle { LinesPoints, Lines, Points };
// A shaded area between lo and hi (same size as x), drawn under the lines (x̄ ± 2s).
struct LineBand {
  std::string label;
  std::vector<double> lo, hi;
  std::size_t line = static_cast<std::size_t>(-1);  // drawn in the colour of lines[line]
};
// A horizontal dashed line across the plot at y (a tolerance).
struct LineRule {
  std::string label;  // "" keeps it out of the key
  double y = 0;
};
struct LinePlot {
  std::string title, xlabel, ylabel;
  std::vector<double> x;
  std::vector<std::pair<std::string, std::vector<double>>> lines;  // label, y (same size as x)
  std::vector<LineBand> bands = {};
  std::vector<LineRule> rules = {};
};
// A line plot whose lines have their own styles: measured points (Points skip NaN values, so
// they can share a dense x grid) among fitted curves (Lines).
struct StyledLinePlot {
  LinePlot plot;
  std::vector<LineStyle> styles;  // one per line of `plot`
};
using Panel = std::variant<BarChart, HeatMap, LinePlot, StyledLinePlot>;

constexpr std::size_t kMaxAnnotatedCells = 144;

// A Pareto chart: the categories in descending order of series `key` (NaN last, ties in their
// order), without the categories where every series is 0 or NaN (an error without effect),
// unless that is every category.
void pareto(BarChart& chart, std::size_t key = 0);

// Writes the panels into one figure at `path` (stacked one per row when a bar chart has many
// categories, else in a grid of up to three columns). The format follows the extension: .png
// (pngcairo) or .svg; anything else throws std::invalid_argument. Text is printed as written
// (no enhanced-text markup: E_XX stays E_XX). Throws std::invalid_argument for inconsistent
// panel data, std::runtime_error when gnuplot is missing ("gnuplot not found on PATH: install
// gnuplot-nox (scripts/install_deps.sh does) or omit --plot") or fails (with its message).
void write_plot(const std::string& path, const std::vector<Panel>& panels,
                const std::string& figure_title);

// "png" or "svg" from the extension of `path` (case-insensitive); throws std::invalid_argument
// "plot FILE: unsupported file type ".pdf" (expected .png or .svg)" otherwise.
std::string plot_format(const std::string& path);
// What write_plot would refuse before drawing, so a command can fail before a long computation:
// a bad extension (std::invalid_argument) or gnuplot missing from PATH (std::runtime_error).
void check_plot_target(const std::string& path);
// Whether an executable `gnuplot` is on PATH.
bool gnuplot_available();

// The gnuplot script write_plot runs (for inspection and tests): writes the panels' data files
// into the existing directory `data_dir` and returns a script that draws into `output` in
// `format` ("png" or "svg"). Throws std::invalid_argument like write_plot.
std::string plot_script(const std::string& data_dir, const std::string& output,
                        const std::string& format, const std::vector<Panel>& panels,
                        const std::string& figure_title);

}  // namespace weilgen
