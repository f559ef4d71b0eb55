#include "weilgen/report/iso230_2_html.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <tuple>

#include "html_page.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/report/iso230_2_document.hpp"
#include "weilgen/report/svg_chart.hpp"

namespace weilgen {

namespace {

const char* const kUpColour = "#1f77b4";    // forward (↑)
const char* const kDownColour = "#d62728";  // reverse (↓)

std::string h(const std::string& s) { return xml_escape(s); }

std::string unit_html(const std::string& u) { return pretty(u); }

std::string decision_class(Decision d) {
  return d == Decision::Conforms ? "pass" : d == Decision::DoesNotConform ? "fail" : "open";
}
std::string decision_text(Decision d) {
  return d == Decision::Conforms ? "PASS" : d == Decision::DoesNotConform ? "FAIL" : "NOT PROVEN";
}

// One figures table (bidirectional, forward, reverse) with data attributes naming the JSON keys.
std::string figures_table(const IsoFigures& F, const std::string& set, const std::string& u,
                          const std::vector<ToleranceCheck>* checks) {
  struct Row {
    const char* name;
    const char* symbol;
    const char* bi;
    const char* up;
    const char* down;
    double IsoFigures::*f_bi;
    double IsoFigures::*f_up;
    double IsoFigures::*f_down;
  };
  const Row rows[] = {
      {"Accuracy", "A", "A", "A_up", "A_down", &IsoFigures::A, &IsoFigures::A_up,
       &IsoFigures::A_down},
      {"Repeatability", "R", "R", "R_up", "R_down", &IsoFigures::R, &IsoFigures::R_up,
       &IsoFigures::R_down},
      {"Systematic positional deviation", "E", "E", "E_up", "E_down", &IsoFigures::E,
       &IsoFigures::E_up, &IsoFigures::E_down},
      {"Range of mean bidirectional deviation", "M", "M", nullptr, nullptr, &IsoFigures::M, nullptr,
       nullptr},
      {"Reversal value", "B", "B", nullptr, nullptr, &IsoFigures::B, nullptr, nullptr},
      {"Mean reversal value", "B\xCC\x84", "B_mean", nullptr, nullptr, &IsoFigures::B_mean, nullptr,
       nullptr}};
  auto limit_of = [&](const char* key) -> std::string {
    if (!checks || !key) return "";
    for (const auto& c : *checks)
      if (c.name == key)
        return " <span class=\"" + decision_class(c.decision) + "\">" +
               (c.pass ? "\xE2\x89\xA4 " : "&gt; ") + format_number(c.limit) + "</span>";
    return "";
  };
  auto cell = [&](const char* key, double IsoFigures::*f) {
    if (!key) return std::string("<td class=\"num na\">\xE2\x80\x93</td>");
    return "<td class=\"num\"><span data-set=\"" + set + "\" data-key=\"" + key + "_um\">" +
           format_fixed(F.*f, 3) + "</span>" + limit_of(key) + "</td>";
  };
  std::ostringstream o;
  o << "<table class=\"figures\"><thead><tr><th>Figure (" << unit_html(u)
    << ")</th><th></th><th>Bidirectional</th><th>Forward \xE2\x86\x91</th><th>Reverse "
       "\xE2\x86\x93</th></tr></thead><tbody>\n";
  for (const Row& r : rows) {
    o << "<tr><td>" << r.name << "</td><td class=\"sym\">" << r.symbol << "</td>"
      << cell(r.bi, r.f_bi) << cell(r.up, r.f_up) << cell(r.down, r.f_down) << "</tr>\n";
  }
  o << "<tr class=\"k\"><td>Coverage factor</td><td class=\"sym\">k</td><td></td><td class=\"num\">"
    << format_fixed(F.k_up, 2) << "</td><td class=\"num\">" << format_fixed(F.k_down, 2)
    << "</td></tr>\n";
  o << "</tbody></table>\n";
  return o.str();
}

void add_cycles(SvgChart& c, const std::vector<std::vector<double>>& x, const char* colour,
                const std::string& label) {
  const std::size_t n = x.empty() ? 0 : x[0].size();
  for (std::size_t j = 0; j < n; ++j) {
    SvgSeries s;
    s.label = j == 0 ? label : "";
    for (const auto& row : x) s.y.push_back(row[j]);
    s.colour = colour;
    s.width = 0.8;
    s.opacity = 0.3;
    c.series.push_back(s);
  }
}

void add_mean_band(SvgChart& c, const std::vector<double>& mean, const std::vector<double>& s,
                   double k, const char* colour, const std::string& name,
                   const std::string& band_name) {
  SvgBand b;
  b.label = band_name;
  b.colour = colour;
  for (std::size_t i = 0; i < mean.size(); ++i) {
    b.lo.push_back(mean[i] - k * s[i]);
    b.hi.push_back(mean[i] + k * s[i]);
  }
  c.bands.push_back(b);
  SvgSeries m;
  m.label = name;
  m.y = mean;
  m.colour = colour;
  m.width = 2;
  m.markers = true;
  c.series.push_back(m);
}

void add_tolerance(SvgChart& c, const std::vector<ToleranceCheck>& checks, const std::string& u) {
  for (const auto& t : checks)
    if (t.name == "band") {
      c.rules.push_back({"tolerance \xC2\xB1" + format_number(t.limit) + " " + pretty(u), t.limit,
                         "#000000", true});
      c.rules.push_back({"", -t.limit, "#000000", true});
    }
}

// The common y range of charts drawn side by side.
std::pair<double, double> y_range_of(const std::vector<const SvgChart*>& charts) {
  double lo = INFINITY, hi = -INFINITY;
  auto take = [&](double v) {
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  };
  for (const SvgChart* c : charts) {
    for (const auto& s : c->series)
      for (double v : s.y) take(v);
    for (const auto& b : c->bands) {
      for (double v : b.lo) take(v);
      for (double v : b.hi) take(v);
    }
    for (const auto& r : c->rules) take(r.y);
  }
  if (!std::isfinite(lo)) return {-1, 1};
  const double pad = 0.04 * std::max(hi - lo, 1e-9);
  return {lo - pad, hi + pad};
}

// The environment as recorded (min, mean, max of the rows) and the corrections made, one row per
// known quantity; nothing when the file records no environment.
void environment_table(std::ostream& o, const NormalisationResult& n) {
  struct Row {
    const char* name;
    const ValueRange& v;
    double scale;
    int decimals;
    const char* unit;
    std::string source;
  };
  const std::string air_source =
      n.air_applied ? "Edl\xC3\xA9n (Birch & Downs), " + format_fixed(n.wavelength_nm, 3) + " nm"
                    : "";
  const Row rows[] = {
      {"Material temperature", n.material_temperature_C, 1, 2,
       "\xC2\xB0"
       "C",
       n.material_source},
      {"Air temperature", n.air_temperature_C, 1, 2,
       "\xC2\xB0"
       "C",
       n.air_temperature_source},
      {"Air pressure", n.air_pressure_Pa, 0.01, 1, "hPa", n.air_pressure_source},
      {"Relative humidity", n.air_humidity_pct, 1, 1, "%", n.air_humidity_source},
      {"Air refractivity (n \xE2\x88\x92 1) \xC3\x97 10\xE2\x81\xB6", n.air_refractivity, 1e6, 3,
       "", air_source},
      {"Air correction \xCE\xB4<sub>air</sub>", n.air_correction_um, 1, 3, "\xC2\xB5m", ""},
      {"Expansion correction \xCE\xB4<sub>T</sub>", n.material_correction_um, 1, 3, "\xC2\xB5m",
       n.material_applied
           ? "\xCE\xB1 = " + format_fixed(n.expansion_ppm_per_K, 2) + " \xC2\xB5m/(m\xC2\xB7K)"
           : ""}};
  bool any = false;
  for (const Row& r : rows) any |= !r.v.empty();
  if (!any) return;
  o << "<table class=\"env\"><tr><th>Quantity</th><th>Min</th><th>Mean</th><th>Max</th>"
       "<th>Unit</th><th>Source</th></tr>\n";
  for (const Row& r : rows) {
    if (r.v.empty()) continue;
    o << "<tr><td>" << r.name << "</td>";
    for (double v : {r.v.min, r.v.mean, r.v.max})
      o << "<td class=\"num\">" << format_fixed(v * r.scale, r.decimals) << "</td>";
    o << "<td>" << r.unit << "</td><td>" << h(r.source) << "</td></tr>\n";
  }
  o << "</table>\n";
}

// The uncertainty of the figures and their budget (ISO 230-9, GUM; Monte Carlo after GUM
// Supplement 1).
void uncertainty_section(std::ostream& o, const Iso230_2StudyResult& res) {
  const UncertaintyResult& U = *res.uncertainty;
  const std::string u = pretty(res.columns.unit);
  o << "<section id=\"uncertainty\"><h2>Measurement uncertainty</h2>\n<p>After ISO 230-9 and "
       "the GUM: every contribution with its distribution and sensitivity, combined (u) and "
       "expanded with k = "
    << format_number(U.coverage_factor) << " (U); the same budget propagated by Monte Carlo "
    << "(GUM Supplement 1, " << U.trials << " trials). Instrument class " << h(U.instrument_class)
    << ", budget: " << h(U.source) << ".</p>\n";
  o << "<table class=\"uncertainty\"><thead><tr><th>Figure</th><th>Value (" << u << ")</th><th>u ("
    << u << ")</th><th>U (" << u << ")</th><th>Monte Carlo u (" << u << ")</th><th>95 % interval ("
    << u << ")</th></tr></thead><tbody>\n";
  std::vector<std::string> shown = iso230_2_budget_figures();
  for (const ToleranceCheck& c : res.tolerance)
    if (std::find(shown.begin(), shown.end(), c.name) == shown.end()) shown.push_back(c.name);
  bool unvalidated = false;
  for (const std::string& name : shown) {
    const FigureUncertainty* f = U.figure(name);
    if (!f) continue;
    const bool flag = U.trials > 0 && !f->validated;
    unvalidated |= flag;
    o << "<tr><td>" << h(name) << "</td><td class=\"num\">" << format_fixed(f->value, 3)
      << "</td><td class=\"num\" data-uncertainty=\"" << h(name) << "\" data-field=\"u_um\">"
      << format_fixed(f->u, 3) << "</td><td class=\"num\" data-uncertainty=\"" << h(name)
      << "\" data-field=\"U_um\">" << format_fixed(f->U, 3) << "</td><td class=\"num\">"
      << format_fixed(f->mc_u, 3) << (flag ? " *" : "") << "</td><td class=\"num\">"
      << (std::isfinite(f->mc_low)
              ? format_fixed(f->mc_low, 3) + " \xE2\x80\xA6 " + format_fixed(f->mc_high, 3)
              : std::string("\xE2\x80\x93"))
      << "</td></tr>\n";
  }
  o << "</tbody></table>\n";
  if (unvalidated)
    o << "<p class=\"note\">* The Monte Carlo u differs from the linearised one by more than 5 % "
         "(GUM Supplement 1, 8): an extreme of the figure switches between targets within the "
         "uncertainty, and the Monte Carlo interval describes it better; the verdicts use U.</p>\n";
  o << "<table class=\"budget\"><thead><tr><th rowspan=\"2\">Contribution</th><th "
       "rowspan=\"2\">Distribution</th><th rowspan=\"2\">u(x)</th>";
  for (const std::string& f : iso230_2_budget_figures()) o << "<th colspan=\"2\">" << f << "</th>";
  o << "</tr><tr>";
  for (std::size_t k = 0; k < iso230_2_budget_figures().size(); ++k)
    o << "<th>c</th><th>|c| u (" << u << "), share</th>";
  o << "</tr></thead><tbody>\n";
  for (const UncertaintyContribution& c : U.contributions) {
    o << "<tr><td title=\"" << h(pretty(c.input)) << "\">" << h(c.name) << "</td><td>"
      << (c.kind == ContributionKind::TypeA ? "type A" : to_string(c.distribution))
      << "</td><td class=\"num\">"
      << (std::isfinite(c.u) ? format_significant(c.u, 3) + " " + pretty(c.unit)
                             : std::string("\xE2\x80\x93"))
      << "</td>";
    for (const std::string& name : iso230_2_budget_figures()) {
      const double sens = c.sensitivity.at(name), part = c.contribution_um.at(name);
      const double total = U.figure(name)->u;
      o << "<td class=\"num\">"
        << (std::isfinite(sens)
                ? format_significant(sens, 3) + (c.kind == ContributionKind::Scale ? " m" : "")
                : std::string("\xE2\x80\x93"))
        << "</td><td class=\"num\" data-budget=\"" << h(name) << "\">" << format_fixed(part, 3)
        << " ("
        << (total > 0 ? format_fixed(100 * part * part / (total * total), 1) : std::string("0"))
        << " %)</td>";
    }
    o << "</tr>\n";
  }
  o << "</tbody></table>\n";
  if (!U.notes.empty()) {
    o << "<ul class=\"statements\">\n";
    for (const std::string& note : U.notes) o << "<li>" << h(pretty(note)) << "</li>\n";
    o << "</ul>\n";
  }
  o << "</section>\n";
}

// The report's page, one method per section in the order they appear. The members are what
// every section reads: the columns, runs and classical figures, the units and the header keys.
class Iso230_2Page {
 public:
  explicit Iso230_2Page(const Iso230_2StudyResult& result)
      : res(result),
        cols(result.columns),
        runs(result.runs),
        F(result.classical.figures),
        u(result.columns.unit),
        P(result.runs.positions_mm),
        m(result.runs.positions_mm.size()),
        pos_unit(result.columns.unit == "urad" ? "deg" : "mm"),
        machine(key("machine")),
        D(result.drift ? &*result.drift : nullptr) {}

  std::string write(const std::string& data, const std::string& source_format) {
    head();
    heading();
    identification(data, source_format);
    environment();
    results();
    if (res.uncertainty) uncertainty_section(o, res);
    targets();
    drift();
    signature_and_method();
    return o.str();
  }

 private:
  std::string key(const std::string& k) const {
    const auto it = res.header_keys.find(k);
    return it == res.header_keys.end() ? std::string() : it->second;
  }

  void head() {
    o << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      << "<meta name=\"generator\" content=\"weilgen " << kVersion << "\">\n<title>ISO 230-2 "
      << h(cols.axis) << (machine.empty() ? "" : " \xE2\x80\x93 " + h(machine))
      << "</title>\n<style>" << report_style() << "</style>\n</head>\n<body>\n<main>\n";
  }

  // Heading, conformance and warnings.
  void heading() {
    o << "<header><h1 data-key=\"title\">Positioning accuracy and repeatability \xE2\x80\x93 "
      << (res.iso_conforming() ? std::string("ISO 230-2:2014")
                               : std::string("evaluated after ISO 230-2:2014, not to ISO 230-2"))
      << "</h1>"
      << "<p class=\"sub\">Axis " << h(cols.axis)
      << (machine.empty() ? "" : " \xC2\xB7 " + h(machine))
      << (key("date").empty() ? "" : " \xC2\xB7 " + h(key("date"))) << "</p></header>\n";
    if (!res.iso_conforming()) {
      o << "<section id=\"conformance\" class=\"banner\"><p>Not to ISO 230-2:2014: the run does "
           "not "
           "meet the standard's test conditions.</p><ul>\n";
      for (const ConformanceIssue& i : res.conformance)
        o << "<li data-check=\"" << h(i.check) << "\">" << h(pretty(i.message)) << "</li>\n";
      o << "</ul></section>\n";
    }
    if (!res.normalisation.warnings.empty()) {
      o << "<section id=\"warnings\" class=\"warnings\"><ul>\n";
      for (const std::string& w : res.normalisation.warnings)
        o << "<li>" << h(pretty(w)) << "</li>\n";
      o << "</ul></section>\n";
    }
  }

  // Test identification: the keys a signed report needs (blank when the file leaves them
  // empty), the axis, targets, cycles and data file, then any other header key.
  void identification(const std::string& data, const std::string& source_format) {
    o << "<section id=\"identification\"><h2>Test identification</h2>\n<table class=\"meta\">\n";
    // Rows a signed report needs are kept when the file leaves them empty: blank, to fill in.
    auto meta_row = [&](const std::string& label, const std::string& value, const std::string& k,
                        bool keep_blank = false) {
      if (value.empty() && !keep_blank) return;
      o << "<tr><td>" << label << "</td><td" << (k.empty() ? "" : " data-key=\"" + k + "\"")
        << (value.empty() ? " class=\"fill\"" : "") << ">" << h(value) << "</td></tr>\n";
    };
    const std::tuple<const char*, const char*, bool> known[] = {
        {"machine", "Machine", true},   {"serial", "Serial number", true},
        {"title", "Test", false},       {"customer", "Customer", false},
        {"location", "Location", true}, {"date", "Test date", true},
        {"operator", "Operator", true}, {"instrument", "Instrument", true}};
    std::set<std::string> shown;
    for (const auto& [k, label, blank] : known) {
      meta_row(label, key(k), k, blank);
      shown.insert(k);
    }
    meta_row("Axis", cols.axis + " (deviation " + cols.deviation + ", " + pretty(u) + ")", "axis");
    meta_row("Targets",
             std::to_string(m) + " from " + format_number(P.front()) + " to " +
                 format_number(P.back()) + " " + pos_unit,
             "targets");
    meta_row("Cycles",
             std::to_string(runs.cycles[kUp].size()) + " forward, " +
                 std::to_string(runs.cycles[kDown].size()) + " reverse",
             "cycles");
    meta_row("Data file", data + " (read as " + source_format + ")", "file");
    for (const auto& [k, v] : res.header_keys) {
      static const std::set<std::string> handled = {"axis",
                                                    "expansion_ppm_per_K",
                                                    "material_temperature_C",
                                                    "air_compensation",
                                                    "air_temperature_C",
                                                    "air_pressure_Pa",
                                                    "air_humidity_pct",
                                                    "laser_wavelength_nm",
                                                    "air_index_assumed",
                                                    "datum_mm",
                                                    "material_compensation",
                                                    "deviation_unit",
                                                    "format"};
      if (!shown.count(k) && !handled.count(k)) meta_row(k, v, k);
    }
    o << "</table></section>\n";
  }

  void environment() {
    o << "<section id=\"environment\"><h2>Environment, normalisation and compensation</h2>\n";
    environment_table(o, res.normalisation);
    o << "<ul class=\"statements\">\n";
    for (const auto& line : iso230_2_normalisation_statement(res))
      o << "<li>" << h(pretty(line)) << "</li>\n";
    o << "</ul></section>\n";
  }

  // Results: figures and charts, classical beside drift-eliminated, on one deviation scale.
  void results() {
    SvgChart classical;
    classical.id = "chart-classical";
    classical.title = "Deviation, mean \xC2\xB1 2s (ISO 230-2)";
    classical.xlabel = "target " + cols.axis + " (" + pos_unit + ")";
    classical.ylabel = "deviation (" + pretty(u) + ")";
    classical.x = P;
    add_cycles(classical, runs.x[kUp], kUpColour, "runs \xE2\x86\x91");
    add_cycles(classical, runs.x[kDown], kDownColour, "runs \xE2\x86\x93");
    add_mean_band(classical, F.mean_up, F.s_up, 2, kUpColour, "mean \xE2\x86\x91",
                  "\xC2\xB1 2s \xE2\x86\x91");
    add_mean_band(classical, F.mean_down, F.s_down, 2, kDownColour, "mean \xE2\x86\x93",
                  "\xC2\xB1 2s \xE2\x86\x93");
    add_tolerance(classical, res.tolerance, u);
    SvgChart drift_chart;
    if (D) {
      drift_chart.id = "chart-drift";
      drift_chart.title = "Drift eliminated: chart \xC2\xB1 2s* (Stejskal et al.)";
      drift_chart.xlabel = classical.xlabel;
      drift_chart.ylabel = classical.ylabel;
      drift_chart.x = P;
      add_cycles(drift_chart, D->chart[kUp].shifted, kUpColour, "runs shifted \xE2\x86\x91");
      add_cycles(drift_chart, D->chart[kDown].shifted, kDownColour, "runs shifted \xE2\x86\x93");
      add_mean_band(drift_chart, D->chart[kUp].value, D->chart[kUp].s, 2, kUpColour,
                    "chart \xE2\x86\x91", "\xC2\xB1 2s* \xE2\x86\x91");
      add_mean_band(drift_chart, D->chart[kDown].value, D->chart[kDown].s, 2, kDownColour,
                    "chart \xE2\x86\x93", "\xC2\xB1 2s* \xE2\x86\x93");
      add_tolerance(drift_chart, res.tolerance, u);
      const auto range = y_range_of({&classical, &drift_chart});
      classical.y_range = drift_chart.y_range = range;
    }
    o << "<section id=\"results\"><h2>Results</h2>\n";
    if (!res.tolerance.empty()) {
      const bool pass = res.verdict == Decision::Conforms;
      bool with_u = false;
      for (const auto& c : res.tolerance) with_u |= std::isfinite(c.U);
      o << "<p class=\"verdict\" data-key=\"tolerance_pass\" data-value=\""
        << (pass ? "true" : "false") << "\">Verdict against the tolerances: <span class=\""
        << decision_class(res.verdict) << "\">" << decision_text(res.verdict) << "</span> ("
        << (with_u ? "classical figures, k = 2, with their expanded uncertainty, ISO 14253-1"
                   : "classical figures, k = 2, without their uncertainty")
        << (res.verdict_reason.empty() ? std::string() : "; " + h(pretty(res.verdict_reason)))
        << ")</p>\n";
    }
    o << "<div class=\"pair\">\n<div><h3>ISO 230-2 evaluation (k = 2)</h3>\n"
      << figures_table(F, "classical", u, &res.tolerance) << "<figure>" << svg_chart(classical)
      << "<figcaption>Every run (thin), the mean unidirectional deviations x\xCC\x84\xE2\x86\x91, "
         "x\xCC\x84\xE2\x86\x93 and the bands x\xCC\x84 \xC2\xB1 "
         "2s.</figcaption></figure>\n</div>\n";
    if (D) {
      o << "<div><h3>Drift-eliminated evaluation (k = 2)</h3>\n"
        << figures_table(D->figures, "drift_eliminated", u, nullptr) << "<figure>"
        << svg_chart(drift_chart) << "<figcaption>Adjacent-position differences accumulated from "
        << h(cols.axis) << " = " << format_number(P[D->reference_target]) << " " << pos_unit
        << ", cycle " << D->reference_cycle
        << "; every run shifted to that reference; s* = s of the differences / \xE2\x88\x9A"
           "2. "
           "Thermal drift between cycles is removed; drift within a pass is not.</figcaption>"
           "</figure>\n</div>\n";
    } else if (!res.iso_only) {
      o << "<div><h3>Drift-eliminated evaluation</h3><p>Needs at least 2 targets.</p></div>\n";
    }
    o << "</div>\n";
    if (res.classical.student) {
      const IsoFigures& S = *res.classical.student;
      o << "<p>With the Student-t coverage factor for " << runs.cycles[kUp].size()
        << " cycles (k = " << format_fixed(S.k_up, 2) << " / " << format_fixed(S.k_down, 2)
        << "): A = <span data-set=\"student\" data-key=\"A_um\">" << format_fixed(S.A, 3)
        << "</span> " << pretty(u) << ", R = <span data-set=\"student\" data-key=\"R_um\">"
        << format_fixed(S.R, 3) << "</span> " << pretty(u) << ".</p>\n";
    }
    if (!res.tolerance.empty()) {
      o << "<table class=\"tolerance\"><thead><tr><th>Tolerance</th><th>Value (" << pretty(u)
        << ")</th><th>U (" << pretty(u) << ")</th><th>Limit (" << pretty(u)
        << ")</th><th>Result</th></tr></thead><tbody>\n";
      for (const auto& c : res.tolerance)
        o << "<tr><td>"
          << (c.name == "band" ? std::string("every x\xCC\x84 \xC2\xB1 2s within \xC2\xB1 limit")
                               : h(c.name))
          << "</td><td class=\"num\" data-set=\"tolerance\" data-key=\"" << h(c.name) << "\">"
          << format_fixed(c.value, 3) << "</td><td class=\"num\">" << format_fixed(c.U, 3)
          << "</td><td class=\"num\">" << format_number(c.limit) << "</td><td class=\""
          << decision_class(c.decision) << "\">" << decision_text(c.decision) << "</td></tr>\n";
      o << "</tbody></table>\n";
    }
    o << "</section>\n";
  }

  void targets() {
    o << "<section id=\"targets\"><h2>Per target (" << pretty(u) << ", k = 2)</h2>\n"
      << "<table class=\"targets\"><thead><tr><th>Target (" << pos_unit
      << ")</th><th>x\xCC\x84 \xE2\x86\x91</th><th>x\xCC\x84 \xE2\x86\x93</th><th>s "
         "\xE2\x86\x91</th><th>s \xE2\x86\x93</th><th>B<sub>i</sub></th><th>R<sub>i</sub> "
         "\xE2\x86\x91</th><th>R<sub>i</sub> "
         "\xE2\x86\x93</th><th>R<sub>i</sub></th><th>x\xCC\x84<sub>i</sub></th>";
    if (D)
      o << "<th>chart \xE2\x86\x91</th><th>s* \xE2\x86\x91</th><th>chart \xE2\x86\x93</th><th>s* "
           "\xE2\x86\x93</th>";
    o << "</tr></thead><tbody>\n";
    for (std::size_t i = 0; i < m; ++i) {
      auto td = [&](const char* k, double v) {
        return "<td class=\"num\" data-set=\"classical\" data-key=\"" + std::string(k) +
               "\" data-index=\"" + std::to_string(i) + "\">" + format_fixed(v, 3) + "</td>";
      };
      o << "<tr><td class=\"num\">" << format_number(P[i]) << "</td>"
        << td("mean_up_um", F.mean_up[i]) << td("mean_down_um", F.mean_down[i])
        << td("s_up_um", F.s_up[i]) << td("s_down_um", F.s_down[i]) << td("B_i_um", F.B_i[i])
        << td("R_i_up_um", F.R_i_up[i]) << td("R_i_down_um", F.R_i_down[i])
        << td("R_i_um", F.R_i[i]) << td("mean_bi_um", F.mean_bi[i]);
      if (D)
        o << "<td class=\"num\">" << format_fixed(D->chart[kUp].value[i], 3)
          << "</td><td class=\"num\">" << format_fixed(D->chart[kUp].s[i], 3)
          << "</td><td class=\"num\">" << format_fixed(D->chart[kDown].value[i], 3)
          << "</td><td class=\"num\">" << format_fixed(D->chart[kDown].s[i], 3) << "</td>";
      o << "</tr>\n";
    }
    o << "</tbody></table></section>\n";
  }

  // Thermal drift: every cycle's offset, the drift rate and the anomaly test.
  void drift() {
    if (D) {
      const DriftPerCycle& C = D->per_cycle;
      SvgChart cyc;
      cyc.id = "chart-cycles";
      cyc.title =
          "Offset of every cycle (relative to cycle " + std::to_string(D->reference_cycle) + ")";
      cyc.xlabel = "cycle";
      cyc.ylabel = "offset (" + pretty(u) + ")";
      for (long c : C.cycles) cyc.x.push_back(static_cast<double>(c));
      cyc.series.push_back({"forward \xE2\x86\x91", C.offset_up, kUpColour, 1.6, false, true, 1});
      cyc.series.push_back(
          {"reverse \xE2\x86\x93", C.offset_down, kDownColour, 1.6, false, true, 1});
      cyc.series.push_back({"mean", C.offset, "#333333", 1.2, true, false, 1});
      cyc.width = 760;
      cyc.height = 300;
      o << "<section id=\"drift\"><h2>Thermal drift</h2>\n<figure>" << svg_chart(cyc)
        << "</figure>\n<p>Drift rate " << format_fixed(C.rate_per_cycle, 4) << " \xC2\xB1 "
        << format_fixed(C.rate_per_cycle_se, 4) << " " << pretty(u) << " per cycle";
      if (std::isfinite(C.rate_per_h))
        o << ", " << format_fixed(C.rate_per_h, 4) << " \xC2\xB1 "
          << format_fixed(C.rate_per_h_se, 4) << " " << pretty(u) << "/h";
      o << " (within-group least squares, standard error). Anomaly test (F test of each adjacent "
           "difference, Bonferroni over "
        << D->tests << " tests, \xCE\xB1 = " << format_number(D->alpha) << "): ";
      if (D->anomalous_positions.empty() && D->anomalous_differences.empty()) {
        o << "no anomalous spread.";
      } else {
        std::vector<std::string> items;
        for (const auto& a : D->anomalous_positions)
          items.push_back(cols.axis + " = " + format_number(P[a.target]) + " " + pos_unit +
                          (a.direction > 0 ? " \xE2\x86\x91" : " \xE2\x86\x93"));
        for (const auto& a : D->anomalous_differences)
          items.push_back(format_number(P[a.from]) + "\xE2\x80\xA6" + format_number(P[a.to]) + " " +
                          pos_unit + (a.direction > 0 ? " \xE2\x86\x91" : " \xE2\x86\x93") +
                          " (p = " + format_significant(a.p_value, 2) + ")");
        o << "anomalous: ";
        for (std::size_t i = 0; i < items.size(); ++i) o << (i ? "; " : "") << h(items[i]);
        o << ".";
      }
      o << "</p></section>\n";
    }
  }

  void signature_and_method() {
    o << "<section id=\"signature\"><h2>Approval</h2><div class=\"signature\"><div>Tested by</div>"
         "<div>Checked by</div><div>Date</div></div></section>\n";
    o << "<footer>Figures as defined in ISO 230-2:2014, clause 3 (coverage factor k = 2). "
         "Drift-eliminated evaluation after T. Stejskal et al., Advances in Science and Technology "
         "Research Journal 11(4), 2017. Normalisation to 20 \xC2\xB0"
         "C per ISO 1; air refraction by "
         "the modified Edl\xC3\xA9n equation of Birch &amp; Downs (Metrologia 30, 1993; 31, 1994). "
         "Report written by weilgen "
      << kVersion << " (docs/iso230-2.md).</footer>\n</main>\n</body>\n</html>\n";
  }

  const Iso230_2StudyResult& res;
  const IsoColumns& cols;
  const IsoRuns& runs;
  const IsoFigures& F;
  const std::string& u;
  const std::vector<double>& P;
  const std::size_t m;
  const std::string pos_unit;
  const std::string machine;
  const DriftResult* D;  // null without a drift elimination
  std::ostringstream o;
};

}  // namespace

std::string iso230_2_html(const std::string& data, const Iso230_2StudyResult& res,
                          const std::string& source_format) {
  return Iso230_2Page(res).write(data, source_format);
}

}  // namespace weilgen
