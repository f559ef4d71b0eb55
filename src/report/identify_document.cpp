#include "weilgen/report/identify_document.hpp"

#include <iomanip>
#include <map>
#include <sstream>

#include "weilgen/base/format.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/report/json_common.hpp"
#include "weilgen/report/prediction_document.hpp"

namespace weilgen {

namespace {
std::string fmt(double v, int precision = 3) { return format_significant(v, precision); }

}  // namespace

using nlohmann::json;

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
  json null = json::array();
  for (const NullCombination& c : r.unidentifiable) {
    json terms = json::array();
    for (const auto& [p, v] : c.terms)
      terms.push_back({{"parameter", param.parameters()[p].label}, {"coefficient", v}});
    null.push_back({{"text", c.str(param.parameters())}, {"terms", terms}});
  }
  json outputs = json::object();
  for (int o = 0; o < 6; ++o) {
    if (!r.count[static_cast<std::size_t>(o)]) continue;
    const std::string u = o < 3 ? "_um" : "_urad";
    outputs[output_name(static_cast<std::size_t>(o))] = {
        {"observations", r.count[static_cast<std::size_t>(o)]},
        {"rms_before" + u, json_number(r.rms_before[static_cast<std::size_t>(o)])},
        {"rms_after" + u, json_number(r.rms_after[static_cast<std::size_t>(o)])},
        {"max_after" + u, json_number(r.max_after[static_cast<std::size_t>(o)])}};
  }
  return {{"weilgen", kVersion},
          {"model", model_json(model)},
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
          {"gauss_newton_iterations", r.gauss_newton_iterations},
          {"outputs", outputs}};
}

std::string identify_text(const Model& model, const ErrorParameterisation& param,
                          const IdentifyResult& r, const PointData& data) {
  std::ostringstream os;
  const Description& d = model.description();
  os << "identify " << d.name << " (order " << model.order() << ", " << model.origin()
     << "): " << r.observations << " observations from " << data.file << " (";
  bool first = true;
  for (int o = 0; o < 6; ++o)
    if (r.count[static_cast<std::size_t>(o)])
      os << (first ? "" : ", ") << output_name(static_cast<std::size_t>(o)) << " "
         << r.count[static_cast<std::size_t>(o)],
          first = false;
  os << ")\n";
  std::map<std::string, int> kinds;
  for (std::size_t k = 0; k < d.errors.size(); ++k)
    ++kinds[param.basis_of(k) ? param.basis_of(k)->name() : std::string("constant")];
  os << "parameters: " << param.size() << " for " << d.errors.size() << " errors (";
  first = true;
  for (const auto& [k, n] : kinds) os << (first ? "" : ", ") << n << " " << k, first = false;
  os << ")";
  if (r.free_parameters < param.size()) os << ", " << param.size() - r.free_parameters << " fixed";
  os << "\nrank " << r.rank << " of " << r.free_parameters << " (condition " << fmt(r.condition)
     << ")";
  if (!r.unidentifiable.empty())
    os << ": " << r.unidentifiable.size() << " combination"
       << (r.unidentifiable.size() > 1 ? "s" : "") << " not identifiable (below)";
  os << "\nresidual sigma " << fmt(r.residual_sigma) << " (µm, µrad as measured)";
  if (r.gauss_newton_iterations) os << ", " << r.gauss_newton_iterations << " Gauss-Newton steps";
  os << "\n\noutput  rms before  rms after  max after\n";
  for (int o = 0; o < 6; ++o) {
    const auto u = static_cast<std::size_t>(o);
    if (!r.count[u]) continue;
    os << std::left << std::setw(8) << output_name(u) << std::right << std::setw(10)
       << fmt(r.rms_before[u]) << std::setw(11) << fmt(r.rms_after[u]) << std::setw(11)
       << fmt(r.max_after[u]) << "  " << observation_unit(static_cast<std::size_t>(o)) << "\n";
  }
  os << "\nparameter" << std::string(16, ' ') << "value      ± s.e.  unit\n";
  for (std::size_t p = 0; p < param.size(); ++p) {
    const IdentParameter& ip = param.parameters()[p];
    os << std::left << std::setw(24) << ip.label << std::right << std::setw(10)
       << (r.fixed[p] ? "fixed" : fmt(r.theta[p], 4)) << std::setw(10)
       << (r.identifiable[p] ? fmt(r.standard_error[p], 2) : std::string("n.i.")) << "  " << ip.unit
       << "\n";
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

}  // namespace weilgen
