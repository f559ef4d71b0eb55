#include "weilgen/report/plot.hpp"

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {
namespace {

namespace fs = std::filesystem;

const char* const kNotFound =
    "gnuplot not found on PATH: install gnuplot-nox (scripts/install_deps.sh does) or omit --plot";

// A gnuplot single-quoted string: no escapes, '' is a quote; one line.
std::string gq(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') {
      out += "''";
    } else if (c == '\n' || c == '\r' || c == '\t') {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out + "'";
}

// A shell single-quoted word.
std::string shq(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// A data-file field: tab-separated, so no tabs, newlines or double quotes inside.
std::string field(const std::string& s) {
  std::string out;
  for (char c : s) out += (c == '\t' || c == '\n' || c == '\r' || c == '"') ? ' ' : c;
  return out.empty() ? std::string(" ") : out;
}

// gnuplot reads NaN and Inf by these names.
std::string gnuplot_number(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "Inf" : "-Inf";
  return format_number(v);
}

std::string short_num(double v) {
  if (!std::isfinite(v)) return "n/a";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::string format_of_path(const std::string& path) {
  const std::string ext = lower(fs::path(path).extension().string());
  if (ext == ".png") return "png";
  if (ext == ".svg") return "svg";
  throw std::invalid_argument("plot " + path + ": unsupported file type \"" +
                              fs::path(path).extension().string() + "\" (expected .png or .svg)");
}

void write_data(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << text;
  out.flush();
  if (!out) throw std::runtime_error("plot: cannot write " + file.string());
}

[[noreturn]] void bad(const std::string& title, const std::string& what) {
  throw std::invalid_argument("plot panel \"" + title + "\": " + what);
}

void check(const BarChart& c) {
  if (c.categories.empty()) bad(c.title, "a bar chart needs at least one category");
  if (c.series.empty()) bad(c.title, "a bar chart needs at least one series");
  for (const BarSeries& s : c.series) {
    if (s.value.size() != c.categories.size()) {
      bad(c.title, "series \"" + s.label + "\" has " + std::to_string(s.value.size()) +
                       " values for " + std::to_string(c.categories.size()) + " categories");
    }
    const bool none = s.lo.empty() && s.hi.empty();
    if (!none && (s.lo.size() != s.value.size() || s.hi.size() != s.value.size())) {
      bad(c.title, "series \"" + s.label +
                       "\": lo and hi must both be empty or have one value "
                       "per category");
    }
  }
}

void check(const HeatMap& h) {
  if (h.x.empty() || h.y.empty()) bad(h.title, "a heat map needs at least one x and one y");
  if (h.z.size() != h.x.size() * h.y.size()) {
    bad(h.title,
        "z has " + std::to_string(h.z.size()) +
            " values, expected x.size() * y.size() = " + std::to_string(h.x.size() * h.y.size()));
  }
  for (const auto* v : {&h.x, &h.y}) {
    for (double d : *v) {
      if (!std::isfinite(d)) bad(h.title, "x and y must be finite");
    }
  }
}

void check(const LinePlot& l) {
  if (l.x.empty()) bad(l.title, "a line plot needs at least one x");
  if (l.lines.empty()) bad(l.title, "a line plot needs at least one line");
  for (const auto& [label, y] : l.lines) {
    if (y.size() != l.x.size()) {
      bad(l.title, "line \"" + label + "\" has " + std::to_string(y.size()) + " values for " +
                       std::to_string(l.x.size()) + " x values");
    }
  }
  for (const LineBand& b : l.bands)
    if (b.lo.size() != l.x.size() || b.hi.size() != l.x.size())
      bad(l.title, "band \"" + b.label + "\" has not one lo and hi per x");
  for (const LineRule& r : l.rules)
    if (!std::isfinite(r.y)) bad(l.title, "rule \"" + r.label + "\" is not finite");
}

void check(const StyledLinePlot& l) {
  check(l.plot);
  if (l.styles.size() != l.plot.lines.size())
    bad(l.plot.title, std::to_string(l.styles.size()) + " line styles for " +
                          std::to_string(l.plot.lines.size()) + " lines");
}

// Categories whose labels need vertical tics.
bool rotated(const BarChart& c) {
  std::size_t longest = 0;
  for (const std::string& s : c.categories) longest = std::max(longest, s.size());
  return c.categories.size() > 8 || longest * c.categories.size() > 60;
}

struct Size {
  int width, height;
};

Size panel_size(const Panel& p) {
  if (const auto* c = std::get_if<BarChart>(&p)) {
    const int n = static_cast<int>(c->categories.size());
    const int per = 8 + 9 * static_cast<int>(c->series.size());
    int height = 420;
    if (rotated(*c)) {
      std::size_t longest = 0;
      for (const std::string& s : c->categories) longest = std::max(longest, s.size());
      height += std::min(200, 7 * static_cast<int>(longest));
    }
    return {std::clamp(140 + n * per, 640, 4000), height};
  }
  if (const auto* h = std::get_if<HeatMap>(&p)) {
    return {std::clamp(200 + 40 * static_cast<int>(h->x.size()), 640, 1200), 480};
  }
  return {720, 440};
}

bool stacked(const std::vector<Panel>& panels) {
  for (const Panel& p : panels) {
    if (const auto* c = std::get_if<BarChart>(&p); c && c->categories.size() > 12) return true;
  }
  return false;
}

void common(std::ostringstream& s, const std::string& title) {
  s << "reset\n";
  s << "set title " << gq(title) << "\n";
  s << "set grid\n";
}

void bar_script(std::ostringstream& s, const fs::path& dir, int index, const BarChart& c) {
  const fs::path data = dir / ("panel" + std::to_string(index) + ".tsv");
  std::ostringstream d;
  double lowest = INFINITY, highest = -INFINITY;  // over values and intervals
  for (std::size_t i = 0; i < c.categories.size(); ++i) {
    d << field(c.categories[i]);
    for (const BarSeries& series : c.series) {
      const double v = series.value[i];
      const bool bars = !series.lo.empty();
      for (double x : {v, bars ? series.lo[i] : v, bars ? series.hi[i] : v}) {
        if (std::isfinite(x)) {
          lowest = std::min(lowest, x);
          highest = std::max(highest, x);
        }
      }
      d << "\t" << gnuplot_number(v) << "\t" << gnuplot_number(bars ? series.lo[i] : v) << "\t"
        << gnuplot_number(bars ? series.hi[i] : v);
    }
    d << "\n";
  }
  const bool all_nan = !std::isfinite(lowest);
  write_data(data, d.str());
  common(s, c.title);
  s << "set datafile separator '\\t'\n";
  s << "set ylabel " << gq(c.ylabel) << "\n";
  s << "set style data histogram\n";
  bool error_bars = false;
  for (const BarSeries& series : c.series) error_bars = error_bars || !series.lo.empty();
  s << (error_bars ? "set style histogram errorbars gap 1 lw 1\n"
                   : "set style histogram clustered gap 1\n");
  s << "set style fill solid 0.85 border -1\n";
  s << "set grid noxtics ytics\n";
  s << "set xtics nomirror scale 0\n";
  if (rotated(c)) {
    s << "set xtics rotate by 90 right" << (c.categories.size() > 40 ? " font ',8'" : "") << "\n";
  }
  s << "set xrange [-0.6:" << c.categories.size() - 1 << ".6]\n";
  // Bars grow from 0: keep 0 in the range.
  if (all_nan || (lowest == 0 && highest == 0)) {
    s << "set yrange [0:1]\n";
  } else if (lowest >= 0) {
    s << "set yrange [0:*]\nset offsets 0, 0, graph 0.05, 0\n";
  } else if (highest <= 0) {
    s << "set yrange [*:0]\nset offsets 0, 0, 0, graph 0.05\n";
  } else {
    s << "set offsets 0, 0, graph 0.05, graph 0.05\n";
  }
  s << (c.series.size() > 1 ? "set key top right\n" : "unset key\n");
  s << "plot ";
  for (std::size_t k = 0; k < c.series.size(); ++k) {
    const std::size_t col = 2 + 3 * k;
    s << (k == 0 ? gq(data.string()) : std::string("''")) << " using " << col;
    if (error_bars) s << ":" << col + 1 << ":" << col + 2;
    if (k == 0) s << ":xtic(1)";
    s << " title " << gq(c.series[k].label) << (k + 1 < c.series.size() ? ", \\\n     " : "\n");
  }
}

// Half-widths of the cells around sorted-or-not coordinates: half the gap to each neighbour.
std::vector<double> half_widths(const std::vector<double>& v) {
  std::vector<double> h(v.size(), 0.5);
  if (v.size() < 2) {
    if (!v.empty() && v[0] != 0) h[0] = 0.05 * std::abs(v[0]);
    return h;
  }
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double left = i > 0 ? std::abs(v[i] - v[i - 1]) : std::abs(v[1] - v[0]);
    const double right = i + 1 < v.size() ? std::abs(v[i + 1] - v[i]) : left;
    h[i] = 0.5 * std::min(left > 0 ? left : right, right > 0 ? right : left);
    if (!(h[i] > 0)) h[i] = 0.5;
  }
  return h;
}

void heat_script(std::ostringstream& s, const fs::path& dir, int index, const HeatMap& h) {
  const fs::path data = dir / ("panel" + std::to_string(index) + ".tsv");
  const std::vector<double> hx = half_widths(h.x), hy = half_widths(h.y);
  double lo = h.zmin, hi = h.zmax;
  double data_lo = std::numeric_limits<double>::infinity(), data_hi = -data_lo;
  for (double z : h.z) {
    if (std::isfinite(z)) {
      data_lo = std::min(data_lo, z);
      data_hi = std::max(data_hi, z);
    }
  }
  if (std::isnan(lo)) lo = data_lo;
  if (std::isnan(hi)) hi = data_hi;
  const bool any = std::isfinite(data_lo);
  const bool annotate = h.annotate && h.z.size() <= kMaxAnnotatedCells;
  std::ostringstream d;
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  for (std::size_t iy = 0; iy < h.y.size(); ++iy) {
    for (std::size_t ix = 0; ix < h.x.size(); ++ix) {
      const double z = h.z[iy * h.x.size() + ix];
      const double t = hi > lo ? (z - lo) / (hi - lo) : 0.5;
      d << gnuplot_number(h.x[ix]) << "\t" << gnuplot_number(h.y[iy]) << "\t"
        << gnuplot_number(hx[ix]) << "\t" << gnuplot_number(hy[iy]) << "\t" << gnuplot_number(z)
        << "\t" << short_num(z) << "\t" << (t > 0.6 ? 1 : 0) << "\n";
      xmin = std::min(xmin, h.x[ix] - hx[ix]);
      xmax = std::max(xmax, h.x[ix] + hx[ix]);
      ymin = std::min(ymin, h.y[iy] - hy[iy]);
      ymax = std::max(ymax, h.y[iy] + hy[iy]);
    }
  }
  write_data(data, d.str());
  common(s, h.title);
  s << "set datafile separator '\\t'\n";
  s << "unset grid\n";
  s << "set xlabel " << gq(h.xlabel) << "\n";
  s << "set ylabel " << gq(h.ylabel) << "\n";
  s << "set cblabel " << gq(h.zlabel) << "\n";
  s << "set palette defined (0 '#fff7ec', 0.25 '#fdd49e', 0.5 '#fc8d59', 0.75 '#d7301f', "
       "1 '#7f0000')\n";
  s << "set xrange [" << gnuplot_number(xmin) << ":" << gnuplot_number(xmax) << "]\n";
  s << "set yrange [" << gnuplot_number(ymin) << ":" << gnuplot_number(ymax) << "]\n";
  if (any && hi > lo) {
    s << "set cbrange [" << gnuplot_number(lo) << ":" << gnuplot_number(hi) << "]\n";
  } else if (any) {
    s << "set cbrange [" << gnuplot_number(lo - 0.5 * std::abs(lo) - 1e-300) << ":"
      << gnuplot_number(hi + 0.5 * std::abs(hi) + 1e-300) << "]\n";
  } else {
    s << "set cbrange [0:1]\n";
  }
  s << "set tics out\n";
  s << "set rmargin 16\n";  // room for the colour box and its label
  s << "unset key\n";
  const std::string q = gq(data.string());
  if (!any) {
    // Nothing to colour: draw the empty frame (gnuplot refuses a plot with no valid point).
    s << "plot " << q << " using 1:2 with points pt -1 notitle\n";
    return;
  }
  s << "plot " << q << " using 1:2:3:4:5 with boxxyerror fs solid 1.0 noborder lc palette";
  if (annotate) {
    s << ", \\\n     " << q
      << " using 1:2:(column(7) == 0 ? stringcolumn(6) : '') with labels tc 'black'"
      << ", \\\n     " << q
      << " using 1:2:(column(7) == 1 ? stringcolumn(6) : '') with labels tc 'white'";
  }
  s << "\n";
}

const char* style_text(LineStyle style) {
  switch (style) {
    case LineStyle::Lines:
      return "lines lw 1.5";
    case LineStyle::Points:
      return "points pt 7 ps 0.9";
    default:
      return "linespoints pt 7 ps 0.6";
  }
}

void line_script(std::ostringstream& s, const fs::path& dir, int index, const LinePlot& l,
                 const std::vector<LineStyle>& styles = {}) {
  const fs::path data = dir / ("panel" + std::to_string(index) + ".tsv");
  std::ostringstream d;
  bool all_nan = true;
  for (std::size_t i = 0; i < l.x.size(); ++i) {
    d << gnuplot_number(l.x[i]);
    for (const auto& line : l.lines) {
      d << "\t" << gnuplot_number(line.second[i]);
      all_nan = all_nan && !std::isfinite(line.second[i]);
    }
    for (const LineBand& b : l.bands)
      d << "\t" << gnuplot_number(b.lo[i]) << "\t" << gnuplot_number(b.hi[i]);
    d << "\n";
  }
  write_data(data, d.str());
  common(s, l.title);
  s << "set datafile separator '\\t'\n";
  s << "set xlabel " << gq(l.xlabel) << "\n";
  s << "set ylabel " << gq(l.ylabel) << "\n";
  s << "set key outside right top\n";
  s << "set offsets graph 0.02, graph 0.02, graph 0.05, graph 0.05\n";
  if (all_nan) s << "set yrange [0:1]\n";
  s << "plot ";
  // Bands first, under the lines; their columns follow the lines' in the data file.
  for (std::size_t k = 0; k < l.bands.size(); ++k) {
    const std::size_t lo = l.lines.size() + 2 + 2 * k;
    s << (k == 0 ? gq(data.string()) : std::string("''")) << " using 1:" << lo << ":" << lo + 1
      << " with filledcurves fs transparent solid 0.18 noborder"
      << (l.bands[k].line < l.lines.size() ? " lt " + std::to_string(l.bands[k].line + 1) : "")
      << " title " << gq(l.bands[k].label) << ", \\\n     ";
  }
  for (std::size_t k = 0; k < l.lines.size(); ++k) {
    s << (k == 0 && l.bands.empty() ? gq(data.string()) : std::string("''")) << " using 1:" << k + 2
      << " with " << style_text(styles.empty() ? LineStyle::LinesPoints : styles[k]) << " lt "
      << k + 1 << " title " << gq(l.lines[k].first)
      << (k + 1 < l.lines.size() || !l.rules.empty() ? ", \\\n     " : "\n");
  }
  for (std::size_t k = 0; k < l.rules.size(); ++k)
    s << gnuplot_number(l.rules[k].y) << " with lines dt 2 lw 1.5 lc rgb '#000000' "
      << (l.rules[k].label.empty() ? std::string("notitle") : "title " + gq(l.rules[k].label))
      << (k + 1 < l.rules.size() ? ", \\\n     " : "\n");
}

bool find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::string dirs(path);
  std::size_t start = 0;
  while (start <= dirs.size()) {
    std::size_t end = dirs.find(':', start);
    if (end == std::string::npos) end = dirs.size();
    std::string dir = dirs.substr(start, end - start);
    if (dir.empty()) dir = ".";
    const std::string exe = dir + "/" + program;
    struct stat st {};
    if (::stat(exe.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(exe.c_str(), X_OK) == 0) {
      return true;
    }
    start = end + 1;
  }
  return false;
}

// A temporary directory removed (with its contents) when the guard goes.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "weilgen-plot-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) {
      throw std::runtime_error("plot: cannot create a temporary directory (" +
                               std::string(std::strerror(errno)) + ")");
    }
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// Removes a file when the guard goes unless released.
class FileGuard {
 public:
  explicit FileGuard(fs::path p) : path_(std::move(p)) {}
  ~FileGuard() {
    if (!path_.empty()) {
      std::error_code ec;
      fs::remove(path_, ec);
    }
  }
  FileGuard(const FileGuard&) = delete;
  FileGuard& operator=(const FileGuard&) = delete;
  void release() { path_.clear(); }

 private:
  fs::path path_;
};

std::string first_lines(const std::string& text, std::size_t max_lines) {
  std::istringstream in(text);
  std::string line, out;
  std::size_t n = 0;
  while (std::getline(in, line) && n < max_lines) {
    if (line.find_first_not_of(" \t^") == std::string::npos) continue;
    out += (out.empty() ? "" : " | ") + line;
    ++n;
  }
  return out;
}

}  // namespace

void pareto(BarChart& b, std::size_t key) {
  check(b);
  if (key >= b.series.size()) bad(b.title, "pareto: no series " + std::to_string(key));
  std::vector<std::size_t> order;
  for (std::size_t c = 0; c < b.categories.size(); ++c) {
    bool zero = true;
    for (const BarSeries& s : b.series) zero = zero && !(std::abs(s.value[c]) > 0);
    if (!zero) order.push_back(c);
  }
  if (order.empty()) return;  // nothing has an effect: an all-zero chart says so
  const std::vector<double>& v = b.series[key].value;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    const bool fx = std::isfinite(v[x]), fy = std::isfinite(v[y]);
    return fx != fy ? fx : (fx && v[x] > v[y]);
  });
  const auto pick = [&](std::vector<double>& values) {
    if (values.empty()) return;
    std::vector<double> out;
    for (std::size_t c : order) out.push_back(values[c]);
    values = out;
  };
  std::vector<std::string> categories;
  for (std::size_t c : order) categories.push_back(b.categories[c]);
  b.categories = categories;
  for (BarSeries& s : b.series) {
    pick(s.value);
    pick(s.lo);
    pick(s.hi);
  }
}

std::string plot_format(const std::string& path) { return format_of_path(path); }

bool gnuplot_available() { return find_on_path("gnuplot"); }

void check_plot_target(const std::string& path) {
  plot_format(path);
  if (!gnuplot_available()) throw std::runtime_error(kNotFound);
}

std::string plot_script(const std::string& data_dir, const std::string& output,
                        const std::string& format, const std::vector<Panel>& panels,
                        const std::string& figure_title) {
  if (format != "png" && format != "svg") {
    throw std::invalid_argument("plot: unknown format \"" + format + "\" (expected png or svg)");
  }
  if (panels.empty()) throw std::invalid_argument("plot " + output + ": no panels to draw");
  for (const Panel& p : panels) std::visit([](const auto& v) { check(v); }, p);

  const int n = static_cast<int>(panels.size());
  const int cols = n == 1 || stacked(panels) ? 1 : (n <= 4 ? 2 : 3);
  const int rows = (n + cols - 1) / cols;
  int width = 0, height = 0;
  for (const Panel& p : panels) {
    const Size s = panel_size(p);
    width = std::max(width, s.width);
    height = std::max(height, s.height);
  }
  const int title_height = figure_title.empty() ? 0 : 40;
  const int fig_w = std::min(8000, cols * width);
  const int fig_h = std::min(12000, rows * height + title_height);

  std::ostringstream s;
  s << "set encoding utf8\n";
  if (format == "png") {
    s << "set terminal pngcairo noenhanced size " << fig_w << "," << fig_h
      << " font 'Sans,10' background '#ffffff'\n";
  } else {
    s << "set terminal svg noenhanced size " << fig_w << "," << fig_h
      << " font 'Sans,10' background '#ffffff'\n";
  }
  s << "set output " << gq(output) << "\n";
  s << "set multiplot layout " << rows << "," << cols;
  if (!figure_title.empty()) s << " title " << gq(figure_title) << " font ',13'";
  s << "\n";
  const fs::path dir(data_dir);
  for (int i = 0; i < n; ++i) {
    const Panel& p = panels[static_cast<std::size_t>(i)];
    s << "# ---- panel " << i + 1 << "\n";
    if (const auto* c = std::get_if<BarChart>(&p)) bar_script(s, dir, i, *c);
    if (const auto* h = std::get_if<HeatMap>(&p)) heat_script(s, dir, i, *h);
    if (const auto* l = std::get_if<LinePlot>(&p)) line_script(s, dir, i, *l);
    if (const auto* l = std::get_if<StyledLinePlot>(&p)) line_script(s, dir, i, l->plot, l->styles);
  }
  s << "unset multiplot\n";
  s << "unset output\n";
  return s.str();
}

void write_plot(const std::string& path, const std::vector<Panel>& panels,
                const std::string& figure_title) {
  const std::string format = plot_format(path);
  if (panels.empty()) throw std::invalid_argument("plot " + path + ": no panels to draw");
  for (const Panel& p : panels) std::visit([](const auto& v) { check(v); }, p);
  if (!gnuplot_available()) throw std::runtime_error(kNotFound);

  const fs::path target(path);
  const fs::path tmp_output = temporary_path_for(path);
  std::error_code ec;
  FileGuard output_guard(tmp_output);

  TempDir work;
  const fs::path script = work.path() / "plot.gp";
  write_data(script,
             plot_script(work.path().string(), tmp_output.string(), format, panels, figure_title));
  const fs::path log = work.path() / "gnuplot.log";
  const std::string command =
      "gnuplot " + shq(script.string()) + " </dev/null >" + shq(log.string()) + " 2>&1";
  const int status = std::system(command.c_str());
  std::string messages;
  read_file(log.string(), messages);
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127 &&
        messages.find("gnuplot") != std::string::npos &&
        messages.find("not found") != std::string::npos) {
      throw std::runtime_error(kNotFound);
    }
    throw std::runtime_error(
        "plot " + path + ": gnuplot failed: " +
        (messages.empty() ? std::string("no message") : first_lines(messages, 4)));
  }
  if (!fs::is_regular_file(tmp_output, ec) || fs::file_size(tmp_output, ec) == 0) {
    throw std::runtime_error("plot " + path + ": gnuplot wrote no figure" +
                             (messages.empty() ? std::string() : ": " + first_lines(messages, 4)));
  }
  fs::rename(tmp_output, target, ec);
  if (ec) throw std::runtime_error("plot " + path + ": cannot replace (" + ec.message() + ")");
  output_guard.release();
}

}  // namespace weilgen
