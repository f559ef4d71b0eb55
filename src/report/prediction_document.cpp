#include "weilgen/report/prediction_document.hpp"

#include <iomanip>
#include <sstream>

#include "weilgen/base/format.hpp"
#include "weilgen/report/json_common.hpp"

namespace weilgen {

std::string prediction_text(const Prediction& p) {
  std::ostringstream os;
  os << "prediction for " << p.file << ": " << p.poses.size() << " poses\n";
  bool any = false;
  for (std::size_t o = 0; o < 6; ++o) {
    if (!p.compared[o]) continue;
    if (!any) os << "output  measured rms  rms(measured - predicted)  max\n";
    any = true;
    os << std::left << std::setw(8) << output_name(o) << std::right << std::setw(12)
       << format_short(p.rms_measured[o]) << std::setw(27) << format_short(p.rms_difference[o])
       << std::setw(10) << format_short(p.max_difference[o]) << "  " << observation_unit(o) << "\n";
  }
  if (!any) os << "(no measured deviations to compare with; --predict-out writes the values)\n";
  return os.str();
}

nlohmann::json prediction_json(const Prediction& p) {
  nlohmann::json outputs = nlohmann::json::object();
  for (std::size_t o = 0; o < 6; ++o) {
    if (!p.compared[o]) continue;
    const std::string u = o < 3 ? "_um" : "_urad";
    outputs[output_name(o)] = {{"compared", p.compared[o]},
                               {"rms_measured" + u, json_number(p.rms_measured[o])},
                               {"rms_difference" + u, json_number(p.rms_difference[o])},
                               {"max_difference" + u, json_number(p.max_difference[o])}};
  }
  nlohmann::json rows = nlohmann::json::array();
  for (std::size_t i = 0; i < p.poses.size(); ++i) {
    nlohmann::json pose = nlohmann::json::object(), pred = nlohmann::json::array();
    for (std::size_t a = 0; a < p.axes.size(); ++a) pose[p.axes[a]] = p.poses[i][a];
    for (double v : p.predicted[i]) pred.push_back(json_number(v));
    rows.push_back({{"line", p.lines[i]}, {"pose", pose}, {"predicted", pred}});
  }
  return {{"file", p.file}, {"kind", "points"}, {"outputs", outputs}, {"rows", rows}};
}

std::string prediction_csv(const Prediction& p, const Description& desc) {
  std::ostringstream s;
  s << "# machine: " << desc.name << "\n# predicted: weilgen identify --predict " << p.file << "\n";
  for (const auto& a : p.axes) s << a << ",";
  s << "dx_um,dy_um,dz_um,da_urad,db_urad,dc_urad\n";
  for (std::size_t i = 0; i < p.poses.size(); ++i) {
    for (double v : p.poses[i]) s << csv_number(v) << ",";
    for (std::size_t o = 0; o < 6; ++o) s << csv_number(p.predicted[i][o]) << (o < 5 ? "," : "\n");
  }
  return s.str();
}

namespace {

nlohmann::json evaluation_json(const BallbarEvaluation& e) {
  return {{"points", e.points},
          {"centre_offset_um",
           {json_number(e.centre_offset_um[0]), json_number(e.centre_offset_um[1])}},
          {"radius_deviation_um", json_number(e.radius_deviation_um)},
          {"max_minus_min_um", json_number(e.max_minus_min_um)},
          {"circular_deviation_um", json_number(e.circular_deviation_um)},
          {"squareness_urad", json_number(e.squareness_urad)},
          {"scale_mismatch_um_per_m", json_number(e.scale_mismatch_um_per_m)}};
}

void print_evaluation(std::ostream& os, const char* what, const BallbarEvaluation& e,
                      const BallbarCircle& c) {
  os << "  " << std::left << std::setw(16) << what << std::right << "G " << std::setw(7)
     << format_short(e.circular_deviation_um) << " µm   centre offset (" << c.first << " "
     << format_short(e.centre_offset_um[0]) << ", " << c.second << " "
     << format_short(e.centre_offset_um[1]) << ") µm   radius "
     << format_short(e.radius_deviation_um) << " µm\n";
}

}  // namespace

std::string ballbar_prediction_text(const BallbarPrediction& p) {
  std::ostringstream os;
  const BallbarCircle& c = p.circle;
  os << "ballbar prediction for " << p.file << ": plane " << c.plane << ", radius "
     << format_short(c.radius_mm) << " mm, " << (c.feed > 0 ? "ccw" : "cw") << "\n";
  print_evaluation(os, "predicted", p.predicted_evaluation, c);
  for (std::size_t i = 0; i < p.compared.size(); ++i) {
    const BallbarComparison& k = p.compared[i];
    // Every measured run named by its direction (and cycle, when the file has several).
    const std::string run = std::string(k.feed > 0 ? "ccw" : "cw") +
                            (k.cycle != 0 ? " " + std::to_string(k.cycle) : std::string());
    print_evaluation(os, ("measured " + run).c_str(), k.measured, c);
    os << "  measured - predicted: rms " << format_short(k.raw.rms_um) << " µm, max "
       << format_short(k.raw.max_abs_um) << " µm; centred rms " << format_short(k.centred.rms_um)
       << " µm, correlation " << format_short(k.centred.correlation)
       << "; G of the difference (after ideal compensation) "
       << format_short(k.difference.circular_deviation_um) << " µm\n";
  }
  return os.str();
}

nlohmann::json ballbar_prediction_json(const BallbarPrediction& p) {
  nlohmann::json compared = nlohmann::json::array();
  for (const BallbarComparison& k : p.compared)
    compared.push_back({{"feed", k.feed > 0 ? "ccw" : "cw"},
                        {"cycle", k.cycle},
                        {"measured", evaluation_json(k.measured)},
                        {"difference", evaluation_json(k.difference)},
                        {"rms_difference_um", json_number(k.raw.rms_um)},
                        {"max_difference_um", json_number(k.raw.max_abs_um)},
                        {"centred_rms_difference_um", json_number(k.centred.rms_um)},
                        {"centred_correlation", json_number(k.centred.correlation)}});
  nlohmann::json trace = {{"angle_deg", p.predicted.angle_deg}, {"dr_um", p.predicted.dr_um}};
  return {{"file", p.file},
          {"kind", "ballbar"},
          {"plane", p.circle.plane},
          {"radius_mm", p.circle.radius_mm},
          {"feed", p.circle.feed > 0 ? "ccw" : "cw"},
          {"predicted", evaluation_json(p.predicted_evaluation)},
          {"predicted_trace", trace},
          {"compared", compared}};
}

}  // namespace weilgen
