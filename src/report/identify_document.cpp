#include "weilgen/report/identify_document.hpp"

#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

#include "weilgen/base/format.hpp"
#include "weilgen/report/csv_table.hpp"
#include "weilgen/report/json_common.hpp"
#include "weilgen/report/prediction_document.hpp"

namespace weilgen {

namespace {
// "_um" or "_urad": the JSON key suffix of an observation kind's figures.
std::string unit_suffix(std::size_t kind) {
  return std::string(observation_unit(kind)) == "µrad" ? "_urad" : "_um";
}

}  // namespace

using nlohmann::json;

json null_combinations_json(const ErrorParameterisation& param,
                            const std::vector<NullCombination>& combinations) {
  json null = json::array();
  for (const NullCombination& c : combinations) {
    json terms = json::array();
    for (const auto& [p, v] : c.terms)
      terms.push_back({{"parameter", param.parameters()[p].label}, {"coefficient", v}});
    null.push_back({{"text", c.str(param.parameters())}, {"terms", terms}});
  }
  return null;
}

json identify_json(const Model& model, const ErrorParameterisation& param, const IdentifyResult& r,
                   const std::vector<std::string>& files) {
  const Description& d = model.description();
  json params = json::array();
  for (std::size_t p = 0; p < param.size(); ++p) {
    const IdentParameter& ip = param.parameters()[p];
    const auto& basis = param.basis_of(static_cast<std::size_t>(ip.error));
    params.push_back({{"label", ip.label},
                      {"error", d.errors[static_cast<std::size_t>(ip.error)].name},
                      {"basis", basis ? basis->name() : "constant"},
                      {"term", ip.term},
                      {"value", json_number(r.theta[p])},
                      {"standard_error", json_number(r.standard_error[p])},
                      {"unit", ip.unit},
                      {"identifiable", static_cast<bool>(r.identifiable[p])},
                      {"fixed", static_cast<bool>(r.fixed[p])}});
  }
  json bases = json::object();
  for (std::size_t k = 0; k < d.errors.size(); ++k) {
    const auto& b = param.basis_of(k);
    if (b)
      bases[d.errors[k].name] = {{"basis", b->name()},
                                 {"coordinate", param.coordinate_of(k)},
                                 {"from", b->a},
                                 {"to", b->b}};
  }
  const json null = null_combinations_json(param, r.unidentifiable);
  json outputs = json::object();
  for (std::size_t o = 0; o < kObservationKinds; ++o) {
    if (!r.count[o]) continue;
    const std::string u = unit_suffix(o);
    outputs[observation_name(o)] = {{"observations", r.count[o]},
                                    {"rms_before" + u, json_number(r.rms_before[o])},
                                    {"rms_after" + u, json_number(r.rms_after[o])},
                                    {"max_after" + u, json_number(r.max_after[o])}};
  }
  return json_document("identify", {{"model", model_json(model)},
                                    {"data", files},
                                    {"observations", r.observations},
                                    {"parameters", params},
                                    {"bases", bases},
                                    {"free_parameters", r.free_parameters},
                                    {"rank", r.rank},
                                    {"condition", json_number(r.condition)},
                                    {"singular_values", r.singular_values},
                                    {"unidentifiable", null},
                                    {"residual_sigma", json_number(r.residual_sigma)},
                                    {"references_removed", r.references},
                                    {"gauss_newton_iterations", r.gauss_newton_iterations},
                                    {"outputs", outputs}});
}

std::string identify_text(const Model& model, const ErrorParameterisation& param,
                          const IdentifyResult& r, const PointData& data) {
  std::ostringstream os;
  const Description& d = model.description();
  os << "identify " << d.name << " (order " << model.order() << ", " << model.origin()
     << "): " << r.observations << " observations from " << data.file << " (";
  bool first = true;
  for (std::size_t o = 0; o < kObservationKinds; ++o)
    if (r.count[o])
      os << (first ? "" : ", ") << observation_name(o) << " " << r.count[o], first = false;
  os << ")\n";
  if (!data.references.empty()) {
    os << "set-up references removed (" << r.references << " functions):";
    for (std::size_t i = 0; i < data.references.size() && i < 6; ++i)
      os << (i ? "; " : " ") << data.references[i].what;
    if (data.references.size() > 6) os << "; and " << data.references.size() - 6 << " more";
    os << "\n";
  }
  std::map<std::string, int> kinds;
  for (std::size_t k = 0; k < d.errors.size(); ++k)
    ++kinds[param.basis_of(k) ? param.basis_of(k)->name() : std::string("constant")];
  os << "parameters: " << param.size() << " for " << d.errors.size() << " errors (";
  first = true;
  for (const auto& [k, n] : kinds) os << (first ? "" : ", ") << n << " " << k, first = false;
  os << ")";
  if (r.free_parameters < param.size()) os << ", " << param.size() - r.free_parameters << " fixed";
  os << "\nrank " << r.rank << " of " << r.free_parameters << " (condition "
     << format_significant(r.condition, 3) << ")";
  if (!r.unidentifiable.empty())
    os << ": " << r.unidentifiable.size() << " combination"
       << (r.unidentifiable.size() > 1 ? "s" : "") << " not identifiable (below)";
  os << "\nresidual sigma " << format_significant(r.residual_sigma, 3) << " (µm, µrad as measured)";
  if (r.gauss_newton_iterations) os << ", " << r.gauss_newton_iterations << " Gauss-Newton steps";
  os << "\n\noutput  rms before  rms after  max after\n";
  for (std::size_t u = 0; u < kObservationKinds; ++u) {
    if (!r.count[u]) continue;
    os << std::left << std::setw(8) << observation_name(u) << std::right << std::setw(10)
       << format_significant(r.rms_before[u], 3) << std::setw(11)
       << format_significant(r.rms_after[u], 3) << std::setw(11)
       << format_significant(r.max_after[u], 3) << "  " << observation_unit(u) << "\n";
  }
  os << "\nparameter" << std::string(16, ' ') << "value      ± s.e.  unit\n";
  for (std::size_t p = 0; p < param.size(); ++p) {
    const IdentParameter& ip = param.parameters()[p];
    os << std::left << std::setw(24) << ip.label << std::right << std::setw(10)
       << (r.fixed[p] ? "fixed" : format_significant(r.theta[p], 4)) << std::setw(10)
       << (r.identifiable[p] ? format_significant(r.standard_error[p], 2) : std::string("n.i."))
       << "  " << ip.unit << "\n";
  }
  if (!r.unidentifiable.empty()) {
    os << "\nNot identifiable from these data (n.i.): adding any multiple of a combination "
          "changes\nno prediction at the measured poses; the values above are the minimum-norm "
          "choice.\n";
    for (std::size_t i = 0; i < r.unidentifiable.size(); ++i)
      os << "  " << i + 1 << ". " << r.unidentifiable[i].str(param.parameters()) << "\n";
  }
  return os.str();
}

json identify_json(const IdentifyRun& run) {
  json j = identify_json(*run.model, *run.param, run.result, run.files);
  j["predictions"] = json::array();
  for (const FilePrediction& p : run.predictions)
    j["predictions"].push_back(p.ballbar ? ballbar_prediction_json(*p.ballbar)
                                         : prediction_json(*p.points));
  return j;
}

std::string identify_text(const IdentifyRun& run) {
  std::string text = identify_text(*run.model, *run.param, run.result, run.points);
  for (const FilePrediction& p : run.predictions)
    text += "\n" + (p.ballbar ? ballbar_prediction_text(*p.ballbar) : prediction_text(*p.points));
  return text;
}

std::string identify_csv(const Model& model, const ErrorParameterisation& param,
                         const IdentifyResult& r) {
  const Description& d = model.description();
  CsvTable t;
  t.comment("weilgen identify " + d.name + ": rank " + std::to_string(r.rank) + " of " +
            std::to_string(r.free_parameters) + " free parameters, " +
            std::to_string(r.observations) + " observations");
  for (const char* c : {"parameter", "error", "basis", "term", "value", "standard_error", "unit",
                        "identifiable", "fixed"})
    t.column(c);
  for (std::size_t p = 0; p < param.size(); ++p) {
    const IdentParameter& ip = param.parameters()[p];
    const auto& basis = param.basis_of(static_cast<std::size_t>(ip.error));
    t.text(ip.label).text(d.errors[static_cast<std::size_t>(ip.error)].name);
    t.text(basis ? basis->name() : "constant").count(ip.term);
    t.number(r.theta[p]).number(r.standard_error[p]).text(ip.unit);
    t.text(r.identifiable[p] ? "yes" : "no").text(r.fixed[p] ? "yes" : "no").end_row();
  }
  return t.str();
}

std::vector<Panel> identify_panels(const ErrorParameterisation& param, const IdentifyResult& r) {
  std::vector<Panel> panels;
  BarChart res;
  res.title = "RMS residual per output";
  res.ylabel = "RMS (um for dx dy dz dr lin str, urad for da db dc ang)";
  BarSeries before{"before (model without errors)", {}, {}, {}}, after{"after", {}, {}, {}};
  for (std::size_t o = 0; o < kObservationKinds; ++o) {
    if (!r.count[o]) continue;
    res.categories.push_back(std::string(observation_name(o)) + " (" + unit_suffix(o).substr(1) +
                             ")");
    before.value.push_back(r.rms_before[o]);
    after.value.push_back(r.rms_after[o]);
  }
  res.series = {before, after};
  if (!res.categories.empty()) panels.push_back(res);
  // Parameters, one chart per unit (values in different units share no axis); fixed ones left
  // out; an interval only where the data identify the parameter.
  std::map<std::string, BarChart> by_unit;
  for (std::size_t p = 0; p < param.size(); ++p) {
    if (r.fixed[p]) continue;
    const IdentParameter& ip = param.parameters()[p];
    BarChart& b = by_unit[ip.unit];
    if (b.series.empty()) {
      b.title = "identified parameters (" + ip.unit + "), 95 % intervals";
      b.ylabel = "value (" + ip.unit + ")";
      b.series.push_back({"value", {}, {}, {}});
    }
    const double v = r.theta[p], se = r.standard_error[p];
    const double h = std::isfinite(se) ? 1.96 * se : 0.0;
    b.categories.push_back(ip.label + (r.identifiable[p] ? "" : " (not identifiable)"));
    b.series[0].value.push_back(v);
    b.series[0].lo.push_back(v - h);
    b.series[0].hi.push_back(v + h);
  }
  for (auto& [unit, b] : by_unit) panels.push_back(b);
  return panels;
}

}  // namespace weilgen
