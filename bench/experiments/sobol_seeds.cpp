// Is the default seed's slow convergence a tail event of the Sobol' estimator or a defect of the
// design? The grinder benchmark of bench/openturns (gantry_grinder, dx at X=0, Y=1500, Z=600,
// order 1, so S_exact is exact; criterion max |S − S_exact| <= 1e-4 over the 21 first-order
// and 21 total indices) over many seeds, with weilgen's default design (R = 4 replicates, each
// an independent random linear matrix scramble plus digital shift of the interleaved Sobol'
// net) against two references that run through the same estimator code:
//   - nus: Owen's nested uniform scrambling of the same nets (the randomisation the scrambled-net
//     variance theory is written for; a linear matrix scramble has the same variance, Owen 2003),
//     replicates seeded from an independent std::mt19937_64 stream per (seed, replicate);
//   - mc: plain Monte Carlo points (std::mt19937_64), the estimator's Monte Carlo variance.
// Per N it prints the distribution of the max error over the seeds (where the default seed 1
// falls in it), the N each seed needs, and tests of what the replicate intervals assume:
// independent replicates (correlations of replicate errors across seeds, the variance of the
// replicate mean against the single-replicate variance / R) and the coverage of the Student-t
// intervals. Before that it checks that its estimator reproduces weilgen's SobolAnalysis on the
// lms design (per replicate, to rounding).
//
//   weilgen_exp_sobol_seeds [--seeds S] [--first F] [--log2n 16,17,18,19] [--replicates R]
//                           [--threads T] [--designs lms,nus,mc] [--csv FILE]
//
// Reported in docs/sensitivity.md ("Is the default seed a bad seed?") and docs/performance.md.
#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/builtin_models.hpp"
#include "weilgen/model/model_loader.hpp"
#include "weilgen/uq/sobol_indices.hpp"

using namespace weilgen;

namespace {

constexpr double kTolerance = 1e-4;  // bench/openturns's criterion

struct Options {
  std::size_t seeds = 200, first = 1, replicates = 4;
  std::vector<int> log2n = {16, 17, 18, 19};
  std::vector<std::string> designs = {"lms", "nus", "mc"};
  unsigned threads = 0;
  std::string csv;
};

// The grinder's dx as a linear function of its 21 errors (exact at order 1).
struct Problem {
  std::vector<InputDistribution> inputs;
  std::vector<double> c;      // d dx / d error (mm per base unit)
  std::vector<double> exact;  // S_i = S_Ti
  std::vector<std::string> names;
};

Problem grinder() {
  Problem p;
  const Description desc = load_machine_file(resolve_machine("gantry_grinder"));
  p.inputs = error_distributions(desc, {}, {});
  for (const ErrorDef& e : desc.errors) p.names.push_back(e.name);
  const PoseSet poses = parse_poses(desc, {"X=0,Y=1500,Z=600"}, {});
  LoadOptions lo;
  lo.order = 1;
  lo.builtins = builtin_models();
  lo.compiler = "none";
  const std::shared_ptr<const Model> model = load_model(desc, lo);
  ModelData data(*model);
  std::vector<double> coeff(6 * desc.errors.size());
  model->coefficients(data, poses.poses[0].data(), coeff.data());
  p.c.assign(coeff.begin(), coeff.begin() + static_cast<std::ptrdiff_t>(desc.errors.size()));
  p.exact = linear_sobol_indices(p.c, p.inputs);
  return p;
}

// One replicate's estimates from n points of 2k uniforms (dimension-major, u[d * n + j];
// coordinates 2v and 2v + 1 are input v's columns of A and B, as weilgen interleaves them):
// Saltelli's first-order and Jansen's total index with the replicate's own mean and variance,
// the formulas of sobol_indices.cpp (sums centred at 0 instead of f at row 0: the same to
// rounding).
void estimate(const Problem& p, std::vector<double>& u, std::size_t n, double* first,
              double* total) {
  const std::size_t k = p.c.size();
  for (std::size_t v = 0; v < k; ++v)
    for (int half = 0; half < 2; ++half) {
      double* col = u.data() + (2 * v + static_cast<std::size_t>(half)) * n;
      p.inputs[v].quantiles(col, col, n);
    }
  double s0 = 0, s1 = 0;
  std::vector<double> sp(k, 0.0), sd(k, 0.0), sq(k, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    double fa = 0, fb = 0;
    for (std::size_t v = 0; v < k; ++v) {
      fa += p.c[v] * u[2 * v * n + j];
      fb += p.c[v] * u[(2 * v + 1) * n + j];
    }
    s0 += fa + fb;
    s1 += fa * fa + fb * fb;
    for (std::size_t v = 0; v < k; ++v) {
      const double d = p.c[v] * (u[(2 * v + 1) * n + j] - u[2 * v * n + j]);
      sp[v] += fb * d;
      sd[v] += d;
      sq[v] += d * d;
    }
  }
  const auto nd = static_cast<double>(n);
  const double m = s0 / (2 * nd), var = s1 / (2 * nd) - m * m;
  for (std::size_t v = 0; v < k; ++v) {
    first[v] = (sp[v] - m * sd[v]) / nd / var;
    total[v] = sq[v] / (2 * nd) / var;
  }
}

double to_unit(std::uint64_t x) {
  const double u = static_cast<double>(x >> 11) * 0x1p-53;
  return u > 0.0 ? u : 0x1p-54;
}

// The unscrambled net x_0 .. x_{n-1} (Gray-code order, x_0 = 0) as 64-bit words, dimension-major.
std::vector<std::uint64_t> plain_net(std::size_t dims, std::size_t n) {
  const SobolSequence seq(dims, 0);  // returns x_1, x_2, ...: exact dyadic rationals
  std::vector<double> u(dims * (n - 1));
  std::vector<std::uint64_t> state;
  seq.points(0, n - 1, u.data(), n - 1, state);
  std::vector<std::uint64_t> x(dims * n, 0);
  for (std::size_t d = 0; d < dims; ++d)
    for (std::size_t j = 1; j < n; ++j)
      x[d * n + j] = static_cast<std::uint64_t>(u[d * (n - 1) + j - 1] * 0x1p53) << 11;
  return x;
}

// Owen's nested uniform scramble of the net's coordinates: digit i (from the top) of a point is
// flipped by the random bit of the node its first i − 1 original digits name; from digit m + 1
// on (n = 2^m) every point's prefix is its own in each coordinate, so those digits are
// independent uniform bits.
void owen_points(const std::vector<std::uint64_t>& net, std::size_t dims, std::size_t n,
                 std::mt19937_64& rng, std::vector<double>& u) {
  unsigned m = 0;
  while ((std::size_t{1} << m) < n) ++m;
  std::vector<std::uint8_t> flip(std::size_t{1} << m);
  u.resize(dims * n);
  for (std::size_t d = 0; d < dims; ++d) {
    for (auto& f : flip) f = static_cast<std::uint8_t>(rng() >> 63);
    for (std::size_t j = 0; j < n; ++j) {
      const std::uint64_t x = net[d * n + j];
      std::uint64_t y = 0, prefix = 0;
      for (unsigned i = 0; i < m; ++i) {
        const std::uint64_t bit = (x >> (63 - i)) & 1u;
        y |= (bit ^ flip[(std::size_t{1} << i) - 1 + prefix]) << (63 - i);
        prefix = (prefix << 1) | bit;
      }
      y |= m < 64 ? rng() >> m : 0;
      u[d * n + j] = to_unit(y);
    }
  }
}

// Per seed and N: the R replicates' estimates (replicate-major, first then total).
struct Run {
  std::vector<double> first, total;  // R x k
};

double quantile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const double h = p * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

std::string sci(double x, int digits = 2) {
  char b[32];
  std::snprintf(b, sizeof b, "%.*e", digits - 1, x);
  return b;
}
std::string fixed(double x, int digits) {
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", digits, x);
  return b;
}

std::vector<int> int_list(const std::string& s) {
  std::vector<int> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(std::stoi(item));
  return out;
}

std::vector<std::string> word_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--seeds") {
      opt.seeds = std::stoul(next());
    } else if (a == "--first") {
      opt.first = std::stoul(next());
    } else if (a == "--log2n") {
      opt.log2n = int_list(next());
    } else if (a == "--replicates") {
      opt.replicates = std::stoul(next());
    } else if (a == "--threads") {
      opt.threads = static_cast<unsigned>(std::stoul(next()));
    } else if (a == "--designs") {
      opt.designs = word_list(next());
    } else if (a == "--csv") {
      opt.csv = next();
    } else {
      std::cerr << "usage: weilgen_exp_sobol_seeds [--seeds S] [--first F] [--log2n 16,17,18,19] "
                   "[--replicates R] [--threads T] [--designs lms,nus,mc] [--csv FILE]\n";
      return 2;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const Problem p = grinder();
  const std::size_t k = p.c.size(), dims = 2 * k, R = opt.replicates;
  const unsigned threads = resolve_threads(opt.threads);
  std::cout << "# Sobol' seeds: gantry_grinder dx at X=0, Y=1500, Z=600, " << k
            << " errors, R = " << R << ", seeds " << opt.first << " .. "
            << opt.first + opt.seeds - 1 << ", " << threads << " threads\n\n";

  // 1. The estimator here against weilgen's SobolAnalysis (lms design, per replicate).
  {
    double worst = 0;
    for (std::size_t s = opt.first; s < opt.first + std::min<std::size_t>(opt.seeds, 4); ++s) {
      SobolOptions so;
      so.samples = std::size_t{1} << opt.log2n.front();
      so.seed = s;
      so.replicates = R;
      so.threads = 1;
      const SobolDesign design(p.inputs, so, false);
      const SobolResult res = SobolAnalysis(so).run(
          design, 1, [&](unsigned, std::size_t count, const double* x, double* y) {
            for (std::size_t j = 0; j < count; ++j) {
              double f = 0;
              for (std::size_t v = 0; v < k; ++v) f += p.c[v] * x[j * k + v];
              y[j] = f;
            }
          });
      const std::size_t n = so.samples / R;
      std::vector<double> u(dims * n), first(k), total(k);
      std::vector<std::uint64_t> state;
      for (std::size_t r = 0; r < R; ++r) {
        SobolSequence(dims, sobol_replicate_seed(s, r, R), true).points(0, n, u.data(), n, state);
        estimate(p, u, n, first.data(), total.data());
        for (std::size_t v = 0; v < k; ++v) {
          worst = std::max(worst, std::abs(first[v] - res.outputs[0].first_replicates[r * k + v]));
          worst = std::max(worst, std::abs(total[v] - res.outputs[0].total_replicates[r * k + v]));
        }
      }
    }
    std::cout << "check: this estimator against weilgen's SobolAnalysis (lms, N = 2^"
              << opt.log2n.front()
              << ", 4 seeds, every replicate's 42 estimates): max |diff| = " << sci(worst)
              << (worst < 1e-9 ? " ok" : " MISMATCH") << "\n\n";
    if (!(worst < 1e-9)) return 1;
  }

  // 2. Every design and seed; per replicate one randomised net of the largest N, whose first
  // N / R points are the design at the smaller N (as a seed's designs at several N are in
  // weilgen: the same scramble, the first points of the sequence).
  const std::size_t nn = opt.log2n.size(), nd = opt.designs.size();
  const std::size_t n_max =
      (std::size_t{1} << *std::max_element(opt.log2n.begin(), opt.log2n.end())) / R;
  std::vector<Run> runs(nd * nn * opt.seeds);  // [design][N][seed]
  std::vector<std::uint64_t> net;
  if (std::find(opt.designs.begin(), opt.designs.end(), "nus") != opt.designs.end())
    net = plain_net(dims, n_max);
  parallel_blocks(nd * opt.seeds, 1, threads,
                  [&](std::size_t t, std::size_t, std::size_t, unsigned) {
                    const std::size_t g = t / opt.seeds, s = opt.first + t % opt.seeds;
                    const std::string& design = opt.designs[g];
                    std::vector<double> all(dims * n_max), u;
                    std::vector<std::uint64_t> state;
                    for (std::size_t a = 0; a < nn; ++a) {
                      runs[(g * nn + a) * opt.seeds + (s - opt.first)].first.resize(R * k);
                      runs[(g * nn + a) * opt.seeds + (s - opt.first)].total.resize(R * k);
                    }
                    for (std::size_t r = 0; r < R; ++r) {
                      if (design == "lms") {
                        SobolSequence(dims, sobol_replicate_seed(s, r, R), true)
                            .points(0, n_max, all.data(), n_max, state);
                      } else {
                        std::seed_seq seq{static_cast<std::uint32_t>(s),
                                          static_cast<std::uint32_t>(r), design == "nus" ? 1u : 2u};
                        std::mt19937_64 rng(seq);
                        if (design == "nus") {
                          owen_points(net, dims, n_max, rng, all);
                        } else {
                          for (double& x : all)
                            x = (static_cast<double>(rng() >> 11) + 0.5) * 0x1p-53;
                        }
                      }
                      for (std::size_t a = 0; a < nn; ++a) {
                        const std::size_t n = (std::size_t{1} << opt.log2n[a]) / R;
                        u.resize(dims * n);
                        for (std::size_t d = 0; d < dims; ++d)
                          std::copy(all.begin() + static_cast<std::ptrdiff_t>(d * n_max),
                                    all.begin() + static_cast<std::ptrdiff_t>(d * n_max + n),
                                    u.begin() + static_cast<std::ptrdiff_t>(d * n));
                        Run& run = runs[(g * nn + a) * opt.seeds + (s - opt.first)];
                        estimate(p, u, n, run.first.data() + r * k, run.total.data() + r * k);
                      }
                    }
                  });

  // 3. Per design and N: the max error over seeds, the default seed's place, the tests.
  std::ofstream csv;
  if (!opt.csv.empty()) {
    csv.open(opt.csv);
    csv << "design,log2n,seed,max_error,max_first_error,max_total_error\n";
  }
  const double t_factor = boost::math::quantile(
      boost::math::students_t_distribution<double>(static_cast<double>(R - 1)), 0.975);
  std::map<std::string, std::vector<int>> needed;  // per design: log2 N each seed needs
  std::cout << "| design | N | median max error | 90 % | 95 % | 99 % | seeds <= 1e-4 | seed 1 | "
               "seeds worse than seed 1 | replicate error correlation (mean, |z| > 2.58) | "
               "Var(mean) / (Var(one) / R) | 95 % t-interval coverage |\n"
            << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: "
               "|\n";
  for (std::size_t g = 0; g < nd; ++g) {
    needed[opt.designs[g]].assign(opt.seeds, 99);
    for (std::size_t a = 0; a < nn; ++a) {
      const Run* base = runs.data() + (g * nn + a) * opt.seeds;
      std::vector<double> worst(opt.seeds);
      std::size_t covered = 0, intervals = 0;
      for (std::size_t s = 0; s < opt.seeds; ++s) {
        double wf = 0, wt = 0;
        for (std::size_t v = 0; v < k; ++v)
          for (int which = 0; which < 2; ++which) {
            if (p.c[v] == 0) continue;  // exactly 0 in every replicate: no interval to test
            const std::vector<double>& rep = which == 0 ? base[s].first : base[s].total;
            double mean = 0;
            for (std::size_t r = 0; r < R; ++r) mean += rep[r * k + v];
            mean /= static_cast<double>(R);
            double ss = 0;
            for (std::size_t r = 0; r < R; ++r)
              ss += (rep[r * k + v] - mean) * (rep[r * k + v] - mean);
            const double half =
                t_factor * std::sqrt(ss / static_cast<double>(R - 1) / static_cast<double>(R));
            const double err = std::abs(mean - p.exact[v]);
            covered += err <= half;
            ++intervals;
            (which == 0 ? wf : wt) = std::max(which == 0 ? wf : wt, err);
          }
        worst[s] = std::max(wf, wt);
        if (worst[s] <= kTolerance && needed[opt.designs[g]][s] == 99)
          needed[opt.designs[g]][s] = opt.log2n[a];
        if (csv)
          csv << opt.designs[g] << "," << opt.log2n[a] << "," << opt.first + s << "," << worst[s]
              << "," << wf << "," << wt << "\n";
      }
      // Independence of the replicates: per estimate (42) and pair of replicates, the
      // correlation of their errors over the seeds; and the variance of the replicate mean
      // against the mean single-replicate variance / R.
      double corr_sum = 0, var_ratio_sum = 0;
      std::size_t corr_n = 0, corr_big = 0, ratio_n = 0;
      const auto S = static_cast<double>(opt.seeds);
      for (int which = 0; which < 2; ++which)
        for (std::size_t v = 0; v < k; ++v) {
          if (p.c[v] == 0) continue;
          std::vector<std::vector<double>> e(R, std::vector<double>(opt.seeds));
          for (std::size_t s = 0; s < opt.seeds; ++s)
            for (std::size_t r = 0; r < R; ++r)
              e[r][s] = (which == 0 ? base[s].first : base[s].total)[r * k + v] - p.exact[v];
          std::vector<double> mu(R, 0.0), var(R, 0.0);
          for (std::size_t r = 0; r < R; ++r) {
            for (double x : e[r]) mu[r] += x / S;
            for (double x : e[r]) var[r] += (x - mu[r]) * (x - mu[r]) / (S - 1);
          }
          for (std::size_t r = 0; r < R; ++r)
            for (std::size_t q = r + 1; q < R; ++q) {
              double cov = 0;
              for (std::size_t s = 0; s < opt.seeds; ++s)
                cov += (e[r][s] - mu[r]) * (e[q][s] - mu[q]) / (S - 1);
              const double rho = cov / std::sqrt(var[r] * var[q]);
              corr_sum += rho;
              ++corr_n;
              corr_big += std::abs(rho) * std::sqrt(S - 3) > 2.58;  // Fisher z ≈ rho for small rho
            }
          double mean_var = 0, vm = 0, mm = 0;
          for (std::size_t r = 0; r < R; ++r) mean_var += var[r] / static_cast<double>(R);
          std::vector<double> m(opt.seeds, 0.0);
          for (std::size_t s = 0; s < opt.seeds; ++s) {
            for (std::size_t r = 0; r < R; ++r) m[s] += e[r][s] / static_cast<double>(R);
            mm += m[s] / S;
          }
          for (double x : m) vm += (x - mm) * (x - mm) / (S - 1);
          if (mean_var > 0) {
            var_ratio_sum += vm / (mean_var / static_cast<double>(R));
            ++ratio_n;
          }
        }
      const double seed1 = opt.first <= 1 && 1 < opt.first + opt.seeds ? worst[1 - opt.first] : NAN;
      std::size_t worse = 0, within = 0;
      for (double w : worst) worse += w > seed1, within += w <= kTolerance;
      std::cout << "| " << opt.designs[g] << " | 2^" << opt.log2n[a] << " | "
                << sci(quantile(worst, 0.5)) << " | " << sci(quantile(worst, 0.9)) << " | "
                << sci(quantile(worst, 0.95)) << " | " << sci(quantile(worst, 0.99)) << " | "
                << within << " / " << opt.seeds << " | " << (std::isnan(seed1) ? "-" : sci(seed1))
                << " | "
                << (std::isnan(seed1) ? "-"
                                      : fixed(100.0 * static_cast<double>(worse) / S, 1) + " %")
                << " | " << fixed(corr_sum / static_cast<double>(corr_n), 3) << ", "
                << fixed(100.0 * static_cast<double>(corr_big) / static_cast<double>(corr_n), 1)
                << " % | " << fixed(var_ratio_sum / static_cast<double>(ratio_n), 2) << " | "
                << fixed(100.0 * static_cast<double>(covered) / static_cast<double>(intervals), 1)
                << " % |\n";
    }
  }
  // 4. Does a seed's error persist as N doubles? Per estimate, the correlation over the seeds of
  // the replicate mean's error at N and at 2N (the first half of the 2N points is the N points).
  std::cout << "\nCorrelation over the seeds of each estimate's error at N and 2N (mean over the "
               "estimates of acting errors):\n\n| design |";
  for (std::size_t a = 0; a + 1 < nn; ++a)
    std::cout << " 2^" << opt.log2n[a] << " and 2^" << opt.log2n[a + 1] << " |";
  std::cout << "\n| --- |" << std::string(3 * (nn - 1), ' ');
  for (std::size_t a = 0; a + 1 < nn; ++a) std::cout << " ---: |";
  std::cout << "\n";
  for (std::size_t g = 0; g < nd; ++g) {
    std::cout << "| " << opt.designs[g] << " |";
    for (std::size_t a = 0; a + 1 < nn; ++a) {
      double sum = 0;
      std::size_t count = 0;
      for (int which = 0; which < 2; ++which)
        for (std::size_t v = 0; v < k; ++v) {
          if (p.c[v] == 0) continue;
          std::vector<double> x(opt.seeds), y(opt.seeds);
          for (std::size_t s = 0; s < opt.seeds; ++s)
            for (int h = 0; h < 2; ++h) {
              const Run& run = runs[(g * nn + a + static_cast<std::size_t>(h)) * opt.seeds + s];
              double m = 0;
              for (std::size_t r = 0; r < R; ++r)
                m += (which == 0 ? run.first : run.total)[r * k + v];
              (h == 0 ? x : y)[s] = m / static_cast<double>(R) - p.exact[v];
            }
          double mx = 0, my = 0, sxy = 0, sxx = 0, syy = 0;
          for (std::size_t s = 0; s < opt.seeds; ++s) mx += x[s], my += y[s];
          mx /= static_cast<double>(opt.seeds), my /= static_cast<double>(opt.seeds);
          for (std::size_t s = 0; s < opt.seeds; ++s)
            sxy += (x[s] - mx) * (y[s] - my), sxx += (x[s] - mx) * (x[s] - mx),
                (syy += (y[s] - my) * (y[s] - my));
          sum += sxy / std::sqrt(sxx * syy);
          ++count;
        }
      std::cout << " " << fixed(sum / static_cast<double>(count), 2) << " |";
    }
    std::cout << "\n";
  }

  // 5. The N each seed needs.
  std::cout << "\nN reaching max error <= 1e-4 (seeds per log2 N; 99 = beyond the largest N):\n\n"
            << "| design | median seed | 90th-percentile seed | seed 1 | counts |\n"
            << "| --- | ---: | ---: | ---: | --- |\n";
  for (const auto& [design, v] : needed) {
    std::map<int, std::size_t> count;
    for (int x : v) ++count[x];
    std::vector<double> d(v.begin(), v.end());
    std::string counts;
    for (const auto& [l, c] : count)
      counts += (counts.empty() ? "" : ", ") +
                (l == 99 ? std::string("beyond") : "2^" + std::to_string(l)) + ": " +
                std::to_string(c);
    auto text = [](double l) {
      return l >= 99 ? std::string("beyond") : "2^" + fixed(l, l == std::floor(l) ? 0 : 1);
    };
    std::sort(d.begin(), d.end());
    // Order statistics (no interpolation between powers of two).
    const double med = d[(d.size() - 1) / 2];
    const double p90 =
        d[static_cast<std::size_t>(std::ceil(0.9 * static_cast<double>(d.size()))) - 1];
    const std::string s1 =
        opt.first <= 1 && 1 < opt.first + opt.seeds ? text(v[1 - opt.first]) : "-";
    std::cout << "| " << design << " | " << text(med) << " | " << text(p90) << " | " << s1 << " | "
              << counts << " |\n";
  }
  // 6. The default seed in detail: which estimate is worst, against that estimate's spread.
  for (std::size_t g = 0; g < nd; ++g) {
    if (opt.designs[g] != "lms" || !(opt.first <= 1 && 1 < opt.first + opt.seeds)) continue;
    std::cout << "\nseed 1 (lms): the worst estimate per N and its error in standard deviations of "
                 "that estimate over the seeds:\n\n";
    for (std::size_t a = 0; a < nn; ++a) {
      const Run* base = runs.data() + (g * nn + a) * opt.seeds;
      double w = -1, z = 0;
      std::string which;
      for (int t = 0; t < 2; ++t)
        for (std::size_t v = 0; v < k; ++v) {
          auto mean_of = [&](const Run& run) {
            double m = 0;
            for (std::size_t r = 0; r < R; ++r) m += (t == 0 ? run.first : run.total)[r * k + v];
            return m / static_cast<double>(R) - p.exact[v];
          };
          double sum2 = 0;
          for (std::size_t s = 0; s < opt.seeds; ++s) sum2 += mean_of(base[s]) * mean_of(base[s]);
          const double e1 = mean_of(base[1 - opt.first]);
          if (std::abs(e1) > w) {
            w = std::abs(e1);
            z = e1 / std::sqrt(sum2 / static_cast<double>(opt.seeds));
            which = (t == 0 ? "S_" : "ST_") + p.names[v];
          }
        }
      std::cout << "- N = 2^" << opt.log2n[a] << ": " << which << " error " << sci(w) << " = "
                << fixed(z, 2) << " RMS errors of that estimate over the seeds\n";
    }
  }
  std::cout << "\nexact indices: ";
  for (std::size_t v = 0; v < k; ++v)
    if (p.exact[v] > 1e-6) std::cout << p.names[v] << " " << sci(p.exact[v], 3) << "  ";
  std::cout << "\n("
            << fixed(
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                   1)
            << " s)\n";
  return 0;
}
