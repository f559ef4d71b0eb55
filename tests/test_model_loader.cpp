// Model loading: built-in models by content key, run-time compilation into a cache, the
// numeric-chain fallback without a compiler; all engines agree.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "test_support.hpp"
#include "weilgen/codegen/generate.hpp"
#include "weilgen/machine/model_key.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/builtin_models.hpp"
#include "weilgen/model/model_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

using namespace weilgen;
namespace fs = std::filesystem;

namespace {

LoadOptions options_in(const std::string& cache, std::vector<std::string>* log = nullptr) {
  LoadOptions o;
  o.cache_dir = cache;
  o.compiler = WEILGEN_CXX;
  o.builtins = builtin_models();
  o.generate = [](const Description& d, int order) {
    GeneratedHeader h;
    h.text = gen::generate_header(d, order, &h.name_space);
    return h;
  };
  if (log) o.log = [log](const std::string& m) { log->push_back(m); };
  return o;
}

std::string fresh_dir(const std::string& name) { return test::fresh_dir(name).string(); }

// Largest difference between two models' deviation and coefficients over random poses/errors.
double max_disagreement(const Model& a, const Model& b, double error_scale) {
  std::mt19937 rng(7);
  ModelData da(a), db(b);
  double worst = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const auto q = test::random_pose(a.description(), rng);
    const auto e = test::scaled(test::random_direction(a.description(), rng), error_scale);
    a.deviation(da, q.data(), e.data(), da.out.data());
    b.deviation(db, q.data(), e.data(), db.out.data());
    for (int o = 0; o < 6; ++o)
      worst = std::max(worst, std::abs(da.out[o] - db.out[o]) * (o < 3 ? 1.0 : 1000.0));
    a.coefficients(da, q.data(), da.coeff.data());
    b.coefficients(db, q.data(), db.coeff.data());
    for (std::size_t k = 0; k < da.coeff.size(); ++k)
      worst = std::max(worst,
                       std::abs(da.coeff[k] - db.coeff[k]) / std::max(1.0, std::abs(da.coeff[k])));
  }
  return worst;
}

// Model::deviation_batch gives exactly Model::deviation, point by point (37 points: not a
// multiple of anything), with and without the orientation.
bool batch_matches(const Model& m) {
  std::mt19937 rng(11);
  ModelData data(m);
  const std::size_t ne = m.num_errors(), count = 37;
  for (int trial = 0; trial < 5; ++trial) {
    const auto q = test::random_pose(m.description(), rng);
    std::vector<double> errors, pos(3 * count), ori(3 * count), only_pos(3 * count), one(6);
    for (std::size_t j = 0; j < count; ++j) {
      const auto e = test::scaled(test::random_direction(m.description(), rng), 1e-3);
      errors.insert(errors.end(), e.begin(), e.end());
    }
    m.deviation_batch(data, q.data(), count, errors.data(), pos.data(), ori.data());
    m.deviation_batch(data, q.data(), count, errors.data(), only_pos.data(), nullptr);
    if (only_pos != pos) return false;
    for (std::size_t j = 0; j < count; ++j) {
      m.deviation(data, q.data(), errors.data() + j * ne, one.data());
      for (std::size_t o = 0; o < 3; ++o)
        if (one[o] != pos[3 * j + o] || one[3 + o] != ori[3 * j + o]) return false;
    }
  }
  return true;
}

// Model::deviation_and_coefficients gives Model::deviation and Model::coefficients (to rounding:
// largest difference relative to the output's magnitude below 1e-14), and with either output
// null writes only the other.
bool combined_matches(const Model& m) {
  std::mt19937 rng(13);
  ModelData data(m);
  const std::size_t ne = m.num_errors();
  for (int trial = 0; trial < 5; ++trial) {
    const auto q = test::random_pose(m.description(), rng);
    const auto e = test::scaled(test::random_direction(m.description(), rng), 1e-3);
    std::vector<double> dev(6), coeff(6 * ne), dev2(6), coeff2(6 * ne), only(6 * ne, -7.0);
    m.deviation(data, q.data(), e.data(), dev.data());
    m.coefficients(data, q.data(), coeff.data());
    m.deviation_and_coefficients(data, q.data(), e.data(), dev2.data(), coeff2.data());
    for (std::size_t o = 0; o < 6; ++o) {
      double scale = 0;
      for (std::size_t j = 0; j < ne; ++j) scale = std::max(scale, std::abs(coeff[o * ne + j]));
      for (std::size_t j = 0; j < ne; ++j)
        if (std::abs(coeff[o * ne + j] - coeff2[o * ne + j]) > 1e-14 * scale) return false;
    }
    double dscale = 0;
    for (std::size_t o = 0; o < 6; ++o) dscale = std::max(dscale, std::abs(dev[o]));
    for (std::size_t o = 0; o < 6; ++o)
      if (std::abs(dev[o] - dev2[o]) > 1e-14 * dscale) return false;
    m.deviation_and_coefficients(data, q.data(), e.data(), nullptr, only.data());
    if (only != coeff2) return false;
    std::fill(dev.begin(), dev.end(), -7.0);
    m.deviation_and_coefficients(data, q.data(), e.data(), dev.data(), nullptr);
    if (dev != dev2) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("model loader: shipped machines are built in and match the exact chain") {
  for (const auto& name : test::shipped_machines()) {
    CAPTURE(name);
    const Description d = load_machine_file(test::machine_path(name));
    const auto model = load_model(d, options_in(fresh_dir("loader_builtin")));
    CHECK(model->engine() == ModelEngine::BuiltIn);
    CHECK(model->order() == d.algebra.order);
    const auto chain = load_model(d, [] {
      LoadOptions o;
      o.engine = EngineChoice::Numeric;
      return o;
    }());
    CHECK(chain->engine() == ModelEngine::NumericChain);
    // Order 1 against the exact chain: errors of 1e-6 (mm, 1e-9 rad) agree to O(s^2).
    CHECK(max_disagreement(*model, *chain, 1e-6) < 1e-8);
    CHECK(batch_matches(*model));
    CHECK(batch_matches(*chain));
    CHECK(combined_matches(*model));
    CHECK(combined_matches(*chain));
  }
}

TEST_CASE("model loader: an edited machine is compiled once, then loaded from the cache") {
  const std::string dir = fresh_dir("loader_edit");
  const std::string cache = dir + "/cache";
  std::string text = test::read_text(test::machine_path("vmc_3axis"));
  // A different tool length: a new machine that no built-in model serves.
  text += "\n# edited by test_model_loader\n";
  const Description d = load_machine_text(text, dir + "/vmc_edit.yaml");
  std::vector<std::string> log;
  const auto compiled = load_model(d, options_in(cache, &log));
  CHECK(compiled->engine() == ModelEngine::Compiled);
  CHECK(compiled->origin().find("compiled (") == 0);
  REQUIRE(log.size() >= 2);
  CHECK(log.front().find("compiling model vmc_3axis") == 0);
  CHECK(fs::is_regular_file(cache + "/vmc_3axis-" + model_key(d.source_hash, 1) + ".so"));
  // No build directories left behind.
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(cache)) ++entries;
  CHECK(entries == 1);

  std::vector<std::string> log2;
  const auto cached = load_model(d, options_in(cache, &log2));
  CHECK(cached->engine() == ModelEngine::Compiled);
  CHECK(cached->origin().find("cached (") == 0);
  CHECK(log2.empty());
  CHECK(max_disagreement(*compiled, *cached, 1e-3) == 0.0);

  // The same machine through the built-in model: the same functions, equal to rounding (the
  // run-time compiler's flags need not be the build's: -mfma contracts differently).
  const auto builtin =
      load_model(load_machine_file(test::machine_path("vmc_3axis")), options_in(cache));
  CHECK(builtin->engine() == ModelEngine::BuiltIn);
  CHECK(max_disagreement(*compiled, *builtin, 1e-3) <= 1e-15);
  CHECK(batch_matches(*compiled));
  CHECK(combined_matches(*compiled));
}

TEST_CASE("model loader: a cached model of an older ABI version is compiled again") {
  // Version 1 (before deviation_batch) and the one before the current one (before
  // deviation_and_coefficients): reading past the end of their tables would crash.
  for (const int old_version : {1, kWeilgenModelAbiVersion - 1}) {
    CAPTURE(old_version);
    const std::string dir = fresh_dir("loader_stale_abi" + std::to_string(old_version));
    const std::string cache = dir + "/cache";
    fs::create_directories(cache);
    std::string text = test::read_text(test::machine_path("two_axis"));
    text += "\n# edited by test_model_loader (stale ABI)\n";
    const Description d = load_machine_text(text, dir + "/two_axis_stale.yaml");
    const std::string key = model_key(d.source_hash, d.algebra.order);
    // An object of an older ABI version (its table is shorter), with the right key.
    const std::string src = dir + "/old.cpp", so = cache + "/two_axis-" + key + ".so";
    std::ofstream(src) << "#include <cstddef>\nstruct Abi1 { int v, order; const char *name, *key;"
                          " std::size_t a, e, p; void *dev, *coeff; };\n"
                          "static const Abi1 abi = {"
                       << old_version << ", 1, \"two_axis\", \"" << key
                       << "\", 0, 0, 0, nullptr, nullptr};\n"
                          "extern \"C\" const Abi1* weilgen_model_abi() { return &abi; }\n";
    REQUIRE(std::system(
                (std::string(WEILGEN_CXX) + " -shared -fPIC -o " + so + " " + src).c_str()) == 0);
    std::vector<std::string> log;
    const auto model = load_model(d, options_in(cache, &log));
    CHECK(model->engine() == ModelEngine::Compiled);
    // Without the cache's integrity trailer the entry is first discarded as damaged (a note);
    // either way it is compiled again.
    REQUIRE_FALSE(log.empty());
    CHECK(std::any_of(log.begin(), log.end(), [](const std::string& l) {
      return l.find("compiling model two_axis") == 0;
    }));
    CHECK(batch_matches(*model));
    CHECK(combined_matches(*model));
    // The new object replaced the stale one: the next load is a cache hit.
    std::vector<std::string> log2;
    CHECK(load_model(d, options_in(cache, &log2))->origin().find("cached (") == 0);
    CHECK(log2.empty());
  }
}

TEST_CASE("model loader: order override compiles an order-2 model that converges as s^3") {
  const std::string cache = fresh_dir("loader_order2");
  const Description d = load_machine_file(test::machine_path("two_axis"));
  LoadOptions o = options_in(cache);
  o.order = 2;
  const auto m2 = load_model(d, o);
  CHECK(m2->engine() == ModelEngine::Compiled);
  CHECK(m2->order() == 2);
  LoadOptions n;
  n.engine = EngineChoice::Numeric;
  const auto chain = load_model(d, n);
  std::mt19937 rng(3);
  const auto q = test::random_pose(d, rng);
  const auto u = test::random_direction(d, rng);
  std::vector<double> s{1e-2, 5e-3, 2.5e-3}, err;
  ModelData a(*m2), b(*chain);
  for (double si : s) {
    const auto e = test::scaled(u, si);
    m2->deviation(a, q.data(), e.data(), a.out.data());
    chain->deviation(b, q.data(), e.data(), b.out.data());
    double m = 0;
    for (int k = 0; k < 6; ++k) m = std::max(m, std::abs(a.out[k] - b.out[k]));
    err.push_back(m);
  }
  CHECK(test::loglog_slope(s, err) == doctest::Approx(3.0).epsilon(0.1));
}

TEST_CASE("model loader: without a compiler, the numeric chain with a warning") {
  const std::string cache = fresh_dir("loader_nocxx");
  std::string text = test::read_text(test::machine_path("two_axis")) + "\n# edited\n";
  const Description d = load_machine_text(text, cache + "/two_axis_edit.yaml");
  std::vector<std::string> log;
  LoadOptions o = options_in(cache, &log);
  o.compiler = "/nonexistent/c++";
  const auto m = load_model(d, o);
  CHECK(m->engine() == ModelEngine::NumericChain);
  REQUIRE(log.size() == 1);
  CHECK(log[0].find("warning: no C++ compiler found (tried /nonexistent/c++)") == 0);
  o.engine = EngineChoice::Compiled;
  CHECK_THROWS_WITH_AS(load_model(d, o), doctest::Contains("cannot compile the model of two_axis"),
                       std::runtime_error);
  o.compiler = "none";
  o.engine = EngineChoice::Auto;
  log.clear();
  CHECK(load_model(d, o)->engine() == ModelEngine::NumericChain);
  CHECK(log[0].find("compilation disabled") != std::string::npos);
}

TEST_CASE("model loader: a compile failure reports the compiler's message") {
  const std::string cache = fresh_dir("loader_fail");
  std::string text = test::read_text(test::machine_path("two_axis")) + "\n# edited again\n";
  const Description d = load_machine_text(text, cache + "/two_axis_fail.yaml");
  LoadOptions o = options_in(cache);
  o.generate = [](const Description&, int) {
    return GeneratedHeader{"#error broken header\n", "two_axis"};
  };
  CHECK_THROWS_WITH_AS(load_model(d, o), doctest::Contains("broken header"), std::runtime_error);
  CHECK_FALSE(fs::exists(cache + "/two_axis-" + model_key(d.source_hash, 1) + ".so"));
}
