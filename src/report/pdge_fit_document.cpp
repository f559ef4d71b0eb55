#include "weilgen/report/pdge_fit_document.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

#include "weilgen/base/format.hpp"
#include "weilgen/report/csv_table.hpp"
#include "weilgen/report/json_common.hpp"

namespace weilgen {

namespace {

using nlohmann::json;

// Table cells: fixed decimals, or significant digits (4 unless said); "-" when not computed.
std::string fmt_g(double v, int digits = 4) { return format_significant(v, digits); }

// Mean of y at each distinct x (sorted): the data line of the plot.
void position_means(const std::vector<double>& x, const std::vector<double>& y,
                    std::vector<double>& xs, std::vector<double>& means) {
  std::map<double, std::pair<double, int>> acc;
  for (std::size_t i = 0; i < x.size(); ++i) {
    auto& a = acc[x[i]];
    a.first += y[i];
    a.second += 1;
  }
  xs.clear();
  means.clear();
  for (const auto& [pos, a] : acc) {
    xs.push_back(pos);
    means.push_back(a.first / a.second);
  }
}

json curve_json(const std::vector<CvCurvePoint>& curve) {
  json a = json::array();
  for (const CvCurvePoint& p : curve) {
    a.push_back({{"order", p.order},
                 {"params", p.params},
                 {"period_mm", json_number(p.period_mm)},
                 {"feasible", p.feasible},
                 {"reason", p.reason},
                 {"train_rmse", json_number(p.train_rmse)},
                 {"cv_rmse", json_number(p.cv.rmse)},
                 {"cv_mse", json_number(p.cv.mse)},
                 {"cv_mse_se", json_number(p.cv.mse_se)}});
  }
  return a;
}

json fit_json(const PdgeFitResult& r) {
  const FitResult& f = r.fit;
  json j = {{"basis", f.basis.name()},
            {"spec", r.spec.str()},
            {"kind", basis_kind_name(f.basis.kind)},
            {"order", f.basis.order},
            {"order_choice", r.order_choice},
            {"params", f.params()},
            {"travel_mm", {f.basis.a, f.basis.b}},
            {"terms", f.basis.term_names()},
            {"coefficients", json_numbers(f.coefficients)},
            {"std_errors", json_numbers(f.std_errors)},
            {"sigma", json_number(f.sigma)},
            {"condition", json_number(f.condition)},
            {"metrics",
             {{"n", f.metrics.n},
              {"e_max", json_number(f.metrics.e_max)},
              {"r2", json_number(f.metrics.r2)},
              {"sse", json_number(f.metrics.sse)},
              {"rmse", json_number(f.metrics.rmse)},
              {"cv_rmse", json_number(r.cv.rmse)},
              {"cv_mse_se", json_number(r.cv.mse_se)}}},
            {"cv_note", r.cv_note},
            {"min_cv_order", r.min_cv_order < 0 ? json() : json(r.min_cv_order)},
            {"cv_curve", curve_json(r.curve)}};
  if (f.basis.kind == BasisKind::Fourier) {
    j["period_mm"] = f.basis.period();
    j["period_choice"] = r.period_choice;
    j["period_at_bound"] = r.period_at_bound;
    json amp = json::array();
    for (int k = 1; k <= f.basis.order; ++k) {
      const auto c = f.coefficients[static_cast<std::size_t>(2 * k - 1)];
      const auto s = f.coefficients[static_cast<std::size_t>(2 * k)];
      amp.push_back({{"k", k},
                     {"wavelength_mm", f.basis.period() / k},
                     {"amplitude", std::hypot(c, s)},
                     {"phase_rad", std::atan2(s, c)}});
    }
    j["harmonics"] = amp;  // a_k cos + b_k sin = amplitude * cos(2 pi k x / L - phase)
  } else {
    j["power_coefficients"] = json_numbers(f.basis.power_coefficients(f.coefficients));
  }
  return j;
}

json source_json(const PdgeProfileSource& s) {
  return {{"error", s.error},         {"kind", s.kind},
          {"unit", s.unit},           {"source", s.source},
          {"sign", s.sign},           {"removed", s.removed},
          {"intercept", s.intercept}, {"slope_per_mm", s.slope_per_mm}};
}

}  // namespace

std::string pdge_fit_text(const PdgeFitStudyOptions& o, const PdgeFitStudyResult& r, bool curves) {
  std::ostringstream os;
  const auto& profiles = r.profiles;
  const auto& results = r.results;
  const auto& failures = r.failures;
  const double a = r.travel_a, b = r.travel_b;
  const std::string& pos_name = r.axis;
  // ---- stdout: a Table-4-style comparison per profile ----
  std::size_t positions = 0;
  {
    std::vector<double> all;
    for (const PdgeProfile& p : profiles) all.insert(all.end(), p.x.begin(), p.x.end());
    positions = distinct_count(all);
  }
  os << "weilgen fit-pdge: " << r.file << " (" << r.format << ", axis " << pos_name << ", "
     << profiles.size() << " profile" << (profiles.size() == 1 ? "" : "s") << ", " << r.rows
     << " rows, " << positions << " positions)\n";
  int folds_used = o.folds;
  for (const auto& per_profile : results)
    for (const PdgeFitResult& fr : per_profile)
      if (fr.folds > 0) folds_used = std::min(folds_used, fr.folds);
  os << "travel [" << fmt_g(a, 10) << ", " << fmt_g(b, 10) << "] mm; CV "
     << (r.fit_options.cv.scheme == CvScheme::Blocks
             ? std::to_string(folds_used) + "-fold blocks" +
                   (folds_used < o.folds
                        ? " (" + std::to_string(o.folds) + " asked: one per interior position)"
                        : std::string())
             : std::string("leave-one-cycle-out"))
     << ", order rule " << o.rule << ", orders " << o.min_order << ".." << o.max_order << "\n";
  for (std::size_t i = 0; i < profiles.size(); ++i) {
    const PdgeProfile& p = profiles[i];
    const std::string u = p.unit;
    os << "\n" << p.name << " (" << u << ", " << p.x.size() << " values";
    if (p.source) {
      os << "; from " << p.column << " x " << (p.source->sign > 0 ? "+1" : "-1") << ", removed "
         << p.source->removed;
      if (p.source->removed == "line")
        os << " " << fmt_g(p.source->intercept) << " + " << fmt_g(p.source->slope_per_mm) << "*"
           << pos_name;
      else if (p.source->removed == "mean")
        os << " " << fmt_g(p.source->intercept);
    }
    os << ")\n";
    std::ostringstream h;
    h << std::left << std::setw(18) << "basis" << std::right << std::setw(6) << "order"
      << std::setw(7) << "params" << std::setw(11) << "period_mm" << std::setw(12) << "e_max_" + u
      << std::setw(9) << "R2" << std::setw(13) << "SSE_" + u + "2" << std::setw(11) << "RMSE_" + u
      << std::setw(14) << "CV_RMSE_" + u << "\n";
    os << h.str();
    std::size_t best = results[i].size();
    for (std::size_t k = 0; k < results[i].size(); ++k) {
      if (!failures[i][k].empty()) continue;
      const double v = results[i][k].cv.rmse;
      if (std::isfinite(v) && (best == results[i].size() || v < results[i][best].cv.rmse)) best = k;
    }
    for (std::size_t k = 0; k < results[i].size(); ++k) {
      const PdgeFitResult& fr = results[i][k];
      const FitResult& f = fr.fit;
      std::string label = fr.spec.str();
      if (!failures[i][k].empty()) {
        os << std::left << std::setw(18) << label << std::right
           << "  not fitted: " << failures[i][k] << "\n";
        continue;
      }
      std::ostringstream line;
      line << std::left << std::setw(18) << label << std::right << std::setw(6)
           << (std::to_string(f.basis.order) + (fr.order_choice == "fixed" ? "" : "*"))
           << std::setw(7) << f.params() << std::setw(11)
           << (f.basis.kind == BasisKind::Fourier && f.basis.order > 0
                   ? format_fixed(f.basis.period(), 2) + (fr.period_at_bound ? "!" : "")
                   : std::string("-"))
           << std::setw(12) << format_fixed(f.metrics.e_max, 3) << std::setw(9)
           << format_fixed(f.metrics.r2, 4) << std::setw(13) << fmt_g(f.metrics.sse, 5)
           << std::setw(11) << format_fixed(f.metrics.rmse, 3) << std::setw(14)
           << format_fixed(fr.cv.rmse, 3) << (k == best ? "  <- least CV error" : "") << "\n";
      os << line.str();
      if (curves) {
        for (const CvCurvePoint& c : fr.curve) {
          os << "      order " << std::setw(2) << c.order << ": train RMSE " << std::setw(8)
             << format_fixed(c.train_rmse, 3) << "  CV RMSE " << std::setw(9)
             << format_fixed(c.cv.rmse, 3) << " (MSE se " << fmt_g(c.cv.mse_se, 3) << ")";
          if (std::isfinite(c.period_mm) && c.order > 0)
            os << "  L " << format_fixed(c.period_mm, 2) << " mm";
          if (!c.feasible) os << "  not feasible: " << c.reason;
          os << "\n";
        }
      }
      if (!fr.cv_note.empty()) os << "      (no CV error: " << fr.cv_note << ")\n";
    }
  }
  bool any_at_bound = false;
  for (std::size_t i = 0; i < results.size(); ++i)
    for (std::size_t k = 0; k < results[i].size(); ++k)
      any_at_bound = any_at_bound || (failures[i][k].empty() && results[i][k].period_at_bound);
  os << "\n* order chosen by cross-validation (" << o.rule
     << " rule). Metrics as Zhang & Chen 2021, Table 4: e_max = max |residual|, R2, SSE, RMSE =\n"
        "sqrt(SSE/n), on the fitted data; CV_RMSE = held-out error.\n";
  if (any_at_bound)
    os << "! searched period at an end of its range [2*order*spacing, 2*travel]: the series\n"
          "  is absorbing a trend, or the period lies outside the range (--period L).\n";

  return os.str();
}

nlohmann::json pdge_fit_json(const PdgeFitStudyOptions& o, const PdgeFitStudyResult& r) {
  const auto& profiles = r.profiles;
  const auto& results = r.results;
  const auto& failures = r.failures;
  const double a = r.travel_a, b = r.travel_b;
  const std::string& pos_name = r.axis;
  // ---- JSON ----
  {
    json line6d;
    if (r.format == "line6d") {
      json conv = json::array();
      for (const auto& c : r.line6d_conversions) conv.push_back(source_json(c));
      line6d = {{"axis", r.axis}, {"spelling", r.line6d_spelling}, {"profiles", conv}};
    }
    json cols = json::array();
    for (std::size_t i = 0; i < profiles.size(); ++i) {
      const PdgeProfile& p = profiles[i];
      json fits = json::array();
      for (std::size_t k = 0; k < results[i].size(); ++k) {
        if (failures[i][k].empty())
          fits.push_back(fit_json(results[i][k]));
        else
          fits.push_back({{"spec", results[i][k].spec.str()}, {"error", failures[i][k]}});
      }
      cols.push_back({{"name", p.name},
                      {"column", p.column},
                      {"unit", p.unit},
                      {"n", p.x.size()},
                      {"positions", distinct_count(p.x)},
                      {"conversion", p.source ? source_json(*p.source) : json()},
                      {"fits", fits}});
    }
    std::vector<std::string> spec_names;
    for (const BasisSpec& s : r.specs) spec_names.push_back(s.str());
    json j = json_document(
        "fit-pdge",
        {{"file", r.file},
         {"format", r.format},
         {"axis", pos_name},
         {"travel_mm", {a, b}},
         {"settings",
          {{"bases", spec_names},
           {"cv", cv_scheme_name(r.fit_options.cv.scheme)},
           {"folds", r.fit_options.cv.scheme == CvScheme::Blocks ? json(o.folds) : json()},
           {"keep_ends", r.fit_options.cv.keep_ends},
           {"rule", o.rule},
           {"min_order", o.min_order},
           {"max_order", o.max_order},
           {"period", o.period}}},
         {"line6d", line6d},
         {"profiles", cols}});
    return j;
  }
}

std::string pdge_fit_csv(const PdgeFitStudyResult& r) {
  CsvTable t;
  t.comment("weilgen fit-pdge " + r.file + " (axis " + r.axis + ")");
  for (const char* c : {"profile", "column", "unit", "basis", "kind", "order", "order_choice"})
    t.column(c);
  t.column("period", "mm");
  for (const char* c : {"params", "n", "e_max", "R2", "SSE", "RMSE", "CV_RMSE", "error"})
    t.column(c);
  for (std::size_t i = 0; i < r.profiles.size(); ++i) {
    const PdgeProfile& p = r.profiles[i];
    for (std::size_t k = 0; k < r.results[i].size(); ++k) {
      const PdgeFitResult& fr = r.results[i][k];
      t.text(p.name).text(p.column).text(p.unit);
      if (!r.failures[i][k].empty()) {
        t.text(fr.spec.str());
        for (int c = 0; c < 11; ++c) t.text("");
        t.text(r.failures[i][k]).end_row();
        continue;
      }
      const FitResult& f = fr.fit;
      t.text(f.basis.name()).text(basis_kind_name(f.basis.kind));
      t.count(static_cast<std::size_t>(f.basis.order));
      t.text(fr.order_choice).number(f.basis.kind == BasisKind::Fourier ? f.basis.period() : NAN);
      t.count(f.params()).count(f.metrics.n).number(f.metrics.e_max);
      t.number(f.metrics.r2).number(f.metrics.sse).number(f.metrics.rmse).number(fr.cv.rmse);
      t.text("").end_row();
    }
  }
  return t.str();
}

namespace {

// Adds the curve `y` to `plot`, or, when a curve already drawn equals it to 1e-9 of its range,
// appends `label` to that curve's label and returns true.
bool add_or_merge(LinePlot& plot, const std::string& label, const std::vector<double>& y) {
  for (std::size_t k = 1; k < plot.lines.size(); ++k) {  // line 0 is the data
    const std::vector<double>& other = plot.lines[k].second;
    double range = 0, diff = 0;
    for (std::size_t i = 0; i < y.size(); ++i) {
      range = std::max(range, std::abs(other[i]));
      diff = std::max(diff, std::abs(other[i] - y[i]));
    }
    if (diff <= 1e-9 * range) {
      plot.lines[k].first += " = " + label;
      return true;
    }
  }
  plot.lines.emplace_back(label, y);
  return false;
}

}  // namespace

std::vector<Panel> pdge_fit_panels(const PdgeFitStudyResult& r) {
  const auto& profiles = r.profiles;
  const auto& results = r.results;
  const auto& failures = r.failures;
  const double a = r.travel_a, b = r.travel_b;
  const std::string& pos_name = r.axis;
  // ---- plot: per profile, data + fits, and residuals ----
  std::vector<Panel> panels;
  {
    for (std::size_t i = 0; i < profiles.size(); ++i) {
      const PdgeProfile& p = profiles[i];
      std::vector<double> xs, means;
      position_means(p.x, p.y, xs, means);
      // x: the positions and a dense grid over the travel.
      std::vector<double> dense = xs;
      for (int k = 0; k <= 200; ++k) dense.push_back(a + (b - a) * k / 200.0);
      std::sort(dense.begin(), dense.end());
      dense.erase(std::unique(dense.begin(), dense.end()), dense.end());
      LinePlot fitp;
      fitp.title = p.name + ": data and fits";
      fitp.xlabel = pos_name + " (mm)";
      fitp.ylabel = p.name + " (" + p.unit + ")";
      fitp.x = dense;
      std::vector<double> data(dense.size(), NAN);
      for (std::size_t k = 0; k < dense.size(); ++k) {
        const auto it = std::lower_bound(xs.begin(), xs.end(), dense[k]);
        if (it != xs.end() && *it == dense[k])
          data[k] = means[static_cast<std::size_t>(it - xs.begin())];
      }
      fitp.lines.emplace_back(p.cycle.empty() ? "data" : "data (mean per position)", data);
      std::vector<LineStyle> styles{LineStyle::Points};
      LinePlot resp;
      resp.title = p.name + ": residuals";
      resp.xlabel = fitp.xlabel;
      resp.ylabel = "residual (" + p.unit + ")";
      resp.x = xs;
      for (std::size_t k = 0; k < results[i].size(); ++k) {
        if (!failures[i][k].empty()) continue;
        const PdgeFitResult& fr = results[i][k];
        std::vector<double> yfit;
        for (double x : dense) yfit.push_back(fr.fit.predict(x));
        // Polynomial, Legendre and Chebyshev bases of one order span one space and give one
        // curve: draw it once, named by every basis that gives it.
        if (add_or_merge(fitp, fr.fit.basis.name(), yfit)) continue;
        styles.push_back(LineStyle::Lines);
        std::vector<double> fx, res;
        position_means(p.x, fr.fit.residuals, fx, res);
        resp.lines.emplace_back(fr.fit.basis.name(), res);
      }
      for (std::size_t k = 0; k < resp.lines.size(); ++k)
        resp.lines[k].first = fitp.lines[k + 1].first;
      panels.push_back(StyledLinePlot{fitp, styles});
      panels.push_back(resp);
    }
  }
  return panels;
}

}  // namespace weilgen
