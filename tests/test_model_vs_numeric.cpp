// The symbolic model against the exact numeric chain (written independently of the generator).
#include <doctest/doctest.h>

#include <fstream>
#include <sstream>

#include "test_support.hpp"
#include "weilgen/codegen/emit_report.hpp"
#include "weilgen/codegen/model_builder.hpp"
#include "weilgen/codegen/model_eval.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

using namespace weilgen;

namespace {

// Slope of the model-versus-chain discrepancy over error scales s = 2^0 ... 2^-5.
// Rotations are scaled by `rot_scale` relative to translations (rad per mm of the test scale).
double convergence_slope(const Description& d, int order, unsigned seed, double* smallest = nullptr,
                         double s_max = 1.0, double rot_scale = 1.0) {
  const gen::SymbolicModel m = gen::build_model(d, order);
  const NumericChain chain(d);
  std::mt19937 rng(seed);
  const auto q = test::random_pose(d, rng);
  auto u = test::random_direction(d, rng);
  for (std::size_t i = 0; i < u.size(); ++i)
    if (d.errors[i].effect == ErrorEffect::Rotation) u[i] *= rot_scale;
  std::vector<double> s, err;
  for (int k = 0; k <= 5; ++k) {
    const double sc = s_max * std::ldexp(1.0, -k);
    const auto e = test::scaled(u, sc);
    s.push_back(sc);
    err.push_back(test::max_abs_diff(gen::evaluate_model(m, q, e), chain.deviation(q, e)));
  }
  if (smallest) *smallest = err.back();
  return test::loglog_slope(s, err);
}

}  // namespace

TEST_CASE("order-r model differs from the exact chain by O(s^(r+1)) on every shipped machine") {
  for (const auto& name : test::shipped_machines()) {
    const Description d = load_machine_file(test::machine_path(name));
    for (int r = 1; r <= 2; ++r) {
      for (unsigned seed : {1u, 2u}) {
        CAPTURE(name);
        CAPTURE(r);
        double smallest = 0;
        const double slope = convergence_slope(d, r, seed, &smallest);
        CHECK(slope == doctest::Approx(r + 1).epsilon(0.1));
        CHECK(smallest > 0);
      }
    }
  }
}

TEST_CASE("order-3 model of the five-axis machine converges as s^4") {
  const Description d = load_machine_file(test::machine_path("five_axis_ac"));
  // Larger errors so that the s^4 residual stays far above rounding (1e-13 mm).
  CHECK(convergence_slope(d, 3, 7, nullptr, 2.0, 10.0) == doctest::Approx(4).epsilon(0.1));
}

TEST_CASE("first-order coefficients equal central differences of the exact chain") {
  for (const auto& name : test::shipped_machines()) {
    CAPTURE(name);
    const Description d = load_machine_file(test::machine_path(name));
    const gen::SymbolicModel m = gen::build_model(d, 1);
    const NumericChain chain(d);
    std::mt19937 rng(11);
    const auto q = test::random_pose(d, rng);
    const auto coeff_model = [&](int o, std::size_t i) {
      // Linear part of the model: evaluate at a unit error (order 1 is exactly linear).
      std::vector<double> e(d.errors.size(), 0.0);
      e[i] = 1.0;
      return gen::evaluate_model(m, q, e)[o];
    };
    for (std::size_t i = 0; i < d.errors.size(); ++i) {
      const double h = 1e-6;
      std::vector<double> ep(d.errors.size(), 0.0), em(d.errors.size(), 0.0);
      ep[i] = h;
      em[i] = -h;
      const auto fp = chain.deviation(q, ep), fm = chain.deviation(q, em);
      for (int o = 0; o < 6; ++o) {
        CAPTURE(d.errors[i].name);
        CAPTURE(o);
        const double fd = (fp[o] - fm[o]) / (2 * h);
        CHECK(coeff_model(o, i) == doctest::Approx(fd).epsilon(1e-6).scale(1.0));
      }
    }
  }
}

TEST_CASE("deviation in the workpiece frame does not depend on the workpiece point") {
  std::string text = test::read_text(test::machine_path("vmc_3axis"));
  const Description a = load_machine_text(text, "vmc_3axis.yaml");
  const auto pos = text.find("workpiece: {body: workpiece, point: [0, 0, 0]}");
  REQUIRE(pos != std::string::npos);
  text.replace(pos, std::string("workpiece: {body: workpiece, point: [0, 0, 0]}").size(),
               "workpiece: {body: workpiece, point: [120, -40, 35]}");
  const Description b = load_machine_text(text, "vmc_3axis_moved.yaml");
  const gen::SymbolicModel ma = gen::build_model(a, 1), mb = gen::build_model(b, 1);
  for (int o = 0; o < 6; ++o) {
    const auto fa = gen::closed_form(ma, o, gen::FormStyle::Text, gen::Notation::Iso);
    CHECK(fa == gen::closed_form(mb, o, gen::FormStyle::Text, gen::Notation::Iso));
    CHECK(fa.size() > 10);
  }
}

TEST_CASE("a relation ideal gives exactly the order-r model with the ideal's monomials removed") {
  // R[e]/I is a quotient ring: truncating inside every product must equal the full order-r model
  // with the monomials of I dropped afterwards.
  std::string text = test::read_text(test::machine_path("five_axis_ac"));
  const Description plain = load_machine_text(text, "five_axis_ac.yaml");
  const std::string from = "algebra: {order: 1}";
  text.replace(text.find(from), from.size(),
               "algebra: {order: 2, relations: [{squares: all}, {within: [location]}, "
               "{pair: [E_XX, E_AC]}]}");
  const Description related = load_machine_text(text, "five_axis_ac_rel.yaml");
  const gen::SymbolicModel full = gen::build_model(plain, 2), quot = gen::build_model(related);
  REQUIRE(quot.order == 2);
  const auto is_location = [&](int i) { return plain.errors[i].group == "location"; };
  GiNaC::exmap to_full;
  for (std::size_t i = 0; i < full.axes.size(); ++i) {
    to_full[quot.axes[i].coordinate] = full.axes[i].coordinate;
    if (full.axes[i].revolute) {
      to_full[quot.axes[i].cos] = full.axes[i].cos;
      to_full[quot.axes[i].sin] = full.axes[i].sin;
    }
  }
  for (std::size_t i = 0; i < full.params.size(); ++i) to_full[quot.params[i]] = full.params[i];
  std::size_t dropped = 0;
  for (int o = 0; o < 6; ++o) {
    std::size_t kept = 0;
    for (const auto& [mono, c] : full.outputs[o].terms()) {
      const bool square = mono.size() == 2 && mono[0] == mono[1];
      const bool loc = mono.size() == 2 && is_location(mono[0]) && is_location(mono[1]);
      const bool pair =
          mono == gen::Monomial{static_cast<std::uint16_t>(plain.error_index("E_XX")),
                                static_cast<std::uint16_t>(plain.error_index("E_AC"))};
      if (square || loc || pair) {
        ++dropped;
        CHECK(quot.coefficient(o, mono).is_zero());
        continue;
      }
      ++kept;
      // Coefficients agree (mapping the quotient model's symbols onto the full model's).
      CHECK((c - quot.coefficient(o, mono).subs(to_full)).expand().is_zero());
    }
    CHECK(kept == quot.outputs[o].terms().size());
  }
  CHECK(dropped > 10);
}

TEST_CASE("the exact chain's stepped deviations equal whole deviations (every shipped machine)") {
  // deviation_steps redoes only the stepped error's body and the products after it; it must give
  // what deviation() gives with that error stepped (the same operations in the same order: bit
  // for bit in a plain build; 1e-12 mm leaves room for a compiler's contraction into FMAs), and
  // deviation(axes, errors, nominal(axes)) what deviation() gives.
  for (const auto& name : test::shipped_machines()) {
    CAPTURE(name);
    const Description d = load_machine_file(test::machine_path(name));
    const NumericChain chain(d);
    std::mt19937 rng(7);
    for (int trial = 0; trial < 3; ++trial) {
      const auto q = test::random_pose(d, rng);
      const auto e = test::scaled(test::random_direction(d, rng), 1e-3);
      std::vector<double> steps(e.size(), 0.0);
      for (std::size_t k = 0; k < steps.size(); k += 1 + static_cast<std::size_t>(trial))
        steps[k] = d.errors[k].effect == ErrorEffect::Rotation ? 1e-6 : 1e-3;
      const Eigen::Matrix4d nominal = chain.nominal(q);
      std::array<double, 6> at{};
      std::vector<std::array<double, 6>> stepped(e.size(), {-1, -1, -1, -1, -1, -1});
      chain.deviation_steps(q, e, steps, nominal, at, stepped);
      const auto whole = chain.deviation(q, e);
      CHECK(test::max_abs_diff(at, whole) <= 1e-12);
      CHECK(test::max_abs_diff(chain.deviation(q, e, nominal), whole) <= 1e-12);
      for (std::size_t k = 0; k < e.size(); ++k) {
        CAPTURE(d.errors[k].name);
        if (steps[k] == 0) {
          CHECK(stepped[k][0] == -1);  // left as it was
          continue;
        }
        std::vector<double> ek = e;
        ek[k] += steps[k];
        const auto ref = chain.deviation(q, ek);
        CHECK(test::max_abs_diff(stepped[k], ref) <= 1e-12);
      }
    }
  }
}
