#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>

#include "effects.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/machine/iso_names.hpp"
#include "weilgen/machine/pdge_basis.hpp"
#include "weilgen/uq/lsq.hpp"

namespace weilgen::gap_detail {

// ---- Model-based effects: higher_order, missing_error, tool_offset ------------------------

// Exact-chain deviation (µm, µrad) at an observation's pose for given errors (base units).
std::array<double, 6> exact(const NumericChain& chain, const std::vector<double>& pose,
                            const std::vector<double>& errors) {
  std::array<double, 6> v = chain.deviation(pose, errors);
  for (std::size_t o = 0; o < 6; ++o) v[o] *= kMeasuredScale[o];
  return v;
}

namespace {

void to_measured(std::array<double, 6>& v) {
  for (std::size_t o = 0; o < 6; ++o) v[o] *= kMeasuredScale[o];
}

// The higher_order refit (Levenberg-Marquardt): at most this many Jacobians; the damping λ on
// equilibrated columns starts here, shrinks ×10 on success down to the floor and grows ×10 on
// failure; it stops when a step gains less than kMinGain of the training SSE.
constexpr int kHigherOrderIterations = 20;
constexpr double kInitialDamping = 1e-4, kMinDamping = 1e-12, kMinGain = 1e-3;
// The start's rank cut (declared units, as Identification's Gauss-Newton): nearly collinear
// PDGE terms (E_XY and E_XX on an R-test, whose axes move together) can cancel in the first-order
// fit at metres each, where their products with the rotations are metres too.
constexpr double kStartRankTolerance = 1e-6;

// θ (the first np entries) fitted to the rows `train` of y through the exact kinematics, from
// the split's linear fit θ0 (all of A's columns; those past np are accepted effects' columns and
// stay as fitted). The linear fit has no part in the model's null space (minimum norm); the
// products of errors make some of those directions visible, and Levenberg-Marquardt (Jacobian of
// the exact chain by forward differences per error) estimates them.
std::vector<double> higher_order_refit(const EffectContext& ctx,
                                       const std::vector<std::size_t>& train,
                                       const VectorXd& theta0, const MatrixXd& A,
                                       const VectorXd& y) {
  const GapData& d = *ctx.data;
  const auto& obs = d.points.observations;
  const ErrorParameterisation& param = *ctx.param;
  const Description& desc = ctx.model->description();
  const std::size_t np = param.size(), ne = ctx.model->num_errors();
  const auto m = static_cast<Index>(train.size());
  std::vector<double> theta = split_theta(theta0, np);
  // The target of the exact chain: y less the accepted effects' columns.
  VectorXd target(m);
  for (Index i = 0; i < m; ++i) {
    const auto r = static_cast<Index>(train[static_cast<std::size_t>(i)]);
    target[i] = y[r] - A.row(r)
                           .tail(A.cols() - static_cast<Index>(np))
                           .dot(theta0.tail(theta0.size() - static_cast<Index>(np)));
  }
  {
    // The linear fit keeps combinations the data barely see (a rank cut of 1e-9 on equilibrated
    // columns), which can be huge where the exact chain is far from linear. Start from its
    // projection on the well-determined directions in declared units (µm, µrad), at zero in
    // the others.
    MatrixXd Al(m, static_cast<Index>(np));
    for (Index i = 0; i < m; ++i)
      Al.row(i) = A.row(static_cast<Index>(train[static_cast<std::size_t>(i)]))
                      .head(static_cast<Index>(np));
    Eigen::HouseholderQR<MatrixXd> qr(Al);
    const MatrixXd R = qr.matrixQR().topRows(std::min(m, Al.cols())).triangularView<Eigen::Upper>();
    // Jacobi, not Eigen 3.4.0's BDCSVD (out-of-bounds read on rank-deficient input: lsq.cpp).
    const Eigen::JacobiSVD<MatrixXd> svd(R, Eigen::ComputeThinV);
    const VectorXd& sv = svd.singularValues();
    Index rank = 0;
    while (rank < sv.size() && sv[rank] > kStartRankTolerance * sv[0]) ++rank;
    const MatrixXd V = svd.matrixV().leftCols(rank);
    const VectorXd t0 = Eigen::Map<const VectorXd>(theta.data(), static_cast<Index>(np));
    const VectorXd t = V * (V.transpose() * t0);
    for (std::size_t p = 0; p < np; ++p) theta[p] = t[static_cast<Index>(p)];
  }
  std::vector<double> err(ne), jac(np);
  // The nominal tool frame of every training pose, computed once for all the chain evaluations
  // there.
  std::vector<Eigen::Matrix4d> nominal(d.points.poses.size());
  {
    std::size_t row = SIZE_MAX;
    for (std::size_t i : train)
      if (obs[i].row != row)
        row = obs[i].row, nominal[row] = ctx.chain->nominal(d.points.poses[row]);
  }
  auto residual = [&](const std::vector<double>& t) {
    VectorXd r(m);
    std::size_t row = SIZE_MAX;
    std::array<double, 6> f{};
    for (Index i = 0; i < m; ++i) {
      const PointObservation& ob = obs[train[static_cast<std::size_t>(i)]];
      if (ob.row != row) {
        row = ob.row;
        param.errors_at(d.points.poses[row].data(), t.data(), err.data());
        f = ctx.chain->deviation(d.points.poses[row], err, nominal[row]);
        to_measured(f);
      }
      r[i] = target[i] - observe(ob, f);
    }
    return r;
  };
  VectorXd r = residual(theta);
  std::vector<std::array<double, 6>> g(ne);  // ∂deviation/∂error at one pose (µm per base unit)
  // Forward differences over 1 declared unit of every error some parameter moves (half the
  // chain evaluations of central ones): their error, h/2 of a second derivative, slows the
  // steps, not the fit, whose residual is exact.
  std::vector<double> steps(ne, 0.0);
  for (const IdentParameter& ip : param.parameters()) {
    const auto k = static_cast<std::size_t>(ip.error);
    steps[k] = desc.errors[k].to_base;
  }
  std::array<double, 6> f0{};
  std::vector<std::array<double, 6>> stepped;
  double lambda = kInitialDamping;
  for (int it = 0; it < kHigherOrderIterations; ++it) {
    MatrixXd J(m, static_cast<Index>(np));
    std::size_t row = SIZE_MAX;
    for (Index i = 0; i < m; ++i) {
      const PointObservation& ob = obs[train[static_cast<std::size_t>(i)]];
      if (ob.row != row) {
        row = ob.row;
        const std::vector<double>& q = d.points.poses[row];
        param.errors_at(q.data(), theta.data(), err.data());
        param.derivatives(q.data(), jac.data());
        ctx.chain->deviation_steps(q, err, steps, nominal[row], f0, stepped);
        to_measured(f0);
        for (std::size_t k = 0; k < ne; ++k) {
          if (steps[k] == 0) continue;
          to_measured(stepped[k]);
          for (std::size_t o = 0; o < 6; ++o) g[k][o] = (stepped[k][o] - f0[o]) / steps[k];
        }
      }
      for (std::size_t p = 0; p < np; ++p)
        J(i, static_cast<Index>(p)) =
            observe(ob, g[static_cast<std::size_t>(param.parameters()[p].error)]) * jac[p];
    }
    // Levenberg-Marquardt on the small triangle of J, columns equilibrated (the scaling commutes
    // with Q): weakly visible directions enter as far as the damping lets them, and λ adapts.
    Eigen::HouseholderQR<MatrixXd> qr(J);
    const Index k = std::min(m, J.cols());
    const MatrixXd R = qr.matrixQR().topRows(k).triangularView<Eigen::Upper>();
    const VectorXd qtr = (qr.householderQ().transpose() * r).head(k);
    const EquilibratedSvd svd(R, 0, /*full_v=*/false);
    const VectorXd& scale = svd.scale();
    const VectorXd b = svd.U().transpose() * qtr;
    const VectorXd sv = svd.sigma().head(b.size());
    const double before = r.squaredNorm();
    std::vector<double> trial;
    bool better = false;
    for (int tries = 0; tries < 12 && !better; ++tries) {
      VectorXd z = VectorXd::Zero(sv.size());
      for (Index j = 0; j < sv.size(); ++j) z[j] = sv[j] * b[j] / (sv[j] * sv[j] + lambda);
      const VectorXd step = (svd.V().leftCols(sv.size()) * z).cwiseQuotient(scale);
      trial = theta;
      for (std::size_t p = 0; p < np; ++p) trial[p] += step[static_cast<Index>(p)];
      VectorXd rt = residual(trial);
      if (rt.squaredNorm() < before)
        r = std::move(rt), better = true, lambda = std::max(lambda / 10, kMinDamping);
      else
        lambda *= 10;
    }
    if (!better) break;
    theta = std::move(trial);
    if (r.squaredNorm() > (1 - kMinGain) * before) break;
  }
  return theta;
}

}  // namespace

void add_higher_order(const EffectContext& ctx, std::vector<Candidate>& out) {
  Candidate c;
  c.name = "higher_order";
  c.variants.push_back({"products of errors (exact kinematics)", {}, true});
  c.refit = [ctx](const std::vector<std::size_t>& train, const VectorXd& theta, const MatrixXd& A,
                  const VectorXd& y) { return higher_order_refit(ctx, train, theta, A, y); };
  const GapData& d = *ctx.data;
  c.columns = [&d, ctx](const Variant&, const std::vector<double>& theta) {
    const auto& obs = d.points.observations;
    MatrixXd E(static_cast<Index>(obs.size()), 1);
    ModelData md(*ctx.model);
    std::vector<double> err(ctx.model->num_errors());
    std::size_t row = SIZE_MAX;
    std::array<double, 6> nonlinear{};
    for (std::size_t i = 0; i < obs.size(); ++i) {
      if (obs[i].row != row) {
        row = obs[i].row;
        const std::vector<double>& q = d.points.poses[row];
        ctx.param->errors_at(q.data(), theta.data(), err.data());
        const std::array<double, 6> full = exact(*ctx.chain, q, err);
        const std::array<double, 6> lin =
            predict_deviation(*ctx.model, md, *ctx.param, theta, q.data());
        for (std::size_t o = 0; o < 6; ++o) nonlinear[o] = full[o] - lin[o];
      }
      E(static_cast<Index>(i), 0) = observe(obs[i], nonlinear);
    }
    return E;
  };
  c.describe = [](const Variant&, const VectorXd& coef, EffectFit& fit) {
    fit.params["scale"] = coef[0];
    fit.summary = "second- and higher-order products of the identified errors (scale " +
                  format_short(coef[0], 3) +
                  " of the exact kinematics' nonlinear part; regenerate at "
                  "algebra order 2)";
  };
  out.push_back(std::move(c));
}

namespace {

// The basis a PDGE missing from the machine file would get on joint `j`: the one the run gives
// the joint's other PDGEs (what --pdge, the machine's `pdge_basis:` or the default chose; the
// most common if they differ), else that of the PDGEs on joints of the same type, else the
// default (poly:3, or fourier:2 over a turn). The truth's missing error follows the run's
// choice, not the default: a Legendre cubic of C seen through fourier:2 is another shape.
Basis missing_error_basis(const Description& desc, const ErrorParameterisation& param,
                          const Joint& j) {
  const bool rotary = j.type == JointType::Revolute;
  std::map<std::string, std::pair<int, Basis>> same_joint, same_type;
  for (std::size_t k = 0; k < desc.errors.size(); ++k) {
    const std::optional<Basis>& b = param.basis_of(k);
    if (!b || desc.errors[k].body < 0) continue;
    const Joint& jk = desc.bodies[static_cast<std::size_t>(desc.errors[k].body)].joint;
    if (jk.coordinate == j.coordinate) {
      ++same_joint.try_emplace(b->name(), 0, *b).first->second.first;
    }
    if ((jk.type == JointType::Revolute) == rotary && j.max > j.min) {
      BasisSpec spec;  // the kind and order, placed on this joint (a Fourier basis over a turn)
      spec.kind = b->kind;
      spec.order = b->order;
      ++same_type.try_emplace(spec.str(), 0, basis_on_joint(spec, j)).first->second.first;
    }
  }
  for (const auto* m : {&same_joint, &same_type}) {
    const Basis* best = nullptr;
    int most = 0;
    for (const auto& [name, nb] : *m)
      if (nb.first > most) most = nb.first, best = &nb.second;
    if (best) return *best;
  }
  return basis_on_joint(parse_basis(default_pdge_basis(j)), j);
}

}  // namespace

void add_missing_error(const EffectContext& ctx, std::vector<Candidate>& out) {
  const Description& desc = ctx.model->description();
  const GapData& d = *ctx.data;
  struct Missing {
    std::string name, coordinate;
    bool pdge;
    Basis basis;    // the PDGE's basis on its joint (missing_error_basis)
    MatrixXd unit;  // per observation: ∂output/∂error (µm or µrad per declared unit)
  };
  auto missing = std::make_shared<std::vector<Missing>>();
  const std::vector<int> axes = desc.axes();
  // The candidate errors (body, name) in a fixed order; then each one's column in parallel.
  std::vector<std::pair<std::size_t, std::string>> names;
  for (std::size_t b = 0; b < desc.bodies.size(); ++b) {
    const Joint& j = desc.bodies[b].joint;
    if (j.type == JointType::Fixed || j.link || !iso_not_applicable(j).empty()) continue;
    std::vector<std::string> ns = iso_motion_errors(j);
    for (const char* k : {"X", "Y", "Z", "A", "B", "C"})  // squareness and location errors
      ns.push_back(std::string("E_") + k + "0" + j.coordinate);
    std::sort(ns.begin(), ns.end());
    ns.erase(std::unique(ns.begin(), ns.end()), ns.end());
    for (const std::string& n : ns)
      if (desc.error_index(n) < 0 && match_iso_name(j, n).status == IsoMatch::Status::Fits)
        names.emplace_back(b, n);
  }
  std::vector<std::optional<Missing>> found(names.size());
  parallel_blocks(
      names.size(), 1, ctx.threads, [&](std::size_t t, std::size_t, std::size_t, unsigned) {
        const std::size_t b = names[t].first;
        const std::string& n = names[t].second;
        const Joint& j = desc.bodies[b].joint;
        const IsoMatch m = match_iso_name(j, n);
        Description aug = desc;
        ErrorDef e;
        e.name = e.iso = n;
        e.effect = m.error.effect;
        e.direction = m.error.direction;
        e.group = m.error.group;
        e.placement = m.error.placement;
        e.dependence = m.error.dependence;
        e.unit = m.error.unit;
        e.to_base = e.effect == ErrorEffect::Rotation ? 1e-6 : 1e-3;  // µrad, µm
        e.body = static_cast<int>(b);
        aug.errors.push_back(e);
        aug.bodies[b].errors.push_back(static_cast<int>(aug.errors.size() - 1));
        NumericChain chain(aug);
        chain.set_parameters(ctx.model->parameters());
        const auto& obs = d.points.observations;
        const bool pdge = e.dependence == Dependence::PDGE && j.max > j.min;
        Missing mi{n, j.coordinate, pdge, pdge ? missing_error_basis(desc, *ctx.param, j) : Basis{},
                   MatrixXd(static_cast<Index>(obs.size()), 1)};
        std::vector<double> err(aug.errors.size(), 0.0);
        std::size_t row = SIZE_MAX;
        std::array<double, 6> g{};
        for (std::size_t i = 0; i < obs.size(); ++i) {
          if (obs[i].row != row) {
            row = obs[i].row;
            err.back() = e.to_base;  // 1 µm or µrad: central differences, third order ~1e-12
            const auto p = exact(chain, d.points.poses[row], err);
            err.back() = -e.to_base;
            const auto m2 = exact(chain, d.points.poses[row], err);
            for (std::size_t o = 0; o < 6; ++o) g[o] = (p[o] - m2[o]) / 2;
          }
          mi.unit(static_cast<Index>(i), 0) = observe(obs[i], g);
        }
        if (mi.unit.norm() > 0) found[t] = std::move(mi);
      });
  for (auto& f : found)
    if (f) missing->push_back(std::move(*f));
  if (missing->empty()) return;
  Candidate c;
  c.name = "missing_error";
  for (std::size_t k = 0; k < missing->size(); ++k)
    c.variants.push_back({(*missing)[k].name, {static_cast<double>(k)}});
  // The coordinate of each observation for a PDGE's basis (missing_error_basis).
  c.columns = [&d, missing, axes, &desc](const Variant& v, const std::vector<double>&) {
    const Missing& mi = (*missing)[static_cast<std::size_t>(v.hyper[0])];
    if (!mi.pdge) return MatrixXd(mi.unit);
    std::size_t a = 0;
    for (std::size_t i = 0; i < axes.size(); ++i)
      if (desc.bodies[static_cast<std::size_t>(axes[i])].joint.coordinate == mi.coordinate) a = i;
    const auto& obs = d.points.observations;
    const auto terms = static_cast<Index>(mi.basis.size());
    MatrixXd E(static_cast<Index>(obs.size()), terms);
    std::vector<double> f(mi.basis.size());
    for (std::size_t i = 0; i < obs.size(); ++i) {
      mi.basis.evaluate(d.points.poses[obs[i].row][a], f.data());
      for (Index t = 0; t < terms; ++t)
        E(static_cast<Index>(i), t) =
            mi.unit(static_cast<Index>(i), 0) * f[static_cast<std::size_t>(t)];
    }
    return E;
  };
  c.determined_part = true;
  c.describe = [missing, &d, axes, &desc](const Variant& v, const VectorXd& coef, EffectFit& fit) {
    const Missing& mi = (*missing)[static_cast<std::size_t>(v.hyper[0])];
    // Its region: along its axis' travel for a PDGE, all the data for a constant; the diagnosis
    // puts it in the output where it removed the most.
    GapRegion r;
    r.by = "output";
    if (mi.pdge) {
      r.by = mi.coordinate;
      r.from = mi.basis.a, r.to = mi.basis.b;
    }
    std::array<double, kObservationKinds> size{};  // the output it moves most, until then
    for (std::size_t i = 0; i < d.points.observations.size(); ++i)
      size[static_cast<std::size_t>(d.points.observations[i].output)] +=
          std::abs(mi.unit(static_cast<Index>(i), 0));
    r.output = observation_name(
        static_cast<std::size_t>(std::max_element(size.begin(), size.end()) - size.begin()));
    fit.region = r;
    const bool rot =
        mi.name.size() > 2 && (mi.name[2] == 'A' || mi.name[2] == 'B' || mi.name[2] == 'C');
    const char* unit = rot ? "µrad" : "µm";
    // Terms the model's own errors absorb are left out of coef (determined_part): their
    // coefficients trade against those errors and say nothing about this one.
    const std::string absorbed = fit.terms_absorbed
                                     ? std::to_string(fit.terms_absorbed) + " of " +
                                           std::to_string(fit.terms) +
                                           " shape terms absorbed by the model's errors, left out; "
                                     : "";
    if (fit.terms && fit.terms_absorbed == fit.terms) {
      fit.summary = mi.name + (mi.pdge ? "(" + mi.coordinate + ")" : "") +
                    ": size not determined (the model's errors absorb it; not in the machine "
                    "file)";
    } else if (!mi.pdge) {
      fit.params[mi.name] = coef[0];
      fit.summary =
          mi.name + " = " + format_short(coef[0], 3) + " " + unit + " (not in the machine file)";
    } else {
      // Over the positions measured, not the whole travel: the data say nothing beyond them.
      std::size_t a = 0;
      for (std::size_t i = 0; i < axes.size(); ++i)
        if (desc.bodies[static_cast<std::size_t>(axes[i])].joint.coordinate == mi.coordinate) a = i;
      double lo = INFINITY, hi = -INFINITY;
      for (const auto& o : d.points.observations)
        lo = std::min(lo, d.points.poses[o.row][a]), hi = std::max(hi, d.points.poses[o.row][a]);
      double peak = 0;
      for (int k = 0; k <= 40; ++k)
        peak = std::max(peak, std::abs(mi.basis.value(coef.data(), lo + (hi - lo) * k / 40.0)));
      fit.params[mi.name + "_peak"] = peak;
      fit.summary = mi.name + "(" + mi.coordinate + ") up to " + format_short(peak, 3) + " " +
                    unit + " over the measured " + mi.coordinate + " " + format_short(lo, 4) +
                    " .. " + format_short(hi, 4) +
                    (a < d.axis_units.size() ? " " + d.axis_units[a] : "") + " (" +
                    mi.basis.name() + "; " + absorbed + "not in the machine file)";
    }
  };
  out.push_back(std::move(c));
}

// Larger than any tool (mm): a fitted tool offset beyond it is not a set-up error.
constexpr double kMaxToolOffsetMm = 1000;

void add_tool_offset(const EffectContext& ctx, std::vector<Candidate>& out) {
  const Description& desc = ctx.model->description();
  int tool = -1;
  for (std::size_t p = 0; p < desc.parameters.size(); ++p)
    if (lower(desc.parameters[p].name).find("tool") != std::string::npos)
      tool = static_cast<int>(p);
  if (tool < 0) return;
  Candidate c;
  c.name = "tool_offset";
  const std::string pname = desc.parameters[static_cast<std::size_t>(tool)].name;
  c.variants.push_back({pname, {static_cast<double>(tool)}, true});
  c.variants.back().theta_iterations = 1;
  const GapData& d = *ctx.data;
  const double base = ctx.model->parameters()[static_cast<std::size_t>(tool)];
  c.columns = [&d, ctx, tool, base](const Variant&, const std::vector<double>& theta) {
    // ∂deviation/∂tool length at the identified errors (µm per mm), by central differences of
    // the exact chain over ±10 mm.
    std::vector<double> params = ctx.model->parameters();
    NumericChain plus(ctx.model->description()), minus(ctx.model->description());
    params[static_cast<std::size_t>(tool)] = base + 10;
    plus.set_parameters(params);
    params[static_cast<std::size_t>(tool)] = base - 10;
    minus.set_parameters(params);
    const auto& obs = d.points.observations;
    MatrixXd E(static_cast<Index>(obs.size()), 1);
    std::vector<double> err(ctx.model->num_errors());
    std::size_t row = SIZE_MAX;
    std::array<double, 6> g{};
    for (std::size_t i = 0; i < obs.size(); ++i) {
      if (obs[i].row != row) {
        row = obs[i].row;
        const std::vector<double>& q = d.points.poses[row];
        ctx.param->errors_at(q.data(), theta.data(), err.data());
        const auto p = exact(plus, q, err), m = exact(minus, q, err);
        for (std::size_t o = 0; o < 6; ++o) g[o] = (p[o] - m[o]) / 20;
      }
      E(static_cast<Index>(i), 0) = observe(obs[i], g);
    }
    return E;
  };
  c.describe = [pname, base](const Variant&, const VectorXd& coef, EffectFit& fit) {
    fit.params["offset_mm"] = coef[0];
    fit.params[pname + "_mm"] = base + coef[0];
    fit.summary = "tool offset " + format_short(coef[0], 3) + " mm (" + pname + " " +
                  format_short(base, 4) + " -> " + format_short(base + coef[0], 4) + " mm)";
    // The column is nearly in the model's span on a machine whose rotations are only its small
    // angular errors: then a tiny remainder, scaled up hundreds of metres, fits whatever shape
    // is left (a step). No tool set-up error is that large.
    if (!(std::abs(coef[0]) <= kMaxToolOffsetMm)) {
      fit.distinguishable = false;
      fit.indistinct_reason = "its size (" + format_short(coef[0], 3) +
                              " mm) is no tool's: a remainder of " +
                              "the column outside the model's errors imitates the gap";
    }
  };
  out.push_back(std::move(c));
}

}  // namespace weilgen::gap_detail
