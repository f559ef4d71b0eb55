#include "weilgen/uq/optimal_design.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "weilgen/base/parallel.hpp"

namespace weilgen {

using Eigen::MatrixXd;
using Eigen::VectorXd;

DesignCriterion parse_design_criterion(const std::string& text) {
  if (text == "D" || text == "d") return DesignCriterion::D;
  if (text == "A" || text == "a") return DesignCriterion::A;
  if (text == "E" || text == "e") return DesignCriterion::E;
  if (text == "I" || text == "i") return DesignCriterion::I;
  throw std::invalid_argument("--criterion: '" + text + "' (expected D, A, E or I)");
}

const char* design_criterion_name(DesignCriterion c) {
  switch (c) {
    case DesignCriterion::D:
      return "D";
    case DesignCriterion::A:
      return "A";
    case DesignCriterion::E:
      return "E";
    case DesignCriterion::I:
      return "I";
  }
  return "?";
}

void ExchangeOptions::validate() const {
  if (restarts < 1) throw std::invalid_argument("--restarts must be at least 1");
  if (max_passes < 1) throw std::invalid_argument("exchange: max_passes must be at least 1");
}

ExchangeDesign::ExchangeDesign(ExchangeOptions options) : options_(options) { options_.validate(); }

double design_criterion(const MatrixXd& M, DesignCriterion c, const MatrixXd& W) {
  const Eigen::SelfAdjointEigenSolver<MatrixXd> es(M, Eigen::EigenvaluesOnly);
  const VectorXd& l = es.eigenvalues();
  const double inf = std::numeric_limits<double>::infinity();
  const double tiny = 1e-13 * std::max(1.0, l.cwiseAbs().maxCoeff());
  const bool singular = l.size() == 0 || l[0] <= tiny;
  switch (c) {
    case DesignCriterion::D: {
      if (singular) return -inf;
      double s = 0;
      for (Eigen::Index i = 0; i < l.size(); ++i) s += std::log(l[i]);
      return s;
    }
    case DesignCriterion::E:
      return singular ? 0.0 : l[0];
    case DesignCriterion::A:
    case DesignCriterion::I: {
      if (singular) return inf;
      const MatrixXd inv = M.ldlt().solve(MatrixXd::Identity(M.rows(), M.cols()));
      return c == DesignCriterion::A ? inv.trace() : (W * inv).trace();
    }
  }
  return 0;
}

double ContinuousBound::for_units(std::size_t n, DesignCriterion c, std::size_t r) const {
  const double nn = static_cast<double>(n);
  if (c == DesignCriterion::D) return bound + static_cast<double>(r) * std::log(nn);
  if (c == DesignCriterion::E) return std::numeric_limits<double>::quiet_NaN();
  return bound / nn;
}

ContinuousBound continuous_design(const DesignProblem& p, DesignCriterion c, std::size_t iterations,
                                  unsigned threads) {
  ContinuousBound out;
  const std::size_t n = p.units.size();
  if (n == 0) throw std::invalid_argument("continuous design: no candidate units");
  const Eigen::Index r = p.units.front().cols();
  if (c == DesignCriterion::E) {
    out.bound = out.value = std::numeric_limits<double>::quiet_NaN();
    return out;
  }
  const MatrixXd W = c == DesignCriterion::A ? MatrixXd::Identity(r, r) : p.weight;
  const bool d_opt = c == DesignCriterion::D;
  std::vector<double> w(n, 1.0 / static_cast<double>(n)), d(n);
  constexpr std::size_t kBlock = 256;
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  for (std::size_t it = 0;; ++it) {
    // M(ξ) in fixed blocks, summed in block order: the same for any thread count.
    std::vector<MatrixXd> part(blocks, MatrixXd::Zero(r, r));
    parallel_blocks(n, kBlock, threads,
                    [&](std::size_t b, std::size_t lo, std::size_t hi, unsigned) {
                      for (std::size_t j = lo; j < hi; ++j)
                        part[b].noalias() += w[j] * p.units[j].transpose() * p.units[j];
                    });
    MatrixXd M = MatrixXd::Zero(r, r);
    for (const MatrixXd& m : part) M += m;
    const Eigen::LDLT<MatrixXd> ldlt(M);
    const MatrixXd Minv = ldlt.solve(MatrixXd::Identity(r, r));
    const MatrixXd K = d_opt ? Minv : MatrixXd(Minv * W * Minv);
    parallel_blocks(n, kBlock, threads, [&](std::size_t, std::size_t lo, std::size_t hi, unsigned) {
      for (std::size_t j = lo; j < hi; ++j)
        d[j] = (p.units[j] * K * p.units[j].transpose()).trace();
    });
    const double dmax = *std::max_element(d.begin(), d.end());
    if (d_opt) {
      out.value = ldlt.vectorD().array().max(1e-300).log().sum();
      out.bound = out.value + dmax - static_cast<double>(r);
    } else {
      out.value = (W * Minv).trace();
      out.bound = 2 * out.value - dmax;
    }
    out.iterations = it;
    if (it >= iterations) break;
    double total = 0;
    for (std::size_t j = 0; j < n; ++j) {
      w[j] *= d_opt ? d[j] / static_cast<double>(r) : std::sqrt(std::max(0.0, d[j]) / out.value);
      total += w[j];
    }
    for (double& x : w) x /= total;
  }
  out.weights = w;
  return out;
}

ObservabilityIndices observability_indices(const VectorXd& s, std::size_t m) {
  ObservabilityIndices o;
  const Eigen::Index L = s.size();
  if (L == 0 || m == 0) return o;
  double log_prod = 0, inv_sum = 0;
  for (Eigen::Index i = 0; i < L; ++i) {
    if (!(s[i] > 0)) return o;  // a zero singular value: nothing is observable in that direction
    log_prod += std::log(s[i]);
    inv_sum += 1 / s[i];
  }
  const double smax = s.maxCoeff(), smin = s.minCoeff();
  o.o1 = std::exp(log_prod / static_cast<double>(L)) / std::sqrt(static_cast<double>(m));
  o.o2 = smin / smax;
  o.o3 = smin;
  o.o4 = smin * smin / smax;
  o.o5 = 1 / inv_sum;
  return o;
}

namespace {

constexpr std::size_t kNone = static_cast<std::size_t>(-1);
constexpr std::size_t kShortlist = 8;  // E: exact λ_min for this many swaps per unit

// splitmix64: one independent stream per restart from the seed.
struct Rng {
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::size_t below(std::size_t n) { return static_cast<std::size_t>(next() % n); }
};

// A move: remove `out` and/or add `in`.
struct Move {
  std::size_t out = kNone, in = kNone;
};

// The state of one restart: the selection, M (with the ridge), M⁻¹, K = M⁻¹WM⁻¹ and the caches
// G_j = Z_j M⁻¹ Z_jᵀ, H_j = Z_j K Z_jᵀ of every candidate.
class State {
 public:
  State(const DesignProblem& p, DesignCriterion c, double ridge)
      : p_(p), c_(c), ridge_(ridge), r_(p.units.front().cols()), in_(p.units.size(), 0) {
    l_ = c_ == DesignCriterion::A || c_ == DesignCriterion::I;
    if (l_) W_ = c_ == DesignCriterion::A ? MatrixXd::Identity(r_, r_) : p.weight;
  }

  const std::vector<std::size_t>& selected() const { return sel_; }
  bool in(std::size_t j) const { return in_[j] != 0; }
  double cost() const { return cost_; }
  double log_det() const { return logdet_; }
  // The value to minimise.
  double value() const {
    if (c_ == DesignCriterion::D) return -logdet_;
    if (l_) return trace_;
    return -lambda_min_;
  }

  void set(std::vector<std::size_t> sel) {
    std::fill(in_.begin(), in_.end(), 0);
    for (std::size_t j : sel) in_[j] = 1;
    sel_ = std::move(sel);
    refresh();
  }

  // Recomputes M, its inverse and every cache from the selection (after many rank updates, and
  // whenever the selection was set).
  void refresh() {
    M_ = ridge_ * MatrixXd::Identity(r_, r_);
    cost_ = 0;
    for (std::size_t j : sel_) {
      M_.noalias() += p_.units[j].transpose() * p_.units[j];
      if (!p_.cost.empty()) cost_ += p_.cost[j];
    }
    const Eigen::LLT<MatrixXd> llt(M_);
    Minv_ = llt.solve(MatrixXd::Identity(r_, r_));
    logdet_ = 2 * llt.matrixLLT().diagonal().array().log().sum();
    if (l_) {
      K_ = Minv_ * W_ * Minv_;
      trace_ = (W_ * Minv_).trace();
    }
    lambda_min_ = min_eigen(M_);
    // Near the ridge, M⁻¹ holds 1/ε in the unseen directions and rank updates lose the digits
    // that matter: every move is then followed by a full refresh.
    fragile_ = lambda_min_ < 100 * ridge_;
    const std::size_t n = p_.units.size();
    G_.resize(n);
    if (l_) H_.resize(n);
    for (std::size_t j = 0; j < n; ++j) {
      const MatrixXd& Z = p_.units[j];
      G_[j] = Z * Minv_ * Z.transpose();
      if (l_) H_[j] = Z * K_ * Z.transpose();
    }
    updates_ = 0;
  }

  // The value after the move (to minimise), and the D value (−log det) for the E shortlist.
  struct Eval {
    double value = std::numeric_limits<double>::infinity();
    double d_value = std::numeric_limits<double>::infinity();
  };
  // `Pi` = M⁻¹ Z_outᵀ and `Ki` = K Z_outᵀ for the unit going out (empty without one).
  Eval evaluate(const Move& mv, const MatrixXd& Pi, const MatrixXd& Ki, bool exact_e) const {
    const Blocks& b = blocks(mv, Pi, Ki, false);
    Eval e;
    lu_.compute(b.S);
    const Eigen::PartialPivLU<MatrixXd>& lu = lu_;
    const double det = lu.determinant() * (b.k_out % 2 ? -1.0 : 1.0);
    if (!(det > 0)) return e;  // M would not stay positive definite (rounding)
    const double new_logdet = logdet_ + std::log(det);
    e.d_value = -new_logdet;
    if (c_ == DesignCriterion::D) {
      e.value = e.d_value;
    } else if (l_) {
      e.value = trace_ - lu.solve(b.H).trace();
    } else if (exact_e) {
      MatrixXd M = M_;
      if (mv.in != kNone) M.noalias() += p_.units[mv.in].transpose() * p_.units[mv.in];
      if (mv.out != kNone) M.noalias() -= p_.units[mv.out].transpose() * p_.units[mv.out];
      e.value = -min_eigen(M);
    }
    return e;
  }

  void apply(const Move& mv) {
    const MatrixXd Pi =
        mv.out == kNone ? MatrixXd() : MatrixXd(Minv_ * p_.units[mv.out].transpose());
    const MatrixXd Ki =
        mv.out == kNone || !l_ ? MatrixXd() : MatrixXd(K_ * p_.units[mv.out].transpose());
    const Blocks b = blocks(mv, Pi, Ki, true);
    const Eigen::PartialPivLU<MatrixXd> lu(b.S);
    const MatrixXd E = lu.inverse();
    const MatrixXd P = Minv_ * b.U;  // r × k
    logdet_ += std::log(lu.determinant() * (b.k_out % 2 ? -1.0 : 1.0));
    MatrixXd T, PWP;
    if (l_) {
      T = Minv_ * W_ * P;
      PWP = P.transpose() * W_ * P;
    }
    Minv_ -= P * E * P.transpose();
    Minv_ = (Minv_ + Minv_.transpose()) / 2;
    M_.noalias() += b.U * b.C.asDiagonal() * b.U.transpose();
    if (l_) {
      K_ = Minv_ * W_ * Minv_;
      trace_ = (W_ * Minv_).trace();
    }
    if (mv.out != kNone) {
      in_[mv.out] = 0;
      sel_.erase(std::find(sel_.begin(), sel_.end(), mv.out));
      if (!p_.cost.empty()) cost_ -= p_.cost[mv.out];
    }
    if (mv.in != kNone) {
      in_[mv.in] = 1;
      sel_.push_back(mv.in);
      if (!p_.cost.empty()) cost_ += p_.cost[mv.in];
    }
    if (fragile_ || ++updates_ >= 32) {
      refresh();
      return;
    }
    if (c_ == DesignCriterion::E) lambda_min_ = min_eigen(M_);
    MatrixXd a, aE, bb;
    const MatrixXd EPWPE = l_ ? MatrixXd(E * PWP * E) : MatrixXd();
    for (std::size_t j = 0; j < p_.units.size(); ++j) {
      a.noalias() = p_.units[j].lazyProduct(P);
      aE.noalias() = a.lazyProduct(E);
      G_[j].noalias() -= aE.lazyProduct(a.transpose());
      if (l_) {
        bb.noalias() = p_.units[j].lazyProduct(T);
        H_[j].noalias() -= bb.lazyProduct(aE.transpose());
        H_[j].noalias() -= aE.lazyProduct(bb.transpose());
        H_[j].noalias() += a.lazyProduct(EPWPE).lazyProduct(a.transpose());
      }
    }
  }

  MatrixXd minv_times(std::size_t j) const { return Minv_ * p_.units[j].transpose(); }
  MatrixXd k_times(std::size_t j) const {
    return l_ ? MatrixXd(K_ * p_.units[j].transpose()) : MatrixXd();
  }

 private:
  struct Blocks {
    MatrixXd U;  // r × k: [Z_inᵀ, Z_outᵀ]
    VectorXd C;  // +1 for the rows coming in, −1 for those going out
    MatrixXd S;  // C + Uᵀ M⁻¹ U (C is its own inverse)
    MatrixXd H;  // Uᵀ K U
    Eigen::Index k_out = 0;
  };

  // The blocks of a move; `with_u` also U (for apply). Reuses the state's workspace.
  const Blocks& blocks(const Move& mv, const MatrixXd& Pi, const MatrixXd& Ki, bool with_u) const {
    Blocks& b = work_;
    const Eigen::Index ki = mv.in == kNone ? 0 : p_.units[mv.in].rows();
    const Eigen::Index ko = mv.out == kNone ? 0 : p_.units[mv.out].rows();
    const Eigen::Index k = ki + ko;
    b.k_out = ko;
    if (with_u) b.U.resize(r_, k);
    b.C.resize(k);
    b.S.resize(k, k);
    if (ki) {
      if (with_u) b.U.leftCols(ki) = p_.units[mv.in].transpose();
      b.C.head(ki).setOnes();
      b.S.topLeftCorner(ki, ki) = G_[mv.in];
    }
    if (ko) {
      if (with_u) b.U.rightCols(ko) = p_.units[mv.out].transpose();
      b.C.tail(ko).setConstant(-1);
      b.S.bottomRightCorner(ko, ko) = G_[mv.out];
    }
    if (ki && ko) {
      b.S.topRightCorner(ki, ko).noalias() = p_.units[mv.in].lazyProduct(Pi);
      b.S.bottomLeftCorner(ko, ki) = b.S.topRightCorner(ki, ko).transpose();
    }
    b.S.diagonal() += b.C;
    if (l_) {
      b.H.resize(k, k);
      if (ki) b.H.topLeftCorner(ki, ki) = H_[mv.in];
      if (ko) b.H.bottomRightCorner(ko, ko) = H_[mv.out];
      if (ki && ko) {
        b.H.topRightCorner(ki, ko).noalias() = p_.units[mv.in].lazyProduct(Ki);
        b.H.bottomLeftCorner(ko, ki) = b.H.topRightCorner(ki, ko).transpose();
      }
    }
    return b;
  }

  static double min_eigen(const MatrixXd& M) {
    return Eigen::SelfAdjointEigenSolver<MatrixXd>(M, Eigen::EigenvaluesOnly).eigenvalues()[0];
  }

  const DesignProblem& p_;
  DesignCriterion c_;
  double ridge_;
  Eigen::Index r_;
  bool l_ = false;
  MatrixXd W_, M_, Minv_, K_;
  std::vector<MatrixXd> G_, H_;
  std::vector<char> in_;
  std::vector<std::size_t> sel_;
  mutable Blocks work_;
  mutable Eigen::PartialPivLU<MatrixXd> lu_;
  double logdet_ = 0, trace_ = 0, lambda_min_ = 0, cost_ = 0;
  int updates_ = 0;
  bool fragile_ = true;
};

bool improves(double candidate, double current) {
  return candidate < current - 1e-10 * std::max(1.0, std::abs(current));
}

struct RestartResult {
  std::vector<std::size_t> selected;
  double value = 0;
  std::size_t passes = 0, exchanges = 0;
};

class Restart {
 public:
  Restart(const DesignProblem& p, const ExchangeOptions& o, double ridge, std::size_t index)
      : p_(p),
        o_(o),
        s_(p, o.criterion, ridge),
        index_(index),
        rng_{o.seed * 0x2545F4914F6CDD1Dull + index} {
    forced_.assign(p.units.size(), 0);
    for (std::size_t f : p.forced) forced_[f] = 1;
  }

  RestartResult run() {
    const bool budget = !p_.cost.empty();
    s_.set(p_.forced);
    if (index_ == 0 || budget)
      greedy();
    else
      random_start();
    RestartResult r;
    for (; r.passes < o_.max_passes;) {
      ++r.passes;
      const std::size_t done = sweep();
      r.exchanges += done;
      if (budget) r.exchanges += fill();
      if (done == 0) break;
    }
    r.selected = s_.selected();
    std::sort(r.selected.begin(), r.selected.end());
    r.value = s_.value();
    return r;
  }

 private:
  bool affordable(std::size_t j, double freed = 0) const {
    return p_.cost.empty() || s_.cost() - freed + p_.cost[j] <= p_.budget * (1 + 1e-12);
  }

  // Additions by the best gain (count mode: of log det, Wynn's sequential design; budget mode: of
  // the criterion per cost, a random one of the best three on restarts after the first).
  void greedy() {
    const bool budget = !p_.cost.empty();
    const MatrixXd none;
    for (;;) {
      if (!budget && s_.selected().size() >= o_.size) return;
      std::vector<std::pair<double, std::size_t>> gains;
      const double now_d = -s_.log_det(), now = s_.value();
      for (std::size_t j = 0; j < p_.units.size(); ++j) {
        if (s_.in(j) || !affordable(j)) continue;
        const State::Eval e = s_.evaluate({kNone, j}, none, none, false);
        const double gain =
            o_.criterion == DesignCriterion::E || !budget ? now_d - e.d_value : now - e.value;
        if (!(gain > 0)) continue;
        gains.emplace_back(budget ? gain / std::max(p_.cost[j], 1e-300) : gain, j);
      }
      if (gains.empty()) return;
      std::stable_sort(gains.begin(), gains.end(),
                       [](const auto& a, const auto& b) { return a.first > b.first; });
      const std::size_t pick =
          budget && index_ > 0 ? rng_.below(std::min<std::size_t>(3, gains.size())) : 0;
      s_.apply({kNone, gains[pick].second});
    }
  }

  void random_start() {
    std::vector<std::size_t> pool;
    for (std::size_t j = 0; j < p_.units.size(); ++j)
      if (!forced_[j]) pool.push_back(j);
    std::vector<std::size_t> sel = p_.forced;
    while (sel.size() < o_.size) {
      const std::size_t k = rng_.below(pool.size());
      sel.push_back(pool[k]);
      pool[k] = pool.back();
      pool.pop_back();
    }
    s_.set(sel);
  }

  // Additions while the budget allows one that improves the criterion.
  std::size_t fill() {
    std::size_t added = 0;
    const MatrixXd none;
    for (;;) {
      std::size_t best = kNone;
      double best_value = s_.value();
      for (std::size_t j = 0; j < p_.units.size(); ++j) {
        if (s_.in(j) || !affordable(j)) continue;
        const double v = value_of(s_.evaluate({kNone, j}, none, none, true));
        if (improves(v, best_value)) best_value = v, best = j;
      }
      if (best == kNone) return added;
      s_.apply({kNone, best});
      ++added;
    }
  }

  double value_of(const State::Eval& e) const { return e.value; }

  // One pass of the modified Fedorov exchange; the number of swaps made.
  std::size_t sweep() {
    std::size_t swaps = 0;
    const std::vector<std::size_t> order = s_.selected();
    for (std::size_t out : order) {
      if (forced_[out] || !s_.in(out)) continue;
      const MatrixXd Pi = s_.minv_times(out), Ki = s_.k_times(out);
      const double freed = p_.cost.empty() ? 0 : p_.cost[out];
      std::size_t best = kNone;
      double best_value = s_.value();
      if (o_.criterion == DesignCriterion::E) {
        std::vector<std::pair<double, std::size_t>> by_d;
        for (std::size_t j = 0; j < p_.units.size(); ++j) {
          if (s_.in(j) || !affordable(j, freed)) continue;
          by_d.emplace_back(s_.evaluate({out, j}, Pi, Ki, false).d_value, j);
        }
        const std::size_t n = std::min(kShortlist, by_d.size());
        std::partial_sort(by_d.begin(), by_d.begin() + static_cast<std::ptrdiff_t>(n), by_d.end());
        for (std::size_t t = 0; t < n; ++t) {
          const double v = s_.evaluate({out, by_d[t].second}, Pi, Ki, true).value;
          if (improves(v, best_value)) best_value = v, best = by_d[t].second;
        }
      } else {
        for (std::size_t j = 0; j < p_.units.size(); ++j) {
          if (s_.in(j) || !affordable(j, freed)) continue;
          const double v = s_.evaluate({out, j}, Pi, Ki, false).value;
          if (improves(v, best_value)) best_value = v, best = j;
        }
      }
      if (best != kNone) {
        s_.apply({out, best});
        ++swaps;
      }
    }
    return swaps;
  }

  const DesignProblem& p_;
  const ExchangeOptions& o_;
  State s_;
  std::size_t index_;
  Rng rng_;
  std::vector<char> forced_;
};

}  // namespace

ExchangeResult ExchangeDesign::run(const DesignProblem& p) const {
  const ExchangeOptions& o = options_;
  if (p.units.empty()) throw std::invalid_argument("exchange: no candidate units");
  const Eigen::Index r = p.units.front().cols();
  if (r == 0) throw std::invalid_argument("exchange: the candidates span no direction");
  for (const MatrixXd& u : p.units)
    if (u.cols() != r) throw std::invalid_argument("exchange: units of different widths");
  if (o.criterion == DesignCriterion::I && (p.weight.rows() != r || p.weight.cols() != r))
    throw std::invalid_argument("exchange: the I criterion needs an r × r weight");
  for (std::size_t f : p.forced)
    if (f >= p.units.size()) throw std::invalid_argument("exchange: a forced unit out of range");
  const bool budget = !p.cost.empty();
  if (budget) {
    if (p.cost.size() != p.units.size()) throw std::invalid_argument("exchange: one cost per unit");
    double forced_cost = 0;
    for (std::size_t f : p.forced) forced_cost += p.cost[f];
    if (forced_cost > p.budget)
      throw std::invalid_argument("exchange: the forced units exceed the budget");
  } else {
    if (o.size > p.units.size())
      throw std::invalid_argument("exchange: " + std::to_string(o.size) + " units asked of " +
                                  std::to_string(p.units.size()) + " candidates");
    if (p.forced.size() > o.size)
      throw std::invalid_argument("exchange: more forced units than the size");
  }
  // The ridge: 1e-10 of the average candidate's information per direction.
  double total = 0;
  for (const MatrixXd& u : p.units) total += u.squaredNorm();
  const double ridge = std::max(
      1e-300, 1e-10 * total / static_cast<double>(p.units.size()) / static_cast<double>(r));

  std::vector<RestartResult> results(o.restarts);
  parallel_blocks(o.restarts, 1, o.threads, [&](std::size_t k, std::size_t, std::size_t, unsigned) {
    results[k] = Restart(p, o, ridge, k).run();
  });
  ExchangeResult out;
  for (std::size_t k = 0; k < results.size(); ++k) {
    out.restart_values.push_back(results[k].value);
    if (k == 0 || improves(results[k].value, results[out.best_restart].value)) out.best_restart = k;
  }
  const RestartResult& best = results[out.best_restart];
  out.selected = best.selected;
  out.passes = best.passes;
  out.exchanges = best.exchanges;
  MatrixXd M = MatrixXd::Zero(r, r);
  for (std::size_t j : best.selected) {
    M.noalias() += p.units[j].transpose() * p.units[j];
    if (budget) out.cost += p.cost[j];
  }
  const MatrixXd W = o.criterion == DesignCriterion::A ? MatrixXd::Identity(r, r) : p.weight;
  out.value = design_criterion(M, o.criterion, W);
  out.log_det = design_criterion(M, DesignCriterion::D, W);
  // restart_values as the criterion's natural sign (the internal value is minimised).
  for (double& v : out.restart_values)
    if (o.criterion == DesignCriterion::D || o.criterion == DesignCriterion::E) v = -v;
  return out;
}

}  // namespace weilgen
