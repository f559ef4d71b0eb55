// weilgen sensitivity: local coefficients, exact (linear) and sampled Sobol' indices of every
// output at every pose. JSON schema and method: docs/sensitivity.md.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "study.hpp"
#include "verbs.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/report/plot.hpp"
#include "weilgen/uq/sobol_indices.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Per pose, output and error.
struct Record {
  double coefficient = kNaN, contribution = kNaN;  // c (output unit per base unit), c*sigma
  double S = kNaN, S_lo = kNaN, S_hi = kNaN, ST = kNaN, ST_lo = kNaN, ST_hi = kNaN;
  double S_exact = kNaN;
};

struct OutputSummary {
  double mean = kNaN, variance = kNaN, variance_linear = kNaN;
};

// Display scale: outputs in µm or µrad.
double display_scale(OutputId o) { return 1e3 * (output_is_angle(o) ? 1e3 : 1.0); }
const char* display_unit(OutputId o) { return output_is_angle(o) ? "urad" : "um"; }

std::vector<OutputId> parse_outputs(const std::string& text) {
  std::vector<OutputId> out;
  for (const auto& item : split(text, ',')) {
    const OutputId o = parse_output(trim(item));
    if (std::find(out.begin(), out.end(), o) != out.end())
      throw std::invalid_argument("--outputs: \"" + item + "\" given twice");
    out.push_back(o);
  }
  if (out.empty()) throw std::invalid_argument("--outputs: no output given");
  return out;
}

}  // namespace

int verb_sensitivity(const Args& args) {
  po::options_description opts(
      "weilgen sensitivity <machine> (--at ...|--grid ...) [options]\n\n"
      "Sensitivity of the tool-point deviation to every error, at every pose:\n"
      "  local  the coefficient c_i of each error and its contribution c_i*sigma_i, ranked;\n"
      "  exact  Sobol' indices of the linear model, S_i = c_i^2 s_i^2 / sum_j c_j^2 s_j^2\n"
      "         (exact at order 1; the first-order reference at order >= 2; not for dp);\n"
      "  sobol  first-order (Saltelli) and total (Jansen) indices by quasi-Monte Carlo on\n"
      "         Sobol' points, with bootstrap confidence intervals.\n"
      "Outputs: dx dy dz (mm), da db dc (rad), dp = |(dx,dy,dz)| (mm, sampling only).\n\n"
      "Options");
  StudyFlags f;
  std::string method = "all", outputs_text = "dx,dy,dz,da,db,dc,dp", sampling = "qmc";
  std::size_t samples = 1u << 14, bootstrap = 200, top = 10;
  double confidence = 0.95;
  opts.add_options()("help,h", "show this help")(
      "method", po::value<std::string>(&method)->default_value("all"),
      "local | sobol | exact | all")(
      "outputs", po::value<std::string>(&outputs_text)->default_value(outputs_text),
      "outputs to analyse, comma-separated")(
      "samples", po::value<std::size_t>(&samples)->default_value(samples),
      "Sobol' base sample size N (powers of two keep the Sobol' net property); N (k+2) model "
      "evaluations per pose")(
      "sampling", po::value<std::string>(&sampling)->default_value("qmc"),
      "qmc (Sobol' points with a seeded digital shift) | mc (pseudo-random)")(
      "bootstrap", po::value<std::size_t>(&bootstrap)->default_value(bootstrap),
      "bootstrap resamples for the confidence intervals (0 = none)")(
      "confidence", po::value<double>(&confidence)->default_value(confidence),
      "confidence level of the intervals")("top", po::value<std::size_t>(&top)->default_value(top),
                                           "rows per table on stdout (0 = all)");
  add_study_options(opts, f, false);
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("sensitivity", args, opts, "machine", 1, vm))
    return *stop;
  if (vm.count("machine")) f.machine = vm["machine"].as<std::string>();
  if (method != "local" && method != "sobol" && method != "exact" && method != "all")
    return usage_error("sensitivity",
                       "--method must be local, sobol, exact or all, not '" + method + "'");
  if (sampling != "qmc" && sampling != "mc")
    return usage_error("sensitivity", "--sampling must be qmc or mc, not '" + sampling + "'");
  if (!(confidence > 0 && confidence < 1))
    return usage_error("sensitivity", "--confidence must be in (0, 1)");
  const bool do_local = method == "local" || method == "all";
  const bool do_exact = method == "exact" || method == "all";
  const bool do_sobol = method == "sobol" || method == "all";
  if (do_sobol && samples < 2)
    return usage_error("sensitivity", "--samples must be >= 2, not " + std::to_string(samples));
  const std::vector<OutputId> outputs = parse_outputs(outputs_text);

  if (!f.plot.empty()) check_plot_target(f.plot);  // before a long run, not after
  const Study st = open_study(f, false);
  const Model& model = *st.model;
  const auto& errors = model.description().errors;
  const std::size_t ne = errors.size(), np = st.poses.poses.size(), no = outputs.size();
  std::vector<double> sigma(ne);
  for (std::size_t i = 0; i < ne; ++i) sigma[i] = st.inputs[i].stddev();

  std::vector<Record> rec(np * no * ne);
  std::vector<OutputSummary> summary(np * no);
  auto at = [&](std::size_t p, std::size_t o, std::size_t i) -> Record& {
    return rec[(p * no + o) * ne + i];
  };

  // Local coefficients and exact indices (cheap).
  ModelData data(model);
  for (std::size_t p = 0; p < np; ++p) {
    model.coefficients(data, st.poses.poses[p].data(), data.coeff.data());
    for (std::size_t o = 0; o < no; ++o) {
      if (outputs[o] == OutputId::Dp) continue;
      const std::size_t row = static_cast<std::size_t>(outputs[o]);
      std::vector<double> c(data.coeff.begin() + row * ne, data.coeff.begin() + (row + 1) * ne);
      double var = 0;
      for (std::size_t i = 0; i < ne; ++i) {
        at(p, o, i).coefficient = c[i];
        at(p, o, i).contribution = c[i] * sigma[i];
        var += c[i] * c[i] * sigma[i] * sigma[i];
      }
      summary[p * no + o].variance_linear = var;
      if (do_exact) {
        const auto s = linear_sobol_indices(c, st.inputs);
        for (std::size_t i = 0; i < ne; ++i) at(p, o, i).S_exact = s[i];
      }
    }
  }

  SobolOptions so;
  so.samples = samples;
  so.sampling = sampling == "qmc" ? Sampling::Qmc : Sampling::MonteCarlo;
  so.seed = f.seed;
  so.bootstrap = bootstrap;
  so.confidence = confidence;
  so.threads = st.threads;
  std::size_t evaluations = 0;
  if (do_sobol) {
    const SobolDesign design(st.inputs, so);
    std::vector<ModelData> work;
    for (unsigned t = 0; t < st.threads; ++t) work.emplace_back(model);
    Progress progress("sensitivity", np, f.quiet);
    for (std::size_t p = 0; p < np; ++p) {
      const double* pose = st.poses.poses[p].data();
      const VectorFunction fn = [&](unsigned t, const double* x, double* y) {
        ModelData& w = work[t];
        model.deviation(w, pose, x, w.out.data());
        for (std::size_t o = 0; o < no; ++o)
          y[o] = outputs[o] == OutputId::Dp
                     ? std::sqrt(w.out[0] * w.out[0] + w.out[1] * w.out[1] + w.out[2] * w.out[2])
                     : w.out[static_cast<std::size_t>(outputs[o])];
      };
      const SobolResult r = SobolAnalysis(so).run(design, no, fn);
      evaluations += r.evaluations;
      for (std::size_t o = 0; o < no; ++o) {
        const SobolIndices& s = r.outputs[o];
        summary[p * no + o].mean = s.mean;
        summary[p * no + o].variance = s.variance;
        for (std::size_t i = 0; i < ne; ++i) {
          Record& x = at(p, o, i);
          x.S = s.first[i], x.S_lo = s.first_lo[i], x.S_hi = s.first_hi[i];
          x.ST = s.total[i], x.ST_lo = s.total_lo[i], x.ST_hi = s.total_hi[i];
        }
      }
      progress.update(p + 1);
    }
  }

  // ---- stdout: per output, errors ranked (per pose for up to 3 poses, else over the grid) ----
  std::cout << "weilgen sensitivity: " << model.name() << " (order " << model.order() << ", "
            << model.origin() << "), " << np << " pose" << (np > 1 ? "s" : "") << ", " << ne
            << " errors";
  if (do_sobol)
    std::cout << ", Sobol' N = " << samples << " (" << sampling << "), " << evaluations
              << " model evaluations";
  std::cout << "\n";
  const bool per_pose = np <= 3;
  const std::size_t groups = per_pose ? np : 1;
  for (std::size_t g = 0; g < groups; ++g) {
    for (std::size_t o = 0; o < no; ++o) {
      const OutputId out = outputs[o];
      const double sc = display_scale(out);
      // Mean over the poses of the group (one pose, or all of them).
      std::vector<double> c(ne, 0), cs(ne, 0), S(ne, 0), ST(ne, 0), Se(ne, 0), STmax(ne, 0);
      std::vector<double> slo(ne, kNaN), shi(ne, kNaN), tlo(ne, kNaN), thi(ne, kNaN);
      const std::size_t p0 = per_pose ? g : 0, p1 = per_pose ? g + 1 : np;
      const double n = static_cast<double>(p1 - p0);
      double sd_mean = 0;
      for (std::size_t p = p0; p < p1; ++p) {
        const auto& sm = summary[p * no + o];
        sd_mean += std::sqrt(std::isfinite(sm.variance) ? sm.variance : sm.variance_linear) / n;
        for (std::size_t i = 0; i < ne; ++i) {
          const Record& r = at(p, o, i);
          c[i] += r.coefficient / n;
          cs[i] += std::abs(r.contribution) / n;
          S[i] += r.S / n;
          ST[i] += r.ST / n;
          Se[i] += r.S_exact / n;
          STmax[i] = std::max(STmax[i], r.ST);
          if (per_pose) slo[i] = r.S_lo, shi[i] = r.S_hi, tlo[i] = r.ST_lo, thi[i] = r.ST_hi;
        }
      }
      std::vector<std::size_t> order(ne);
      for (std::size_t i = 0; i < ne; ++i) order[i] = i;
      const auto key = [&](std::size_t i) {
        if (do_sobol) return ST[i];
        if (do_exact && std::isfinite(Se[i])) return Se[i];
        return std::isfinite(cs[i]) ? cs[i] : 0.0;
      };
      std::stable_sort(order.begin(), order.end(),
                       [&](std::size_t a, std::size_t b) { return key(a) > key(b); });
      std::cout << "\n"
                << output_name(out) << " ("
                << (per_pose ? pose_label(st.poses, g)
                             : "mean over " + std::to_string(np) + " poses")
                << "), standard deviation " << std::setprecision(4) << sd_mean * sc << " "
                << display_unit(out) << "\n";
      std::ostringstream h;
      h << std::left << std::setw(10) << "error" << std::right;
      if (do_local && out != OutputId::Dp)
        h << std::setw(14) << "coefficient" << std::setw(12)
          << std::string("|c|s ") + display_unit(out);
      if (do_exact && out != OutputId::Dp) h << std::setw(9) << "S_exact";
      if (do_sobol) {
        h << std::setw(9) << "S" << (per_pose ? "  CI              " : "") << std::setw(9) << "ST";
        if (per_pose)
          h << "  CI";
        else
          h << std::setw(9) << "ST max";
      }
      std::cout << h.str() << "\n";
      const std::size_t rows = top == 0 ? ne : std::min(top, ne);
      for (std::size_t k = 0; k < rows; ++k) {
        const std::size_t i = order[k];
        std::ostringstream line;
        line << std::left << std::setw(10) << errors[i].name << std::right << std::fixed;
        if (do_local && out != OutputId::Dp)
          line << std::setw(14) << std::setprecision(6) << std::defaultfloat << c[i] << std::fixed
               << std::setw(12) << std::setprecision(3) << cs[i] * sc;
        if (do_exact && out != OutputId::Dp) line << std::setw(9) << std::setprecision(4) << Se[i];
        if (do_sobol) {
          line << std::setw(9) << std::setprecision(4) << S[i];
          if (per_pose)
            line << "  [" << std::setw(7) << slo[i] << "," << std::setw(7) << shi[i] << "]";
          line << std::setw(9) << ST[i];
          if (per_pose)
            line << "  [" << std::setw(7) << tlo[i] << "," << std::setw(7) << thi[i] << "]";
          else
            line << std::setw(9) << STmax[i];
        }
        std::cout << line.str() << "\n";
      }
    }
  }
  if (!per_pose) std::cout << "\nPer-pose values: --json FILE or --csv FILE.\n";

  // ---- JSON / CSV / plot ----
  if (!f.json.empty()) {
    nlohmann::json results = nlohmann::json::array(), sums = nlohmann::json::array();
    for (std::size_t p = 0; p < np; ++p)
      for (std::size_t o = 0; o < no; ++o) {
        const auto& sm = summary[p * no + o];
        sums.push_back({{"pose", pose_json(st.poses, p)},
                        {"output", output_name(outputs[o])},
                        {"unit", output_unit(outputs[o])},
                        {"mean", json_number(sm.mean)},
                        {"variance", json_number(sm.variance)},
                        {"variance_linear", json_number(sm.variance_linear)}});
        for (std::size_t i = 0; i < ne; ++i) {
          const Record& r = at(p, o, i);
          results.push_back(
              {{"pose", pose_json(st.poses, p)},
               {"output", output_name(outputs[o])},
               {"error", errors[i].name},
               {"coefficient", json_number(r.coefficient)},
               {"coefficient_unit", std::string(output_unit(outputs[o])) + "/" +
                                        (errors[i].effect == ErrorEffect::Rotation ? "rad" : "mm")},
               {"contribution", json_number(r.contribution)},
               {"S", json_number(r.S)},
               {"S_ci", {json_number(r.S_lo), json_number(r.S_hi)}},
               {"ST", json_number(r.ST)},
               {"ST_ci", {json_number(r.ST_lo), json_number(r.ST_hi)}},
               {"S_exact", json_number(r.S_exact)}});
        }
      }
    nlohmann::json j = {{"weilgen", kVersion},
                        {"verb", "sensitivity"},
                        {"model", model_json(model)},
                        {"settings",
                         {{"method", method},
                          {"samples", do_sobol ? nlohmann::json(samples) : nlohmann::json()},
                          {"sampling", sampling},
                          {"seed", f.seed},
                          {"bootstrap", bootstrap},
                          {"confidence", confidence},
                          {"evaluations", evaluations}}},
                        {"inputs", inputs_json(model, st.inputs)},
                        {"summary", sums},
                        {"results", results}};
    write_output(f.json, j.dump(1) + "\n");
  }
  if (!f.csv.empty()) {
    std::ostringstream c;
    for (const auto& a : st.poses.axes) c << csv_field(a) << ",";
    c << "output,output_unit,error,coefficient,contribution,S,S_lo,S_hi,ST,ST_lo,ST_hi,S_exact\n";
    for (std::size_t p = 0; p < np; ++p)
      for (std::size_t o = 0; o < no; ++o)
        for (std::size_t i = 0; i < ne; ++i) {
          const Record& r = at(p, o, i);
          for (double v : st.poses.poses[p]) c << csv_number(v) << ",";
          c << output_name(outputs[o]) << "," << output_unit(outputs[o]) << "," << errors[i].name;
          for (double v : {r.coefficient, r.contribution, r.S, r.S_lo, r.S_hi, r.ST, r.ST_lo,
                           r.ST_hi, r.S_exact})
            c << "," << csv_number(v);
          c << "\n";
        }
    write_output(f.csv, c.str());
  }
  if (!f.plot.empty()) {
    std::vector<Panel> panels;
    for (std::size_t o = 0; o < no; ++o) {
      BarChart b;
      b.title = std::string(output_name(outputs[o])) +
                (np > 1 ? " (mean over " + std::to_string(np) + " poses)"
                        : " (" + pose_label(st.poses, 0) + ")");
      b.ylabel = "index";
      for (const auto& e : errors) b.categories.push_back(e.name);
      BarSeries s{"S", {}, {}, {}}, t{"ST", {}, {}, {}}, x{"S exact", {}, {}, {}};
      for (std::size_t i = 0; i < ne; ++i) {
        double vs = 0, vt = 0, vx = 0, lo = 0, hi = 0, tl = 0, th = 0;
        for (std::size_t p = 0; p < np; ++p) {
          const Record& r = at(p, o, i);
          vs += r.S / np, vt += r.ST / np, vx += r.S_exact / np;
          lo += r.S_lo / np, hi += r.S_hi / np, tl += r.ST_lo / np, th += r.ST_hi / np;
        }
        s.value.push_back(vs), s.lo.push_back(lo), s.hi.push_back(hi);
        t.value.push_back(vt), t.lo.push_back(tl), t.hi.push_back(th);
        x.value.push_back(vx);
      }
      if (do_sobol) {
        if (np > 1 || bootstrap == 0) s.lo.clear(), s.hi.clear(), t.lo.clear(), t.hi.clear();
        b.series.push_back(s);
        b.series.push_back(t);
      }
      if (do_exact && outputs[o] != OutputId::Dp) b.series.push_back(x);
      if (b.series.empty()) {
        BarSeries l{"|c| sigma", {}, {}, {}};
        for (std::size_t i = 0; i < ne; ++i) {
          double v = 0;
          for (std::size_t p = 0; p < np; ++p) v += std::abs(at(p, o, i).contribution) / np;
          l.value.push_back(std::isfinite(v) ? v * display_scale(outputs[o]) : 0.0);
        }
        b.ylabel = std::string("|c| sigma (") + display_unit(outputs[o]) + ")";
        b.series.push_back(l);
      }
      panels.push_back(b);
    }
    write_plot(f.plot, panels, "weilgen sensitivity: " + model.name());
  }
  return 0;
}

}  // namespace weilgen::cli
