// weilgen fit-pdge: parametric fits of position-dependent errors (polynomial, Fourier, Legendre,
// Chebyshev), compared by the 6D-laser seed's Table 4 metrics, the order chosen by
// cross-validation. Bases, CV rule, period search, metrics and the JSON schema: docs/fit-pdge.md;
// the 6D line variant of the CSV: docs/data-format.md.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "study.hpp"
#include "verbs.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/measure/line6d.hpp"
#include "weilgen/measure/measurement_csv.hpp"
#include "weilgen/measure/pdge_fit.hpp"
#include "weilgen/report/plot.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

namespace {

using nlohmann::json;

// One profile to fit: y(x) with its unit and where it came from.
struct Profile {
  std::string name;    // E_YX or dx_um
  std::string column;  // CSV column (E_YX: the laser channel or the ISO column)
  std::string unit;    // um or urad
  std::vector<double> x, y;
  std::vector<int> cycle;  // empty without a cycle column
  json source;             // line6d conversion record, or null
};

std::string fmt(double v, int precision) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  s << std::fixed << std::setprecision(precision) << v;
  return s.str();
}

std::string fmt_g(double v, int precision = 4) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

json numbers(const std::vector<double>& v) {
  json a = json::array();
  for (double x : v) a.push_back(json_number(x));
  return a;
}

std::vector<std::string> split_list(const std::vector<std::string>& items) {
  std::vector<std::string> out;
  for (const std::string& item : items) {
    std::size_t start = 0;
    while (start <= item.size()) {
      std::size_t comma = item.find(',', start);
      if (comma == std::string::npos) comma = item.size();
      std::string s = item.substr(start, comma - start);
      s.erase(0, s.find_first_not_of(" \t"));
      s.erase(s.find_last_not_of(" \t") + 1);
      if (!s.empty()) out.push_back(s);
      start = comma + 1;
    }
  }
  return out;
}

// --basis: "all" or comma-separated specs; --order/--period fill what a spec leaves open.
std::vector<BasisSpec> parse_bases(const std::vector<std::string>& flags, const std::string& order,
                                   const std::string& period) {
  std::vector<std::string> items = split_list(flags);
  if (items.empty()) items = {"all"};
  std::vector<std::string> expanded;
  for (const std::string& s : items) {
    if (s == "all") {
      for (const char* k : {"poly", "fourier", "legendre", "chebyshev"}) expanded.push_back(k);
    } else {
      expanded.push_back(s);
    }
  }
  int default_order = -1;
  if (order != "auto") {
    char* end = nullptr;
    const long v = std::strtol(order.c_str(), &end, 10);
    if (order.empty() || *end != '\0' || v < 0 || v > 200)
      throw std::invalid_argument("--order: \"" + order + "\": expected a whole number or auto");
    default_order = static_cast<int>(v);
  }
  bool period_search = false;
  double period_mm = NAN;
  if (period == "auto") {
    period_search = true;
  } else if (period != "travel") {
    std::string p = period;
    if (p.size() > 2 && p.compare(p.size() - 2, 2, "mm") == 0) p.resize(p.size() - 2);
    char* end = nullptr;
    period_mm = std::strtod(p.c_str(), &end);
    if (p.empty() || *end != '\0' || !std::isfinite(period_mm) || period_mm <= 0)
      throw std::invalid_argument("--period: \"" + period +
                                  "\": expected a length > 0 in mm, auto or travel");
  }
  std::vector<BasisSpec> specs;
  for (const std::string& s : expanded) {
    BasisSpec b;
    try {
      b = parse_basis(s, true);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("--basis: ") + e.what());
    }
    const bool order_given = s.find(':') != std::string::npos;
    if (!order_given) b.order = default_order;
    if (b.kind == BasisKind::Fourier && !b.period_search && std::isnan(b.period_mm)) {
      b.period_search = period_search;
      b.period_mm = period_mm;
    }
    for (const BasisSpec& other : specs)
      if (other.str() == b.str())
        throw std::invalid_argument("--basis: " + b.str() + " given twice");
    specs.push_back(b);
  }
  return specs;
}

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
            {"coefficients", numbers(f.coefficients)},
            {"std_errors", numbers(f.std_errors)},
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
    j["power_coefficients"] = numbers(f.basis.power_coefficients(f.coefficients));
  }
  return j;
}

}  // namespace

int verb_fit_pdge(const Args& args) {
  po::options_description opts(
      "weilgen fit-pdge <data.csv> [options]\n\n"
      "Fits each position-dependent error profile y(x) on polynomial, Fourier, Legendre and\n"
      "Chebyshev bases and compares them by the 6D-laser seed's Table 4 metrics (e_max, R2, SSE,\n"
      "RMSE) and by cross-validated RMSE; with --order auto (the default) the order of each basis\n"
      "is chosen by cross-validation, never by training error.\n"
      "Profiles: a 6D line file ('# format: line6d') gives its six errors converted to ISO names\n"
      "(E_XX ... E_CX, Table 2 signs, straightness line removed); any other measurement CSV gives\n"
      "its deviation columns (dx_um ... dc_urad) against the axis column.\n"
      "docs/fit-pdge.md, docs/data-format.md.\n\nOptions");
  std::vector<std::string> basis_flags, column_flags;
  std::string order = "auto", period = "travel", cv = "blocks", rule = "1se", axis, travel;
  std::string json_path, plot_path, angular = "mean";
  int max_order = 10, min_order = 0, folds = 10;
  bool keep_line = false, curves = false;
  opts.add_options()("help,h", "show this help")(
      "basis", po::value<std::vector<std::string>>(&basis_flags)->composing(),
      "bases, comma-separated or repeated: all (default) or KIND[:ORDER[:PERIOD]] with KIND "
      "poly|fourier|legendre|chebyshev, e.g. fourier:3,poly:7 or fourier:auto:auto")(
      "order", po::value<std::string>(&order)->default_value("auto"),
      "order of the bases given without one: a whole number, or auto (cross-validation)")(
      "min-order", po::value<int>(&min_order)->default_value(0), "smallest order tried by auto")(
      "max-order", po::value<int>(&max_order)->default_value(10), "largest order tried by auto")(
      "period", po::value<std::string>(&period)->default_value("travel"),
      "Fourier period of the bases given without one: travel (b - a), a length in mm, or "
      "auto (searched: grid over 1/L, then Brent, on the training SSE at each order)")(
      "cv", po::value<std::string>(&cv)->default_value("blocks"),
      "cross-validation: blocks (contiguous stretches of positions; the end positions always "
      "train) or cycles (leave one cycle out; needs a cycle column)")(
      "folds", po::value<int>(&folds)->default_value(10),
      "number of blocks (--cv blocks; fewer when the data has fewer interior positions)")(
      "rule", po::value<std::string>(&rule)->default_value("1se"),
      "order choice: 1se (smallest order within one standard error of the least CV error) | "
      "min (least CV error)")("column",
                              po::value<std::vector<std::string>>(&column_flags)->composing(),
                              "profiles to fit, comma-separated or repeated (E_BX, E_BX_urad, "
                              "dx_um ...; default: every profile)")(
      "axis", po::value<std::string>(&axis),
      "position column of a non-6D file (default: '# axis:' header key, else the only "
      "coordinate column that varies)")(
      "travel", po::value<std::string>(&travel),
      "basis travel a:b in mm (default: the data's smallest to largest position)")(
      "keep-line", po::bool_switch(&keep_line),
      "6D files: keep the straightness reference line (default: removed, eq. (1))")(
      "angular-reference", po::value<std::string>(&angular)->default_value("mean"),
      "6D files: mean (remove each angular profile's mean) | none")(
      "curves", po::bool_switch(&curves), "print the CV curve (error per order) of every fit")(
      "json", po::value<std::string>(&json_path), "write every number to FILE (JSON)")(
      "plot", po::value<std::string>(&plot_path),
      "draw data, fitted curves and residuals to FILE (.png or .svg, gnuplot)");
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("fit-pdge", args, opts, "data", 1, vm)) return *stop;
  if (!vm.count("data")) return usage_error("fit-pdge", "no data file given");
  const std::string data_path = vm["data"].as<std::string>();
  if (cv != "blocks" && cv != "cycles")
    return usage_error("fit-pdge", "--cv must be blocks or cycles, not '" + cv + "'");
  if (rule != "1se" && rule != "min")
    return usage_error("fit-pdge", "--rule must be 1se or min, not '" + rule + "'");
  if (angular != "mean" && angular != "none")
    return usage_error("fit-pdge",
                       "--angular-reference must be mean or none, not '" + angular + "'");
  if (min_order < 0 || max_order < min_order)
    return usage_error("fit-pdge", "--min-order/--max-order: need 0 <= min <= max");
  if (folds < 2) return usage_error("fit-pdge", "--folds must be >= 2");
  const std::vector<BasisSpec> specs = parse_bases(basis_flags, order, period);
  if (!plot_path.empty()) check_plot_target(plot_path);

  // ---- read the profiles ----
  std::vector<Profile> profiles;
  std::string format = "points", pos_name;
  json line6d_json;
  std::size_t rows = 0;
  {
    // Header keys first (unknown columns allowed), to know the variant.
    ReadOptions probe;
    probe.allow_unknown = true;
    const MeasurementTable head = read_measurements(data_path, probe);
    if (is_line6d(head)) {
      format = "line6d";
      const MeasurementTable table = read_measurements(data_path, line6d_read_options());
      Line6dOptions lo;
      lo.remove_straightness_line = !keep_line;
      lo.angular = angular == "mean" ? AngularReference::Mean : AngularReference::None;
      const Line6dData d = line6d_from_table(table, lo);
      pos_name = d.axis;
      rows = d.position.size();
      json conv = json::array();
      for (const Line6dProfile& p : d.profiles) {
        Profile q;
        q.name = p.error;
        q.column = p.source;
        q.unit = p.unit;
        json src = {{"error", p.error},
                    {"kind", profile_kind_name(p.kind)},
                    {"unit", p.unit},
                    {"source", p.source},
                    {"sign", p.sign},
                    {"removed", p.removed},
                    {"intercept", p.reference.intercept},
                    {"slope_per_mm", p.reference.slope}};
        conv.push_back(src);
        q.source = src;
        for (std::size_t i = 0; i < p.values.size(); ++i) {
          if (std::isnan(p.values[i])) continue;
          q.x.push_back(d.position[i]);
          q.y.push_back(p.values[i]);
          if (!d.cycle.empty()) q.cycle.push_back(d.cycle[i]);
        }
        profiles.push_back(std::move(q));
      }
      line6d_json = {{"axis", d.axis}, {"spelling", d.spelling}, {"profiles", conv}};
    } else {
      const MeasurementTable table = read_measurements(data_path);
      rows = table.rows();
      pos_name = axis.empty() ? head.header_key("axis") : axis;
      if (pos_name.empty()) {
        std::vector<std::string> varying;
        for (const std::string& c : table.columns_with(ColumnRole::Coordinate)) {
          const auto& v = table.column(c);
          if (std::any_of(v.begin(), v.end(), [&](double a) { return a != v.front(); }))
            varying.push_back(c);
        }
        if (varying.size() != 1)
          throw std::invalid_argument("give the position column with --axis (" +
                                      std::to_string(varying.size()) +
                                      " coordinate columns vary in " + data_path + ")");
        pos_name = varying.front();
      }
      const std::vector<double>& pos = table.column(pos_name);
      std::vector<int> cyc;
      if (table.has("cycle"))
        for (double c : table.column("cycle")) cyc.push_back(static_cast<int>(c));
      for (const std::string& c : table.columns_with(ColumnRole::Deviation)) {
        Profile q;
        q.name = c;
        q.column = c;
        q.unit = table.info_of(c).unit;
        const auto& v = table.column(c);
        for (std::size_t i = 0; i < v.size(); ++i) {
          if (std::isnan(v[i]) || std::isnan(pos[i])) continue;
          q.x.push_back(pos[i]);
          q.y.push_back(v[i]);
          if (!cyc.empty()) q.cycle.push_back(cyc[i]);
        }
        if (!q.x.empty()) profiles.push_back(std::move(q));
      }
    }
  }
  // --column selection.
  const std::vector<std::string> wanted = split_list(column_flags);
  if (!wanted.empty()) {
    std::vector<Profile> chosen;
    for (const std::string& w : wanted) {
      auto it = std::find_if(profiles.begin(), profiles.end(), [&](const Profile& p) {
        return p.name == w || p.column == w || p.name + "_" + p.unit == w;
      });
      if (it == profiles.end()) {
        std::string known;
        for (const Profile& p : profiles) known += (known.empty() ? "" : ", ") + p.name;
        throw std::invalid_argument("--column: \"" + w + "\" is not a profile of " + data_path +
                                    " (profiles: " + (known.empty() ? "none" : known) + ")");
      }
      chosen.push_back(*it);
    }
    profiles = std::move(chosen);
  }
  if (profiles.empty())
    throw std::invalid_argument(data_path + ": no profile to fit (no deviation or 6D column)");

  // Travel: --travel, else the smallest to largest position of every profile.
  double a = INFINITY, b = -INFINITY;
  if (!travel.empty()) {
    const auto colon = travel.find(':');
    char* e1 = nullptr;
    char* e2 = nullptr;
    const std::string sa = travel.substr(0, colon);
    const std::string sb = colon == std::string::npos ? "" : travel.substr(colon + 1);
    a = std::strtod(sa.c_str(), &e1);
    b = std::strtod(sb.c_str(), &e2);
    if (colon == std::string::npos || sa.empty() || sb.empty() || *e1 || *e2)
      throw std::invalid_argument("--travel: \"" + travel + "\": expected a:b in mm");
  } else {
    for (const Profile& p : profiles)
      for (double v : p.x) a = std::min(a, v), b = std::max(b, v);
  }
  Basis::make(BasisKind::Polynomial, 0, a, b);  // zero-length travel: a clear message

  PdgeFitOptions fo;
  fo.min_order = min_order;
  fo.max_order = max_order;
  fo.rule = rule == "1se" ? OrderRule::OneStandardError : OrderRule::Minimum;
  fo.cv.scheme = cv == "blocks" ? CvScheme::Blocks : CvScheme::Cycles;
  fo.cv.folds = folds;
  const PdgeFit fitter(fo);

  // ---- fit ----
  // A basis the data cannot support is reported and the others still fitted; exit status 1.
  std::vector<std::vector<PdgeFitResult>> results(profiles.size());
  std::vector<std::vector<std::string>> failures(profiles.size());
  std::size_t failed = 0;
  for (std::size_t i = 0; i < profiles.size(); ++i) {
    const Profile& p = profiles[i];
    for (const BasisSpec& s : specs) {
      try {
        results[i].push_back(fitter.run(p.x, p.y, p.cycle, s, a, b));
        failures[i].emplace_back();
      } catch (const std::invalid_argument& e) {
        results[i].emplace_back();
        results[i].back().spec = s;
        failures[i].push_back(e.what());
        ++failed;
      }
    }
  }

  // ---- stdout: a Table-4-style comparison per profile ----
  std::size_t positions = 0;
  {
    std::vector<double> all;
    for (const Profile& p : profiles) all.insert(all.end(), p.x.begin(), p.x.end());
    positions = distinct_count(all);
  }
  std::cout << "weilgen fit-pdge: " << data_path << " (" << format << ", axis " << pos_name << ", "
            << profiles.size() << " profile" << (profiles.size() == 1 ? "" : "s") << ", " << rows
            << " rows, " << positions << " positions)\n";
  int folds_used = folds;
  for (const auto& per_profile : results)
    for (const PdgeFitResult& r : per_profile)
      if (r.folds > 0) folds_used = std::min(folds_used, r.folds);
  std::cout << "travel [" << fmt_g(a, 10) << ", " << fmt_g(b, 10) << "] mm; CV "
            << (fo.cv.scheme == CvScheme::Blocks
                    ? std::to_string(folds_used) + "-fold blocks" +
                          (folds_used < folds
                               ? " (" + std::to_string(folds) + " asked: one per interior position)"
                               : std::string())
                    : std::string("leave-one-cycle-out"))
            << ", order rule " << rule << ", orders " << min_order << ".." << max_order << "\n";
  for (std::size_t i = 0; i < profiles.size(); ++i) {
    const Profile& p = profiles[i];
    const std::string u = p.unit;
    std::cout << "\n" << p.name << " (" << u << ", " << p.x.size() << " values";
    if (!p.source.is_null()) {
      std::cout << "; from " << p.column << " x " << (p.source["sign"].get<int>() > 0 ? "+1" : "-1")
                << ", removed " << p.source["removed"].get<std::string>();
      if (p.source["removed"] == "line")
        std::cout << " " << fmt_g(p.source["intercept"].get<double>()) << " + "
                  << fmt_g(p.source["slope_per_mm"].get<double>()) << "*" << pos_name;
      else if (p.source["removed"] == "mean")
        std::cout << " " << fmt_g(p.source["intercept"].get<double>());
    }
    std::cout << ")\n";
    std::ostringstream h;
    h << std::left << std::setw(18) << "basis" << std::right << std::setw(6) << "order"
      << std::setw(7) << "params" << std::setw(11) << "period_mm" << std::setw(12) << "e_max_" + u
      << std::setw(9) << "R2" << std::setw(13) << "SSE_" + u + "2" << std::setw(11) << "RMSE_" + u
      << std::setw(14) << "CV_RMSE_" + u << "\n";
    std::cout << h.str();
    std::size_t best = results[i].size();
    for (std::size_t k = 0; k < results[i].size(); ++k) {
      if (!failures[i][k].empty()) continue;
      const double v = results[i][k].cv.rmse;
      if (std::isfinite(v) && (best == results[i].size() || v < results[i][best].cv.rmse)) best = k;
    }
    for (std::size_t k = 0; k < results[i].size(); ++k) {
      const PdgeFitResult& r = results[i][k];
      const FitResult& f = r.fit;
      std::string label = r.spec.str();
      if (!failures[i][k].empty()) {
        std::cout << std::left << std::setw(18) << label << std::right
                  << "  not fitted: " << failures[i][k] << "\n";
        continue;
      }
      std::ostringstream line;
      line << std::left << std::setw(18) << label << std::right << std::setw(6)
           << (std::to_string(f.basis.order) + (r.order_choice == "fixed" ? "" : "*"))
           << std::setw(7) << f.params() << std::setw(11)
           << (f.basis.kind == BasisKind::Fourier && f.basis.order > 0
                   ? fmt(f.basis.period(), 2) + (r.period_at_bound ? "!" : "")
                   : std::string("-"))
           << std::setw(12) << fmt(f.metrics.e_max, 3) << std::setw(9) << fmt(f.metrics.r2, 4)
           << std::setw(13) << fmt_g(f.metrics.sse, 5) << std::setw(11) << fmt(f.metrics.rmse, 3)
           << std::setw(14) << fmt(r.cv.rmse, 3) << (k == best ? "  <- least CV error" : "")
           << "\n";
      std::cout << line.str();
      if (curves) {
        for (const CvCurvePoint& c : r.curve) {
          std::cout << "      order " << std::setw(2) << c.order << ": train RMSE " << std::setw(8)
                    << fmt(c.train_rmse, 3) << "  CV RMSE " << std::setw(9) << fmt(c.cv.rmse, 3)
                    << " (MSE se " << fmt_g(c.cv.mse_se, 3) << ")";
          if (std::isfinite(c.period_mm) && c.order > 0)
            std::cout << "  L " << fmt(c.period_mm, 2) << " mm";
          if (!c.feasible) std::cout << "  not feasible: " << c.reason;
          std::cout << "\n";
        }
      }
      if (!r.cv_note.empty()) std::cout << "      (no CV error: " << r.cv_note << ")\n";
    }
  }
  bool any_at_bound = false;
  for (std::size_t i = 0; i < results.size(); ++i)
    for (std::size_t k = 0; k < results[i].size(); ++k)
      any_at_bound = any_at_bound || (failures[i][k].empty() && results[i][k].period_at_bound);
  std::cout << "\n* order chosen by cross-validation (" << rule
            << " rule). Metrics as the seed's Table 4: e_max = max |residual|, R2, SSE, RMSE =\n"
               "sqrt(SSE/n), on the fitted data; CV_RMSE = held-out error.\n";
  if (any_at_bound)
    std::cout
        << "! searched period at an end of its range [2*order*spacing, 2*travel]: the series\n"
           "  is absorbing a trend, or the period lies outside the range (--period L).\n";

  // ---- JSON ----
  if (!json_path.empty()) {
    json cols = json::array();
    for (std::size_t i = 0; i < profiles.size(); ++i) {
      const Profile& p = profiles[i];
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
                      {"conversion", p.source},
                      {"fits", fits}});
    }
    std::vector<std::string> spec_names;
    for (const BasisSpec& s : specs) spec_names.push_back(s.str());
    json j = {{"weilgen", kVersion},
              {"verb", "fit-pdge"},
              {"file", data_path},
              {"format", format},
              {"axis", pos_name},
              {"travel_mm", {a, b}},
              {"settings",
               {{"bases", spec_names},
                {"cv", cv_scheme_name(fo.cv.scheme)},
                {"folds", fo.cv.scheme == CvScheme::Blocks ? json(folds) : json()},
                {"keep_ends", fo.cv.keep_ends},
                {"rule", rule},
                {"min_order", min_order},
                {"max_order", max_order},
                {"period", period}}},
              {"line6d", line6d_json},
              {"profiles", cols}};
    write_output(json_path, j.dump(1) + "\n");
  }

  // ---- plot: per profile, data + fits, and residuals ----
  if (!plot_path.empty()) {
    std::vector<Panel> panels;
    for (std::size_t i = 0; i < profiles.size(); ++i) {
      const Profile& p = profiles[i];
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
      LinePlot resp;
      resp.title = p.name + ": residuals";
      resp.xlabel = fitp.xlabel;
      resp.ylabel = "residual (" + p.unit + ")";
      resp.x = xs;
      for (std::size_t k = 0; k < results[i].size(); ++k) {
        if (!failures[i][k].empty()) continue;
        const PdgeFitResult& r = results[i][k];
        std::vector<double> yfit;
        for (double x : dense) yfit.push_back(r.fit.predict(x));
        fitp.lines.emplace_back(r.fit.basis.name(), yfit);
        std::vector<double> fx, res;
        position_means(p.x, r.fit.residuals, fx, res);
        resp.lines.emplace_back(r.fit.basis.name(), res);
      }
      panels.push_back(fitp);
      panels.push_back(resp);
    }
    write_plot(plot_path, panels, "weilgen fit-pdge: " + data_path);
  }
  return failed ? 1 : 0;
}

}  // namespace weilgen::cli
