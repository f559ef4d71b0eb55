#include "weilgen/report/svg_chart.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace weilgen {

namespace {

std::string px(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

std::string tick_label(double v, double step) {
  int decimals = 0;
  if (step < 1) decimals = static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  const double mantissa = step / std::pow(10.0, std::floor(std::log10(step) + 1e-12));
  if (std::abs(mantissa - 2.5) < 1e-6) ++decimals;
  if (std::abs(v) < step * 1e-9) v = 0;  // no "-0"
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*f", std::max(decimals, 0), v);
  return buf;
}

// Legend items: a line (series, rule) or a filled box (band).
struct LegendItem {
  std::string label, colour;
  bool box = false, dashed = false;
  double opacity = 1;
};

// Runs of consecutive finite values: [first, last] index pairs.
std::vector<std::pair<std::size_t, std::size_t>> finite_runs(const std::vector<double>& a,
                                                             const std::vector<double>* b) {
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  std::size_t start = 0;
  bool open = false;
  for (std::size_t i = 0; i <= a.size(); ++i) {
    const bool ok = i < a.size() && std::isfinite(a[i]) && (!b || std::isfinite((*b)[i]));
    if (ok && !open) start = i, open = true;
    if (!ok && open) runs.emplace_back(start, i - 1), open = false;
  }
  return runs;
}

}  // namespace

std::string xml_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::vector<double> nice_ticks(double lo, double hi, int count) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return {};
  if (hi < lo) std::swap(lo, hi);
  if (hi - lo < 1e-12 * std::max(1.0, std::abs(lo))) lo -= 1, hi += 1;
  const double raw = (hi - lo) / std::max(count, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    step = m * mag;
    if (step >= raw * (1 - 1e-9)) break;
  }
  std::vector<double> ticks;
  const double first = std::floor(lo / step + 1e-9) * step;
  for (double t = first; t <= hi + step * (1 - 1e-9); t += step) {
    ticks.push_back(std::abs(t) < step * 1e-9 ? 0.0 : t);
    if (ticks.size() > 200) break;
  }
  return ticks;
}

namespace {

// Every x finite, one y per x in each series, one lo and hi per x in each band.
void check_svg_chart(const SvgChart& c) {
  const std::size_t n = c.x.size();
  for (double v : c.x)
    if (!std::isfinite(v))
      throw std::invalid_argument("svg chart \"" + c.title + "\": x not finite");
  for (const auto& s : c.series)
    if (s.y.size() != n)
      throw std::invalid_argument("svg chart \"" + c.title + "\": series \"" + s.label + "\" has " +
                                  std::to_string(s.y.size()) + " values for " + std::to_string(n) +
                                  " x");
  for (const auto& b : c.bands)
    if (b.lo.size() != n || b.hi.size() != n)
      throw std::invalid_argument("svg chart \"" + c.title + "\": band \"" + b.label +
                                  "\" needs one lo and hi per x");
}

// The legend's rows below the plot, from the plot's left edge at `top` (px).
void svg_legend(std::ostream& o, const std::vector<std::vector<const LegendItem*>>& rows,
                double left, double top) {
  double ly = top;
  for (const auto& row : rows) {
    double lx = left;
    for (const LegendItem* it : row) {
      if (it->box)
        o << "<rect x=\"" << px(lx) << "\" y=\"" << px(ly - 6) << "\" width=\"24\" height=\"10\" "
          << "fill=\"" << it->colour << "\" fill-opacity=\"" << px(std::max(it->opacity, 0.25))
          << "\"/>\n";
      else
        o << "<line x1=\"" << px(lx) << "\" y1=\"" << px(ly) << "\" x2=\"" << px(lx + 24)
          << "\" y2=\"" << px(ly) << "\" stroke=\"" << it->colour << "\" stroke-width=\"2\""
          << (it->dashed ? " stroke-dasharray=\"6 4\"" : "") << "/>\n";
      o << "<text x=\"" << px(lx + 30) << "\" y=\"" << px(ly + 4) << "\">" << xml_escape(it->label)
        << "</text>\n";
      lx += 34 + 6.6 * static_cast<double>(it->label.size());
    }
    ly += 18;
  }
}

}  // namespace

std::string svg_chart(const SvgChart& c) {
  const std::size_t n = c.x.size();
  if (n == 0) throw std::invalid_argument("svg chart \"" + c.title + "\": no x values");
  check_svg_chart(c);

  // Ranges.
  double xlo = *std::min_element(c.x.begin(), c.x.end());
  double xhi = *std::max_element(c.x.begin(), c.x.end());
  if (xhi - xlo < 1e-12) xlo -= 1, xhi += 1;
  double ylo = INFINITY, yhi = -INFINITY;
  auto take = [&](double v) {
    if (std::isfinite(v)) ylo = std::min(ylo, v), yhi = std::max(yhi, v);
  };
  if (c.y_range) {
    take(c.y_range->first);
    take(c.y_range->second);
  } else {
    for (const auto& s : c.series)
      for (double v : s.y) take(v);
    for (const auto& b : c.bands) {
      for (double v : b.lo) take(v);
      for (double v : b.hi) take(v);
    }
    for (const auto& r : c.rules) take(r.y);
  }
  if (!std::isfinite(ylo)) ylo = -1, yhi = 1;
  const std::vector<double> yt = nice_ticks(ylo, yhi, 6);
  const std::vector<double> xt = nice_ticks(xlo, xhi, 7);
  ylo = yt.front(), yhi = yt.back();
  const double ystep = yt.size() > 1 ? yt[1] - yt[0] : 1;
  const double xstep = xt.size() > 1 ? xt[1] - xt[0] : 1;

  // Legend rows (below the plot).
  std::vector<LegendItem> legend;
  for (const auto& b : c.bands)
    if (!b.label.empty()) legend.push_back({b.label, b.colour, true, false, b.opacity});
  for (const auto& s : c.series)
    if (!s.label.empty()) legend.push_back({s.label, s.colour, false, s.dashed, s.opacity});
  for (const auto& r : c.rules)
    if (!r.label.empty()) legend.push_back({r.label, r.colour, false, r.dashed, 1});
  const double left = 66, right = 16, top = c.title.empty() ? 14 : 34, bottom = 52;
  const double plot_w = c.width - left - right, plot_h = c.height - top - bottom;
  std::vector<std::vector<const LegendItem*>> rows(1);
  double row_w = 0;
  for (const auto& item : legend) {
    const double w = 34 + 6.6 * static_cast<double>(item.label.size());
    if (row_w + w > plot_w && !rows.back().empty()) rows.emplace_back(), row_w = 0;
    rows.back().push_back(&item);
    row_w += w;
  }
  const double legend_h = legend.empty() ? 0 : 18.0 * static_cast<double>(rows.size()) + 4;
  const double total_h = c.height + legend_h;
  auto X = [&](double v) { return left + (v - xlo) / (xhi - xlo) * plot_w; };
  auto Y = [&](double v) { return top + (yhi - v) / (yhi - ylo) * plot_h; };
  // The x range is the data's (the ticks may start before it): clip ticks to it.
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\""
    << (c.id.empty() ? "" : " id=\"" + xml_escape(c.id) + "\"") << " width=\"" << c.width
    << "\" height=\"" << px(total_h) << "\" viewBox=\"0 0 " << c.width << " " << px(total_h)
    << "\" font-family=\"Helvetica, Arial, sans-serif\" font-size=\"12\""
    << " role=\"img\" aria-label=\"" << xml_escape(c.title) << "\">\n";
  o << "<rect x=\"0\" y=\"0\" width=\"" << c.width << "\" height=\"" << px(total_h)
    << "\" fill=\"#ffffff\"/>\n";
  if (!c.title.empty())
    o << "<text x=\"" << px(left + plot_w / 2) << "\" y=\"20\" text-anchor=\"middle\" "
      << "font-size=\"14\" font-weight=\"bold\">" << xml_escape(c.title) << "</text>\n";
  // Grid and ticks.
  o << "<g stroke=\"#dddddd\" stroke-width=\"1\">\n";
  for (double t : yt)
    o << "<line x1=\"" << px(left) << "\" y1=\"" << px(Y(t)) << "\" x2=\"" << px(left + plot_w)
      << "\" y2=\"" << px(Y(t)) << "\"/>\n";
  for (double t : xt)
    if (t >= xlo - 1e-9 * xstep && t <= xhi + 1e-9 * xstep)
      o << "<line x1=\"" << px(X(t)) << "\" y1=\"" << px(top) << "\" x2=\"" << px(X(t))
        << "\" y2=\"" << px(top + plot_h) << "\"/>\n";
  o << "</g>\n<g fill=\"#333333\">\n";
  for (double t : yt)
    o << "<text x=\"" << px(left - 6) << "\" y=\"" << px(Y(t) + 4) << "\" text-anchor=\"end\">"
      << tick_label(t, ystep) << "</text>\n";
  for (double t : xt)
    if (t >= xlo - 1e-9 * xstep && t <= xhi + 1e-9 * xstep)
      o << "<text x=\"" << px(X(t)) << "\" y=\"" << px(top + plot_h + 16)
        << "\" text-anchor=\"middle\">" << tick_label(t, xstep) << "</text>\n";
  o << "<text x=\"" << px(left + plot_w / 2) << "\" y=\"" << px(top + plot_h + 36)
    << "\" text-anchor=\"middle\">" << xml_escape(c.xlabel) << "</text>\n";
  o << "<text transform=\"translate(16 " << px(top + plot_h / 2)
    << ") rotate(-90)\" text-anchor=\"middle\">" << xml_escape(c.ylabel) << "</text>\n</g>\n";
  // Data, clipped to the plot.
  const std::string clip = (c.id.empty() ? std::string("chart") : c.id) + "-clip";
  o << "<clipPath id=\"" << xml_escape(clip) << "\"><rect x=\"" << px(left) << "\" y=\"" << px(top)
    << "\" width=\"" << px(plot_w) << "\" height=\"" << px(plot_h)
    << "\"/></clipPath>\n<g clip-path=\"url(#" << xml_escape(clip) << ")\">\n";
  for (const auto& b : c.bands) {
    for (const auto& [i0, i1] : finite_runs(b.lo, &b.hi)) {
      o << "<polygon fill=\"" << b.colour << "\" fill-opacity=\"" << px(b.opacity)
        << "\" stroke=\"none\" points=\"";
      for (std::size_t i = i0; i <= i1; ++i) o << px(X(c.x[i])) << "," << px(Y(b.hi[i])) << " ";
      for (std::size_t i = i1 + 1; i-- > i0;) o << px(X(c.x[i])) << "," << px(Y(b.lo[i])) << " ";
      o << "\"/>\n";
    }
  }
  for (const auto& r : c.rules)
    o << "<line x1=\"" << px(left) << "\" y1=\"" << px(Y(r.y)) << "\" x2=\"" << px(left + plot_w)
      << "\" y2=\"" << px(Y(r.y)) << "\" stroke=\"" << r.colour << "\" stroke-width=\"1.4\""
      << (r.dashed ? " stroke-dasharray=\"7 4\"" : "") << "/>\n";
  for (const auto& s : c.series) {
    const std::string style = "fill=\"none\" stroke=\"" + s.colour + "\" stroke-width=\"" +
                              px(s.width) + "\"" + (s.dashed ? " stroke-dasharray=\"6 4\"" : "") +
                              (s.opacity < 1 ? " stroke-opacity=\"" + px(s.opacity) + "\"" : "");
    for (const auto& [i0, i1] : finite_runs(s.y, nullptr)) {
      o << "<polyline " << style << " points=\"";
      for (std::size_t i = i0; i <= i1; ++i) o << px(X(c.x[i])) << "," << px(Y(s.y[i])) << " ";
      o << "\"/>\n";
    }
    if (s.markers)
      for (std::size_t i = 0; i < n; ++i)
        if (std::isfinite(s.y[i]))
          o << "<circle cx=\"" << px(X(c.x[i])) << "\" cy=\"" << px(Y(s.y[i]))
            << "\" r=\"2.6\" fill=\"" << s.colour << "\"/>\n";
  }
  o << "</g>\n<rect x=\"" << px(left) << "\" y=\"" << px(top) << "\" width=\"" << px(plot_w)
    << "\" height=\"" << px(plot_h) << "\" fill=\"none\" stroke=\"#333333\"/>\n";
  svg_legend(o, rows, left, c.height + 10);
  o << "</svg>\n";
  return o.str();
}

}  // namespace weilgen
