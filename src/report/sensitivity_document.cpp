#include "weilgen/report/sensitivity_document.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "weilgen/base/constants.hpp"
#include "weilgen/report/csv_table.hpp"
#include "weilgen/report/json_common.hpp"

namespace weilgen {

namespace {

// Display scale: outputs in µm or µrad.
double display_scale(OutputId o) { return 1e3 * (output_is_angle(o) ? 1e3 : 1.0); }
const char* display_unit(OutputId o) { return output_is_angle(o) ? "urad" : "um"; }

}  // namespace

std::string sensitivity_method_name(const SensitivityOptions& o) {
  if (o.local && o.exact && o.sobol) return "all";
  return o.sobol ? "sobol" : o.exact ? "exact" : "local";
}

const char* sampling_name(Sampling s) { return s == Sampling::Qmc ? "qmc" : "mc"; }

std::string sobol_interval_text(const SensitivityResult& r) {
  std::ostringstream os;
  os << std::setprecision(3) << 100 * r.confidence << " % ";
  switch (r.intervals) {
    case SobolIntervals::Replicates:
      os << "Student t over " << r.replicates
         << " independent randomised replicates (each index is their mean)";
      break;
    case SobolIntervals::Bootstrap:
      if (r.bootstrap == 0) return "none (--bootstrap 0)";
      os << "percentile bootstrap, " << r.bootstrap << " resamples";
      break;
    case SobolIntervals::None:
      return "none";
  }
  return os.str();
}

std::string sensitivity_text(const Study& st, const SensitivityOptions& opt,
                             const SensitivityResult& r, std::size_t top) {
  std::ostringstream os;
  const Model& model = *st.model;
  const auto& errors = model.description().errors;
  const std::size_t ne = r.errors, np = r.poses, no = r.outputs.size();
  os << "weilgen sensitivity: " << model.name() << " (order " << model.order() << ", "
     << model.origin() << "), " << np << " pose" << (np > 1 ? "s" : "") << ", " << ne << " errors";
  if (opt.sobol)
    os << ", Sobol' N = " << opt.sobol_options.samples << " ("
       << sampling_name(opt.sobol_options.sampling) << "), " << r.evaluations
       << " model evaluations";
  os << "\n";
  if (opt.sobol) os << "Sobol' intervals: " << sobol_interval_text(r) << "\n";
  const bool per_pose = np <= 3;
  const std::size_t groups = per_pose ? np : 1;
  for (std::size_t g = 0; g < groups; ++g) {
    for (std::size_t o = 0; o < no; ++o) {
      const OutputId out = r.outputs[o];
      const double sc = display_scale(out);
      // Mean over the poses of the group (one pose, or all of them).
      std::vector<double> c(ne, 0), cs(ne, 0), S(ne, 0), ST(ne, 0), Se(ne, 0), STmax(ne, 0);
      std::vector<double> slo(ne, kNaN), shi(ne, kNaN), tlo(ne, kNaN), thi(ne, kNaN);
      const std::size_t p0 = per_pose ? g : 0, p1 = per_pose ? g + 1 : np;
      const double n = static_cast<double>(p1 - p0);
      double sd_mean = 0;
      for (std::size_t p = p0; p < p1; ++p) {
        const auto& sm = r.summary_at(p, o);
        sd_mean += std::sqrt(std::isfinite(sm.variance) ? sm.variance : sm.variance_linear) / n;
        for (std::size_t i = 0; i < ne; ++i) {
          const SensitivityRecord& x = r.at(p, o, i);
          c[i] += x.coefficient / n;
          cs[i] += std::abs(x.contribution) / n;
          S[i] += x.S / n;
          ST[i] += x.ST / n;
          Se[i] += x.S_exact / n;
          STmax[i] = std::max(STmax[i], x.ST);
          if (per_pose) slo[i] = x.S_lo, shi[i] = x.S_hi, tlo[i] = x.ST_lo, thi[i] = x.ST_hi;
        }
      }
      std::vector<std::size_t> order(ne);
      for (std::size_t i = 0; i < ne; ++i) order[i] = i;
      const auto key = [&](std::size_t i) {
        if (opt.sobol) return ST[i];
        if (opt.exact && std::isfinite(Se[i])) return Se[i];
        return std::isfinite(cs[i]) ? cs[i] : 0.0;
      };
      std::stable_sort(order.begin(), order.end(),
                       [&](std::size_t a, std::size_t b) { return key(a) > key(b); });
      os << "\n"
         << output_name(out) << " ("
         << (per_pose ? pose_label(st.poses, g) : "mean over " + std::to_string(np) + " poses")
         << "), standard deviation " << std::setprecision(4) << sd_mean * sc << " "
         << display_unit(out) << "\n";
      std::ostringstream h;
      h << std::left << std::setw(10) << "error" << std::right;
      if (opt.local && out != OutputId::Dp)
        h << std::setw(14) << "coefficient" << std::setw(8) << "unit" << std::setw(12)
          << std::string("|c|s ") + display_unit(out);
      if (opt.exact && out != OutputId::Dp) h << std::setw(9) << "S_exact";
      if (opt.sobol) {
        h << std::setw(9) << "S" << (per_pose ? "  CI              " : "") << std::setw(9) << "ST";
        if (per_pose)
          h << "  CI";
        else
          h << std::setw(9) << "ST max";
      }
      os << h.str() << "\n";
      // Errors without any effect on this output (all zero) are counted, not listed.
      const auto no_effect = [&](std::size_t i) {
        for (double v : {c[i], cs[i], S[i], ST[i], Se[i]})
          if (std::abs(v) > 0) return false;
        return true;
      };
      std::size_t effective = 0;
      for (std::size_t i = 0; i < ne; ++i) effective += no_effect(i) ? 0 : 1;
      const std::size_t rows = top == 0 ? effective : std::min(top, effective);
      for (std::size_t k = 0, shown = 0; k < ne && shown < rows; ++k) {
        const std::size_t i = order[k];
        if (no_effect(i)) continue;
        ++shown;
        std::ostringstream line;
        line << std::left << std::setw(10) << errors[i].name << std::right << std::fixed;
        if (opt.local && out != OutputId::Dp)
          line << std::setw(14) << std::setprecision(6) << std::defaultfloat << c[i] << std::fixed
               << std::setw(8) << (std::string(output_unit(out)) + "/" + errors[i].base_unit())
               << std::setw(12) << std::setprecision(3) << cs[i] * sc;
        if (opt.exact && out != OutputId::Dp) line << std::setw(9) << std::setprecision(4) << Se[i];
        if (opt.sobol) {
          line << std::setw(9) << std::setprecision(4) << S[i];
          if (per_pose)
            line << "  [" << std::setw(7) << slo[i] << "," << std::setw(7) << shi[i] << "]";
          line << std::setw(9) << ST[i];
          if (per_pose)
            line << "  [" << std::setw(7) << tlo[i] << "," << std::setw(7) << thi[i] << "]";
          else
            line << std::setw(9) << STmax[i];
        }
        os << line.str() << "\n";
      }
      if (effective < ne)
        os << "  (" << ne - effective << " error" << (ne - effective > 1 ? "s" : "")
           << " without effect on " << output_name(out) << " not listed)\n";
    }
  }
  if (!per_pose) os << "\nPer-pose values: --json FILE or --csv FILE.\n";
  return os.str();
}

nlohmann::json sensitivity_json(const Study& st, const SensitivityOptions& opt,
                                const SensitivityResult& r) {
  const Model& model = *st.model;
  const auto& errors = model.description().errors;
  nlohmann::json results = nlohmann::json::array(), sums = nlohmann::json::array();
  for (std::size_t p = 0; p < r.poses; ++p)
    for (std::size_t o = 0; o < r.outputs.size(); ++o) {
      const OutputId out = r.outputs[o];
      const auto& sm = r.summary_at(p, o);
      sums.push_back({{"pose", pose_json(st.poses, p)},
                      {"output", output_name(out)},
                      {"unit", output_unit(out)},
                      {"mean", json_number(sm.mean)},
                      {"variance", json_number(sm.variance)},
                      {"variance_linear", json_number(sm.variance_linear)}});
      for (std::size_t i = 0; i < r.errors; ++i) {
        const SensitivityRecord& x = r.at(p, o, i);
        results.push_back(
            {{"pose", pose_json(st.poses, p)},
             {"output", output_name(out)},
             {"error", errors[i].name},
             {"coefficient", json_number(x.coefficient)},
             {"coefficient_unit", std::string(output_unit(out)) + "/" + errors[i].base_unit()},
             {"contribution", json_number(x.contribution)},
             {"S", json_number(x.S)},
             {"S_ci", {json_number(x.S_lo), json_number(x.S_hi)}},
             {"ST", json_number(x.ST)},
             {"ST_ci", {json_number(x.ST_lo), json_number(x.ST_hi)}},
             {"S_exact", json_number(x.S_exact)}});
      }
    }
  const SobolOptions& so = opt.sobol_options;
  return json_document(
      "sensitivity", {{"model", model_json(model)},
                      {"settings",
                       {{"method", sensitivity_method_name(opt)},
                        {"samples", opt.sobol ? nlohmann::json(so.samples) : nlohmann::json()},
                        {"sampling", sampling_name(so.sampling)},
                        {"seed", so.seed},
                        {"intervals", opt.sobol ? nlohmann::json(interval_method_name(r.intervals))
                                                : nlohmann::json()},
                        {"replicates", opt.sobol ? nlohmann::json(r.replicates) : nlohmann::json()},
                        {"bootstrap", r.bootstrap},
                        {"confidence", so.confidence},
                        {"evaluations", r.evaluations}}},
                      {"inputs", inputs_json(model, st.inputs)},
                      {"summary", sums},
                      {"results", results}});
}

std::string sensitivity_csv(const Study& st, const SensitivityResult& r) {
  const auto& errors = st.model->description().errors;
  CsvTable t;
  t.pose_columns(st.poses);
  for (const char* c : {"output", "output_unit", "error", "error_unit", "coefficient",
                        "coefficient_unit", "contribution", "contribution_unit", "S", "S_lo",
                        "S_hi", "ST", "ST_lo", "ST_hi", "S_exact"})
    t.column(c);
  for (std::size_t p = 0; p < r.poses; ++p)
    for (std::size_t o = 0; o < r.outputs.size(); ++o)
      for (std::size_t i = 0; i < r.errors; ++i) {
        const SensitivityRecord& x = r.at(p, o, i);
        const std::string ou = output_unit(r.outputs[o]), eu = errors[i].base_unit();
        t.pose(st.poses.poses[p]).text(output_name(r.outputs[o])).text(ou);
        t.text(errors[i].name).text(eu).number(x.coefficient).text(ou + "/" + eu);
        t.number(x.contribution).text(ou);
        for (double v : {x.S, x.S_lo, x.S_hi, x.ST, x.ST_lo, x.ST_hi, x.S_exact}) t.number(v);
        t.end_row();
      }
  return t.str();
}

std::vector<Panel> sensitivity_panels(const Study& st, const SensitivityOptions& opt,
                                      const SensitivityResult& r) {
  const auto& errors = st.model->description().errors;
  const std::size_t np = r.poses, ne = r.errors;
  const double npd = static_cast<double>(np);
  std::vector<Panel> panels;
  for (std::size_t o = 0; o < r.outputs.size(); ++o) {
    const OutputId out = r.outputs[o];
    BarChart b;
    b.title =
        std::string(output_name(out)) + (np > 1 ? " (mean over " + std::to_string(np) + " poses)"
                                                : " (" + pose_label(st.poses, 0) + ")");
    b.ylabel = "index";
    for (const auto& e : errors) b.categories.push_back(e.name);
    BarSeries s{"S", {}, {}, {}}, t{"ST", {}, {}, {}}, x{"S exact", {}, {}, {}};
    for (std::size_t i = 0; i < ne; ++i) {
      double vs = 0, vt = 0, vx = 0, lo = 0, hi = 0, tl = 0, th = 0;
      for (std::size_t p = 0; p < np; ++p) {
        const SensitivityRecord& k = r.at(p, o, i);
        vs += k.S / npd, vt += k.ST / npd, vx += k.S_exact / npd;
        lo += k.S_lo / npd, hi += k.S_hi / npd, tl += k.ST_lo / npd, th += k.ST_hi / npd;
      }
      s.value.push_back(vs), s.lo.push_back(lo), s.hi.push_back(hi);
      t.value.push_back(vt), t.lo.push_back(tl), t.hi.push_back(th);
      x.value.push_back(vx);
    }
    if (opt.sobol) {
      if (np > 1 || !std::isfinite(r.at(0, o, 0).S_lo))
        s.lo.clear(), s.hi.clear(), t.lo.clear(), t.hi.clear();
      b.series.push_back(s);
      b.series.push_back(t);
    }
    if (opt.exact && out != OutputId::Dp) b.series.push_back(x);
    if (b.series.empty()) {
      BarSeries l{"|c| sigma", {}, {}, {}};
      for (std::size_t i = 0; i < ne; ++i) {
        double v = 0;
        for (std::size_t p = 0; p < np; ++p) v += std::abs(r.at(p, o, i).contribution) / npd;
        l.value.push_back(std::isfinite(v) ? v * display_scale(out) : 0.0);
      }
      b.ylabel = std::string("|c| sigma (") + display_unit(out) + ")";
      b.series.push_back(l);
    }
    pareto(b, opt.sobol ? 1 : 0);  // by ST, else S exact, else |c| sigma
    panels.push_back(b);
  }
  return panels;
}

}  // namespace weilgen
