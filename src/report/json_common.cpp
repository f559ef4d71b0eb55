#include "weilgen/report/json_common.hpp"

#include <cmath>

#include "weilgen/base/format.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/machine/model_key.hpp"

namespace weilgen {

nlohmann::json json_document(const std::string& verb, nlohmann::json body) {
  body["weilgen"] = kVersion;
  body["verb"] = verb;
  return body;
}

nlohmann::json json_number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

nlohmann::json json_numbers(const std::vector<double>& v) {
  nlohmann::json a = nlohmann::json::array();
  for (double x : v) a.push_back(json_number(x));
  return a;
}

std::string pose_label(const PoseSet& poses, std::size_t i) {
  std::string s;
  for (std::size_t a = 0; a < poses.axes.size(); ++a)
    s += (a ? " " : "") + poses.axes[a] + "=" + format_number(poses.poses[i][a]);
  return s;
}

nlohmann::json pose_json(const PoseSet& poses, std::size_t i) {
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t a = 0; a < poses.axes.size(); ++a) j[poses.axes[a]] = poses.poses[i][a];
  return j;
}

nlohmann::json model_json(const Model& m) {
  const Description& d = m.description();
  nlohmann::json axes = nlohmann::json::array();
  for (int b : d.axes())
    axes.push_back({{"name", d.bodies[b].joint.coordinate}, {"unit", d.bodies[b].joint.unit}});
  return {{"machine", d.name},
          {"source", d.source_file},
          {"order", m.order()},
          {"key", model_key(d.source_hash, m.order())},
          {"engine", engine_name(m.engine())},
          {"origin", m.origin()},
          {"axes", axes}};
}

nlohmann::json inputs_json(const Model& m, const std::vector<InputDistribution>& inputs) {
  nlohmann::json j = nlohmann::json::array();
  const auto& errs = m.description().errors;
  for (std::size_t i = 0; i < errs.size(); ++i) {
    const double f = errs[i].to_base;
    const InputDistribution in_unit = inputs[i].scaled(1.0 / f);
    j.push_back({{"error", errs[i].name},
                 {"unit", errs[i].unit},
                 {"distribution", in_unit.str()},
                 {"mean", in_unit.mean()},
                 {"stddev", in_unit.stddev()}});
  }
  return j;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string csv_number(double v) { return std::isfinite(v) ? format_number(v) : ""; }

}  // namespace weilgen
