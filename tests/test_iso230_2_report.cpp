// The ISO 230-2 report pieces: tolerances and their verdicts on the hand-computed example, the
// inline SVG charts (weilgen/report/svg_chart.hpp), the HTML report's structure and numbers
// (weilgen/report/iso230_2_html.hpp) against the JSON, and `iso230-2 --report` end to end. The
// rendering in a real browser is the CTest iso230_2_report_browser (tests/report/).
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>

#include "test_support.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/measure/iso230_2_study.hpp"
#include "weilgen/report/iso230_2_document.hpp"
#include "weilgen/report/iso230_2_html.hpp"
#include "weilgen/report/plot.hpp"
#include "weilgen/report/svg_chart.hpp"

using namespace weilgen;
using nlohmann::json;
using test::cli;
using test::run;

namespace {

std::string small_csv() {
  return std::string(WEILGEN_SOURCE_DIR) + "/examples/data/iso230_2_small.csv";
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t k = text.find(what); k != std::string::npos; k = text.find(what, k + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("tolerance: parsing and the verdicts on the hand-computed example") {
  const IsoTolerance t = parse_iso_tolerance("11, A=14, R=13.9,B_mean=0.5");
  REQUIRE(t.band.has_value());
  CHECK(*t.band == 11);
  REQUIRE(t.figures.size() == 3);
  Iso230_2StudyOptions o;
  o.tolerance = t;
  const Iso230_2StudyResult r = Iso230_2Study(o).run(read_measurements(small_csv()));
  REQUIRE(r.tolerance.size() == 4);
  // Band: the extreme mean +- 2s is x_down(200) + 2 s = 7 + 4 = 11 (docs/iso230-2.md's table).
  CHECK(r.tolerance[0].name == "band");
  CHECK(r.tolerance[0].value == doctest::Approx(11));
  CHECK(r.tolerance[0].pass);
  CHECK(r.tolerance[1].name == "A");
  CHECK(r.tolerance[1].pass);                               // A = 14 <= 14
  CHECK_FALSE(r.tolerance[2].pass);                         // R = 14 > 13.9
  CHECK(r.tolerance[3].value == doctest::Approx(1.0 / 3));  // |B mean|
  CHECK(r.tolerance[3].pass);
  const auto lines = iso230_2_tolerance_statement(r);
  CHECK(lines.back() == "  verdict: FAIL (R out of tolerance)");
  CHECK_THROWS_WITH(parse_iso_tolerance("A=0"),
                    "--tolerance A=0: '0' is not a number > 0 (in the deviation unit, um or urad)");
  try {
    parse_iso_tolerance("Q=3");
    FAIL("no error");
  } catch (const std::invalid_argument& e) {
    CHECK(std::string(e.what()).rfind("--tolerance Q=3: unknown figure 'Q' (figures: B, B_mean",
                                      0) == 0);
  }
  CHECK_THROWS_AS(parse_iso_tolerance("5,6"), std::invalid_argument);
  CHECK_THROWS_AS(parse_iso_tolerance("A=1,A=2"), std::invalid_argument);
}

TEST_CASE("svg chart: round ticks, gaps at NaN, bands, rules, escaping, errors") {
  CHECK(nice_ticks(0, 10, 5) == std::vector<double>{0, 2, 4, 6, 8, 10});
  CHECK(nice_ticks(-3.2, 11.7, 6) == std::vector<double>{-5, -2.5, 0, 2.5, 5, 7.5, 10, 12.5});
  CHECK(nice_ticks(0.001, 0.0093, 4) == std::vector<double>{0, 0.0025, 0.005, 0.0075, 0.01});
  const std::vector<double> t = nice_ticks(5, 5, 6);  // a flat range widens to +-1
  CHECK(t.front() <= 4);
  CHECK(t.back() >= 6);
  SvgChart c;
  c.id = "c1";
  c.title = "A & B <test>";
  c.x = {0, 1, 2, 3, 4};
  c.series.push_back({"line", {0, 1, NAN, 3, 4}, "#ff0000", 1.5, false, true, 1});
  c.bands.push_back({"band", {-1, 0, 1, 2, 3}, {1, 2, 3, 4, 5}, "#0000ff", 0.2});
  c.rules.push_back({"limit", 4.5, "#000000", true});
  const std::string svg = svg_chart(c);
  CHECK(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\" id=\"c1\"", 0) == 0);
  CHECK(count(svg, "<polyline") == 2);  // the NaN breaks the line
  CHECK(count(svg, "<circle") == 4);    // markers where y is finite
  CHECK(count(svg, "<polygon") == 1);
  CHECK(svg.find("A &amp; B &lt;test&gt;") != std::string::npos);
  CHECK(svg.find("stroke-dasharray=\"7 4\"") != std::string::npos);
  CHECK(svg_chart(c) == svg);  // deterministic
  c.series[0].y.pop_back();
  CHECK_THROWS_AS(svg_chart(c), std::invalid_argument);
  CHECK_THROWS_AS(svg_chart(SvgChart{}), std::invalid_argument);
}

TEST_CASE("html report: sections, charts, numbers equal to the JSON, nothing external") {
  Iso230_2StudyOptions o;
  o.tolerance = parse_iso_tolerance("12,A=15");
  const MeasurementTable t = read_measurements(small_csv());
  const Iso230_2StudyResult r = Iso230_2Study(o).run(t);
  const std::string html = iso230_2_html("small.csv", r);
  const json j = iso230_2_json("small.csv", r);
  CHECK(html.rfind("<!DOCTYPE html>", 0) == 0);
  for (const char* id :
       {"identification", "environment", "results", "targets", "drift", "signature"})
    CHECK(html.find("<section id=\"" + std::string(id) + "\"") != std::string::npos);
  for (const char* id : {"chart-classical", "chart-drift", "chart-cycles"})
    CHECK(html.find("id=\"" + std::string(id) + "\"") != std::string::npos);
  CHECK(count(html, "<svg ") == 3);
  // Self-contained: no scripts, links, images or remote URLs (the SVG namespace is a name).
  for (const char* bad : {"<script", "<link", "<img", "src=", "href=", "@import", "https:"})
    CHECK(html.find(bad) == std::string::npos);
  CHECK(count(html, "http://") == count(html, "xmlns=\"http://www.w3.org/2000/svg\""));
  // Every number tagged with data-set/data-key equals the JSON's, rounded to 3 decimals.
  const std::regex tagged(
      "data-set=\"([a-z_]+)\" data-key=\"([A-Za-z_]+)\"(?: data-index=\"([0-9]+)\")?>([^<]*)<");
  std::size_t checked = 0;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), tagged);
       it != std::sregex_iterator(); ++it) {
    const std::string set = (*it)[1], key = (*it)[2], index = (*it)[3], text = (*it)[4];
    if (set == "tolerance") continue;
    const json& base = set == "classical" ? j
                       : set == "student" ? j["student"]
                                          : j["drift_eliminated"];
    const json& v = index.empty() ? base[key] : base[key][std::stoul(index)];
    CHECK_MESSAGE(text == format_fixed(v.get<double>(), 3), set << "/" << key << index);
    ++checked;
  }
  CHECK(checked == 12 + 12 + 2 + 9 * 3);  // two figure tables, Student-t A and R, 9 per target
  // The tolerance lines on both deviation charts, the verdict, the statements.
  CHECK(count(html,
              "tolerance \xC2\xB1"
              "12 \xC2\xB5m") == 2);
  // The air is not compensated (the file does not say): the verdict is not proven, the title and
  // a banner say the run is not to ISO 230-2, with every condition it misses.
  CHECK(html.find("data-key=\"tolerance_pass\" data-value=\"false\"") != std::string::npos);
  CHECK(html.find("<span class=\"open\">NOT PROVEN</span>") != std::string::npos);
  CHECK(html.find("evaluated after ISO 230-2:2014, not to ISO 230-2</h1>") != std::string::npos);
  for (const char* check : {"targets", "cycles", "air", "temperature"})
    CHECK(html.find("<li data-check=\"" + std::string(check) + "\">") != std::string::npos);
  // Identification rows a signed report needs are there, blank to fill in.
  for (const char* key : {"serial", "location", "date", "operator"})
    CHECK(html.find("<td data-key=\"" + std::string(key) + "\" class=\"fill\"></td>") !=
          std::string::npos);
  CHECK(html.find("Not normalised to 20 \xC2\xB0"
                  "C") != std::string::npos);
  CHECK(html.find("Air refraction: the file does not say") != std::string::npos);
  // Header keys of the file appear in the identification table.
  CHECK(html.find("<td data-key=\"axis\">") != std::string::npos);
}

TEST_CASE("iso230-2 --report: writes the HTML with the JSON, bad targets are refused first") {
  const auto dir = test::fresh_dir("iso_report_cli");
  const std::string html = (dir / "r.html").string(), js = (dir / "r.json").string();
  test::Run r = run(cli("iso230-2 " + small_csv() + " --report " + html + " --json " + js +
                        " --tolerance 12,A=13"));
  CHECK(r.status == 0);
  CHECK(r.out.find("wrote " + html) != std::string::npos);
  // The file does not say whether the air was compensated: A's 14 > 13 proves nothing.
  CHECK(r.out.find("verdict: NOT PROVEN (the refractive index of the air is not compensated") !=
        std::string::npos);
  json j = json::parse(test::read_text(js));
  CHECK(j["tolerance"]["verdict"] == "not proven");
  CHECK(j["normalisation"]["air"]["compensation"] == "unstated");
  r = run(cli("iso230-2 " + small_csv() + " --report " + html + " --json " + js +
              " --tolerance 12,A=13 --air-compensation instrument"));
  CHECK(r.status == 0);
  CHECK(r.out.find("verdict: FAIL (A out of tolerance)") != std::string::npos);
  const std::string text = test::read_text(html);
  CHECK(text.find("fail\">FAIL") != std::string::npos);
  j = json::parse(test::read_text(js));
  CHECK(j["tolerance"]["pass"] == false);
  CHECK(j["tolerance"]["verdict"] == "does not conform");
  // Refused before the work, nothing written: a report that is not .html, the data file itself,
  // a bad tolerance, a bad air mode.
  write_file_atomically(html, "keep\n");
  CHECK(run(cli("iso230-2 " + small_csv() + " --report " + (dir / "r.pdf").string())).status == 2);
  CHECK(run(cli("iso230-2 " + small_csv() + " --report " + small_csv())).status == 2);
  CHECK(run(cli("iso230-2 " + small_csv() + " --report " + html + " --tolerance A=-1")).status ==
        2);
  CHECK(run(cli("iso230-2 " + small_csv() + " --report " + html + " --air-compensation yes"))
            .status == 2);
  CHECK(run(cli("iso230-2 " + small_csv() + " --report " + html + " --wavelength 1064")).status ==
        2);
  // Bad input after the flags: exit 3, the report untouched.
  r = run(cli("iso230-2 " + small_csv() + " --report " + html + " --expansion 11.5"));
  CHECK(r.status == 3);
  CHECK(r.out.find("no material temperature") != std::string::npos);
  CHECK(test::read_text(html) == "keep\n");
  // Normalisation from flags is stated in the text.
  r = run(cli("iso230-2 " + small_csv() + " --expansion 11.5 --material-temperature T_table"));
  CHECK(r.status == 3);  // the small example has no T_table column
  r = run(cli("iso230-2 " + small_csv() + " --expansion 11.5 --material-temperature 20"));
  CHECK(r.status == 0);
  CHECK(r.out.find("Normalised to 20 degC by weilgen (ISO 1; --normalise auto): corrected with "
                   "alpha 11.5 um/(m K) (--expansion); material temperature 20.00 degC "
                   "[--material-temperature]") != std::string::npos);
}

TEST_CASE("iso230-2 --csv and --plot: the per-target table equals the JSON, refusals come first") {
  const auto dir = test::fresh_dir("iso_csv_cli");
  const std::string csv = (dir / "t.csv").string(), js = (dir / "t.json").string(),
                    svg = (dir / "t.svg").string();
  const std::string data = std::string(WEILGEN_SOURCE_DIR) + "/examples/data/carto_x.csv";
  const bool plot = gnuplot_available();
  test::Run r = run(cli("iso230-2 " + data + " --csv " + csv + " --json " + js +
                        (plot ? " --plot " + svg : std::string())));
  REQUIRE(r.status == 0);
  CHECK(r.out.find("wrote " + csv) != std::string::npos);
  const json j = json::parse(test::read_text(js));
  const std::vector<std::string> lines = split(test::read_text(csv), '\n');
  REQUIRE(lines.size() == 1 + 11 + 1);  // header, 11 targets, the final newline
  const std::vector<std::string> header = split(lines[0], ',');
  CHECK(lines[0] ==
        "target_mm,mean_up_um,mean_down_um,s_up_um,s_down_um,B_i_um,R_i_up_um,R_i_down_um,R_i_um,"
        "mean_bi_um,lower_up_um,upper_up_um,lower_down_um,upper_down_um,chart_up_um,s_star_up_um,"
        "chart_down_um,s_star_down_um");
  const json& d = j["drift_eliminated"];
  for (std::size_t i = 0; i < 11; ++i) {
    const std::vector<std::string> cells = split(lines[i + 1], ',');
    REQUIRE(cells.size() == header.size());
    auto at = [&](const std::string& name) {
      const auto it = std::find(header.begin(), header.end(), name);
      return std::stod(cells[static_cast<std::size_t>(it - header.begin())]);
    };
    // Written with format_number: the same doubles as the JSON.
    CHECK(at("target_mm") == j["positions_mm"][i].get<double>());
    for (const char* key : {"mean_up_um", "mean_down_um", "s_up_um", "s_down_um", "B_i_um",
                            "R_i_up_um", "R_i_down_um", "R_i_um", "mean_bi_um"})
      CHECK_MESSAGE(at(key) == j[key][i].get<double>(), key << " " << i);
    CHECK(at("chart_up_um") == d["mean_up_um"][i].get<double>());
    CHECK(at("s_star_down_um") == d["s_down_um"][i].get<double>());
    // The band drawn on the chart: x̄ ± 2 s.
    CHECK(at("lower_up_um") == doctest::Approx(at("mean_up_um") - 2 * at("s_up_um")));
    CHECK(at("upper_down_um") == doctest::Approx(at("mean_down_um") + 2 * at("s_down_um")));
  }
  CHECK(test::read_text(csv).find("103.2,") != std::string::npos);  // targets as written
  if (plot) CHECK(test::read_text(svg).find("<svg") != std::string::npos);
  // The report's environment table: the recorded ranges in the units a lab reads (hPa, degC).
  const std::string html = (dir / "t.html").string();
  REQUIRE(run(cli("iso230-2 " + data + " --report " + html)).status == 0);
  const std::string report = test::read_text(html);
  CHECK(report.find("<table class=\"env\">") != std::string::npos);
  CHECK(report.find("<td>Air pressure</td><td class=\"num\">1009.4</td><td class=\"num\">1009.6"
                    "</td><td class=\"num\">1009.9</td><td>hPa</td>") != std::string::npos);
  CHECK(report.find("<td class=\"num\">-17.551</td><td class=\"num\">-8.776</td>") !=
        std::string::npos);  // the expansion correction, um (hand: -11.7 * 1.5 * 1 = -17.55)
  // A flag that cannot be honoured is refused before the work, and nothing is written.
  const std::string keep = (dir / "keep.json").string();
  const auto refused = [&](const std::string& flags) {
    const test::Run x = run(cli("iso230-2 " + data + " --json " + keep + " " + flags));
    CHECK_MESSAGE(x.status != 0, flags);
    CHECK_MESSAGE(!std::filesystem::exists(keep), flags);
    return x;
  };
  CHECK(refused("--plot " + (dir / "t.pdf").string()).out.find(".pdf") != std::string::npos);
  CHECK(refused("--csv " + data).out.find("--csv") != std::string::npos);
  CHECK(refused("--csv " + dir.string()).out.find("is a directory") != std::string::npos);
  CHECK(refused("--plot " + data).status == 2);
  // gnuplot missing: --plot is refused with the reason, not skipped.
  const test::Run x = run("env PATH=/nonexistent " +
                          cli("iso230-2 " + data + " --plot " + svg + "x.svg --json " + keep));
  CHECK(x.status != 0);
  CHECK(x.out.find("gnuplot not found") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(keep));
}

TEST_CASE("report details: --iso-only, --expansion 0, no -0.000, bands and tolerance lines") {
  // --iso-only: no Student-t set and no drift elimination, in the study, the text and the JSON.
  Iso230_2StudyOptions o;
  o.iso_only = true;
  const MeasurementTable t = read_measurements(small_csv());
  const Iso230_2StudyResult r = Iso230_2Study(o).run(t);
  CHECK_FALSE(r.classical.student.has_value());
  CHECK_FALSE(r.drift.has_value());
  const std::string text = iso230_2_text("small.csv", r);
  CHECK(text.find("Student-t  ") == std::string::npos);  // no column of the figures
  CHECK(text.find("drift-elim.") == std::string::npos);
  CHECK(text.find("Drift elimination and the Student-t set: off (--iso-only).") !=
        std::string::npos);
  const json j = iso230_2_json("small.csv", r);
  CHECK(j["student"].is_null());
  CHECK(j["drift_eliminated"].is_null());
  CHECK(j["iso_only"] == true);
  const std::string html = iso230_2_html("small.csv", r);
  CHECK(html.find("chart-drift") == std::string::npos);
  CHECK(html.find("Student-t") == std::string::npos);
  const auto dir = test::fresh_dir("iso_details_cli");
  CHECK(run(cli("iso230-2 " + small_csv() + " --iso-only --comp-table " + (dir / "c.tbl").string() +
                " --comp-source drift"))
            .status == 2);
  CHECK(run(cli("iso230-2 " + small_csv() + " --iso-only --reference-cycle 2")).status == 2);

  // --expansion 0 corrects nothing and does not say "normalised".
  const std::string carto = std::string(WEILGEN_SOURCE_DIR) + "/examples/data/carto_x.csv";
  test::Run zero = run(cli("iso230-2 " + carto + " --expansion 0"));
  REQUIRE(zero.status == 0);
  CHECK(zero.out.find("Not normalised to 20 degC (--normalise auto): expansion coefficient 0 "
                      "(--expansion): no expansion correction") != std::string::npos);
  CHECK(zero.out.find("Normalised to") == std::string::npos);

  // A value that rounds to zero is printed without a sign, in every table.
  CHECK(format_fixed(-0.0004, 3) == "0.000");
  CHECK(format_fixed(-0.0005001, 3) == "-0.001");
  CHECK(format_fixed(-0.0, 2) == "0.00");
  const std::string drift = std::string(WEILGEN_SOURCE_DIR) + "/examples/data/iso230_2_drift.csv";
  test::Run d = run(cli("iso230-2 " + drift));
  REQUIRE(d.status == 0);
  CHECK(d.out.find("-0.000") == std::string::npos);
  CHECK(zero.out.find("-0.000") == std::string::npos);

  // The gnuplot charts: x-bar +- 2s as shaded bands in their line's colour, the tolerance lines.
  Iso230_2StudyOptions tol;
  tol.tolerance = parse_iso_tolerance("12");
  const Iso230_2StudyResult rt = Iso230_2Study(tol).run(t);
  const std::string script =
      plot_script(dir.string(), (dir / "p.png").string(), "png", iso230_2_panels(rt), "t");
  CHECK(count(script,
              "with filledcurves fs transparent solid 0.18 noborder lt 1 title "
              "'mean up +-2s'") == 1);
  CHECK(count(script,
              "with filledcurves fs transparent solid 0.18 noborder lt 2 title "
              "'mean down +-2s'") == 1);
  CHECK(count(script, "12 with lines dt 2 lw 1.5 lc rgb '#000000' title 'tolerance +-12 um'") == 2);
  CHECK(count(script, "-12 with lines dt 2 lw 1.5 lc rgb '#000000' notitle") == 2);
  CHECK(script.find("mean up +2s") == std::string::npos);  // no longer drawn as lines
}

TEST_CASE("conformance: ISO 230-2's test conditions, each named, and the report's title") {
  auto runs = [](std::size_t targets, double travel_mm, std::size_t cycles) {
    IsoRuns r;
    for (std::size_t i = 0; i < targets; ++i)
      r.positions_mm.push_back(travel_mm * static_cast<double>(i) / (targets - 1));
    for (int d : {kUp, kDown})
      for (std::size_t j = 1; j <= cycles; ++j) r.cycles[d].push_back(static_cast<long>(j));
    return r;
  };
  IsoColumns linear;
  linear.unit = "um";
  NormalisationResult ok;
  ok.air = AirCompensation::Instrument;
  ok.material_temperature_C.add(20.5);
  auto checks = [](const std::vector<ConformanceIssue>& issues) {
    std::vector<std::string> out;
    for (const auto& i : issues) out.push_back(i.check);
    return out;
  };
  CHECK(iso230_2_conformance(runs(5, 1000, 5), linear, ok).empty());
  CHECK(checks(iso230_2_conformance(runs(4, 400, 5), linear, ok)) ==
        std::vector<std::string>{"targets"});
  // 5 per metre: 1500 mm needs 8; beyond 2000 mm one per 250 mm: 3000 mm needs 12.
  CHECK(iso230_2_conformance(runs(7, 1500, 5), linear, ok)[0].message ==
        "7 targets over 1500 mm; ISO 230-2 asks for 8 (at least 5, and 5 per metre of travel)");
  CHECK(iso230_2_conformance(runs(8, 1500, 5), linear, ok).empty());
  CHECK(iso230_2_conformance(runs(11, 3000, 5), linear, ok)[0].message ==
        "11 targets over 3000 mm; ISO 230-2 asks for 12 (one per 250 mm of travel beyond 2000 "
        "mm)");
  // Three cycles are named; more than five are fine.
  CHECK(iso230_2_conformance(runs(5, 1000, 3), linear, ok)[0].message ==
        "3 cycles forward and 3 reverse; ISO 230-2 asks for 5 in each direction");
  CHECK(iso230_2_conformance(runs(5, 1000, 8), linear, ok).empty());
  // The air not compensated, and nothing known of the temperature.
  NormalisationResult raw;
  CHECK(checks(iso230_2_conformance(runs(5, 1000, 5), linear, raw)) ==
        std::vector<std::string>{"air", "temperature"});
  raw.air = AirCompensation::None;
  CHECK(iso230_2_conformance(runs(5, 1000, 5), linear, raw)[0].message ==
        "the refractive index of the air is not compensated (stated as not compensated): the "
        "readings may be off by about 271 um per metre of travel");
  raw.material_compensation = "instrument";  // the instrument normalised: nothing to state
  raw.air_applied = true;
  CHECK(iso230_2_conformance(runs(5, 1000, 5), linear, raw).empty());

  // Two targets x two cycles: the text, JSON and report say so; the shipped CARTO run conforms.
  const auto dir = test::fresh_dir("iso_conformance_cli");
  const std::string tiny = (dir / "tiny.csv").string(), js = (dir / "t.json").string(),
                    html = (dir / "t.html").string();
  write_file_atomically(tiny,
                        "# axis: X\n# air_compensation: instrument\n# material_temperature_C: 20\n"
                        "X,dir,cycle,dx_um\n0,1,1,1\n100,1,1,2\n100,-1,1,3\n0,-1,1,1\n"
                        "0,1,2,1\n100,1,2,2\n100,-1,2,3\n0,-1,2,1\n");
  test::Run r = run(cli("iso230-2 " + tiny + " --json " + js + " --report " + html));
  REQUIRE(r.status == 0);
  CHECK(r.out.find("Conformance: NOT to ISO 230-2\n") != std::string::npos);
  CHECK(r.out.find("- targets: 2 targets over 100 mm; ISO 230-2 asks for 5") != std::string::npos);
  CHECK(r.out.find("- cycles: 2 cycles forward and 2 reverse") != std::string::npos);
  json j = json::parse(test::read_text(js));
  CHECK(j["conformance"]["iso230_2"] == false);
  CHECK(j["conformance"]["issues"].size() == 2);
  CHECK(test::read_text(html).find("not to ISO 230-2</h1>") != std::string::npos);
  const std::string carto = std::string(WEILGEN_SOURCE_DIR) + "/examples/data/carto_x.csv";
  r = run(cli("iso230-2 " + carto + " --json " + js + " --report " + html));
  REQUIRE(r.status == 0);
  CHECK(json::parse(test::read_text(js))["conformance"]["iso230_2"] == true);
  CHECK(test::read_text(html).find("Positioning accuracy and repeatability \xE2\x80\x93 ISO "
                                   "230-2:2014</h1>") != std::string::npos);
  CHECK(test::read_text(html).find("id=\"conformance\"") == std::string::npos);
}
