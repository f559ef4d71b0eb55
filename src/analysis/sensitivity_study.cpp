#include "weilgen/analysis/sensitivity_study.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "weilgen/base/memory.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {

namespace {

// Σ c_i x_i as four interleaved partial sums (i mod 4) added at the end as (s0 + s2) + (s1 + s3):
// a fixed order, so the same numbers on any thread and with or without SSE2 (two pairs of SIMD
// lanes, two independent chains of additions).
double dot4(const double* c, const double* x, std::size_t n) {
  std::size_t i = 0;
  double s[4] = {0, 0, 0, 0};
#if defined(__SSE2__)
  __m128d a = _mm_setzero_pd(), b = _mm_setzero_pd();
  for (; i + 4 <= n; i += 4) {
    a = _mm_add_pd(a, _mm_mul_pd(_mm_loadu_pd(c + i), _mm_loadu_pd(x + i)));
    b = _mm_add_pd(b, _mm_mul_pd(_mm_loadu_pd(c + i + 2), _mm_loadu_pd(x + i + 2)));
  }
  _mm_storeu_pd(s, a);
  _mm_storeu_pd(s + 2, b);
#else
  for (; i + 4 <= n; i += 4)
    for (int k = 0; k < 4; ++k)
      s[k] += c[i + static_cast<std::size_t>(k)] * x[i + static_cast<std::size_t>(k)];
#endif
  for (int k = 0; i < n; ++i, ++k) s[k] += c[i] * x[i];
  return (s[0] + s[2]) + (s[1] + s[3]);
}

}  // namespace

void SensitivityOptions::validate() const {
  if (!local && !exact && !sobol) throw std::invalid_argument("--method: no method chosen");
  if (outputs.empty()) throw std::invalid_argument("--outputs: no output given");
  for (std::size_t o = 0; o < outputs.size(); ++o)
    if (std::find(outputs.begin(), outputs.begin() + static_cast<std::ptrdiff_t>(o), outputs[o]) !=
        outputs.begin() + static_cast<std::ptrdiff_t>(o))
      throw std::invalid_argument(std::string("--outputs: \"") + output_name(outputs[o]) +
                                  "\" given twice");
  // Named by their flags before SobolOptions::validate names them by field.
  if (!(sobol_options.confidence > 0 && sobol_options.confidence < 1))
    throw std::invalid_argument("--confidence must be in (0, 1)");
  if (sobol && sobol_options.samples < 2)
    throw std::invalid_argument("--samples must be >= 2, not " +
                                std::to_string(sobol_options.samples));
  if (sobol) sobol_options.validate();
}

void parse_sensitivity_method(const std::string& m, SensitivityOptions& o) {
  if (m != "local" && m != "sobol" && m != "exact" && m != "all")
    throw std::invalid_argument("--method must be local, sobol, exact or all, not '" + m + "'");
  o.local = m == "local" || m == "all";
  o.exact = m == "exact" || m == "all";
  o.sobol = m == "sobol" || m == "all";
}

std::vector<OutputId> parse_output_list(const std::string& text) {
  std::vector<OutputId> out;
  for (const auto& item : split(text, ',')) {
    OutputId o;
    try {
      o = parse_output(trim(item));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("--outputs: ") + e.what());
    }
    if (std::find(out.begin(), out.end(), o) != out.end())
      throw std::invalid_argument("--outputs: \"" + item + "\" given twice");
    out.push_back(o);
  }
  if (out.empty()) throw std::invalid_argument("--outputs: no output given");
  return out;
}

Sampling parse_sampling(const std::string& text) {
  if (text == "qmc") return Sampling::Qmc;
  if (text == "mc") return Sampling::MonteCarlo;
  throw std::invalid_argument("--sampling must be qmc or mc, not '" + text + "'");
}

void set_sobol_intervals(SobolOptions& o, const long long* replicates, const long long* bootstrap) {
  if (replicates && bootstrap)
    throw std::invalid_argument(
        "--replicates and --bootstrap are two ways to get intervals: give one of them");
  if (bootstrap) {
    if (*bootstrap < 0 || *bootstrap > 100000)
      throw std::invalid_argument(
          "--bootstrap must be in [0, 100000] resamples (0 = no "
          "intervals), not " +
          std::to_string(*bootstrap));
    o.intervals = SobolIntervals::Bootstrap;
    o.bootstrap = static_cast<std::size_t>(*bootstrap);
    return;
  }
  o.intervals = SobolIntervals::Replicates;
  if (replicates) {
    if (*replicates < 2 || *replicates > 1024)
      throw std::invalid_argument("--replicates must be in [2, 1024], not " +
                                  std::to_string(*replicates));
    o.replicates = static_cast<std::size_t>(*replicates);
  }
  const std::size_t r = o.replicates;
  if (o.samples % r != 0 || o.samples / r < 2)
    throw std::invalid_argument(
        "--samples " + std::to_string(o.samples) + " must be a multiple of --replicates " +
        std::to_string(r) + " (each replicate has N/R >= 2 rows; e.g. --samples " +
        std::to_string(std::max<std::size_t>(2, (o.samples + r - 1) / r) * r) + ")");
  if (o.sampling == Sampling::Qmc && o.seed == 0)
    throw std::invalid_argument(
        "--seed 0 gives unrandomised Sobol' points, which cannot make independent replicates: "
        "use a seed != 0, or --bootstrap B");
}

SensitivityStudy::SensitivityStudy(SensitivityOptions options) : options_(std::move(options)) {
  options_.validate();
}

SensitivityResult SensitivityStudy::run(
    const Study& st, const std::function<void(std::size_t, std::size_t)>& progress) const {
  const Model& model = *st.model;
  const std::vector<OutputId>& outputs = options_.outputs;
  const std::size_t ne = model.num_errors(), np = st.poses.poses.size(), no = outputs.size();
  // Refused before anything is allocated: the records and the Sobol' analysis of one pose.
  const SobolOptions& so0 = options_.sobol_options;
  check_memory(static_cast<double>(np * no * ne) * sizeof(SensitivityRecord) +
                   (options_.sobol ? sobol_memory_bytes(so0, ne, no) : 0.0),
               "--samples " + std::to_string(so0.samples) + ", --bootstrap " +
                   std::to_string(so0.bootstrap) + " at " + std::to_string(np) +
                   (np == 1 ? " pose" : " poses"),
               "lower --samples, --bootstrap or the number of poses");
  SensitivityResult res;
  res.outputs = outputs;
  res.poses = np;
  res.errors = ne;
  res.records.resize(np * no * ne);
  res.summary.resize(np * no);
  res.confidence = options_.sobol_options.confidence;
  auto at = [&](std::size_t p, std::size_t o, std::size_t i) -> SensitivityRecord& {
    return res.records[(p * no + o) * ne + i];
  };
  std::vector<double> sigma(ne);
  for (std::size_t i = 0; i < ne; ++i) sigma[i] = st.inputs[i].stddev();

  // Local coefficients and exact indices (cheap).
  ModelData data(model);
  for (std::size_t p = 0; p < np; ++p) {
    model.coefficients(data, st.poses.poses[p].data(), data.coeff.data());
    for (std::size_t o = 0; o < no; ++o) {
      if (outputs[o] == OutputId::Dp) continue;
      const std::size_t row = static_cast<std::size_t>(outputs[o]);
      std::vector<double> c(data.coeff.begin() + static_cast<std::ptrdiff_t>(row * ne),
                            data.coeff.begin() + static_cast<std::ptrdiff_t>((row + 1) * ne));
      double var = 0;
      for (std::size_t i = 0; i < ne; ++i) {
        at(p, o, i).coefficient = c[i];
        at(p, o, i).contribution = c[i] * sigma[i];
        var += c[i] * c[i] * sigma[i] * sigma[i];
      }
      res.summary[p * no + o].variance_linear = var;
      if (options_.exact) {
        const auto s = linear_sobol_indices(c, st.inputs);
        for (std::size_t i = 0; i < ne; ++i) at(p, o, i).S_exact = s[i];
      }
    }
  }
  if (!options_.sobol) return res;

  SobolOptions so = options_.sobol_options;
  so.threads = st.threads;
  res.intervals = so.intervals;
  res.replicates = so.replicate_count();
  res.bootstrap = so.intervals == SobolIntervals::Bootstrap ? so.bootstrap : 0;
  // Stored when several poses reuse it; one pose makes each block of rows as it goes.
  const SobolDesign design(st.inputs, so, np > 1);
  const SobolAnalysis analysis(so);
  // Per thread: a model workspace and the batch's position and orientation; orientation only
  // when an angular output is analysed, position only for dx, dy, dz, dp.
  bool need_pos = false, need_ori = false;
  for (OutputId o : outputs) (output_is_angle(o) ? need_ori : need_pos) = true;
  std::vector<ModelData> work;
  std::vector<std::vector<double>> pos(st.threads, std::vector<double>(3 * kSobolMaxBatch)),
      ori(pos);
  for (unsigned t = 0; t < st.threads; ++t) work.emplace_back(model);
  // Order 1 (a compiled model): every output but dp is exactly linear in the errors, so its
  // linear form (the deviation at zero error and the coefficients, once per pose) is the model;
  // evaluating it costs ne multiply-adds per output (as the reliability sweep does, and as a
  // peer tool given the model as a matrix would).
  const bool linear = model.order() == 1 && model.engine() != ModelEngine::NumericChain &&
                      std::find(outputs.begin(), outputs.end(), OutputId::Dp) == outputs.end();
  std::vector<double> base(6), coeff(6 * ne), rows(no * ne), offset(no);
  for (std::size_t p = 0; p < np; ++p) {
    const double* pose = st.poses.poses[p].data();
    if (linear) {
      const std::vector<double> zero(ne, 0.0);
      model.deviation_and_coefficients(data, pose, zero.data(), base.data(), coeff.data());
      for (std::size_t o = 0; o < no; ++o) {
        const auto id = static_cast<std::size_t>(outputs[o]);
        offset[o] = base[id];
        std::copy(coeff.begin() + static_cast<std::ptrdiff_t>(id * ne),
                  coeff.begin() + static_cast<std::ptrdiff_t>((id + 1) * ne),
                  rows.begin() + static_cast<std::ptrdiff_t>(o * ne));
      }
    }
    const BatchFunction linear_fn = [&](unsigned, std::size_t count, const double* x, double* y) {
      for (std::size_t j = 0; j < count; ++j)
        for (std::size_t o = 0; o < no; ++o) {
          y[j * no + o] = offset[o] + dot4(rows.data() + o * ne, x + j * ne, ne);
        }
    };
    const BatchFunction model_fn = [&](unsigned t, std::size_t count, const double* x, double* y) {
      const double* ps = pos[t].data();
      const double* os = ori[t].data();
      model.deviation_batch(work[t], pose, count, x, need_pos ? pos[t].data() : nullptr,
                            need_ori ? ori[t].data() : nullptr);
      for (std::size_t j = 0; j < count; ++j)
        for (std::size_t o = 0; o < no; ++o) {
          const auto id = static_cast<std::size_t>(outputs[o]);
          const double* w = ps + 3 * j;
          y[j * no + o] = outputs[o] == OutputId::Dp
                              ? std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
                          : id < 3 ? w[id]
                                   : os[3 * j + id - 3];
        }
    };
    const SobolResult r = analysis.run(design, no, linear ? linear_fn : model_fn);
    res.evaluations += r.evaluations;
    for (std::size_t o = 0; o < no; ++o) {
      const SobolIndices& s = r.outputs[o];
      res.summary[p * no + o].mean = s.mean;
      res.summary[p * no + o].variance = s.variance;
      for (std::size_t i = 0; i < ne; ++i) {
        SensitivityRecord& x = at(p, o, i);
        x.S = s.first[i], x.S_lo = s.first_lo[i], x.S_hi = s.first_hi[i];
        x.ST = s.total[i], x.ST_lo = s.total_lo[i], x.ST_hi = s.total_hi[i];
      }
    }
    if (progress) progress(p + 1, np);
  }
  return res;
}

}  // namespace weilgen
