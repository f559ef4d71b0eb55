// The generated grinder and VMC models against the papers' printed closed forms, term by term.
// Where a printed equation is wrong, the correct term is pinned here and the machine file's notes
// (and so the generated report) say why.
#include <doctest/doctest.h>

#include <map>

#include "test_support.hpp"
#include "weilgen/codegen/model_builder.hpp"
#include "weilgen/machine/yaml_loader.hpp"

using namespace weilgen;

namespace {

using Terms = std::map<std::string, std::string>;  // error name -> expected coefficient

// Parses `text` with the model's coordinate symbols (lower case) and parameters.
GiNaC::ex parse(const gen::SymbolicModel& m, const std::string& text) {
  GiNaC::symtab table;
  for (const auto& a : m.axes) table[a.coordinate.get_name()] = a.coordinate;
  for (const auto& p : m.params) table[p.get_name()] = p;
  GiNaC::parser reader(table, true);
  return reader(text);
}

// Checks that output o has exactly the expected linear terms (tool_length = 0 as in the papers).
void check_output(const gen::SymbolicModel& m, int o, const Terms& printed,
                  const Terms& corrections,
                  const std::vector<std::string>& printed_but_wrong = {}) {
  Terms expected = printed;
  for (const auto& [k, v] : corrections) expected[k] = v;
  GiNaC::exmap seed_setup;
  for (const auto& p : m.params) seed_setup[p] = 0;
  for (std::size_t i = 0; i < m.errors.size(); ++i) {
    const std::string& name = m.desc.errors[i].name;
    CAPTURE(output_name(static_cast<std::size_t>(o)));
    CAPTURE(name);
    const GiNaC::ex got = m.coefficient(o, {static_cast<std::uint16_t>(i)}).subs(seed_setup);
    const auto it = expected.find(name);
    const GiNaC::ex want = it == expected.end() ? GiNaC::ex(0) : parse(m, it->second);
    CHECK((got - want).expand().is_zero());
  }
  for (const auto& name : printed_but_wrong) {
    CAPTURE(name);
    CHECK(m.coefficient(o, {static_cast<std::uint16_t>(m.desc.error_index(name))}).is_zero());
  }
}

}  // namespace

TEST_CASE("gantry grinder: eqs. (16)-(18) of the reliability seed, with the two corrections") {
  const gen::SymbolicModel m =
      gen::build_model(load_machine_file(test::machine_path("gantry_grinder")), 1);
  // Seed symbols: δxx=E_XX, εxx=E_AX, εyx=E_BX, εzx=E_CX, Sxy=E_C0X, Sxz=E_B0Z, Syz=E_A0Z, ...
  // dx = -δxx - zεyx + yεzx + δxz + δxy + ySxy (18); eq. (17) adds -yεzz, dropped in (18).
  check_output(
      m, 0,
      {{"E_XX", "-1"}, {"E_BX", "-z"}, {"E_CX", "y"}, {"E_XZ", "1"}, {"E_XY", "1"}, {"E_C0X", "y"}},
      {{"E_CZ", "-y"}});
  // dy = -δyx + zεxx + xεzx + δyz + δyy + xSxy
  check_output(
      m, 1,
      {{"E_YX", "-1"}, {"E_AX", "z"}, {"E_CX", "x"}, {"E_YZ", "1"}, {"E_YY", "1"}, {"E_C0X", "x"}},
      {});
  // dz = -δzx - yεxx - xεyx + δzz + yεxz + δzy + ySyz
  check_output(m, 2,
               {{"E_ZX", "-1"},
                {"E_AX", "-y"},
                {"E_BX", "-x"},
                {"E_ZZ", "1"},
                {"E_AZ", "y"},
                {"E_ZY", "1"},
                {"E_A0Z", "y"}},
               {});
  check_output(m, 3, {{"E_AX", "-1"}, {"E_AZ", "1"}, {"E_A0Z", "1"}, {"E_AY", "1"}}, {});
  check_output(m, 4, {{"E_BX", "-1"}, {"E_BZ", "1"}, {"E_B0Z", "1"}, {"E_BY", "1"}}, {});
  // dc printed -εzx + εzz + εzy; eq. (15) makes the X term -(εzx + Sxy).
  check_output(m, 5, {{"E_CX", "-1"}, {"E_CZ", "1"}, {"E_CY", "1"}}, {{"E_C0X", "-1"}});
}

TEST_CASE("VMC: eq. (3) of the 6D-laser seed, with the d_z(z) correction") {
  const gen::SymbolicModel m =
      gen::build_model(load_machine_file(test::machine_path("vmc_3axis")), 1);
  // Seed symbols: d_i(j) = E_<I><J>, ε_ji (axis j about i) = E_<rot i><J>,
  // S_xy = E_C0Y, S_yz = E_A0Z, S_xz = -E_B0Z.
  // Δx = -dx(x) - dx(y) + dx(z) - y(εxz + εyz) - z(εxy + εyy) + ySxy - zSxz
  check_output(m, 0,
               {{"E_XX", "-1"},
                {"E_XY", "-1"},
                {"E_XZ", "1"},
                {"E_CX", "-y"},
                {"E_CY", "-y"},
                {"E_BX", "-z"},
                {"E_BY", "-z"},
                {"E_C0Y", "y"},
                {"E_B0Z", "z"}},
               {});
  // Δy = -dy(x) - dy(y) + dy(z) + xεxz + z(εxx + εyx) - zSyz
  check_output(m, 1,
               {{"E_YX", "-1"},
                {"E_YY", "-1"},
                {"E_YZ", "1"},
                {"E_CX", "x"},
                {"E_AX", "z"},
                {"E_AY", "z"},
                {"E_A0Z", "-z"}},
               {});
  // Δz = -dz(x) - dz(y) + d_y(z) [printed; Table 3 gives d_z(z)] - xεxy + y(εxx + εyx)
  check_output(m, 2, {{"E_ZX", "-1"}, {"E_ZY", "-1"}, {"E_BX", "-x"}, {"E_AX", "y"}, {"E_AY", "y"}},
               {{"E_ZZ", "1"}}, {"E_YZ"});
}

TEST_CASE("two-axis seed example: eq. (5)-style sums of the rotation errors") {
  // Over the dual numbers the orientation errors of serial joints add (seed eq. (5)), rotated by
  // the nominal A rotation for the errors that sit after it.
  const gen::SymbolicModel m =
      gen::build_model(load_machine_file(test::machine_path("two_axis")), 1);
  GiNaC::symtab table;
  for (const auto& a : m.axes)
    if (a.revolute) {
      table["ca"] = a.cos;
      table["sa"] = a.sin;
    }
  GiNaC::parser reader(table, true);
  const auto coeff = [&](int o, const std::string& e) {
    return m.coefficient(o, {static_cast<std::uint16_t>(m.desc.error_index(e))});
  };
  CHECK(coeff(3, "E_AY").is_equal(1));
  CHECK(coeff(3, "E_AA").is_equal(1));
  CHECK((coeff(4, "E_BA") - reader("ca")).expand().is_zero());
  CHECK((coeff(4, "E_CA") + reader("sa")).expand().is_zero());
  CHECK((coeff(5, "E_BA") - reader("sa")).expand().is_zero());
  CHECK((coeff(5, "E_CA") - reader("ca")).expand().is_zero());
}
