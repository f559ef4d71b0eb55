// Line charts as inline SVG, for self-contained HTML reports (no gnuplot, no external files):
// lines with optional markers, shaded bands (mean ± 2s), horizontal rules (tolerances), axes
// with round ticks, a legend below the plot. The output is deterministic text (coordinates with
// two decimals) so that reports can be compared byte for byte. report/plot.hpp draws the same
// kind of figure to PNG/SVG files through gnuplot.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace weilgen {

struct SvgSeries {
  std::string label;      // legend text; "" keeps the series out of the legend
  std::vector<double> y;  // one per x; NaN breaks the line
  std::string colour = "#1f77b4";
  double width = 1.6;  // px
  bool dashed = false;
  bool markers = false;  // a dot at every point
  double opacity = 1.0;
};
// The area between lo and hi (one value per x; NaN breaks it).
struct SvgBand {
  std::string label;
  std::vector<double> lo, hi;
  std::string colour = "#1f77b4";
  double opacity = 0.18;
};
// A horizontal line across the plot at y.
struct SvgRule {
  std::string label;
  double y = 0;
  std::string colour = "#000000";
  bool dashed = true;
};
struct SvgChart {
  std::string id;  // the <svg> element's id ("" for none)
  std::string title, xlabel, ylabel;
  std::vector<double> x;
  std::vector<SvgBand> bands;  // drawn first
  std::vector<SvgSeries> series;
  std::vector<SvgRule> rules;
  std::optional<std::pair<double, double>> y_range;  // fixed y range; none: from the data
  int width = 560, height = 380;                     // px
};

// A self-contained <svg> element. Throws std::invalid_argument when x is empty or not finite,
// or a series or band does not have one value per x.
std::string svg_chart(const SvgChart& chart);

// Round tick values covering [lo, hi] with about `count` steps of 1, 2, 2.5 or 5 × 10^k.
std::vector<double> nice_ticks(double lo, double hi, int count = 6);

// Text for XML and HTML: & < > " ' escaped.
std::string xml_escape(const std::string& text);

}  // namespace weilgen
