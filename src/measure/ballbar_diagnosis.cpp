// The ballbar causes fitted jointly by least squares on every run of a trace. The shapes, sign
// conventions, the tests and the recovery proof: docs/ballbar.md, "weilgen ballbar".
#include "weilgen/measure/ballbar_diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/uq/dense.hpp"
#include "weilgen/uq/test_statistics.hpp"

namespace weilgen {

namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

// One point of one run, with what every cause's shape needs.
struct Pt {
  double c = 0, s = 0;        // cos θ, sin θ
  double x1 = 0, x2 = 0;      // the axes' positions from the centre, mm: R cos θ, R sin θ
  double phi1 = 0, phi2 = 0;  // deg travelled since the axis' last reversal, in (0, 180]
  int dir1 = 1, dir2 = 1, feed = 1;
  std::size_t run = 0;
};

// Degrees travelled since the reversal at `at` (and at + 180), along the feed; a point exactly at
// a reversal belongs to the motion before it (180).
double since_reversal(double theta_deg, double at_deg, int feed) {
  double a = std::fmod(theta_deg - at_deg, 180.0);
  if (a < 0) a += 180;
  double phi = feed > 0 ? a : 180 - a;
  if (phi < 1e-9) phi = 180;
  if (phi > 180) phi = 180;
  return phi;
}

enum class Kind { Linear, Spike, Cyclic };

// A cause: its columns in dr (µm per unit of its size) for a hyper-parameter (the spike's width
// in deg, the cyclic error's pitch in mm; unused for a linear cause).
struct Spec {
  std::string id, name, axis, unit;
  Kind kind = Kind::Linear;
  int which = 0;                           // 0: the first axis, 1: the second (spikes, cyclic)
  std::function<double(const Pt&)> shape;  // Linear
  std::vector<double> grid;                // Spike, Cyclic
  double hyper = kNaN;
  bool separable = true;
  std::string note;
  Index width() const { return kind == Kind::Cyclic ? 2 : 1; }
};

MatrixXd columns(const Spec& c, double hyper, const std::vector<Pt>& pts) {
  MatrixXd m(static_cast<Index>(pts.size()), c.width());
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const Pt& p = pts[k];
    const Index r = static_cast<Index>(k);
    const double proj = c.which == 0 ? p.c : p.s;  // the axis' motion seen radially
    const int dir = c.which == 0 ? p.dir1 : p.dir2;
    switch (c.kind) {
      case Kind::Linear:
        m(r, 0) = c.shape(p);
        break;
      case Kind::Spike:
        m(r, 0) = -dir * std::exp(-(c.which == 0 ? p.phi1 : p.phi2) / hyper) * proj;
        break;
      case Kind::Cyclic: {
        const double t = 2 * kPi * (c.which == 0 ? p.x1 : p.x2) / hyper;
        m(r, 0) = proj * std::cos(t);
        m(r, 1) = proj * std::sin(t);
        break;
      }
    }
  }
  return m;
}

// Least squares through the normal equations: coefficients and the residual sum of squares.
struct Fit {
  VectorXd beta;
  double sse = 0;
  bool ok = false;
};

Fit solve(const MatrixXd& A, const VectorXd& y) {
  Fit f;
  const MatrixXd G = A.transpose() * A;
  const Eigen::LDLT<MatrixXd> ldlt(G);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return f;
  // A singular Gram matrix shows as a vanishing pivot.
  const VectorXd d = ldlt.vectorD();
  const double top = d.cwiseAbs().maxCoeff();
  if (!(d.cwiseAbs().minCoeff() > 1e-12 * top)) return f;
  f.beta = ldlt.solve(A.transpose() * y);
  f.sse = (y - A * f.beta).squaredNorm();
  f.ok = true;
  return f;
}

MatrixXd join_columns(const MatrixXd& a, const MatrixXd& b) {
  MatrixXd m(a.rows(), a.cols() + b.cols());
  m << a, b;
  return m;
}

// The diagnosis' passes over the runs' points, in order: the points, the set-up columns, the
// causes, their separability, their hyper-parameters, then the fit with each cause's test.
class BallbarDiagnosisPasses {
 public:
  BallbarDiagnosisPasses(const BallbarDiagnosisInput& input, const BallbarDiagnosisOptions& options)
      : in(input), options_(options), R(input.radius_mm) {
    res.alpha = options_.alpha;
  }

  BallbarDiagnosisResult run() {
    collect_points();
    setup_columns();
    list_causes();
    mark_inseparable();
    choose_hyperparameters();
    const VectorXd model = test_causes();
    fitted_and_residuals(model);
    return std::move(res);
  }

 private:
  // The points of every run, and the finest angular step (for the grids).
  void collect_points() {
    std::vector<double> values;
    for (std::size_t r = 0; r < in.traces.size(); ++r) {
      const BallbarTrace& t = in.traces[r];
      BallbarRun run;
      run.feed = t.feed;
      run.cycle = t.cycle;
      run.evaluation = evaluate_ballbar(t, R, options_.max_harmonic);
      std::vector<double> sorted;
      for (double a : t.angle_deg) sorted.push_back(std::fmod(std::fmod(a, 360.0) + 360.0, 360.0));
      std::sort(sorted.begin(), sorted.end());
      sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
      if (sorted.size() < 8)
        throw std::invalid_argument("ballbar: run " + std::to_string(r + 1) + " has " +
                                    std::to_string(sorted.size()) +
                                    " distinct angles: the diagnosis needs at least 8");
      for (std::size_t k = 1; k < sorted.size(); ++k)
        step_deg = std::max(step_deg, sorted[k] - sorted[k - 1]);
      res.runs.push_back(run);
      const std::vector<int> d1 = ballbar_travel_direction(t.angle_deg, t.feed, 0);
      const std::vector<int> d2 = ballbar_travel_direction(t.angle_deg, t.feed, 1);
      for (std::size_t k = 0; k < t.size(); ++k) {
        Pt p;
        const double th = t.angle_deg[k] * kPi / 180;
        p.c = std::cos(th);
        p.s = std::sin(th);
        p.x1 = R * p.c;
        p.x2 = R * p.s;
        p.dir1 = d1[k];
        p.dir2 = d2[k];
        p.feed = t.feed;
        p.phi1 = since_reversal(t.angle_deg[k], 0, t.feed);
        p.phi2 = since_reversal(t.angle_deg[k], 90, t.feed);
        p.run = r;
        pts.push_back(p);
        values.push_back(t.dr_um[k]);
      }
    }
    // The largest step between neighbouring angles of any run bounds what the grids may resolve.
    step_deg = std::max(step_deg, 1e-3);
    y = Eigen::Map<const VectorXd>(values.data(), static_cast<Index>(values.size()));
    n = pts.size();
    res.points = n;
    // ISO 230-4's H: the first ccw run against the first cw run.
    const auto ccw = std::find_if(in.traces.begin(), in.traces.end(),
                                  [](const BallbarTrace& t) { return t.feed > 0; });
    const auto cw = std::find_if(in.traces.begin(), in.traces.end(),
                                 [](const BallbarTrace& t) { return t.feed < 0; });
    if (ccw != in.traces.end() && cw != in.traces.end())
      res.hysteresis_um = circular_hysteresis_um(*ccw, *cw, 180);
  }

  // The set-up of every run: its radius deviation and centre offset.
  void setup_columns() {
    base = MatrixXd(static_cast<Index>(n), static_cast<Index>(3 * in.traces.size()));
    base.setZero();
    for (std::size_t k = 0; k < n; ++k) {
      const Index r = static_cast<Index>(k), c = static_cast<Index>(3 * pts[k].run);
      base(r, c) = 1;
      base(r, c + 1) = pts[k].c;
      base(r, c + 2) = pts[k].s;
    }
  }

  // The causes, in the order in which they claim a shape the runs cannot separate.
  void list_causes() {
    const std::string& a1 = in.first;
    const std::string& a2 = in.second;
    auto linear = [&](std::string id, std::string name, std::string axis, std::string unit,
                      std::function<double(const Pt&)> shape) {
      Spec s;
      s.id = std::move(id);
      s.name = std::move(name);
      s.axis = std::move(axis);
      s.unit = std::move(unit);
      s.shape = std::move(shape);
      specs.push_back(s);
    };
    // Squareness S (µrad): d1 = S·x2, dr = (S R/2) sin 2θ.
    linear("squareness", "squareness " + a1 + a2, "", "urad",
           [r = R](const Pt& p) { return 1e-3 * r * p.s * p.c; });
    // Scale mismatch k1 − k2 (µm/m): d_i = k_i x_i, dr = R (k1 − k2)/2 cos 2θ + const.
    linear("scale_mismatch", "scale mismatch " + a1 + "-" + a2, "", "um/m",
           [r = R](const Pt& p) { return 0.5e-3 * r * (p.c * p.c - p.s * p.s); });
    // Straightness (µm, the bow over the diameter): d2 = s (x1/R)², d1 = s (x2/R)².
    linear("straightness_" + a1, "straightness " + a1, a1, "um",
           [](const Pt& p) { return p.s * p.c * p.c; });
    linear("straightness_" + a2, "straightness " + a2, a2, "um",
           [](const Pt& p) { return p.c * p.s * p.s; });
    // Backlash B (µm, lost motion): the axis stops short by B/2, d = −dir B/2.
    linear("backlash_" + a1, "backlash " + a1, a1, "um",
           [](const Pt& p) { return -p.dir1 / 2.0 * p.c; });
    linear("backlash_" + a2, "backlash " + a2, a2, "um",
           [](const Pt& p) { return -p.dir2 / 2.0 * p.s; });
    // Servo mismatch M (µm): the first axis lags the second by Δτ, dr = feed M sin 2θ,
    // M = v Δτ / 2.
    linear("servo_mismatch", "servo mismatch " + a1 + "-" + a2, "", "um",
           [](const Pt& p) { return p.feed * 2 * p.s * p.c; });
    // Lateral play L (µm): the axis' carriage shifts across its travel by L/2 with its direction,
    // d2 = −dir1 L/2 (d1 = −dir2 L/2 for the second axis).
    linear("lateral_play_" + a1, "lateral play " + a1, a1, "um",
           [](const Pt& p) { return -p.dir1 / 2.0 * p.s; });
    linear("lateral_play_" + a2, "lateral play " + a2, a2, "um",
           [](const Pt& p) { return -p.dir2 / 2.0 * p.c; });
    // Reversal spikes S (µm) of width w (deg): after a reversal the axis sticks, d = −dir S
    // e^(−φ/w).
    std::vector<double> widths;
    for (double w : {0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0})
      if (w >= 0.5 * step_deg) widths.push_back(w);
    if (widths.empty()) widths.push_back(16.0);
    // One cause of each axis, searched on `grid`.
    auto searched = [&](Kind kind, const std::string& id, const std::string& name,
                        const std::vector<double>& grid) {
      for (int which : {0, 1}) {
        Spec s;
        s.kind = kind;
        s.which = which;
        s.axis = which == 0 ? a1 : a2;
        s.id = id + "_" + s.axis;
        s.name = name + " " + s.axis;
        s.unit = "um";
        s.grid = grid;
        if (grid.empty()) {
          s.separable = false;
          s.note = "the sampling does not resolve a pitch below the radius";
        }
        specs.push_back(s);
      }
    };
    searched(Kind::Spike, "reversal_spike", "reversal spike", widths);
    // Cyclic error C (µm amplitude) of pitch p (mm): d = C cos(2π x/p + φ); pitches from what
    // the sampling resolves (2.5 steps of the axis at its fastest) to the diameter.
    std::vector<double> pitches;
    for (double p = std::max(1.0, 2.5 * R * step_deg * kPi / 180); p <= 2 * R; p *= 1.01)
      pitches.push_back(p);
    searched(Kind::Cyclic, "cyclic", "cyclic error", pitches);
  }

  // Separability: a cause whose shape the set-up and the causes before it already span (more
  // than 99 % of its norm) cannot be told from them on these runs.
  void mark_inseparable() {
    MatrixXd A = base;
    for (Spec& s : specs) {
      if (!s.separable) continue;
      const double hyper = s.kind == Kind::Linear ? kNaN : s.grid[s.grid.size() / 2];
      const MatrixXd g = columns(s, hyper, pts);
      const Eigen::ColPivHouseholderQR<MatrixXd> qr(A);
      for (Index j = 0; j < g.cols(); ++j) {
        const VectorXd col = g.col(j);
        const VectorXd rest = col - A * qr.solve(col);
        if (!(rest.norm() > 0.1 * col.norm())) {
          s.separable = false;
          s.note =
              "not separable from the set-up and the causes before it on these runs" +
              std::string(std::none_of(in.traces.begin(), in.traces.end(),
                                       [](const BallbarTrace& t) { return t.feed < 0; }) ||
                                  std::none_of(in.traces.begin(), in.traces.end(),
                                               [](const BallbarTrace& t) { return t.feed > 0; })
                              ? " (one direction only: it needs both)"
                              : "");
        }
      }
      if (s.separable) A = join_columns(A, g);
    }
  }

  // The design matrix: the set-up and every separable cause at its current hyper-parameter,
  // without the cause `skip` (-1: none).
  MatrixXd design(int skip) const {
    MatrixXd m = base;
    for (std::size_t k = 0; k < specs.size(); ++k) {
      const Spec& s = specs[k];
      if (!s.separable || static_cast<int>(k) == skip) continue;
      m = join_columns(m, columns(s, s.hyper, pts));
    }
    return m;
  }

  // The hyper-parameters: each searched on its grid with the others at their current choice,
  // twice round.
  void choose_hyperparameters() {
    for (Spec& s : specs)
      if (s.kind != Kind::Linear && s.separable) s.hyper = s.grid[s.grid.size() / 2];
    for (int round = 0; round < 2; ++round)
      for (std::size_t k = 0; k < specs.size(); ++k) {
        Spec& s = specs[k];
        if (s.kind == Kind::Linear || !s.separable) continue;
        const MatrixXd others = design(static_cast<int>(k));
        double best = INFINITY, best_h = s.hyper;
        auto sse_at = [&](double h) {
          const Fit f = solve(join_columns(others, columns(s, h, pts)), y);
          return f.ok ? f.sse : INFINITY;
        };
        for (double h : s.grid) {
          const double e = sse_at(h);
          if (e < best) best = e, best_h = h;
        }
        if (s.kind == Kind::Cyclic) {  // golden section within the grid's neighbours
          double lo = best_h / 1.01, hi = best_h * 1.01;
          const double g = (std::sqrt(5.0) - 1) / 2;
          double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
          double f1 = sse_at(x1), f2 = sse_at(x2);
          for (int it = 0; it < 40; ++it) {
            if (f1 < f2) {
              hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = sse_at(x1);
            } else {
              lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = sse_at(x2);
            }
          }
          const double h = 0.5 * (lo + hi);
          if (sse_at(h) < best) best_h = h;
        }
        s.hyper = best_h;
      }
  }

  // The full fit, the noise, and each cause's partial F test; the causes ranked. Returns the
  // fitted model at every point.
  VectorXd test_causes() {
    const MatrixXd full = design(-1);
    const Fit fit = solve(full, y);
    if (!fit.ok) throw std::invalid_argument("ballbar: the diagnosis' least squares is singular");
    res.parameters = static_cast<std::size_t>(full.cols());
    const double dof = static_cast<double>(n) - static_cast<double>(full.cols());
    if (!(dof >= 1)) throw std::invalid_argument("ballbar: more causes than points");
    const double sigma2 = fit.sse / dof;
    res.residual_rms_um = std::sqrt(fit.sse / static_cast<double>(n));
    const MatrixXd cov = sigma2 * (full.transpose() * full).inverse();
    std::size_t tests = 0;
    for (const Spec& s : specs) tests += s.separable ? 1 : 0;
    Index col = base.cols();
    const VectorXd model = full * fit.beta;
    for (std::size_t k = 0; k < specs.size(); ++k) {
      const Spec& s = specs[k];
      BallbarCause c;
      c.id = s.id;
      c.name = s.name;
      c.axis = s.axis;
      c.unit = s.unit;
      c.separable = s.separable;
      c.note = s.note;
      if (s.kind == Kind::Spike) c.detail_name = "width", c.detail_unit = "deg";
      if (s.kind == Kind::Cyclic) c.detail_name = "pitch", c.detail_unit = "mm";
      if (s.id == "servo_mismatch") c.detail_name = "lag", c.detail_unit = "ms";
      if (!s.separable) {
        c.size = kNaN;
        res.causes.push_back(c);
        continue;
      }
      const Index w = s.width();
      const VectorXd b = fit.beta.segment(col, w);
      const MatrixXd cv = cov.block(col, col, w, w);
      const VectorXd part = full.middleCols(col, w) * b;
      c.contribution_um = part.maxCoeff() - part.minCoeff();
      if (s.kind == Kind::Cyclic) {
        c.size = std::hypot(b(0), b(1));
        const Eigen::Vector2d grad =
            c.size > 0 ? Eigen::Vector2d(b(0) / c.size, b(1) / c.size) : Eigen::Vector2d(1, 0);
        c.se = std::sqrt(grad.dot(cv * grad));
        c.detail = s.hyper;
      } else {
        c.size = b(0);
        c.se = std::sqrt(cv(0, 0));
        if (s.kind == Kind::Spike) c.detail = s.hyper;
      }
      if (s.id == "servo_mismatch" && std::isfinite(in.feedrate_mm_min) && in.feedrate_mm_min > 0)
        c.detail = 2 * c.size / (in.feedrate_mm_min / 60);  // Δτ = 2M/v: µm over mm/s is ms
      // The model without this cause.
      MatrixXd reduced(full.rows(), full.cols() - w);
      reduced << full.leftCols(col), full.rightCols(full.cols() - col - w);
      const Fit without = solve(reduced, y);
      const double F = without.ok ? ((without.sse - fit.sse) / static_cast<double>(w)) / sigma2 : 0;
      c.p_value = F > 0 ? fisher_f_sf(F, static_cast<double>(w), dof) : 1.0;
      const double grid = s.kind == Kind::Linear ? 1.0 : static_cast<double>(s.grid.size());
      c.threshold_p = options_.alpha / static_cast<double>(tests) / grid;
      c.significant =
          c.p_value < c.threshold_p && c.contribution_um >= options_.min_contribution_um;
      res.causes.push_back(c);
      col += w;
    }
    std::stable_sort(res.causes.begin(), res.causes.end(),
                     [](const BallbarCause& a, const BallbarCause& b) {
                       if (a.significant != b.significant) return a.significant;
                       if (a.separable != b.separable) return a.separable;
                       return a.contribution_um > b.contribution_um;
                     });
    return model;
  }

  // The fitted model and the residual per run.
  void fitted_and_residuals(const VectorXd& model) {
    std::size_t k = 0;
    for (const BallbarTrace& t : in.traces) {
      std::vector<double> f, e;
      for (std::size_t i = 0; i < t.size(); ++i, ++k) {
        f.push_back(model(static_cast<Index>(k)));
        e.push_back(y(static_cast<Index>(k)) - model(static_cast<Index>(k)));
      }
      res.fitted_um.push_back(f);
      res.residual_um.push_back(e);
    }
  }

  const BallbarDiagnosisInput& in;
  const BallbarDiagnosisOptions& options_;
  const double R;  // ballbar radius, mm
  BallbarDiagnosisResult res;
  std::vector<Pt> pts;  // every run's points in order
  VectorXd y;           // their radius deviations, µm
  std::size_t n = 0;    // number of points
  double step_deg = 0;  // the largest step between neighbouring angles of any run
  MatrixXd base;        // the set-up columns
  std::vector<Spec> specs;
};

}  // namespace

void BallbarDiagnosisOptions::validate() const {
  if (!(alpha > 0 && alpha < 1)) throw std::invalid_argument("--alpha must be in (0, 1)");
  if (!(min_contribution_um >= 0))
    throw std::invalid_argument("--min-contribution must be >= 0 um");
  if (max_harmonic < 1) throw std::invalid_argument("ballbar: max_harmonic must be >= 1");
}

bool BallbarDiagnosisResult::clean() const {
  return std::none_of(causes.begin(), causes.end(),
                      [](const BallbarCause& c) { return c.significant; });
}

BallbarDiagnosis::BallbarDiagnosis(BallbarDiagnosisOptions options) : options_(options) {
  options_.validate();
}

BallbarDiagnosisResult BallbarDiagnosis::run(const BallbarDiagnosisInput& in) const {
  if (in.traces.empty()) throw std::invalid_argument("ballbar: no runs to diagnose");
  if (!(in.radius_mm > 0)) throw std::invalid_argument("ballbar: the radius must be > 0");
  return BallbarDiagnosisPasses(in, options_).run();
}

}  // namespace weilgen
