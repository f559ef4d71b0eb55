// `weilgen ballbar`: the trace, its circle and feedrate, the ISO 230-4 figures and the diagnosis,
// and with a machine the model's terms behind each geometric cause (docs/ballbar.md).
#include "weilgen/analysis/ballbar_request.hpp"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "weilgen/analysis/ballbar_model.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/error.hpp"
#include "weilgen/base/output_paths.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/uq/dense.hpp"

namespace weilgen {

namespace {

BallbarDiagnosisOptions diagnosis_options(const BallbarRequest& rq) {
  BallbarDiagnosisOptions o;
  o.alpha = rq.alpha;
  o.min_contribution_um = rq.min_contribution_um;
  return o;
}

}  // namespace

void BallbarRequest::validate() const {
  diagnosis_options(*this).validate();
  if (trace.empty()) throw std::invalid_argument("no trace file given");
  if (!feedrate.empty()) parse_feedrate_mm_min(feedrate, "--feedrate");
}

void BallbarRequest::check_outputs(const std::string& json, const std::string& plot,
                                   const std::string& report) const {
  auto extension = [](const std::string& path) {
    return lower(std::filesystem::path(path).extension().string());
  };
  if (!plot.empty() && extension(plot) != ".svg")
    throw std::invalid_argument("--plot " + plot + ": the polar plot is an .svg file");
  if (!report.empty() && extension(report) != ".html" && extension(report) != ".htm")
    throw std::invalid_argument("--report " + report + ": the report is an .html file");
  std::vector<PathArg> inputs = {{"trace file", trace}};
  if (!model.machine.empty() && std::filesystem::exists(model.machine))
    inputs.push_back({"machine file", model.machine});
  check_output_paths(inputs, {{"--json", json}, {"--plot", plot}, {"--report", report}});
}

std::vector<BallbarCauseTerm> ballbar_cause_terms(const Model& model, const BallbarCircle& circle,
                                                  const PdgeBasisChoice& basis) {
  const Description& desc = model.description();
  const BallbarMachine machine = ballbar_machine(model);
  // The trace of every term at 1° steps: dr rows of the first-order design matrix.
  PointData pd;
  std::vector<double> angles;
  for (int k = 0; k < 360; ++k) angles.push_back(k);
  const std::vector<std::array<double, 3>> u = ballbar_directions(machine, circle, angles);
  for (std::size_t k = 0; k < angles.size(); ++k) {
    pd.poses.push_back(ballbar_pose(machine, circle, angles[k]));
    PointObservation ob;
    ob.row = k;
    ob.output = kRadialOutput;
    ob.radial = u[k];
    pd.observations.push_back(ob);
  }
  pd.count[kRadialOutput] = angles.size();
  const ErrorParameterisation param(desc, basis, model.parameters());
  const Eigen::MatrixXd A = design_matrix(model, param, pd);
  // The set-up (radius, centre) and the geometric causes' shapes, in their units (µrad, µm/m,
  // µm), as ballbar_diagnosis.cpp writes them.
  const double R = circle.radius_mm;
  const auto n = static_cast<Eigen::Index>(angles.size());
  Eigen::MatrixXd base(n, 3), shapes(n, 4);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = angles[static_cast<std::size_t>(k)] * kPi / 180, c = std::cos(t),
                 s = std::sin(t);
    base.row(k) << 1, c, s;
    shapes.row(k) << 1e-3 * R * s * c, 0.5e-3 * R * (c * c - s * s), s * c * c, c * s * s;
  }
  const std::string a1 = circle.first, a2 = circle.second;
  const std::string ids[4] = {"squareness", "scale_mismatch", "straightness_" + a1,
                              "straightness_" + a2};
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> set_up(base);
  Eigen::MatrixXd clean = shapes - base * set_up.solve(shapes);
  std::vector<BallbarCauseTerm> out;
  for (Eigen::Index p = 0; p < A.cols(); ++p) {
    const Eigen::VectorXd col = A.col(p);
    const Eigen::VectorXd rest = col - base * set_up.solve(col);
    if (!(rest.norm() > 1e-9 * (1 + col.norm()))) continue;  // moves the centre only
    for (int j = 0; j < 4; ++j) {
      const Eigen::VectorXd g = clean.col(j);
      const double c = g.dot(rest) / g.squaredNorm();
      if ((rest - c * g).squaredNorm() <= 0.01 * rest.squaredNorm()) {
        const IdentParameter& ip = param.parameters()[static_cast<std::size_t>(p)];
        out.push_back({ids[j], ip.label, ip.unit, c});
      }
    }
  }
  return out;
}

BallbarStudy run_ballbar(const BallbarRequest& rq) {
  rq.validate();
  BallbarStudy st;
  st.file = rq.trace;
  ReadOptions read;
  read.allow_unknown = rq.allow_unknown;
  std::shared_ptr<const Model> model;
  std::unique_ptr<Description> desc;
  BallbarMachine machine;
  if (rq.with_machine()) {
    desc = std::make_unique<Description>(rq.description());
    model = rq.open(*desc);
    machine = ballbar_machine(*model);
    read = machine_read_options(*desc, rq.allow_unknown);
    st.machine = desc->name;
  } else {
    machine = ballbar_machine_by_letters({"X", "Y", "Z", "U", "V", "W"});
  }
  const MeasurementTable table = read_measurements(rq.trace, read);
  if (rq.warn)
    for (const auto& w : table.warnings) rq.warn(w);
  BallbarFlags flags = rq.circle;
  if (!model) {
    // On its own a trace needs its radius and plane (XY unless said); the centre only names
    // where the test was.
    if (flags.plane.empty() && !table.header_keys.count("plane")) flags.plane = "XY";
    if (flags.centre.empty() && !table.header_keys.count("centre") &&
        !table.header_keys.count("center")) {
      flags.centre = "X=0";
      st.centre_given = false;
    }
  }
  st.circle = parse_ballbar_circle(table, machine, flags);
  st.header_keys = table.header_keys;
  if (!rq.feedrate.empty()) {
    st.feedrate_mm_min = parse_feedrate_mm_min(rq.feedrate, "--feedrate");
  } else if (const auto it = table.header_keys.find("feedrate"); it != table.header_keys.end()) {
    try {
      st.feedrate_mm_min =
          parse_feedrate_mm_min(it->second, "ballbar: '# feedrate: " + it->second + "'");
    } catch (const std::invalid_argument& e) {
      throw InputError(SourceLoc{table.file, table.header_key_lines.at("feedrate"), 0}, e.what());
    }
  }
  st.traces = ballbar_traces(table, st.circle);
  BallbarDiagnosisInput in;
  in.traces = st.traces;
  in.radius_mm = st.circle.radius_mm;
  in.first = st.circle.first;
  in.second = st.circle.second;
  in.feedrate_mm_min = st.feedrate_mm_min;
  try {
    st.diagnosis = BallbarDiagnosis(diagnosis_options(rq)).run(in);
  } catch (const std::invalid_argument& e) {  // what the data cannot give is the file's fault
    throw InputError(SourceLoc{table.file, 0, 0}, e.what());
  }
  if (model) st.terms = ballbar_cause_terms(*model, st.circle, parse_pdge_flags(*desc, rq.pdge));
  return st;
}

}  // namespace weilgen
