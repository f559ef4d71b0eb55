// Figures through gnuplot: PNG and SVG written whole, nothing left behind, failures leave the
// target untouched.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "weilgen/base/atomic_file.hpp"
#include "weilgen/report/plot.hpp"

using namespace weilgen;
namespace fs = std::filesystem;

namespace {

std::string fresh_dir(const std::string& name) {
  const fs::path p = fs::path(WEILGEN_TEST_TMP) / "plot" / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// 70 error names (E_XX-style, with underscores) and two Sobol-like series with intervals.
BarChart many_bars() {
  BarChart c;
  c.title = "Sobol indices of dx";
  c.ylabel = "index";
  BarSeries first{"first order S_i", {}, {}, {}}, total{"total S_Ti", {}, {}, {}};
  for (int i = 0; i < 70; ++i) {
    c.categories.push_back("E_" + std::string(1, static_cast<char>('A' + i % 26)) + "0" +
                           std::to_string(i));
    const double v = 0.5 * std::exp(-0.1 * i);
    first.value.push_back(v);
    total.value.push_back(1.2 * v);
    total.lo.push_back(1.1 * v);
    total.hi.push_back(1.3 * v);
  }
  c.series = {first, total};
  return c;
}

HeatMap heat() {
  HeatMap h;
  h.title = "P_f over the grid";
  h.xlabel = "Y (mm)";
  h.ylabel = "Z (mm)";
  h.zlabel = "P_f";
  h.x = {-1500, -750, 0, 750, 1500};
  h.y = {600, 800, 1000, 1200, 1400};
  for (double y : h.y) {
    for (double x : h.x) h.z.push_back(1e-3 * (1 + x * x / 1e6) * y / 1000);
  }
  h.z[3] = NAN;
  return h;
}

LinePlot lines() {
  LinePlot l;
  l.title = "sigma_dx along Y";
  l.xlabel = "Y (mm)";
  l.ylabel = "mm";
  l.x = {0, 1, 2, 3};
  l.lines = {{"first_line", {1, 2, 3, 4}}, {"second", {2, 2, NAN, 1}}};
  return l;
}

}  // namespace

TEST_CASE("plot: PNG and SVG through gnuplot") {
  const std::string dir = fresh_dir("ok");
  const std::string png = dir + "/figure.png";
  const std::string svg = dir + "/figure.svg";
  write_plot(png, {many_bars(), heat(), lines()}, "gantry_grinder: E_XX ... 70 errors");
  write_plot(svg,
             {heat(), lines(), BarChart{"few", "y", {"E_XX", "E_YX"}, {{"s", {0.2, 0.8}, {}, {}}}}},
             "");
  std::string bytes;
  REQUIRE(read_file(png, bytes));
  REQUIRE(bytes.size() > 8);
  CHECK(bytes.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)) == 0);
  CHECK(bytes.size() > 10000);
  REQUIRE(read_file(svg, bytes));
  const bool xml = bytes.rfind("<?xml", 0) == 0 || bytes.rfind("<svg", 0) == 0;
  CHECK(xml);
  CHECK(bytes.find("</svg>") != std::string::npos);
  CHECK(bytes.find("E_XX") != std::string::npos);  // printed as written, not E subscript XX
  // Nothing but the two figures in the directory (no temporary files).
  CHECK(files_in(dir) == std::vector<std::string>{"figure.png", "figure.svg"});

  // Replacing an existing figure; upper-case extension; a nested new directory.
  write_plot(dir + "/sub/more.PNG", {lines()}, "t");
  CHECK(fs::file_size(dir + "/sub/more.PNG") > 0);
  write_plot(png, {lines()}, "again");
  REQUIRE(read_file(png, bytes));
  CHECK(bytes.compare(0, 4, std::string("\x89PNG", 4)) == 0);
  CHECK(files_in(dir) == std::vector<std::string>{"figure.png", "figure.svg", "sub"});

  // Degenerate data still gives a figure: all-NaN panels, one cell, constant z.
  HeatMap one;
  one.x = {0};
  one.y = {5};
  one.z = {2};
  HeatMap blank = heat();
  for (double& z : blank.z) z = NAN;
  BarChart nan_bars{"nan", "", {"a"}, {{"s", {NAN}, {}, {}}}};
  write_plot(dir + "/edge.svg", {one, blank, nan_bars}, "edge cases");
  CHECK(fs::file_size(dir + "/edge.svg") > 0);
}

TEST_CASE("plot: the script") {
  const std::string dir = fresh_dir("script");
  const std::string s = plot_script(dir, dir + "/o.png", "png", {many_bars(), heat()}, "it's");
  CHECK(s.find("pngcairo noenhanced") != std::string::npos);
  CHECK(s.find("set xtics rotate by 90 right") != std::string::npos);
  CHECK(s.find("set multiplot layout 2,1 title 'it''s'") != std::string::npos);  // stacked
  CHECK(s.find("set style histogram errorbars") != std::string::npos);
  CHECK(s.find("with labels") != std::string::npos);  // 25 cells: annotated
  CHECK(fs::exists(dir + "/panel0.tsv"));
  CHECK(fs::exists(dir + "/panel1.tsv"));
  const std::string g = plot_script(dir, dir + "/o.svg", "svg", {lines(), lines(), lines()}, "");
  CHECK(g.find("set terminal svg noenhanced") != std::string::npos);
  CHECK(g.find("set multiplot layout 2,2\n") != std::string::npos);
  HeatMap big = heat();
  big.x.resize(40, 0);
  for (std::size_t i = 0; i < big.x.size(); ++i) big.x[i] = static_cast<double>(i);
  big.z.assign(big.x.size() * big.y.size(), 1.0);
  CHECK(plot_script(dir, "o.png", "png", {big}, "").find("with labels") == std::string::npos);
}

TEST_CASE("plot: failures leave the target untouched") {
  const std::string dir = fresh_dir("fail");
  const std::string target = dir + "/keep.png";
  std::ofstream(target, std::ios::binary) << "old contents";
  const auto unchanged = [&] {
    std::string text;
    REQUIRE(read_file(target, text));
    CHECK(text == "old contents");
    CHECK(files_in(dir) == std::vector<std::string>{"keep.png"});
  };

  CHECK_THROWS_WITH_AS(write_plot(dir + "/figure.pdf", {lines()}, ""),
                       doctest::Contains("unsupported file type \".pdf\" (expected .png or .svg)"),
                       std::invalid_argument);
  CHECK_THROWS_AS(write_plot(dir + "/figure", {lines()}, ""), std::invalid_argument);
  CHECK_THROWS_AS(check_plot_target(dir + "/figure.jpg"), std::invalid_argument);
  CHECK(plot_format("a/b.SVG") == "svg");
  CHECK(gnuplot_available());
  check_plot_target(target);
  CHECK_THROWS_WITH_AS(write_plot(target, {}, ""), doctest::Contains("no panels"),
                       std::invalid_argument);
  BarChart wrong{"bad", "", {"a", "b"}, {{"s", {1.0}, {}, {}}}};
  CHECK_THROWS_WITH_AS(write_plot(target, {wrong}, ""),
                       doctest::Contains("series \"s\" has 1 values for 2 categories"),
                       std::invalid_argument);
  BarChart half{"bad", "", {"a"}, {{"s", {1.0}, {0.5}, {}}}};
  CHECK_THROWS_AS(write_plot(target, {half}, ""), std::invalid_argument);
  HeatMap h = heat();
  h.z.pop_back();
  CHECK_THROWS_WITH_AS(write_plot(target, {h}, ""), doctest::Contains("z has 24 values"),
                       std::invalid_argument);
  LinePlot l = lines();
  l.lines[1].second.pop_back();
  CHECK_THROWS_AS(write_plot(target, {l}, ""), std::invalid_argument);
  unchanged();

  // gnuplot missing.
  const std::string saved = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", (dir + "/nothing-here").c_str(), 1);
  std::string message, early;
  try {
    write_plot(target, {lines()}, "");
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  try {
    check_plot_target(target);
  } catch (const std::runtime_error& e) {
    early = e.what();
  }
  ::setenv("PATH", saved.c_str(), 1);
  CHECK(early == message);
  CHECK(message ==
        "gnuplot not found on PATH: install gnuplot-nox (scripts/install_deps.sh does) or omit "
        "--plot");
  unchanged();

  // gnuplot itself failing (a target directory gnuplot cannot write into is not portable to
  // test as root; a stand-in gnuplot that fails is).
  const std::string fake = dir + "/../fakebin";
  fs::create_directories(fake);
  // It writes a partial figure where the script says, then fails.
  std::ofstream(fake + "/gnuplot")
      << "#!/bin/sh\nout=$(sed -n \"s/^set output '\\(.*\\)'$/\\1/p\" \"$1\")\n"
         "printf partial > \"$out\"\necho 'line 3: all points undefined' >&2\nexit 1\n";
  fs::permissions(fake + "/gnuplot", fs::perms::owner_all);
  ::setenv("PATH", (fake + ":" + saved).c_str(), 1);
  message.clear();
  try {
    write_plot(target, {lines()}, "");
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  ::setenv("PATH", saved.c_str(), 1);
  CHECK(message.find("gnuplot failed: line 3: all points undefined") != std::string::npos);
  unchanged();
}
