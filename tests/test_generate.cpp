// Generation end to end: golden files, determinism, topology edits, order-2 code compiled and
// run, and the CLI's handling of bad input.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "test_support.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/codegen/emit_cpp.hpp"
#include "weilgen/codegen/emit_report.hpp"
#include "weilgen/codegen/generate.hpp"
#include "weilgen/codegen/model_eval.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

using namespace weilgen;
using test::cli;
using test::fresh_dir;
using test::run;
using test::Run;
namespace fs = std::filesystem;

namespace {

std::string text_of(const std::string& path) {
  std::string s;
  REQUIRE(read_file(path, s));
  return s;
}

void replace_once(std::string& s, const std::string& from, const std::string& to) {
  const auto pos = s.find(from);
  REQUIRE_MESSAGE(pos != std::string::npos, from);
  s.replace(pos, from.size(), to);
}

}  // namespace

TEST_CASE("committed generated files are byte-identical to fresh generation, in any order") {
  // Two passes in different orders: GiNaC's internal term order depends on symbol creation order,
  // the output must not.
  std::vector<std::string> names = test::shipped_machines();
  for (int pass = 0; pass < 2; ++pass) {
    for (const auto& name : names) {
      CAPTURE(name);
      const Description d = load_machine_file(test::machine_path(name));
      const auto files =
          gen::generate_files(d, 0, std::string(WEILGEN_SOURCE_DIR) + "/generated", true);
      REQUIRE(files.size() == 4);  // header, report, C API header and source
      CHECK(gen::stale_files(files).empty());
    }
    std::reverse(names.begin(), names.end());
  }
}

TEST_CASE("order-2 generation is deterministic") {
  const Description d = load_machine_file(test::machine_path("five_axis_ac"));
  const auto a = gen::generate_files(d, 2, "x");
  const auto b = gen::generate_files(load_machine_file(test::machine_path("vmc_3axis")), 2, "x");
  const auto c = gen::generate_files(d, 2, "x");
  CHECK(a[0].contents == c[0].contents);
  CHECK(a[1].contents == c[1].contents);
  CHECK(a[0].path == "x/five_axis_ac_o2.hpp");
  CHECK(b[0].contents.find("HigherOrder") != std::string::npos);
}

TEST_CASE("order 2: the pipe cutter's header and report are byte-identical from separate runs") {
  // GiNaC orders terms and picks the sign of sums by hash, which differs between processes; the
  // emitters must not follow it (canonical signs of sums, of their powers and of report
  // coefficients; sign-invariant operand order in CSE).
  std::vector<std::string> headers, reports;
  for (int run_index = 0; run_index < 3; ++run_index) {
    const fs::path dir = fresh_dir("det_o2_" + std::to_string(run_index));
    REQUIRE(run(cli("generate pipe_cutter --order 2 --out " + dir.string())).status == 0);
    headers.push_back(text_of((dir / "pipe_cutter_o2.hpp").string()));
    reports.push_back(text_of((dir / "pipe_cutter_o2.md").string()));
  }
  CHECK(headers[0] == headers[1]);
  CHECK(headers[0] == headers[2]);
  CHECK(reports[0] == reports[1]);
  CHECK(reports[0] == reports[2]);
}

TEST_CASE("topology edit: X moved from the workpiece branch to the tool branch") {
  std::string text = text_of(test::machine_path("vmc_3axis"));
  // Column-moving variant: bed -> X -> Z -> spindle carries the tool; the table rides on Y only.
  replace_once(text, "  x_axis:\n    parent: y_axis", "  x_axis:\n    parent: bed");
  replace_once(text, "  workpiece:\n    parent: x_axis", "  workpiece:\n    parent: y_axis");
  replace_once(text, "  z_axis:\n    parent: bed", "  z_axis:\n    parent: x_axis");
  const fs::path dir = fresh_dir("topology_edit");
  const std::string path = (dir / "vmc_column.yaml").string();
  write_file_atomically(path, text);

  const Description d = load_machine_file(path);
  const gen::SymbolicModel m = gen::build_model(d, 1);
  // X now moves the tool: its positioning error enters dx with +1 instead of -1.
  CHECK(m.coefficient(0, {static_cast<std::uint16_t>(d.error_index("E_XX"))}).is_equal(1));
  const Description original = load_machine_file(test::machine_path("vmc_3axis"));
  CHECK(gen::build_model(original, 1)
            .coefficient(0, {static_cast<std::uint16_t>(original.error_index("E_XX"))})
            .is_equal(-1));

  // The regenerated model still matches the exact chain to O(s²).
  const NumericChain chain(d);
  std::mt19937 rng(3);
  const auto q = test::random_pose(d, rng);
  const auto u = test::random_direction(d, rng);
  const double r1 = test::max_abs_diff(gen::evaluate_model(m, q, test::scaled(u, 0.2)),
                                       chain.deviation(q, test::scaled(u, 0.2)));
  const double r2 = test::max_abs_diff(gen::evaluate_model(m, q, test::scaled(u, 0.1)),
                                       chain.deviation(q, test::scaled(u, 0.1)));
  CHECK(r1 / r2 == doctest::Approx(4).epsilon(0.15));

  // And through the CLI the header is regenerated with the new closed form.
  const Run g = run(cli("generate " + path + " --out " + dir.string()));
  CHECK(g.status == 0);
  const std::string header = text_of((dir / "vmc_3axis.hpp").string());
  CHECK(header.find("vmc_column.yaml") != std::string::npos);
  CHECK(header != text_of(std::string(WEILGEN_SOURCE_DIR) + "/generated/vmc_3axis.hpp"));
}

TEST_CASE("order-2 header compiles standalone (C++20, no exceptions), matches the chain, packs") {
  const fs::path dir = fresh_dir("order2");
  const Run g = run(cli("generate five_axis_ac --order 2 --out " + dir.string()));
  REQUIRE_MESSAGE(g.status == 0, g.out);
  // A driver that evaluates Deviation, and rebuilds it from Coefficients and HigherOrder.
  const std::string driver = R"(#include "five_axis_ac_o2.hpp"
#include <cmath>
#include <cstdio>
#include <cstdlib>
namespace m = weilgen_models::five_axis_ac_o2;
int main(int argc, char** argv) {
  std::array<double, m::kNumAxes> q{};
  std::array<double, m::kNumErrors> e{};
  std::array<double, m::kNumParams> p{};
  int k = 1;
  for (auto& v : q) v = std::atof(argv[k++]);
  for (auto& v : e) v = std::atof(argv[k++]);
  for (std::size_t i = 0; i < p.size(); ++i) p[i] = m::kParams[i].default_value;
  if (k != argc) return 2;
  std::array<double, 3> pos{}, rot{};
  m::Deviation(q, e, p, &pos, &rot);
  std::array<double, 3 * m::kNumErrors> cp{}, cr{};
  m::Coefficients(q, p, &cp, &cr);
  std::array<double, m::kNumOutputs * m::kNumHigherTerms> h{};
  m::HigherOrder(q, p, &h);
  for (std::size_t o = 0; o < 6; ++o) {
    double v = 0;
    for (std::size_t i = 0; i < m::kNumErrors; ++i) v += (o < 3 ? cp[o * m::kNumErrors + i] : cr[(o - 3) * m::kNumErrors + i]) * e[i];
    for (std::size_t t = 0; t < m::kNumHigherTerms; ++t) {
      double mono = h[o * m::kNumHigherTerms + t];
      for (int idx : m::kHigherTerms[t]) if (idx >= 0) mono *= e[static_cast<std::size_t>(idx)];
      v += mono;
    }
    std::printf("%.17g %.17g\n", o < 3 ? pos[o] : rot[o - 3], v);
  }
  // The same functions over Pack<4>, lane l at the errors times (1 + l / 8): every lane must be
  // what the double functions give at its inputs, to 1e-12 of the largest value of its output
  // array (Pack's vector sin/cos is within 1 ulp of the C library's; exit 3 otherwise).
  using P = weilgen_models::Pack<4>;
  std::array<P, m::kNumAxes> pq{};
  std::array<P, m::kNumErrors> pe{};
  std::array<P, m::kNumParams> pp{};
  for (std::size_t i = 0; i < q.size(); ++i) pq[i] = P(q[i]);
  for (std::size_t i = 0; i < p.size(); ++i) pp[i] = P(p[i]);
  for (std::size_t l = 0; l < 4; ++l)
    for (std::size_t i = 0; i < e.size(); ++i) pe[i].Set(l, e[i] * (1.0 + double(l) / 8));
  std::array<P, 3> ppos{}, prot{};
  std::array<P, 3 * m::kNumErrors> pcp{}, pcr{};
  std::array<P, m::kNumOutputs * m::kNumHigherTerms> ph{};
  m::Deviation(pq, pe, pp, &ppos, &prot);
  m::Coefficients(pq, pp, &pcp, &pcr);
  m::HigherOrder(pq, pp, &ph);
  double worst = 0;
  const auto compare = [&](const auto& packs, const auto& doubles, std::size_t l) {
    double scale = 1e-300;
    for (double b : doubles) scale = std::fmax(scale, std::fabs(b));
    for (std::size_t k = 0; k < doubles.size(); ++k)
      worst = std::fmax(worst, std::fabs(packs[k].Get(l) - doubles[k]) / scale);
  };
  for (std::size_t l = 0; l < 4; ++l) {
    std::array<double, m::kNumErrors> el{};
    for (std::size_t i = 0; i < e.size(); ++i) el[i] = e[i] * (1.0 + double(l) / 8);
    m::Deviation(q, el, p, &pos, &rot);
    compare(ppos, pos, l);
    compare(prot, rot, l);
    compare(pcp, cp, l);
    compare(pcr, cr, l);
    compare(ph, h, l);
  }
  std::printf("pack %.3g\n", worst);
  return worst < 1e-12 ? 0 : 3;
})";
  const Description d = load_machine_file(test::machine_path("five_axis_ac"));
  // The same model with Deviation summing the higher terms by its loop over kHigherTable (the
  // form of models with many higher terms, emit_cpp.hpp).
  const fs::path loop_dir = dir / "loop";
  fs::create_directories(loop_dir);
  gen::SymbolicModel o2 = gen::build_model(d, 2);
  o2.desc.name += "_o2";
  const std::string loop_header = gen::emit_cpp_header(o2, "machines/five_axis_ac.yaml", 0);
  REQUIRE(loop_header.find("kHigherTable.size(); k += 3) {\n      at +=") != std::string::npos);
  write_file_atomically((loop_dir / "five_axis_ac_o2.hpp").string(), loop_header);
  // And with MonomialCoefficients in parts of 40 statements (the form of a long one, emit_cpp.hpp
  // SplitLimits): temporaries shared between parts, each part with its own inputs.
  const fs::path split_dir = dir / "split";
  fs::create_directories(split_dir);
  const std::string split_header =
      gen::emit_cpp_header(o2, "machines/five_axis_ac.yaml", gen::kMaxNestedHigherTerms, {0, 40});
  REQUIRE(split_header.find("MonomialCoefficientsPart2<Scalar>(axes, params, _s.data()") !=
          std::string::npos);
  REQUIRE(split_header.find("  _s[0] = ") != std::string::npos);
  write_file_atomically((split_dir / "five_axis_ac_o2.hpp").string(), split_header);
  // The last: Pack without the vector extension (the plain array other compilers get).
  const fs::path portable_dir = dir / "portable";
  fs::create_directories(portable_dir);
  fs::copy_file(dir / "five_axis_ac_o2.hpp", portable_dir / "five_axis_ac_o2.hpp");
  for (const fs::path& include : {dir, loop_dir, split_dir, portable_dir}) {
    CAPTURE(include.string());
    // Beside the header: a quoted include looks in the driver's directory first.
    write_file_atomically((include / "driver.cpp").string(), driver);
    const std::string exe = (include / "driver").string();
    const std::string portable = include == portable_dir ? " -DWEILGEN_MODELS_PACK_PORTABLE" : "";
    const Run c =
        run(std::string(WEILGEN_CXX) +
            " -std=c++20 -O1 -Wall -Wextra -Werror -fno-exceptions -fno-rtti" + portable + " -I" +
            include.string() + " " + (include / "driver.cpp").string() + " -o " + exe);
    REQUIRE_MESSAGE(c.status == 0, c.out);

    const NumericChain chain(d);
    std::mt19937 rng(9);
    const auto q = test::random_pose(d, rng);
    const auto u = test::random_direction(d, rng);
    std::vector<double> residual;
    for (double s : {0.4, 0.2}) {
      const auto e = test::scaled(u, s);
      std::ostringstream args;
      args.precision(17);
      for (double v : q) args << " " << v;
      for (double v : e) args << " " << v;
      const Run r = run(exe + args.str());
      REQUIRE_MESSAGE(r.status == 0, r.out);  // 3: a Pack lane differs from the double result
      CHECK(r.out.find("\npack ") != std::string::npos);
      std::istringstream in(r.out);
      std::array<double, 6> dev{};
      for (int o = 0; o < 6; ++o) {
        double rebuilt = 0;
        in >> dev[o] >> rebuilt;
        CHECK(rebuilt == doctest::Approx(dev[o]).epsilon(1e-9).scale(1e-9));
      }
      residual.push_back(test::max_abs_diff(dev, chain.deviation(q, e)));
    }
    // Third-order residual: halving s divides it by about 8.
    CHECK(residual[0] / residual[1] == doctest::Approx(8).epsilon(0.15));
  }
}

TEST_CASE("order-3 report: closed forms to degree 2, higher terms counted, the largest listed") {
  const Description d = load_machine_file(test::machine_path("five_axis_ac"));
  const gen::SymbolicModel m = gen::build_model(d, 3);
  const std::string md = gen::emit_report_markdown(m, "machines/five_axis_ac.yaml");
  REQUIRE(md.find("## Terms of degree 3 and higher") != std::string::npos);
  CHECK(md.find("weilgen show machines/five_axis_ac.yaml --order 3") != std::string::npos);
  for (int o = 0; o < 6; ++o) {
    // The report's closed form is the full one without its degree-3 terms.
    const std::string shown = gen::closed_form(m, o, gen::FormStyle::Text, gen::Notation::Iso, 2);
    const std::string full = gen::closed_form(m, o, gen::FormStyle::Text, gen::Notation::Iso);
    CHECK(md.find(shown + "\n") != std::string::npos);
    CHECK(full.size() > shown.size());
    CHECK(full.compare(0, shown.size(), shown) == 0);
    // The count table: terms of each degree in the model.
    std::array<int, 4> count{};
    for (const auto& [mono, c] : m.outputs[o].terms()) ++count[mono.size()];
    const std::string row = "| " + std::string(output_name(static_cast<std::size_t>(o))) + " | " +
                            std::to_string(count[1]) + " | " + std::to_string(count[2]) + " | " +
                            std::to_string(count[3]) + " |";
    CHECK_MESSAGE(md.find(row) != std::string::npos, row);
  }
  // The largest degree-3 term of dx at the mid-range pose, found here by GiNaC's own numeric
  // evaluation (subs + evalf), is the first row listed for dx, with its coefficient.
  GiNaC::exmap at;
  for (const auto& a : m.axes) {
    const Joint& j = d.bodies[a.body].joint;
    const double q = (j.min + j.max) / 2;
    at[a.coordinate] = q;
    if (a.revolute) {
      at[a.cos] = std::cos(q * j.to_base);
      at[a.sin] = std::sin(q * j.to_base);
    }
  }
  const auto defaults = d.parameter_defaults();
  for (std::size_t i = 0; i < m.params.size(); ++i)
    at[m.params[i]] = defaults.at(d.parameters[i].name);
  double best = -1;
  std::map<std::string, std::pair<double, double>> dx_terms;  // name -> (coefficient, size)
  for (const auto& [mono, c] : m.outputs[0].terms()) {
    if (mono.size() != 3) continue;
    const double v = GiNaC::ex_to<GiNaC::numeric>(m.with_divisors(c).subs(at).evalf()).to_double();
    double size = std::abs(v);
    for (auto i : mono) {
      const Distribution& dist = d.errors[i].distribution;
      REQUIRE(dist.kind == Distribution::Kind::Normal);
      size *= std::sqrt(dist.a * dist.a + dist.b * dist.b) * d.errors[i].to_base;
    }
    dx_terms[m.monomial_name(mono)] = {v, size};
    best = std::max(best, size);
  }
  // The first dx row of the table of the largest terms (ties may list either of equal terms).
  const auto table = md.find("| output | monomial | coefficient at the pose | size |");
  REQUIRE(table != std::string::npos);
  const auto row = md.find("\n| dx | ", table);
  REQUIRE(row != std::string::npos);
  std::vector<std::string> cells;
  std::istringstream line(md.substr(row + 1, md.find('\n', row + 1) - row - 1));
  for (std::string cell; std::getline(line, cell, '|');)
    if (cell.size() > 2) cells.push_back(cell.substr(1, cell.size() - 2));
  REQUIRE(cells.size() == 4);
  REQUIRE(dx_terms.count(cells[1]) == 1);
  CHECK(cells[2] == format_significant(dx_terms[cells[1]].first, 4));
  CHECK(cells[3] == format_significant(best, 3));
}

TEST_CASE("CLI: bad input exits non-zero with file:line:column and writes nothing") {
  const fs::path dir = fresh_dir("bad_input");
  const std::string bad = (dir / "bad.yaml").string();
  std::string text = text_of(test::machine_path("two_axis"));
  replace_once(text, "axis: y, coordinate: Y", "axis: [0, 0, 0], coordinate: Y");
  write_file_atomically(bad, text);
  write_file_atomically((dir / "two_axis.hpp").string(), "old contents\n");
  const Run r = run(cli("generate " + bad + " --out " + dir.string()));
  CHECK(r.status == 3);
  CHECK(r.out.find(bad + ":") != std::string::npos);
  CHECK(r.out.find("zero") != std::string::npos);
  CHECK(text_of((dir / "two_axis.hpp").string()) == "old contents\n");
  CHECK_FALSE(fs::exists(dir / "two_axis.md"));

  // A good and a bad machine together: nothing is written for either.
  const Run r2 = run(cli("generate two_axis " + bad + " --out " + dir.string()));
  CHECK(r2.status == 3);
  CHECK_FALSE(fs::exists(dir / "two_axis.md"));

  CHECK(run(cli("generate no_such_machine")).status == 3);
  CHECK(run(cli("generate two_axis --order 0")).status == 2);
  CHECK(run(cli("show two_axis --format pdf")).status == 2);
  CHECK(run(cli("frobnicate")).status == 2);
}

TEST_CASE("the banner names the machine file by its path alone, not by where weilgen was built") {
  // A copy of a shipped machine in another directory named machines/, and one elsewhere: the
  // label depends on the path only, so an installed or relocated binary writes the same bytes.
  const fs::path dir = fresh_dir("banner");
  fs::create_directories(dir / "machines");
  const std::string text = text_of(test::machine_path("two_axis"));
  write_file_atomically((dir / "machines" / "two_axis.yaml").string(), text);
  write_file_atomically((dir / "two_axis.yaml").string(), text);
  CHECK(gen::source_label((dir / "machines" / "two_axis.yaml").string()) ==
        "machines/two_axis.yaml");
  CHECK(gen::source_label((dir / "two_axis.yaml").string()) == "two_axis.yaml");
  // The relocated copy generates exactly the committed header, whatever WEILGEN_MACHINES_DIR says.
  ::setenv("WEILGEN_MACHINES_DIR", dir.string().c_str(), 1);
  const auto files =
      gen::generate_files(load_machine_file((dir / "machines" / "two_axis.yaml").string()), 0, "x");
  ::unsetenv("WEILGEN_MACHINES_DIR");
  CHECK(files[0].contents == text_of(std::string(WEILGEN_SOURCE_DIR) + "/generated/two_axis.hpp"));
}

TEST_CASE("CLI: --check reports stale files and exits 1") {
  const fs::path dir = fresh_dir("check");
  CHECK(run(cli("generate two_axis --out " + dir.string())).status == 0);
  CHECK(run(cli("generate two_axis --check --out " + dir.string())).status == 0);
  std::string h = text_of((dir / "two_axis.hpp").string());
  replace_once(h, "kOrder = 1", "kOrder = 7");
  write_file_atomically((dir / "two_axis.hpp").string(), h);
  const Run r = run(cli("generate two_axis --check --out " + dir.string()));
  CHECK(r.status == 1);
  CHECK(r.out.find("two_axis.hpp: stale, 1 of") != std::string::npos);
}

TEST_CASE("CLI: show prints closed forms in text, LaTeX, JSON and the papers' notation") {
  const Run t = run(cli("show gantry_grinder --output dx"));
  CHECK(t.status == 0);
  CHECK(t.out.rfind("dx = -E_XX", 0) == 0);
  CHECK(t.out.find("dy") == std::string::npos);
  const Run a = run(cli("show vmc_3axis --notation alias --output dx"));
  CHECK(a.out.find("- z·Sxz") !=
        std::string::npos);  // S_xz = -E_B0Z, as Zhang & Chen 2021 prints it
  const Run l = run(cli("show gantry_grinder --format latex"));
  CHECK(l.out.find("E_{XX}") != std::string::npos);
  const Run j = run(cli("show gantry_grinder --format json"));
  CHECK(j.out.find("\"closed_form\"") != std::string::npos);
  // Python syntax: the text form with * and ** (the Python package evaluates it against the
  // model, tests/python/test_closed_form.py).
  const Run y = run(cli("show five_axis_ac --format sympy --output dx"));
  CHECK(y.status == 0);
  CHECK(y.out.rfind("dx = cos(c)*E_XX + cos(a)*sin(c)*E_YX", 0) == 0);
  CHECK(y.out.find("·") == std::string::npos);
  CHECK(y.out.find('^') == std::string::npos);
  // The flag table of every verb (the Python package's keywords): --order is a whole number
  // from 1, --format defaults to text.
  const Run f = run(cli("show --flags-json"));
  CHECK(f.status == 0);
  CHECK(f.out.find("\"name\": \"format\"") != std::string::npos);
  CHECK(f.out.find("\"default\": \"text\"") != std::string::npos);
  CHECK(f.out.find("\"text\": \"a whole number from 1 to ") != std::string::npos);
  CHECK(run(cli("--help")).status == 0);
  for (const char* verb : {"generate", "show", "list"})
    CHECK(run(cli(std::string(verb) + " --help")).status == 0);
}
