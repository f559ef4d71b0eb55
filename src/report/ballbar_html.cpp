// The ballbar polar plot and HTML report (docs/ballbar.md, "weilgen ballbar").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "html_page.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/report/ballbar_document.hpp"
#include "weilgen/report/svg_chart.hpp"

namespace weilgen {

namespace {

const char* const kCcw = "#1f77b4";  // counter-clockwise runs
const char* const kCw = "#d62728";   // clockwise runs

std::string polar_px(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

}  // namespace

std::string p_text(double p) {
  // Below double precision's resolution of 1 - cdf the value is only a bound.
  return p < 1e-16 ? "< 1e-16" : format_significant(p, 2);
}

std::string ballbar_polar_svg(const BallbarStudy& st) {
  const BallbarDiagnosisResult& d = st.diagnosis;
  const BallbarCircle& c = st.circle;
  // Every run about its own least-squares centre (the set-up removed, as ISO 230-4 evaluates
  // it); the deviations magnified about the nominal circle drawn at r0.
  std::vector<std::vector<double>> centred;
  double lo = INFINITY, hi = -INFINITY, sum = 0;
  std::size_t count = 0;
  for (const BallbarRun& r : d.runs) {
    centred.push_back(r.evaluation.centred_um);
    for (double v : r.evaluation.centred_um)
      lo = std::min(lo, v), hi = std::max(hi, v), sum += v, ++count;
  }
  const double mid = count ? sum / static_cast<double>(count) : 0;
  double half = std::max({hi - mid, mid - lo, 0.5});
  const std::vector<double> ticks = nice_ticks(-half, half, 4);
  half = std::max(std::abs(ticks.front()), std::abs(ticks.back()));
  const double cx = 350, cy = 370, r0 = 170, span = 110;  // px: the band ±half µm spans ±span
  const double k = span / half;                           // px per µm
  auto at = [&](double theta_deg, double dev_um) {
    const double r = r0 + k * (dev_um - mid), t = theta_deg * kPi / 180;
    return std::make_pair(cx + r * std::cos(t), cy - r * std::sin(t));
  };
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" id=\"ballbar-polar\" width=\"1090\" "
       "height=\"740\" "
       "viewBox=\"0 0 1090 740\" font-family=\"Helvetica, Arial, sans-serif\" font-size=\"12\">\n";
  o << "<rect width=\"1090\" height=\"740\" fill=\"#ffffff\"/>\n";
  o << "<text x=\"" << polar_px(cx)
    << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\" "
       "font-weight=\"bold\">Ballbar "
    << xml_escape(c.plane) << ", R " << format_number(c.radius_mm)
    << " mm: radial deviation about each run's centre</text>\n";
  // Deviation rings (dashed) and the nominal circle (solid), labelled in µm.
  for (double t : ticks) {
    const double r = r0 + k * t;
    if (r <= 0) continue;
    o << "<circle cx=\"" << polar_px(cx) << "\" cy=\"" << polar_px(cy) << "\" r=\"" << polar_px(r)
      << "\" fill=\"none\" stroke=\"" << (std::abs(t) < 1e-12 ? "#444444" : "#c8d0dc")
      << "\" stroke-width=\"" << (std::abs(t) < 1e-12 ? "1.2" : "0.8") << "\""
      << (std::abs(t) < 1e-12 ? "" : " stroke-dasharray=\"3 3\"") << "/>\n";
    o << "<text x=\"" << polar_px(cx + 3) << "\" y=\"" << polar_px(cy - r - 2)
      << "\" fill=\"#666666\">" << (t > 0 ? "+" : "") << format_significant(t, 3)
      << " \xC2\xB5m</text>\n";
  }
  // Spokes every 30°, the axes named at 0° and 90°.
  for (int a = 0; a < 360; a += 30) {
    const auto [x0, y0] = at(a, mid - r0 / k * 0.15);
    const auto [x1, y1] = at(a, mid + (span + 25) / k);
    o << "<line x1=\"" << polar_px(x0) << "\" y1=\"" << polar_px(y0) << "\" x2=\"" << polar_px(x1)
      << "\" y2=\"" << polar_px(y1) << "\" stroke=\"#e3e8ef\" stroke-width=\"0.8\"/>\n";
    const auto [tx, ty] = at(a, mid + (span + 38) / k);
    std::string label = std::to_string(a) + "\xC2\xB0";
    if (a == 0) label = "+" + c.first + " 0\xC2\xB0";
    if (a == 90) label = "+" + c.second + " 90\xC2\xB0";
    o << "<text x=\"" << polar_px(tx) << "\" y=\"" << polar_px(ty + 4)
      << "\" text-anchor=\"middle\" "
      << "fill=\"#444444\">" << xml_escape(label) << "</text>\n";
  }
  // Each run's minimum zone: the two circles about its minimum-zone centre, seen in its
  // least-squares-centred coordinates.
  for (std::size_t r = 0; r < d.runs.size(); ++r) {
    const BallbarEvaluation& e = d.runs[r].evaluation;
    const char* colour = d.runs[r].feed > 0 ? kCcw : kCw;
    for (double side : {-0.5, 0.5}) {
      o << "<path class=\"zone\" d=\"";
      for (int a = 0; a <= 360; a += 2) {
        const double t = a * kPi / 180;
        const double dev = e.mz_radius_deviation_um + side * e.mz_circular_deviation_um +
                           (e.mz_centre_offset_um[0] - e.centre_offset_um[0]) * std::cos(t) +
                           (e.mz_centre_offset_um[1] - e.centre_offset_um[1]) * std::sin(t);
        const auto [x, y] = at(a, dev);
        o << (a == 0 ? "M" : " L") << polar_px(x) << " " << polar_px(y);
      }
      o << " Z\" fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"0.9\" "
        << "stroke-dasharray=\"6 3\" opacity=\"0.6\"/>\n";
    }
  }
  // The runs.
  for (std::size_t r = 0; r < d.runs.size(); ++r) {
    const BallbarTrace& t = st.traces[r];
    const char* colour = d.runs[r].feed > 0 ? kCcw : kCw;
    o << "<path class=\"run\" data-run=\""
      << xml_escape(ballbar_run_label(d.runs[r].feed, d.runs[r].cycle)) << "\" d=\"";
    for (std::size_t i = 0; i < t.size(); ++i) {
      const auto [x, y] = at(t.angle_deg[i], centred[r][i]);
      o << (i == 0 ? "M" : " L") << polar_px(x) << " " << polar_px(y);
    }
    o << " Z\" fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"1.6\"/>\n";
  }
  // The annotations: per run G, G_mz; H; the ranked diagnosis.
  double y = 60;
  auto line = [&](const std::string& text, const std::string& colour = "#222222",
                  bool bold = false) {
    o << "<text x=\"710\" y=\"" << polar_px(y) << "\" fill=\"" << colour << "\""
      << (bold ? " font-weight=\"bold\"" : "") << ">" << xml_escape(text) << "</text>\n";
    y += 17;
  };
  line("ISO 230-4", "#1f3b63", true);
  for (const BallbarRun& r : d.runs) {
    const std::string colour = r.feed > 0 ? kCcw : kCw;
    o << "<line x1=\"710\" y1=\"" << polar_px(y - 4) << "\" x2=\"732\" y2=\"" << polar_px(y - 4)
      << "\" stroke=\"" << colour << "\" stroke-width=\"2.5\"/>\n";
    o << "<text x=\"738\" y=\"" << polar_px(y) << "\">"
      << xml_escape(ballbar_run_label(r.feed, r.cycle)) << ": G "
      << format_fixed(r.evaluation.circular_deviation_um, 2) << " \xC2\xB5m, minimum zone "
      << format_fixed(r.evaluation.mz_circular_deviation_um, 2) << " \xC2\xB5m</text>\n";
    y += 17;
  }
  if (std::isfinite(d.hysteresis_um)) line("H " + format_fixed(d.hysteresis_um, 2) + " \xC2\xB5m");
  line("dashed: each run's minimum zone", "#666666");
  line("scale: " + format_significant(ticks.size() > 1 ? ticks[1] - ticks[0] : half, 3) +
           " \xC2\xB5m per ring",
       "#666666");
  y += 10;
  line("Diagnosis (ranked)", "#1f3b63", true);
  int shown = 0;
  for (const BallbarCause& cause : d.causes) {
    if (!cause.significant || shown == 8) continue;
    ++shown;
    line(std::to_string(shown) + ". " + cause.name + " " +
         format_fixed(cause.size, cause.unit == "um" ? 2 : 1) + " " + pretty(cause.unit) + " (" +
         format_fixed(cause.contribution_um, 2) + " \xC2\xB5m)");
  }
  if (shown == 0) line("clean: no cause above the noise");
  line("residual " + format_fixed(d.residual_rms_um, 3) + " \xC2\xB5m rms", "#666666");
  o << "</svg>\n";
  return o.str();
}

std::string ballbar_html(const BallbarStudy& st) {
  const BallbarCircle& c = st.circle;
  const BallbarDiagnosisResult& d = st.diagnosis;
  auto key = [&](const std::string& k) {
    const auto it = st.header_keys.find(k);
    return it == st.header_keys.end() ? std::string() : it->second;
  };
  std::ostringstream o;
  o << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
    << "<meta name=\"generator\" content=\"weilgen " << kVersion << "\">\n<title>Ballbar "
    << xml_escape(c.plane) << "</title>\n<style>" << report_style()
    << "table.diagnosis td.rank { text-align: center; }\n</style>\n</head>\n<body>\n<main>\n";
  o << "<header><h1>Circular test \xE2\x80\x93 ISO 230-4 and ballbar diagnosis</h1><p "
       "class=\"sub\">Plane "
    << xml_escape(c.plane) << " \xC2\xB7 radius " << format_number(c.radius_mm) << " mm"
    << (std::isfinite(st.feedrate_mm_min)
            ? " \xC2\xB7 feedrate " + format_number(st.feedrate_mm_min) + " mm/min"
            : std::string())
    << (key("machine").empty() ? "" : " \xC2\xB7 " + xml_escape(key("machine")))
    << "</p></header>\n";
  // Identification: the rows a signed report needs stay, blank to fill in.
  o << "<section id=\"identification\"><h2>Test identification</h2>\n<table class=\"meta\">\n";
  for (const auto& [k, label] :
       std::vector<std::pair<std::string, std::string>>{{"machine", "Machine"},
                                                        {"serial", "Serial number"},
                                                        {"location", "Location"},
                                                        {"date", "Test date"},
                                                        {"operator", "Operator"},
                                                        {"instrument", "Instrument"}}) {
    const std::string v = key(k);
    o << "<tr><td>" << label << "</td><td data-key=\"" << k << "\""
      << (v.empty() ? " class=\"fill\"" : "") << ">" << xml_escape(v) << "</td></tr>\n";
  }
  // The centre as the machine's coordinates: those of the plane and any not at 0.
  std::string centre;
  if (st.centre_given)
    for (const auto& [name, v] : c.centre)
      if (v != 0 || name == c.first || name == c.second)
        centre += (centre.empty() ? "" : ", ") + name + " " + format_number(v);
  o << "<tr><td>Circle</td><td>plane " << xml_escape(c.plane) << " (\xCE\xB8 from +"
    << xml_escape(c.first) << " toward +" << xml_escape(c.second) << "), radius "
    << format_number(c.radius_mm) << " mm"
    << (centre.empty() ? std::string() : ", centre " + xml_escape(centre)) << "</td></tr>\n";
  if (!st.machine.empty())
    o << "<tr><td>Model</td><td>" << xml_escape(st.machine) << "</td></tr>\n";
  o << "<tr><td>Data file</td><td>" << xml_escape(st.file) << "</td></tr>\n</table></section>\n";
  // ISO 230-4 per run.
  o << "<section id=\"iso230_4\"><h2>ISO 230-4 figures (\xC2\xB5m)</h2>\n<table "
       "class=\"figures\"><thead><tr><th>Figure</th>";
  for (const BallbarRun& r : d.runs)
    o << "<th>" << xml_escape(ballbar_run_label(r.feed, r.cycle)) << "</th>";
  o << "</tr></thead><tbody>\n";
  struct Row {
    std::string name, key;
    double (*get)(const BallbarEvaluation&);
  };
  const Row rows[] = {{"Circular deviation G (least-squares centre)", "G_um",
                       [](const BallbarEvaluation& e) { return e.circular_deviation_um; }},
                      {"Circular deviation G (minimum zone)", "G_minimum_zone_um",
                       [](const BallbarEvaluation& e) { return e.mz_circular_deviation_um; }},
                      {"Radial deviation F max", "F_max_um",
                       [](const BallbarEvaluation& e) { return e.radial_deviation_max_um; }},
                      {"Radial deviation F min", "F_min_um",
                       [](const BallbarEvaluation& e) { return e.radial_deviation_min_um; }},
                      {"Radius deviation", "radius_deviation_um",
                       [](const BallbarEvaluation& e) { return e.radius_deviation_um; }},
                      {"Centre offset " + c.first, "centre_first",
                       [](const BallbarEvaluation& e) { return e.centre_offset_um[0]; }},
                      {"Centre offset " + c.second, "centre_second",
                       [](const BallbarEvaluation& e) { return e.centre_offset_um[1]; }}};
  for (const Row& row : rows) {
    o << "<tr><td>" << xml_escape(row.name) << "</td>";
    for (std::size_t i = 0; i < d.runs.size(); ++i)
      o << "<td class=\"num\" data-run=\"" << i << "\" data-key=\"" << row.key << "\">"
        << format_fixed(row.get(d.runs[i].evaluation), 3) << "</td>";
    o << "</tr>\n";
  }
  o << "</tbody></table>\n<p>Circular hysteresis H (first ccw against first cw run): "
    << (std::isfinite(d.hysteresis_um) ? "<span data-key=\"hysteresis_um\">" +
                                             format_fixed(d.hysteresis_um, 3) + "</span> \xC2\xB5m"
                                       : std::string("needs a run in each direction"))
    << ".</p></section>\n";
  o << "<section id=\"polar\"><h2>Polar plot</h2>\n<figure>" << ballbar_polar_svg(st)
    << "<figcaption>Both directions (ccw blue, cw red), each about its least-squares centre, "
       "magnified about the nominal circle; dashed: each run's minimum zone.</figcaption>"
       "</figure></section>\n";
  // The diagnosis.
  o << "<section id=\"diagnosis\"><h2>Diagnosis</h2>\n<p>The usual ballbar causes fitted "
       "together by least squares on every run (each run's centre and radius free); residual "
    << format_fixed(d.residual_rms_um, 3)
    << " \xC2\xB5m rms; a cause is named when its partial F test "
       "passes at a family-wise \xCE\xB1 = "
    << format_number(d.alpha) << ". "
    << (d.clean() ? "<strong>Clean: no cause stands out of the noise.</strong>" : "")
    << "</p>\n<table class=\"diagnosis\"><thead><tr><th>Rank</th><th>Cause</th><th>Size</th>"
       "<th>\xC2\xB1 se</th><th>Unit</th><th>Detail</th><th>Contribution (\xC2\xB5m)</th>"
       "<th>p</th><th>Status</th></tr></thead><tbody>\n";
  int rank = 0;
  for (const BallbarCause& k : d.causes) {
    o << "<tr" << (k.significant ? " class=\"named\"" : "") << " data-cause=\"" << xml_escape(k.id)
      << "\"><td class=\"rank\">" << (k.significant ? std::to_string(++rank) : std::string())
      << "</td><td>" << xml_escape(k.name) << "</td><td class=\"num\">"
      << (k.separable ? format_fixed(k.size, k.unit == "um" ? 2 : 1) : std::string("\xE2\x80\x93"))
      << "</td><td class=\"num\">"
      << (k.separable ? format_fixed(k.se, k.unit == "um" ? 2 : 1) : std::string("\xE2\x80\x93"))
      << "</td><td>" << pretty(k.unit) << "</td><td>"
      << (std::isfinite(k.detail) ? xml_escape(k.detail_name) + " " + format_fixed(k.detail, 2) +
                                        " " + xml_escape(k.detail_unit)
                                  : std::string())
      << "</td><td class=\"num\">"
      << (k.separable ? format_fixed(k.contribution_um, 2) : std::string())
      << "</td><td class=\"num\">" << (k.separable ? p_text(k.p_value) : std::string())
      << "</td><td>"
      << (k.significant ? "<strong>named</strong>"
          : k.separable ? "within the noise"
                        : xml_escape(k.note))
      << "</td></tr>\n";
  }
  o << "</tbody></table>\n";
  if (!st.terms.empty()) {
    o << "<h3>Through the model (" << xml_escape(st.machine)
      << ")</h3><p>The model's terms that alone "
         "would make a named geometric cause, and the value each would need:</p><ul "
         "class=\"statements\">\n";
    for (const BallbarCause& k : d.causes)
      if (k.significant)
        for (const BallbarCauseTerm& t : st.terms)
          if (t.cause == k.id && t.per_unit != 0)
            o << "<li>" << xml_escape(k.name) << ": " << xml_escape(t.term) << " = "
              << format_significant(k.size / t.per_unit, 4) << " " << pretty(t.unit) << "</li>\n";
    o << "</ul>\n";
  }
  o << "</section>\n";
  o << "<section id=\"signature\"><h2>Approval</h2><div class=\"signature\"><div>Tested by</div>"
       "<div>Checked by</div><div>Date</div></div></section>\n";
  o << "<footer>G, F and H as defined in ISO 230-4 (least-squares and minimum-zone centres). "
       "Diagnosis and the models of its causes: docs/ballbar.md. Report written by weilgen "
    << kVersion << ".</footer>\n</main>\n</body>\n</html>\n";
  return o.str();
}

}  // namespace weilgen
