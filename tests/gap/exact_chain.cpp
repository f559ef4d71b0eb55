// Gap diagnosis: vmc_3axis through its exact chain (a bump of E_YY, two effects at once, a
// basis term that vanishes at every sample).
#include <doctest/doctest.h>

#include <filesystem>

#include "gap/fixtures.hpp"

using namespace weilgen;
using namespace weilgen::gap_test;

TEST_CASE("gap: a bump of E_YY along Y is named with its error and recovered at its centre") {
  const auto model = vmc();
  const int k = error_index(*model, "E_YY");
  const double centre = -220, width = 45, height_um = 4;
  const std::string csv = chain_csv(
      *model, vmc_grid(), 0.3, 21,
      [&](const ChainRow& r, std::vector<double>&, std::vector<double>& e, Eigen::Vector3d&) {
        const double z = (r.q[0] - centre) / width;
        e[static_cast<std::size_t>(k)] += height_um * 1e-3 * std::exp(-0.5 * z * z);
      });
  const GapResult r = diagnose(csv, model, "cycle:3", poly2());
  CHECK(r.verdict.names("pdge_shape"));
  const EffectFit* e = effect(r, "pdge_shape");
  REQUIRE(e);
  INFO(e->summary);
  CHECK(e->params.count("error_E_YY") == 1);
  CHECK(e->summary.find("bump of E_YY of Y") == 0);
  CHECK(e->params.at("centre_mm") == doctest::Approx(centre).epsilon(0.03));
  CHECK(std::abs(e->params.at("amplitude_um")) == doctest::Approx(height_um).epsilon(0.15));
  REQUIRE_FALSE(r.where.empty());
  CHECK(r.where.front().by == "Y");
  CHECK(r.where.front().from <= centre);
  CHECK(r.where.front().to >= centre);
}

TEST_CASE("gap: two effects at once, a reversal of X and a thermal drift, are both named") {
  const auto model = vmc();
  const int k = error_index(*model, "E_XX");
  auto T = [](double t) { return 22 + 2.5 * (1 - std::exp(-t / 4000)); };
  const std::string csv = chain_csv(
      *model, vmc_grid(), 0.3, 22,
      [&](const ChainRow& r, std::vector<double>&, std::vector<double>& e, Eigen::Vector3d& x) {
        e[static_cast<std::size_t>(k)] += -r.dir.at("X") * 3e-3 / 2;  // B = 3 µm
        x = Eigen::Vector3d(0, 2.0, -1.5) * (T(r.t_s) - 22);          // µm/K in dy, dz
      },
      ",T_spindle", [&](const ChainRow& r) { return std::to_string(T(r.t_s)); });
  const GapResult r = diagnose(csv, model, "cycle:3", poly2());
  std::set<std::string> named;
  for (const EffectFit& f : r.explanation) named.insert(f.name);
  INFO(r.verdict.reason);
  CHECK((r.verdict.names("reversal") || r.verdict.names("thermal_drift")));
  CHECK(named == std::set<std::string>{"reversal", "thermal_drift"});
  const EffectFit* rev = effect(r, "reversal");
  REQUIRE(rev);
  CHECK(rev->summary.find("reversal of X") == 0);
  CHECK(std::abs(rev->params.at("reversal_um")) == doctest::Approx(3).epsilon(0.1));
  const EffectFit* th = effect(r, "thermal_drift");
  REQUIRE(th);
  INFO(th->summary);
  REQUIRE(th->params.count("drift_y_um_per_K"));
  CHECK(th->params.at("drift_y_um_per_K") == doctest::Approx(2.0).epsilon(0.1));
  // dz: the offset and Z's scale are nearly collinear over Z = -250, -100 mm; their sum at the
  // grid's mean Z is the growth.
  const double scale_z =
      th->params.count("scale_Z_um_per_m_per_K") ? th->params.at("scale_Z_um_per_m_per_K") : 0;
  CHECK(th->params.at("drift_z_um_per_K") - 0.175 * scale_z == doctest::Approx(-1.5).epsilon(0.1));
}

TEST_CASE("gap: a basis term that vanishes at every sample is not fitted") {
  // As in identify (test_identify.cpp): sin(2π·2·y/L) is rounding noise at the five Y positions.
  // Each fold's equilibrated SVD used to count it in the rank (47) and fit it with ~1e16.
  const std::filesystem::path dir = test::fresh_dir("gap_vanishing_term");
  const std::string json = (dir / "g.json").string();
  const test::Run ok = test::run(test::cli("gap vmc_3axis -q --pdge E_YY=fourier:3 --data " +
                                           std::string(WEILGEN_SOURCE_DIR) +
                                           "/examples/data/vmc_3axis_points.csv --json " + json));
  REQUIRE_MESSAGE(ok.status == 0, ok.out);
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  CHECK(j["baseline"]["parameters"] == 78);
  CHECK(j["baseline"]["rank"] == 46);
  CHECK(j["baseline"]["heldout_rms_all_um"].get<double>() < 10);
}
