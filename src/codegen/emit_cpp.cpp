#include "weilgen/codegen/emit_cpp.hpp"

#include <algorithm>
#include <array>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/codegen/cse.hpp"
#include "weilgen/codegen/emit_c_api.hpp"
#include "weilgen/codegen/emit_compensation.hpp"
#include "weilgen/codegen/printer.hpp"
#include "weilgen/machine/model_key.hpp"

namespace weilgen::gen {

using GiNaC::ex;

// The text of templates/model.hpp after its marker line, embedded at build time
// (src/codegen/CMakeLists.txt).
extern const char* const kModelTemplate;

namespace {

std::string string_literal(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

const char* dist_kind(Distribution::Kind k) {
  switch (k) {
    case Distribution::Kind::Normal:
      return "DistributionKind::kNormal";
    case Distribution::Kind::Uniform:
      return "DistributionKind::kUniform";
    case Distribution::Kind::TruncatedNormal:
      return "DistributionKind::kTruncatedNormal";
    case Distribution::Kind::None:
      break;
  }
  return "DistributionKind::kNone";
}

const char* placement_name(ErrorPlacement p) {
  switch (p) {
    case ErrorPlacement::After:
      return "after";
    case ErrorPlacement::Before:
      return "before";
    case ErrorPlacement::Axis:
      return "axis";
  }
  return "";
}

// Symbol name → C++ identifier, and the statement that defines each input from the arguments.
struct InputTable {
  std::map<std::string, std::string> code_name;
  std::map<std::string, std::string> definition;  // by code name
  std::vector<std::string> order;                 // code names in declaration order
  // Inputs computed from others (reciprocals of divisors): code name -> the code names it uses.
  std::map<std::string, std::set<std::string>> depends;
  std::map<std::string, OpCount> cost;  // operations of a computed input's definition
};

void collect_symbols(const ex& e, std::set<std::string>& out);

InputTable inputs_of(const SymbolicModel& m) {
  InputTable t;
  std::set<std::string> taken;
  auto add = [&](const std::string& sym, const std::string& code, const std::string& def) {
    if (!taken.insert(code).second)
      throw std::runtime_error("name clash in generated code: '" + code +
                               "' is both a coordinate, an error or a parameter name");
    t.code_name[sym] = code;
    t.definition[code] = def;
    t.order.push_back(code);
  };
  for (std::size_t i = 0; i < m.axes.size(); ++i) {
    const auto& a = m.axes[i];
    const Joint& j = m.desc.bodies[a.body].joint;
    add(a.coordinate.get_name(), j.coordinate, "axes[" + std::to_string(i) + "]");
    if (a.revolute) {
      const std::string arg = j.coordinate + " * Scalar(" + format_literal(j.to_base) + ")";
      add(a.cos.get_name(), "cos_" + j.coordinate, "cos(" + arg + ")");
      add(a.sin.get_name(), "sin_" + j.coordinate, "sin(" + arg + ")");
    }
  }
  for (std::size_t i = 0; i < m.errors.size(); ++i)
    add(m.errors[i].get_name(), m.errors[i].get_name(), "errors[" + std::to_string(i) + "]");
  for (std::size_t i = 0; i < m.params.size(); ++i)
    add(m.params[i].get_name(), m.params[i].get_name(), "params[" + std::to_string(i) + "]");
  // Reciprocals of derived divisors, once per call (model_builder.hpp, Reciprocal).
  for (const Reciprocal& r : m.reciprocals) {
    ExprPrinter pr(ExprPrinter::Style::Cpp, t.code_name);
    const std::string code = r.symbol.get_name();
    add(code, code, "Scalar(1) / (" + pr.print(r.divisor) + ")");
    std::set<std::string> syms;
    collect_symbols(r.divisor, syms);
    for (const auto& sym : syms) t.depends[code].insert(t.code_name.at(sym));
    OpCount c = pr.ops();
    ++c.divs;
    t.cost[code] = c;
  }
  return t;
}

void collect_symbols(const ex& e, std::set<std::string>& out) {
  if (GiNaC::is_a<GiNaC::symbol>(e)) {
    out.insert(GiNaC::ex_to<GiNaC::symbol>(e).get_name());
    return;
  }
  for (std::size_t i = 0; i < e.nops(); ++i) collect_symbols(e.op(i), out);
}

struct OutputGroup {
  std::string pointer;  // argument name
  std::vector<ex> values;
  bool fill_zeros = false;  // one fill() instead of an assignment per zero (sparse outputs)
  std::string alias = {};   // the reference the assignments use; empty: "_" + pointer
};

// Named coefficient polynomials of a Deviation-style function: every coefficient that is a sum
// or a product of several symbols gets a placeholder `_coefN` (shared by all outputs and
// monomials), and the error monomials with the same placeholder are grouped,
// _coef3·(E_AA + E_AY − E_A0A), instead of repeating the product per error. Signs and numeric
// factors are chosen canonically: GiNaC would otherwise pick the sign of a sum inside a product
// by its hash order, which varies between runs.
struct Coefficients {
  std::vector<std::pair<GiNaC::symbol, ex>> defs;
  std::map<std::string, GiNaC::symbol> by_text;
  CanonicalText canon;
  // Every coefficient but a number gets a placeholder (single symbols too), named
  // `<prefix>N<suffix>`: the shared MonomialCoefficients of models with higher terms use `_c[N]`.
  bool everything = false;
  // Each placeholder's polynomial with its common factors collected (with_common_factors).
  bool factored = false;
  std::string prefix = "_coef", suffix;

  // c = factor · placeholder, or nullopt when c is a number or (unless `everything`) a single
  // symbol (used inline).
  std::optional<std::pair<ex, GiNaC::symbol>> split(const ex& c) {
    ex factor = 1, rest = c;
    if (GiNaC::is_a<GiNaC::mul>(c)) {
      rest = 1;
      for (std::size_t i = 0; i < c.nops(); ++i) {
        const ex op = c.op(i);
        if (GiNaC::is_a<GiNaC::numeric>(op)) {
          factor *= op;
        } else if (GiNaC::is_a<GiNaC::add>(op)) {
          // Sums in canonical sign: GiNaC's choice varies between runs.
          const CanonicalText::Signed r = canon.canonical_sign(op);
          if (r.negated) factor = -factor;
          rest *= r.value;
        } else {
          rest *= op;
        }
      }
      if (everything ? GiNaC::is_a<GiNaC::numeric>(rest)
                     : !GiNaC::is_a<GiNaC::mul>(rest) && !GiNaC::is_a<GiNaC::power>(rest))
        return std::nullopt;
    } else if (!GiNaC::is_a<GiNaC::add>(c)) {
      if (!everything || GiNaC::is_a<GiNaC::numeric>(c)) return std::nullopt;
    } else {
      const CanonicalText::Signed r = canon.canonical_sign(c);
      rest = r.value;
      if (r.negated) factor = -1;
    }
    const std::string& key = canon.of(rest);
    auto it = by_text.find(key);
    if (it == by_text.end()) {
      GiNaC::symbol sym(prefix + std::to_string(defs.size()) + suffix);
      defs.emplace_back(sym, factored ? with_common_factors(rest, canon) : rest);
      it = by_text.emplace(key, sym).first;
    }
    return std::make_pair(factor, it->second);
  }

  // The first-order coefficients ∂output/∂error_i, position and orientation rows, each written
  // as factor · placeholder when it is one (the same canonical sign as in the outputs).
  void first_order(const SymbolicModel& m, std::vector<ex>& pos, std::vector<ex>& rot) {
    for (int o = 0; o < 6; ++o)
      for (std::size_t i = 0; i < m.errors.size(); ++i) {
        const ex c = m.coefficient(o, {static_cast<std::uint16_t>(i)});
        const auto s = split(c);
        (o < 3 ? pos : rot).push_back(s ? s->first * s->second : c);
      }
  }

  // c = factor · symbol (an axis, a parameter, sin/cos of an axis), or nullopt: the monomials
  // with such a coefficient are grouped like those of a placeholder, Y·(E_C0X + E_CX − E_CZ),
  // one multiplication for the group instead of one per error.
  static std::optional<std::pair<ex, GiNaC::symbol>> symbol_times_number(const ex& c) {
    if (GiNaC::is_a<GiNaC::symbol>(c)) return std::make_pair(ex(1), GiNaC::ex_to<GiNaC::symbol>(c));
    if (!GiNaC::is_a<GiNaC::mul>(c) || c.nops() != 2) return std::nullopt;
    for (std::size_t i = 0; i < 2; ++i)
      if (GiNaC::is_a<GiNaC::numeric>(c.op(i)) && GiNaC::is_a<GiNaC::symbol>(c.op(1 - i)))
        return std::make_pair(c.op(i), GiNaC::ex_to<GiNaC::symbol>(c.op(1 - i)));
    return std::nullopt;
  }

  // Σ c_m · monomial_m of one output, grouped by placeholder, each group's monomials (and those
  // with an inline coefficient) in nested form (factored_sum).
  // With max_degree > 0, only the monomials up to that degree.
  ex output(const Poly& p, const std::vector<GiNaC::symbol>& errors, int max_degree = 0) {
    using Terms = std::vector<std::pair<Monomial, ex>>;
    Terms direct;
    std::map<std::string, std::pair<GiNaC::symbol, Terms>> grouped;
    for (const auto& [mono, c] : p.terms()) {
      if (max_degree > 0 && static_cast<int>(mono.size()) > max_degree) continue;
      std::optional<std::pair<ex, GiNaC::symbol>> s = split(c);
      if (!s) s = symbol_times_number(c);
      if (s) {
        auto& g = grouped[s->second.get_name()];
        g.first = s->second;
        g.second.emplace_back(mono, s->first);
      } else {
        direct.emplace_back(mono, c);
      }
    }
    GiNaC::exvector parts{factored_sum(std::move(direct), errors)};
    for (auto& [name, g] : grouped)
      parts.push_back(g.first * factored_sum(std::move(g.second), errors));
    return GiNaC::add(parts);
  }
};

struct FunctionCode {
  std::string body;
  OpCount ops;
  std::size_t temps = 0;
};

// Body of a generated function: used inputs, one CSE pass over all groups, guarded outputs.
// The "// Inputs" block declaring the inputs that the symbols `used` name (and the inputs the
// computed ones need); their cost (sin/cos calls, reciprocals) is added to `cost`.
std::string inputs_block(const InputTable& inputs, const std::set<std::string>& used,
                         OpCount& cost) {
  std::set<std::string> used_code;
  for (const auto& s : used)
    if (auto it = inputs.code_name.find(s); it != inputs.code_name.end())
      used_code.insert(it->second);
  // cos/sin of a coordinate need the coordinate itself; each costs a call and a multiply.
  const auto is_trig = [](const std::string& code) {
    return code.rfind("cos_", 0) == 0 || code.rfind("sin_", 0) == 0;
  };
  // Computed inputs (reverse declaration order: they may use earlier ones) pull in what they use.
  for (auto it = inputs.order.rbegin(); it != inputs.order.rend(); ++it) {
    if (!used_code.count(*it) || !inputs.depends.count(*it)) continue;
    used_code.insert(inputs.depends.at(*it).begin(), inputs.depends.at(*it).end());
    cost += inputs.cost.at(*it);
  }
  for (const auto& code : inputs.order)
    if (used_code.count(code) && is_trig(code)) {
      used_code.insert(code.substr(4));
      ++cost.functions;
      ++cost.muls;
    }
  std::ostringstream os;
  os << "  // Inputs\n";
  for (const auto& code : inputs.order)
    if (used_code.count(code))
      os << "  const Scalar " << code << " = " << inputs.definition.at(code) << ";\n";
  return os.str();
}

FunctionCode function_body(const InputTable& inputs, const std::vector<OutputGroup>& groups,
                           const Coefficients* coefficients = nullptr) {
  std::vector<ex> all;
  const std::size_t ncoef = coefficients ? coefficients->defs.size() : 0;
  for (std::size_t k = 0; k < ncoef; ++k) all.push_back(coefficients->defs[k].second);
  for (const auto& g : groups) all.insert(all.end(), g.values.begin(), g.values.end());
  const CseResult cse = eliminate_common_subexpressions(all);

  std::set<std::string> used;
  for (const auto& t : cse.temps) collect_symbols(t.value, used);
  for (const auto& o : cse.outputs) collect_symbols(o, used);

  ExprPrinter printer(ExprPrinter::Style::Cpp, inputs.code_name);
  std::ostringstream os;
  OpCount trig;
  os << inputs_block(inputs, used, trig);
  os << "\n  // Intermediate terms (" << cse.temps.size() << ")\n";
  for (const auto& t : cse.temps)
    os << "  const Scalar " << t.symbol.get_name() << " = " << printer.print(t.value) << ";\n";
  if (ncoef > 0) os << "\n  // Coefficients of the error monomials (" << ncoef << ")\n";
  for (std::size_t k = 0; k < ncoef; ++k)
    os << "  const Scalar " << coefficients->defs[k].first.get_name() << " = "
       << printer.print(cse.outputs[k]) << ";\n";
  os << "\n  // Outputs\n";
  std::size_t k = ncoef;
  for (const auto& g : groups) {
    const std::string alias = g.alias.empty() ? "_" + g.pointer : g.alias;
    os << "  if (" << g.pointer << " != nullptr) {\n";
    os << "    auto& " << alias << " = *" << g.pointer << ";\n";
    if (g.fill_zeros) os << "    " << alias << ".fill(Scalar(0));\n";
    for (std::size_t i = 0; i < g.values.size(); ++i, ++k) {
      if (g.fill_zeros && cse.outputs[k].is_zero()) continue;
      // Neighbours 2j, 2j + 1 by one StorePair (model.hpp: a 16-byte store for double); compilers
      // store them one by one otherwise, and the stores bound these functions.
      if (!g.fill_zeros && i % 2 == 0 && i + 1 < g.values.size()) {
        os << "    StorePair(" << alias << ".data()" << (i ? " + " + std::to_string(i) : "") << ", "
           << printer.print(cse.outputs[k]) << ", " << printer.print(cse.outputs[k + 1]) << ");\n";
        ++i;
        ++k;
        continue;
      }
      os << "    " << alias << "[" << i << "] = " << printer.print(cse.outputs[k]) << ";\n";
    }
    os << "  }\n";
  }
  FunctionCode fc{os.str(), printer.ops(), cse.temps.size()};
  fc.ops += trig;
  return fc;
}

// A long function in parts (split_function, emit_cpp.hpp's kSplitStatements): a compiler's time
// and memory grow faster than the length of a function (g++ -O2 took 228 s and 2.2 GiB for the
// pipe cutter's order-3 MonomialCoefficients of 16 208 statements), so it becomes functions of
// at most `part_statements` statements each, called in order. A temporary used by a later part
// is the element `_s[slot]` of a shared array in every part; every part declares the inputs it
// uses.

struct SplitCode {
  std::string parts;  // the part functions' definitions
  std::string calls;  // the body of the function that calls them
  OpCount ops;
  std::size_t temps = 0, parts_count = 0, shared = 0;
};

// `values` into `alias`[i] (an std::array<Scalar, size_name>&) by the functions
// `name`Part0, `name`Part1, ... with the arguments of `signature` ("const std::array<Scalar,
// kNumAxes>& axes, ...") and `arguments` ("axes, params"); `calls` guards on `pointer`.
SplitCode split_function(const InputTable& inputs, const std::vector<ex>& values,
                         const std::string& name, const std::string& signature,
                         const std::string& arguments, const std::string& pointer,
                         const std::string& alias, const std::string& size_name,
                         const SplitLimits& limits) {
  const CseResult cse = eliminate_common_subexpressions(values);
  const std::size_t nt = cse.temps.size(), total = nt + cse.outputs.size();
  SplitCode out;
  if (total <= limits.split_statements || total == 0) return out;  // parts_count 0: one function
  const std::size_t per = std::max<std::size_t>(1, limits.part_statements);
  const std::size_t parts = (total + per - 1) / per;
  // Statements: temporaries 0 .. nt-1, outputs nt ... In the order written, each temporary comes
  // just before its first use (outputs in order, a temporary's own temporaries first), so that
  // most are used inside their own part.
  std::map<std::string, std::size_t> temp_index;
  for (std::size_t i = 0; i < nt; ++i) temp_index[cse.temps[i].symbol.get_name()] = i;
  std::vector<std::set<std::size_t>> uses(total);  // the temporaries each statement uses
  std::vector<std::set<std::string>> symbols(total);
  for (std::size_t i = 0; i < total; ++i) {
    collect_symbols(i < nt ? cse.temps[i].value : cse.outputs[i - nt], symbols[i]);
    for (const auto& sym : symbols[i])
      if (auto it = temp_index.find(sym); it != temp_index.end()) uses[i].insert(it->second);
  }
  std::vector<std::size_t> order;
  std::vector<char> placed(nt, 0);
  for (std::size_t o = nt; o < total; ++o) {
    // Depth-first over the temporaries the output needs (an explicit stack: chains can be long).
    std::vector<std::pair<std::size_t, bool>> stack{{o, false}};
    while (!stack.empty()) {
      auto [i, expanded] = stack.back();
      stack.pop_back();
      if (expanded) {
        if (i >= nt || !placed[i]) order.push_back(i);
        if (i < nt) placed[i] = 1;
        continue;
      }
      if (i < nt && placed[i]) continue;
      stack.push_back({i, true});
      for (auto it = uses[i].rbegin(); it != uses[i].rend(); ++it)
        if (!placed[*it]) stack.push_back({*it, false});
    }
  }
  for (std::size_t t = 0; t < nt; ++t)
    if (!placed[t]) order.push_back(t);  // unused by any output (not expected)
  std::vector<std::size_t> position(total);
  for (std::size_t k = 0; k < total; ++k) position[order[k]] = k;
  auto part_of = [&](std::size_t k) { return k * parts / total; };  // by position, even parts
  // A temporary used in a later part than its own is shared.
  std::vector<std::size_t> slot(nt, SIZE_MAX);
  for (std::size_t k = 0; k < total; ++k)
    for (std::size_t t : uses[order[k]])
      if (part_of(position[t]) != part_of(k) && slot[t] == SIZE_MAX) slot[t] = out.shared++;
  // A shared temporary is `_s[slot]` wherever it appears (as long a name as `_tmpN`).
  std::map<std::string, std::string> names = inputs.code_name;
  for (std::size_t t = 0; t < nt; ++t)
    if (slot[t] != SIZE_MAX)
      names[cse.temps[t].symbol.get_name()] = "_s[" + std::to_string(slot[t]) + "]";
  ExprPrinter printer(ExprPrinter::Style::Cpp, names);
  std::ostringstream defs;
  std::size_t begin = 0;
  for (std::size_t part = 0; part < parts; ++part) {
    std::size_t end = begin;
    while (end < total && part_of(end) == part) ++end;
    std::set<std::string> used;
    for (std::size_t k = begin; k < end; ++k)
      used.insert(symbols[order[k]].begin(), symbols[order[k]].end());
    std::ostringstream body;
    body << inputs_block(inputs, used, out.ops) << "\n";
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t i = order[k];
      if (i < nt) {
        const std::string value = printer.print(cse.temps[i].value);
        if (slot[i] == SIZE_MAX)
          body << "  const Scalar " << cse.temps[i].symbol.get_name() << " = " << value << ";\n";
        else
          body << "  _s[" << slot[i] << "] = " << value << ";\n";
      } else {
        body << "  " << alias << "[" << i - nt << "] = " << printer.print(cse.outputs[i - nt])
             << ";\n";
      }
    }
    defs << "template <typename Scalar>\nWEILGEN_MODELS_NOINLINE void " << name << "Part" << part
         << "(" << signature << ", Scalar* const _s,\n    std::array<Scalar, " << size_name << ">& "
         << alias << ") {\n  using std::cos;\n  using std::sin;\n  using std::sqrt;\n"
         << body.str() << "}\n\n";
    begin = end;
  }
  std::ostringstream calls;
  calls << "  if (" << pointer << " == nullptr) return;\n"
        << "  // Temporaries that later parts use (" << out.shared
        << "), each written before it is read.\n"
        << "  std::array<Scalar, " << std::max<std::size_t>(out.shared, 1) << "> _s;\n";
  for (std::size_t part = 0; part < parts; ++part)
    calls << "  " << name << "Part" << part << "<Scalar>(" << arguments << ", _s.data(), *"
          << pointer << ");\n";
  out.ops += printer.ops();
  out.temps = nt;
  out.parts_count = parts;
  out.parts = defs.str();
  out.calls = calls.str();
  return out;
}

// Items of a long initializer list, several to a line of at most 98 characters.
std::string packed_lines(const std::vector<std::string>& items) {
  std::string out, line;
  for (const auto& item : items) {
    if (line.size() + item.size() > 98) {
      out += line + "\n";
      line.clear();
    }
    line += item;
  }
  if (!line.empty()) out += line + "\n";
  return out;
}

// kMaxNestedHigherTerms (emit_cpp.hpp): the nested form costs about 8 bytes of header per
// coefficient (0.7 MB of the pipe cutter's order-3 header), the loop 3-4 times the time per call
// (measured at order 2). Every shipped machine up to order 3 stays nested except the pipe cutter
// at order 3 (91 791).

// A model with terms of degree >= 2: every coefficient that is not a number is defined once, as
// `_c[N]` of MonomialCoefficients, and the functions use them: DeviationAndCoefficients (the
// monomials in nested form, the first-order coefficients as factor·_c[N]), Deviation (which
// calls it without the coefficients) and HigherOrder, a loop over a table (output, term) →
// (coefficient, numeric factor) instead of one assignment per term.
struct HigherTable {
  FunctionCode monomial, deviation, deviation_and_coefficients, higher_order;
  std::size_t count = 0;       // kNumMonomialCoefficients
  std::string tables;          // kHigherFactors and kHigherTable
  std::string monomial_parts;  // MonomialCoefficients' parts when split (split_function)
  std::size_t parts = 0;
};

HigherTable higher_table(const SymbolicModel& m, const std::vector<Monomial>& higher,
                         const InputTable& inputs, std::size_t max_nested,
                         const SplitLimits& limits) {
  Coefficients shared;
  shared.everything = true;
  shared.prefix = "_c[";
  shared.suffix = "]";
  // Deviation writes every monomial in nested form, or (many higher terms) the first-order part
  // nested plus _h[o], the higher terms summed by a loop over the table.
  std::size_t entries = 0;
  for (const Poly& p : m.outputs)
    for (const auto& [mono, c] : p.terms()) entries += mono.size() >= 2;
  const bool nested = entries <= max_nested;
  std::vector<ex> pos, rot, spos, srot;
  for (int o = 0; o < 6; ++o) {
    ex out = shared.output(m.outputs[o], m.errors, nested ? 0 : 1);
    if (!nested) out += GiNaC::symbol("_h[" + std::to_string(o) + "]");
    (o < 3 ? pos : rot).push_back(out);
  }
  shared.first_order(m, spos, srot);
  // The table, term by term (each monomial is formed once): per non-zero coefficient, the step
  // from the previous entry's index term * kNumOutputs + output, its placeholder (none: the
  // number 1) and its numeric factor.
  std::vector<std::tuple<std::size_t, std::string, std::size_t>> rows;
  std::vector<GiNaC::numeric> factors;
  std::size_t at = 0, last = 0;
  for (const Monomial& mono : higher)
    for (int o = 0; o < 6; ++o, ++at) {
      const ex c = m.coefficient(o, mono);
      if (c.is_zero()) continue;
      const auto s = shared.split(c);
      const GiNaC::numeric f = GiNaC::ex_to<GiNaC::numeric>(s ? s->first : c);
      auto it = std::find_if(factors.begin(), factors.end(),
                             [&](const GiNaC::numeric& x) { return x.is_equal(f); });
      if (it == factors.end()) it = factors.insert(factors.end(), f);
      rows.emplace_back(at - last, s ? s->second.get_name() : std::string(),
                        static_cast<std::size_t>(it - factors.begin()));
      last = at;
    }
  std::map<std::string, std::size_t> index;
  for (std::size_t k = 0; k < shared.defs.size(); ++k) index[shared.defs[k].first.get_name()] = k;

  HigherTable t;
  t.count = shared.defs.size();
  std::vector<ex> values;
  for (const auto& def : shared.defs) values.push_back(def.second);
  // A short name for the ~10 000 assignments (`_k[N] = ...`).
  const SplitCode split = split_function(
      inputs, values, "MonomialCoefficients",
      "[[maybe_unused]] const std::array<Scalar, kNumAxes>& axes,\n    [[maybe_unused]] const "
      "std::array<Scalar, kNumParams>& params",
      "axes, params", "coefficients", "_k", "kNumMonomialCoefficients", limits);
  if (split.parts_count == 0) {
    t.monomial = function_body(inputs, {{"coefficients", values, false, "_k"}});
  } else {
    t.monomial = {split.calls, split.ops, split.temps};
    t.monomial_parts = split.parts;
    t.parts = split.parts_count;
  }
  const std::string call =
      "  std::array<Scalar, kNumMonomialCoefficients> _c{};\n"
      "  MonomialCoefficients(axes, params, &_c);\n";
  const std::string coefficient =
      "(c < kNumMonomialCoefficients ? _c[c] : Scalar(1)) * "
      "Scalar(kHigherFactors[kHigherTable[k + 2]])";
  const std::string higher_sum =
      "  // The terms of degree >= 2, monomial by monomial (kHigherTable).\n"
      "  std::array<Scalar, kNumOutputs> _h{};\n"
      "  if (position != nullptr || orientation != nullptr) {\n"
      "    std::size_t at = 0, term = kNumHigherTerms;\n"
      "    Scalar monomial(1);\n"
      "    for (std::size_t k = 0; k < kHigherTable.size(); k += 3) {\n"
      "      at += kHigherTable[k];\n"
      "      if (at / kNumOutputs != term) {\n"
      "        term = at / kNumOutputs;\n"
      "        monomial = Scalar(1);\n"
      "        for (const int i : kHigherTerms[term])\n"
      "          if (i >= 0) monomial = monomial * errors[static_cast<std::size_t>(i)];\n"
      "      }\n"
      "      const std::uint32_t c = kHigherTable[k + 1];\n"
      "      _h[at % kNumOutputs] = _h[at % kNumOutputs] + " +
      coefficient +
      " * monomial;\n"
      "    }\n"
      "  }\n\n";
  // The loop: per entry three multiplications (coefficient, factor, monomial) and an addition;
  // per monomial of degree d, d multiplications.
  OpCount loop;
  loop.muls = 3 * static_cast<long>(rows.size());
  loop.adds = static_cast<long>(rows.size());
  for (const Monomial& mono : higher) loop.muls += static_cast<long>(mono.size());
  t.deviation_and_coefficients = function_body(inputs, {{"position", pos},
                                                        {"orientation", rot},
                                                        {"position_coeff", spos},
                                                        {"orientation_coeff", srot}});
  t.deviation_and_coefficients.body =
      call + (nested ? "\n" : higher_sum) + t.deviation_and_coefficients.body;
  if (nested) loop = {};
  t.deviation_and_coefficients.ops += t.monomial.ops;
  t.deviation_and_coefficients.ops += loop;
  t.deviation_and_coefficients.temps += t.monomial.temps;
  // Deviation's cost: the coefficients, the loop and the outputs (its body only forwards).
  t.deviation = function_body(inputs, {{"position", pos}, {"orientation", rot}});
  t.deviation.ops += t.monomial.ops;
  t.deviation.ops += loop;
  t.deviation.temps += t.monomial.temps;
  t.deviation.body =
      "  DeviationAndCoefficients<Scalar>(axes, errors, params, position, orientation, nullptr,\n"
      "                                   nullptr);\n";
  t.higher_order.ops = t.monomial.ops;
  t.higher_order.ops.muls += static_cast<long>(rows.size());
  t.higher_order.temps = t.monomial.temps;
  t.higher_order.body = "  if (terms == nullptr) return;\n" + call +
                        "  auto& _terms = *terms;\n"
                        "  _terms.fill(Scalar(0));\n"
                        "  std::size_t at = 0;\n"
                        "  for (std::size_t k = 0; k < kHigherTable.size(); k += 3) {\n"
                        "    at += kHigherTable[k];\n"
                        "    const std::uint32_t c = kHigherTable[k + 1];\n"
                        "    _terms[at % kNumOutputs * kNumHigherTerms + at / kNumOutputs] =\n"
                        "        " +
                        coefficient +
                        ";\n"
                        "  }\n";

  std::ostringstream os;
  os << "// The terms of degree >= 2 as a table, read by HigherOrder (and by "
        "DeviationAndCoefficients\n"
        "// when it sums them by a loop): per non-zero coefficient, term by term, the step from "
        "the\n"
        "// previous entry's index term * kNumOutputs + output, the index of its "
        "MonomialCoefficients\n"
        "// value (kNumMonomialCoefficients: the number 1) and of its numeric factor in "
        "kHigherFactors.\n";
  os << "inline constexpr std::array<double, " << factors.size() << "> kHigherFactors = {{";
  for (std::size_t i = 0; i < factors.size(); ++i)
    os << (i ? ", " : "") << format_literal(factors[i].to_double());
  os << "}};\n";
  os << "inline constexpr std::array<std::uint32_t, " << 3 * rows.size() << "> kHigherTable = {{\n";
  std::vector<std::string> items;
  for (const auto& [step, name, factor] : rows) {
    const std::size_t k = name.empty() ? t.count : index.at(name);
    items.push_back(std::to_string(step) + "," + std::to_string(k) + "," + std::to_string(factor) +
                    ",");
  }
  os << packed_lines(items);
  os << "}};\n\n";
  t.tables = os.str();
  return t;
}

std::string doc_list(const std::vector<std::string>& names) {
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i) s += (i ? ", " : "") + names[i];
  return s;
}

// The generated functions' bodies with their operation counts, before the template places them.
struct ModelCode {
  std::vector<Monomial> higher;  // monomials of degree >= 2 with a non-zero coefficient
  FunctionCode coefficients, deviation, deviation_and_coefficients, higher_order, nominal_pose,
      nominal_jacobian;
  HigherTable table;  // the shared coefficient polynomials (only with `higher`)
};

// The cheaper of a function generated as written and with its coefficients' common factors
// collected (with_common_factors): collecting saves operations when the factored sums are shared
// (pipe cutter 676 → 509) but can cost some where they are not (five_axis_ac 331 → 334), and
// only the CSE over the whole function tells.
template <typename Build>
FunctionCode fewer_operations(const Build& build) {
  FunctionCode plain = build(false), factored = build(true);
  return factored.ops.total() < plain.ops.total() ? factored : plain;
}

// Coefficients: ∂output/∂error at zero error, row-major [output][error].
FunctionCode coefficients_function(const SymbolicModel& m, const InputTable& inputs) {
  return fewer_operations([&](bool factored) {
    std::vector<ex> pos, rot;
    CanonicalText canon;
    for (int o = 0; o < 6; ++o)
      for (std::size_t i = 0; i < m.errors.size(); ++i) {
        const ex c = m.coefficient(o, {static_cast<std::uint16_t>(i)});
        (o < 3 ? pos : rot).push_back(factored ? with_common_factors(c, canon) : c);
      }
    return function_body(inputs, {{"position_coeff", pos}, {"orientation_coeff", rot}});
  });
}

// Deviation and DeviationAndCoefficients of a model without terms of degree >= 2: the full
// algebra element of each output, its coefficients named once.
void first_order_functions(const SymbolicModel& m, const InputTable& inputs, ModelCode& code) {
  const auto deviation_outputs = [&](Coefficients& coefs, std::vector<ex>& pos,
                                     std::vector<ex>& rot) {
    for (int o = 0; o < 6; ++o) (o < 3 ? pos : rot).push_back(coefs.output(m.outputs[o], m.errors));
  };
  code.deviation = fewer_operations([&](bool factored) {
    Coefficients coefs;
    coefs.factored = factored;
    std::vector<ex> pos, rot;
    deviation_outputs(coefs, pos, rot);
    return function_body(inputs, {{"position", pos}, {"orientation", rot}}, &coefs);
  });
  // Both at once: one CSE over the deviation and the coefficients, so that the sin/cos of the
  // axes and the nominal terms they share are computed once. A coefficient that is a named
  // coefficient of Deviation is written as factor·_coefN (the same canonical sign), so that the
  // two are not computed twice under different signs.
  code.deviation_and_coefficients = fewer_operations([&](bool factored) {
    Coefficients shared;
    shared.factored = factored;
    std::vector<ex> pos, rot, spos, srot;
    deviation_outputs(shared, pos, rot);
    shared.first_order(m, spos, srot);
    return function_body(inputs,
                         {{"position", pos},
                          {"orientation", rot},
                          {"position_coeff", spos},
                          {"orientation_coeff", srot}},
                         &shared);
  });
}

// The pose at zero errors.
FunctionCode nominal_pose_function(const SymbolicModel& m, const InputTable& inputs) {
  std::vector<ex> pos, rot;
  for (int i = 0; i < 3; ++i) {
    pos.push_back(m.nominal[i][3]);
    for (int j = 0; j < 3; ++j) rot.push_back(m.nominal[i][j]);
  }
  return function_body(inputs, {{"position", pos}, {"rotation", rot}});
}

// The nominal pose's Jacobian in the axes' units: a revolute column per deg is the per-rad
// derivative times to_base, a named constant `_to_baseN * (...)` rather than multiplied into
// every term.
FunctionCode nominal_jacobian_function(const SymbolicModel& m, const InputTable& inputs) {
  InputTable with_units = inputs;
  std::map<double, GiNaC::symbol> unit_factor;
  std::vector<ex> jac(m.nominal_jacobian.size());
  const std::size_t na = m.axes.size();
  for (std::size_t k = 0; k < jac.size(); ++k) {
    const double to_base = m.desc.bodies[m.axes[k % na].body].joint.to_base;
    jac[k] = m.nominal_jacobian[k];
    if (to_base == 1.0 || jac[k].is_zero()) continue;
    auto it = unit_factor.find(to_base);
    if (it == unit_factor.end()) {
      const std::string code = "_to_base" + std::to_string(unit_factor.size());
      it = unit_factor.emplace(to_base, GiNaC::symbol(code)).first;
      with_units.code_name[code] = code;
      with_units.definition[code] = "Scalar(" + format_literal(to_base) + ")";
      with_units.order.push_back(code);
    }
    jac[k] = it->second * jac[k];
  }
  return function_body(with_units, {{"jacobian", jac}});
}

ModelCode model_code(const SymbolicModel& m, std::size_t max_nested_higher_terms,
                     const SplitLimits& split) {
  const InputTable inputs = inputs_of(m);
  ModelCode code;
  code.higher = m.higher_monomials();
  code.coefficients = coefficients_function(m, inputs);
  if (code.higher.empty()) {
    first_order_functions(m, inputs, code);
  } else {
    code.table = higher_table(m, code.higher, inputs, max_nested_higher_terms, split);
    code.deviation = code.table.deviation;
    code.deviation_and_coefficients = code.table.deviation_and_coefficients;
    code.higher_order = code.table.higher_order;
  }
  code.nominal_pose = nominal_pose_function(m, inputs);
  code.nominal_jacobian = nominal_jacobian_function(m, inputs);
  return code;
}

// The banner's lines that name the source, the machine and the algebra.
std::string banner_block(const SymbolicModel& m, const std::string& source_label) {
  const Description& d = m.desc;
  std::ostringstream os;
  os << "// GENERATED by weilgen " << kVersion << " from " << source_label
     << ". Do not edit: edit the machine file and run `weilgen generate`.\n";
  os << "// Machine: " << d.name << (d.title.empty() ? "" : " — " + d.title) << "\n";
  os << "// Algebra: R[e_1..e_" << m.errors.size() << "] / I, I = <all monomials of degree "
     << m.order + 1 << ">";
  if (!m.relations.empty()) os << " + <" << m.relations.size() << " relation monomials>";
  os << " (order " << m.order << (m.order == 1 ? ", dual numbers" : "") << ")\n";
  return os.str();
}

std::string operation_counts_block(const SymbolicModel& m, const ModelCode& c) {
  const bool higher = !c.higher.empty();
  std::ostringstream os;
  if (higher)
    os << "//   MonomialCoefficients: " << c.table.monomial.ops.str() << ", "
       << c.table.monomial.temps << " temporaries (" << c.table.count
       << " coefficients; included in each function below that uses them)\n";
  os << "//   Deviation:    " << c.deviation.ops.str() << ", " << c.deviation.temps
     << " temporaries\n";
  os << "//   Coefficients: " << c.coefficients.ops.str() << ", " << c.coefficients.temps
     << " temporaries\n";
  os << "//   DeviationAndCoefficients: " << c.deviation_and_coefficients.ops.str() << ", "
     << c.deviation_and_coefficients.temps << " temporaries\n";
  if (higher)
    os << "//   HigherOrder:  " << c.higher_order.ops.str() << ", " << c.higher_order.temps
       << " temporaries\n";
  os << "//   NominalPose:  " << c.nominal_pose.ops.str() << ", " << c.nominal_pose.temps
     << " temporaries\n";
  os << "//   NominalJacobian: " << c.nominal_jacobian.ops.str() << ", " << c.nominal_jacobian.temps
     << " temporaries\n";
  os << "//   Compensate:   per iteration errors_at + Deviation + NominalPose + "
     << (m.axes_turn_output() ? 6 : 3) << "x" << m.axes.size()
     << " least-squares step; once per call NominalJacobian + NominalPose + Cholesky\n";
  return os.str();
}

// The model's counts, from kModelKey to kMaxHigherDegree.
std::string counts_block(const SymbolicModel& m, const std::vector<Monomial>& higher) {
  std::ostringstream os;
  os << "inline constexpr const char* kModelKey = "
     << string_literal(model_key(m.desc.source_hash, m.order)) << ";\n";
  os << "inline constexpr std::size_t kNumAxes = " << m.axes.size() << ";\n";
  os << "inline constexpr std::size_t kNumErrors = " << m.errors.size() << ";\n";
  os << "inline constexpr std::size_t kNumParams = " << m.desc.parameters.size() << ";\n";
  os << "inline constexpr std::size_t kNumOutputs = " << kNumDeviationOutputs << ";\n";
  os << "inline constexpr std::size_t kNumHigherTerms = " << higher.size() << ";\n";
  os << "inline constexpr std::size_t kMaxHigherDegree = "
     << (higher.empty() ? 0 : higher.back().size()) << ";\n";
  return os.str();
}

std::string axis_rows(const SymbolicModel& m) {
  std::ostringstream os;
  for (const auto& a : m.axes) {
    const Joint& j = m.desc.bodies[a.body].joint;
    os << "    {" << string_literal(j.coordinate) << ", " << string_literal(j.unit) << ", "
       << (a.revolute ? "true" : "false") << ", " << format_literal(j.min) << ", "
       << format_literal(j.max) << ", " << format_literal(j.to_base) << "},\n";
  }
  return os.str();
}

std::string error_rows(const Description& d) {
  std::ostringstream os;
  for (const auto& e : d.errors) {
    std::string aliases;
    for (const auto& al : e.aliases)
      aliases += (aliases.empty() ? "" : " ") + std::string(al.sign < 0 ? "-" : "") + al.name;
    os << "    {" << string_literal(e.name) << ", " << string_literal(e.iso) << ", "
       << string_literal(aliases) << ", " << string_literal(e.group) << ", "
       << string_literal(e.unit) << ", " << format_literal(e.to_base) << ", "
       << (e.dependence == Dependence::PDGE ? "true" : "false") << ", "
       << string_literal(d.bodies[e.body].name) << ", "
       << string_literal(placement_name(e.placement)) << ", "
       << (e.effect == ErrorEffect::Rotation ? "true" : "false") << ", "
       << dist_kind(e.distribution.kind) << ", " << format_literal(e.distribution.a) << ", "
       << format_literal(e.distribution.b) << ", " << format_literal(e.distribution.lo) << ", "
       << format_literal(e.distribution.hi) << "},\n";
  }
  return os.str();
}

std::string param_rows(const Description& d) {
  std::ostringstream os;
  const auto defaults = d.parameter_defaults();
  for (const auto& p : d.parameters)
    os << "    {" << string_literal(p.name) << ", " << string_literal(p.unit) << ", "
       << format_literal(defaults.at(p.name)) << "},\n";
  return os.str();
}

std::string outputs_block() {
  std::string names, units;
  for (std::size_t o = 0; o < kNumDeviationOutputs; ++o) {
    names += std::string(o ? ", " : "") + string_literal(output_name(o));
    units += std::string(o ? ", " : "") + string_literal(output_unit(o));
  }
  return "inline constexpr std::array<const char*, kNumOutputs> kOutputs = {{" + names + "}};\n" +
         "inline constexpr std::array<const char*, kNumOutputs> kOutputUnits = {{" + units +
         "}};\n";
}

// kHigherTerms' declaration and rows (several monomials per line: tens of thousands at order 3).
std::string higher_terms_block(const std::vector<Monomial>& higher) {
  const std::size_t width = higher.empty() ? 1 : higher.back().size();
  std::vector<std::string> rows;
  for (const auto& mono : higher) {
    std::string item = "{{";
    for (std::size_t i = 0; i < width; ++i)
      item += (i ? "," : "") + (i < mono.size() ? std::to_string(mono[i]) : std::string("-1"));
    rows.push_back(item + "}},");
  }
  return "inline constexpr std::array<std::array<int, " + std::to_string(width) +
         ">, kNumHigherTerms> kHigherTerms = {{\n" + packed_lines(rows);
}

// A block of the template that keeps its own text (without its marker lines).
std::pair<std::string, std::string> kept(const std::string& block) {
  return {block, template_block(kModelTemplate, block)};
}

// One function section of the template with its body.
std::string function_text(const std::string& section, const FunctionCode& code,
                          const std::vector<std::pair<std::string, std::string>>& blocks = {}) {
  auto all = blocks;
  all.push_back({"body", code.body});
  return instantiate_template(template_block(kModelTemplate, section), "", "", all);
}

// The functions in the header's order: without terms of degree >= 2, Deviation, Coefficients
// and DeviationAndCoefficients; with them, MonomialCoefficients first (the others call it), then
// DeviationAndCoefficients, which Deviation calls, and HigherOrder.
std::string functions_block(const SymbolicModel& m, const ModelCode& c) {
  const Description& d = m.desc;
  std::vector<std::string> axis_names, error_names, param_names;
  for (const auto& a : m.axes) axis_names.push_back(d.bodies[a.body].joint.coordinate);
  for (const auto& e : d.errors) error_names.push_back(e.name);
  for (const auto& p : d.parameters) param_names.push_back(p.name);
  std::vector<std::pair<std::string, std::string>> deviation_blocks = {
      {"inputs", "//   axes:   " + doc_list(axis_names) + "\n//   errors: " +
                     doc_list(error_names) + "\n//   params: " + doc_list(param_names) + "\n"}};
  deviation_blocks.push_back(
      d.output
          ? std::make_pair(std::string("deviation_subject"),
                           "// Deviation of the output point (" +
                               (d.output->description.empty() ? std::string("the output transform")
                                                              : d.output->description) +
                               "):\n")
          : kept("deviation_subject"));
  const std::string deviation = function_text("deviation", c.deviation, deviation_blocks);
  const std::string coefficients = function_text("coefficients", c.coefficients);
  const std::string both =
      function_text("deviation_and_coefficients", c.deviation_and_coefficients);
  std::string out;
  if (c.higher.empty()) {
    out = deviation + coefficients + both;
  } else {
    if (c.table.parts > 0)
      out += instantiate_template(
          template_block(kModelTemplate, "monomial_parts"), "", "",
          {{"parts_count", "// MonomialCoefficients in " + std::to_string(c.table.parts) +
                               " parts, each a function of its own (a compiler's time and\n"},
           {"parts", c.table.monomial_parts}});
    out += function_text("monomial_coefficients", c.table.monomial) + both + "\n" + deviation +
           coefficients + function_text("higher_order", c.higher_order);
  }
  // The nominal pose names the tool frame or the machine file's output transform.
  out += function_text("nominal_pose", c.nominal_pose,
                       {{d.output ? "tool_frame" : "output_transform", ""},
                        kept(d.output ? "output_transform" : "tool_frame")});
  return out + function_text("nominal_jacobian", c.nominal_jacobian);
}

}  // namespace

std::string emit_cpp_header(const SymbolicModel& m, const std::string& source_label,
                            std::size_t max_nested_higher_terms, const SplitLimits& split) {
  const Description& d = m.desc;
  const ModelCode code = model_code(m, max_nested_higher_terms, split);
  const bool higher = !code.higher.empty();
  const std::string constants =
      "inline constexpr const char* kMachineName = " + string_literal(d.name) +
      ";\ninline constexpr int kOrder = " + std::to_string(m.order) + ";\n";
  const std::string monomial_tables =
      higher ? instantiate_template(
                   template_block(kModelTemplate, "monomial_tables"), "", "",
                   {{"monomial_count", "inline constexpr std::size_t kNumMonomialCoefficients = " +
                                           std::to_string(code.table.count) + ";\n" +
                                           code.table.tables}})
             : std::string();
  // The template names the model only by the lower-case stand-in (its namespace).
  return instantiate_template(
      kModelTemplate, d.name, d.name,
      {{"banner", banner_block(m, source_label)},
       {"operation_counts", operation_counts_block(m, code)},
       {"higher_includes", higher ? template_block(kModelTemplate, "higher_includes") : ""},
       {"constants", constants},
       {"counts", counts_block(m, code.higher)},
       {"axes", axis_rows(m)},
       {"errors", error_rows(d)},
       {"params", param_rows(d)},
       {"outputs", outputs_block()},
       {"indices", emit_index_constants(m)},
       {"higher_terms", higher_terms_block(code.higher)},
       {"monomial_tables", monomial_tables},
       {"functions", functions_block(m, code)},
       {"compensation", compensation_code(m.axes_turn_output())}});
}

}  // namespace weilgen::gen
