#include "weilgen/codegen/emit_report.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "weilgen/base/format.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/codegen/model_eval.hpp"
#include "weilgen/codegen/printer.hpp"

namespace weilgen::gen {

using GiNaC::ex;

namespace {

std::string latex_name(const std::string& n) {
  // E_XX -> E_{XX}; other underscores escaped.
  const auto u = n.find('_');
  if (u == std::string::npos) return n;
  std::string head = n.substr(0, u), tail = n.substr(u + 1);
  std::string esc;
  for (char c : tail) esc += (c == '_') ? std::string("\\_") : std::string(1, c);
  return head + "_{" + esc + "}";
}

// Display name and sign of error i in the chosen notation.
std::pair<std::string, int> display(const SymbolicModel& m, std::size_t i, Notation n,
                                    FormStyle style) {
  const ErrorDef& e = m.desc.errors[i];
  if (n == Notation::Alias && !e.aliases.empty()) {
    const Alias& a = e.aliases.front();
    return {a.name, a.sign};
  }
  return {style == FormStyle::Latex ? latex_name(e.name) : e.name, 1};
}

// A coefficient as printed before its error name: its sign (a leading '-') split off.
struct CoefficientText {
  bool negative = false;
  std::string text;
};

CoefficientText coefficient_text(ex coeff, ExprPrinter& pr, FormStyle style) {
  CoefficientText out;
  if (GiNaC::is_a<GiNaC::add>(coeff)) {
    // -(a + b)·E reads better than (-a - b)·E: factor out the sign of a mostly negative sum.
    std::size_t negatives = 0;
    for (std::size_t i = 0; i < coeff.nops(); ++i) negatives += pr.prints_negative(coeff.op(i));
    if (2 * negatives > coeff.nops()) {
      out.negative = true;
      coeff = (-coeff).expand();
    } else if (2 * negatives == coeff.nops()) {
      // As many negative terms as positive: GiNaC's sign of the sum varies between runs; take
      // the canonical one.
      CanonicalText canon;
      const CanonicalText::Signed r = canon.canonical_sign(coeff);
      out.negative = r.negated;
      coeff = r.value;
    }
    out.text = (style == FormStyle::Latex ? "\\left(" : "(") + pr.print(coeff) +
               (style == FormStyle::Latex ? "\\right)" : ")");
  } else {
    out.text = pr.print(coeff);
    if (!out.text.empty() && out.text[0] == '-') {
      out.negative = true;
      out.text.erase(0, 1);
    }
  }
  return out;
}

const char* product_sign(FormStyle style) {
  return style == FormStyle::Latex ? "\\," : style == FormStyle::Sympy ? "*" : "·";
}

// Appends " + c·name" (or the first term) to acc in place: a closed form at order 3 has tens of
// thousands of terms, and building a new string per term would copy it each time.
void append_term(std::string& acc, const CoefficientText& c, const std::string& name,
                 FormStyle style) {
  const char* times = product_sign(style);
  acc += acc.empty() ? (c.negative ? "-" : "") : (c.negative ? " - " : " + ");
  if (c.text != "1") acc.append(c.text).append(times);
  acc += name;
}

std::map<std::string, std::string> symbol_names(const SymbolicModel& m, FormStyle style) {
  std::map<std::string, std::string> names;
  if (style != FormStyle::Latex) return names;
  for (const auto& a : m.axes) {
    if (!a.revolute) continue;
    names[a.cos.get_name()] = "\\cos " + a.coordinate.get_name();
    names[a.sin.get_name()] = "\\sin " + a.coordinate.get_name();
  }
  for (const auto& p : m.params) names[p.get_name()] = latex_name(p.get_name());
  return names;
}

// Common factors pulled out for reading: cos(c)·z - cos(c)·L -> cos(c)·(z - L).
ex readable(const ex& c) { return GiNaC::collect_common_factors(c); }

// Printed coefficients of one style, memoised by (coefficient, sign): at order 3 a coefficient
// recurs in many monomials and outputs, and both notations print it again.
class TermPrinter {
 public:
  TermPrinter(const SymbolicModel& m, FormStyle style)
      : m_(m),
        style_(style),
        pr_(style == FormStyle::Latex   ? ExprPrinter::Style::Latex
            : style == FormStyle::Sympy ? ExprPrinter::Style::Sympy
                                        : ExprPrinter::Style::Text,
            symbol_names(m, style)) {}
  FormStyle style() const { return style_; }
  const CoefficientText& operator()(const ex& coefficient, int sign) {
    const auto key = std::make_pair(coefficient, sign);
    auto it = memo_.find(key);
    if (it == memo_.end()) {
      const ex c = readable((m_.with_divisors(coefficient) * sign).expand());
      it = memo_.emplace(key, coefficient_text(c, pr_, style_)).first;
    }
    return it->second;
  }

 private:
  struct Less {
    bool operator()(const std::pair<ex, int>& a, const std::pair<ex, int>& b) const {
      if (a.second != b.second) return a.second < b.second;
      return a.first.compare(b.first) < 0;
    }
  };
  const SymbolicModel& m_;
  FormStyle style_;
  ExprPrinter pr_;
  std::map<std::pair<ex, int>, CoefficientText, Less> memo_;
};

std::string closed_form(const SymbolicModel& m, int o, Notation notation, int max_degree,
                        TermPrinter& tp) {
  const FormStyle style = tp.style();
  std::string s;
  for (std::size_t i = 0; i < m.errors.size(); ++i) {
    const ex c = m.coefficient(o, {static_cast<std::uint16_t>(i)});
    if (c.is_zero()) continue;
    const auto [name, sign] = display(m, i, notation, style);
    append_term(s, tp(c, sign), name, style);
  }
  for (const auto& mono : m.higher_monomials()) {
    if (max_degree > 0 && static_cast<int>(mono.size()) > max_degree) break;  // sorted by degree
    const ex c = m.coefficient(o, mono);
    if (c.is_zero()) continue;
    std::string name;
    int sign = 1;
    for (auto i : mono) {
      const auto [n, sg] = display(m, i, notation, style);
      name += (name.empty() ? "" : product_sign(style)) + n;
      sign *= sg;
    }
    append_term(s, tp(c, sign), name, style);
  }
  const std::string lhs =
      style == FormStyle::Latex
          ? std::string("\\delta_{") + (output_name(static_cast<std::size_t>(o)) + 1) + "}"
          : output_name(static_cast<std::size_t>(o));
  return lhs + " = " + (s.empty() ? "0" : s);
}

// Root mean square of error i's distribution in base units (mm, rad): the size of the error a
// term is weighed with; 1 µm or 1 µrad when the file gives no distribution.
double error_scale(const ErrorDef& e) {
  const Distribution& d = e.distribution;
  double rms = 0;
  switch (d.kind) {
    case Distribution::Kind::Normal:
    case Distribution::Kind::TruncatedNormal:
      rms = std::sqrt(d.a * d.a + d.b * d.b);
      break;
    case Distribution::Kind::Uniform:
      rms = std::sqrt((d.a * d.a + d.a * d.b + d.b * d.b) / 3);
      break;
    case Distribution::Kind::None:
      return 1e-3 * (e.effect == ErrorEffect::Rotation ? 1e-3 : 1);
  }
  return rms * e.to_base;
}

// The part of the report for terms above `shown` degrees: counts per output and degree, and the
// largest terms at the mid-range pose (a reader's question: which products of errors matter).
std::string higher_terms_summary(const SymbolicModel& m, const std::vector<Monomial>& higher,
                                 int shown, const std::string& source_label) {
  const Description& d = m.desc;
  const int top_degree = static_cast<int>(higher.back().size());
  std::vector<double> axes;
  std::string pose;
  for (const auto& a : m.axes) {
    const Joint& j = d.bodies[a.body].joint;
    axes.push_back((j.min + j.max) / 2);
    pose += (pose.empty() ? "" : ", ") + j.coordinate + " = " + format_short(axes.back()) + " " +
            j.unit;
  }
  std::vector<double> scale;
  for (const auto& e : d.errors) scale.push_back(error_scale(e));
  CoefficientEvaluator at_pose(m, axes);

  struct Term {
    double size, coefficient;
    int output;
    std::size_t monomial;
  };
  constexpr std::size_t kListed = 5;  // per output
  std::vector<Term> largest;
  std::vector<std::vector<std::size_t>> count(kNumDeviationOutputs,
                                              std::vector<std::size_t>(top_degree + 1, 0));
  std::size_t above = 0;
  for (int o = 0; o < kNumDeviationOutputs; ++o) {
    std::vector<Term> terms;
    for (const auto& [mono, c] : m.outputs[o].terms()) {
      ++count[o][mono.size()];
      if (static_cast<int>(mono.size()) <= shown) continue;
      ++above;
      const double v = at_pose(c);
      double size = std::abs(v);
      for (auto i : mono) size *= scale[i];
      const auto k = static_cast<std::size_t>(
          std::lower_bound(higher.begin(), higher.end(), mono,
                           [](const Monomial& a, const Monomial& b) {
                             return a.size() != b.size() ? a.size() < b.size() : a < b;
                           }) -
          higher.begin());
      terms.push_back({size, v, o, k});
    }
    const std::size_t n = std::min(kListed, terms.size());
    // Ties (equal sizes) by the monomial's place in kHigherTerms: the same order on every run.
    std::partial_sort(terms.begin(), terms.begin() + static_cast<std::ptrdiff_t>(n), terms.end(),
                      [](const Term& a, const Term& b) {
                        return a.size != b.size ? a.size > b.size : a.monomial < b.monomial;
                      });
    largest.insert(largest.end(), terms.begin(), terms.begin() + static_cast<std::ptrdiff_t>(n));
  }

  std::ostringstream os;
  os << "## Terms of degree " << shown + 1 << " and higher\n\n";
  os << "Order " << m.order << " has " << above << " terms (output, monomial) of degree "
     << shown + 1 << (top_degree > shown + 1 ? " to " + std::to_string(top_degree) : std::string())
     << ", too many to read here. `weilgen show " << source_label << " --order " << m.order
     << "` prints every term (`--format latex` or `--format json` too); the header's "
        "`HigherOrder` evaluates their coefficients (monomials in `kHigherTerms`).\n\n";
  os << "| output";
  for (int g = 1; g <= top_degree; ++g) os << " | degree " << g;
  os << " |\n| ---";
  for (int g = 1; g <= top_degree; ++g) os << " | ---:";
  os << " |\n";
  for (int o = 0; o < kNumDeviationOutputs; ++o) {
    os << "| " << output_name(static_cast<std::size_t>(o));
    for (int g = 1; g <= top_degree; ++g) os << " | " << count[o][g];
    os << " |\n";
  }
  os << "\nThe " << kListed << " largest of them per output at the mid-range pose (" << pose
     << "; parameters at their defaults), each error at the root mean square of its "
        "distribution (1 µm or 1 µrad without one): the coefficient there, and the term's size "
        "|coefficient · Π errors| in the output's unit (mm, rad).\n\n"
        "| output | monomial | coefficient at the pose | size |\n| --- | --- | ---: | ---: |\n";
  for (const Term& t : largest)
    os << "| " << output_name(static_cast<std::size_t>(t.output)) << " | "
       << m.monomial_name(higher[t.monomial]) << " | " << format_significant(t.coefficient, 4)
       << " | " << format_significant(t.size, 3) << " |\n";
  os << "\n";
  return os.str();
}

}  // namespace

std::string closed_form(const SymbolicModel& m, int o, FormStyle style, Notation notation,
                        int max_degree) {
  TermPrinter tp(m, style);
  return closed_form(m, o, notation, max_degree, tp);
}

nlohmann::json closed_forms_json(const SymbolicModel& m, Notation notation) {
  nlohmann::json j;
  j["machine"] = m.desc.name;
  j["order"] = m.order;
  j["notation"] = notation == Notation::Iso ? "iso" : "alias";
  ExprPrinter pr(ExprPrinter::Style::Text);
  TermPrinter text(m, FormStyle::Text), latex(m, FormStyle::Latex);
  for (int o = 0; o < kNumDeviationOutputs; ++o) {
    nlohmann::json out;
    out["unit"] = output_unit(static_cast<std::size_t>(o));
    out["closed_form"] = closed_form(m, o, notation, 0, text);
    out["latex"] = closed_form(m, o, notation, 0, latex);
    nlohmann::json lin = nlohmann::json::object();
    for (std::size_t i = 0; i < m.errors.size(); ++i) {
      const ex c = m.with_divisors(m.coefficient(o, {static_cast<std::uint16_t>(i)}));
      if (c.is_zero()) continue;
      const auto [name, sign] = display(m, i, notation, FormStyle::Text);
      lin[name] = pr.print((c * sign).expand());
    }
    out["linear"] = lin;
    nlohmann::json hi = nlohmann::json::array();
    for (const auto& mono : m.higher_monomials()) {
      const ex c = m.with_divisors(m.coefficient(o, mono));
      if (c.is_zero()) continue;
      nlohmann::json names = nlohmann::json::array();
      int sign = 1;
      for (auto i : mono) {
        const auto [n, sg] = display(m, i, notation, FormStyle::Text);
        names.push_back(n);
        sign *= sg;
      }
      hi.push_back({{"monomial", names}, {"coefficient", pr.print((c * sign).expand())}});
    }
    out["higher"] = hi;
    j["outputs"][output_name(static_cast<std::size_t>(o))] = out;
  }
  return j;
}

namespace {

// The banner, title and the algebra, outputs and notation the closed forms use.
void markdown_intro(std::ostream& os, const SymbolicModel& m, const std::string& source_label) {
  const Description& d = m.desc;
  os << "<!-- GENERATED by weilgen " << kVersion << " from " << source_label
     << ". Do not edit: edit the machine file and run `weilgen generate`. -->\n\n";
  os << "# " << d.name << (d.title.empty() ? "" : " — " + d.title) << "\n\n";
  os << "Closed-form error model generated from `" << source_label << "`.\n\n";
  os << "- Algebra: R[e_1..e_" << d.errors.size() << "] / I, I = ⟨all monomials of degree "
     << m.order + 1 << "⟩";
  if (!m.relations.empty()) {
    os << " + ⟨";
    for (std::size_t k = 0; k < m.relations.size(); ++k)
      os << (k ? ", " : "") << m.monomial_name(m.relations[k]);
    os << "⟩";
  }
  os << " (order " << m.order << (m.order == 1 ? ": dual numbers" : "") << ").\n";
  if (d.output) {
    os << "- Outputs: deviation of the output transform's point"
       << (d.output->description.empty() ? "" : " (" + d.output->description + ")")
       << ": dx, dy, dz in mm; da, db, dc in rad (see \"Derived quantities\"). Errors in base "
          "units (mm, rad).\n";
  } else {
    os << "- Outputs: tool point relative to the workpiece, in the workpiece frame: dx, dy, dz in "
          "mm; da, db, dc in rad. Errors in base units (mm, rad).\n";
  }
  os << "- Coordinates print in lower case (`X` → `x`); revolute coordinates appear as "
        "`cos(c)`, `sin(c)` of the angle.\n\n";
}

// The closed forms in ISO 230-1 names (and in the source's aliases when it has them), up to
// kReportMaxDegree with the higher terms summarised.
void markdown_closed_forms(std::ostream& os, const SymbolicModel& m,
                           const std::string& source_label) {
  const Description& d = m.desc;
  const std::vector<Monomial> higher = m.higher_monomials();
  const int shown = !higher.empty() && static_cast<int>(higher.back().size()) > kReportMaxDegree
                        ? kReportMaxDegree
                        : 0;
  os << "## Closed forms\n\n";
  if (shown > 0)
    os << "Terms up to degree " << shown << "; the terms of degree " << shown + 1
       << " and higher are summarised in \"Terms of degree " << shown + 1
       << " and higher\" below.\n\n";
  os << "```text\n";
  TermPrinter tp(m, FormStyle::Text);
  for (int o = 0; o < kNumDeviationOutputs; ++o)
    os << closed_form(m, o, Notation::Iso, shown, tp) << "\n";
  os << "```\n\n";
  bool has_alias = false;
  for (const auto& e : d.errors) has_alias |= !e.aliases.empty();
  if (has_alias) {
    os << "### In the source's notation (first alias of each error)\n\n```text\n";
    for (int o = 0; o < kNumDeviationOutputs; ++o)
      os << closed_form(m, o, Notation::Alias, shown, tp) << "\n";
    os << "```\n\n";
  }
  if (shown > 0) os << higher_terms_summary(m, higher, shown, source_label);
}

void markdown_coefficients(std::ostream& os, const SymbolicModel& m) {
  const Description& d = m.desc;
  os << "## First-order coefficients ∂output/∂error\n\n| error | dx | dy | dz | da | db | dc |\n"
        "| --- | --- | --- | --- | --- | --- | --- |\n";
  ExprPrinter pr(ExprPrinter::Style::Text);
  for (std::size_t i = 0; i < d.errors.size(); ++i) {
    os << "| " << d.errors[i].name;
    for (int o = 0; o < kNumDeviationOutputs; ++o) {
      const ex c = m.with_divisors(m.coefficient(o, {static_cast<std::uint16_t>(i)}));
      os << " | " << (c.is_zero() ? "·" : pr.print(c));
    }
    os << " |\n";
  }
}

// The nominal pose, its Jacobian and what Compensate solves with them.
void markdown_nominal(std::ostream& os, const SymbolicModel& m) {
  const Description& d = m.desc;
  ExprPrinter pr(ExprPrinter::Style::Text);
  os << "\n## Nominal kinematics (NominalPose, NominalJacobian, Compensate)\n\n"
     << "Nominal pose at zero errors: position of the " << (d.output ? "output" : "tool")
     << " point in mm.\n\n```text\n";
  for (int i = 0; i < 3; ++i)
    os << output_name(static_cast<std::size_t>(i))[1]
       << "0 = " << pr.print(m.with_divisors(m.nominal[i][3])) << "\n";
  os << "```\n\nJacobian of the nominal pose per mm (prismatic) or per rad (revolute); the "
        "header's `NominalJacobian` is per axis unit (a column per deg is this times π/180). "
        "Orientation rows are the rotation rate vee(∂R/∂q·Rᵀ).\n\n"
        "| axis | dx | dy | dz | da | db | dc |\n| --- | --- | --- | --- | --- | --- | --- |\n";
  const std::size_t na = m.axes.size();
  std::vector<std::string> idle;
  for (std::size_t k = 0; k < na; ++k) {
    const std::string& name = d.bodies[m.axes[k].body].joint.coordinate;
    os << "| " << name;
    bool moves = false;
    for (int o = 0; o < kNumDeviationOutputs; ++o) {
      const ex c = m.with_divisors(m.nominal_jacobian[o * na + k]);
      moves |= !c.is_zero();
      os << " | " << (c.is_zero() ? "·" : pr.print(c));
    }
    os << " |\n";
    if (!moves) idle.push_back(name);
  }
  os << "\n`Compensate` (docs/compensation.md) solves in least squares over the position rows"
     << (m.axes_turn_output()
             ? std::string(" and the orientation rows: the tilt of the tool axis (z) "
                           "weighted by kCompensationLengthMm, the spin about it by "
                           "kCompensationSpinWeight of that")
             : std::string(" (no axis turns the ") + (d.output ? "output frame" : "tool") +
                   ": orientation is not compensated)")
     << ".";
  if (!idle.empty()) {
    os << " The nominal pose does not depend on ";
    for (std::size_t i = 0; i < idle.size(); ++i)
      os << (i == 0 ? "" : i + 1 == idle.size() ? " and " : ", ") << idle[i];
    os << ": the least-squares problem is singular and `Compensate` returns -1.";
  }
  os << "\n";
}

void markdown_errors(std::ostream& os, const SymbolicModel& m) {
  const Description& d = m.desc;
  os << "\n## Errors\n\n| name | aliases | body | group | placement | PIGE/PDGE | unit | "
        "distribution |\n| --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& e : d.errors) {
    std::string al;
    for (const auto& a : e.aliases)
      al += (al.empty() ? "" : ", ") + std::string(a.sign < 0 ? "−" : "") + a.name;
    const char* pl = e.placement == ErrorPlacement::After
                         ? "after"
                         : (e.placement == ErrorPlacement::Before ? "before" : "axis");
    os << "| " << e.name << " | " << al << " | " << d.bodies[e.body].name << " | " << e.group
       << " | " << pl << " | " << (e.dependence == Dependence::PDGE ? "PDGE" : "PIGE") << " | "
       << e.unit << " | " << e.distribution.str() << " |\n";
  }
}

void markdown_axes(std::ostream& os, const SymbolicModel& m) {
  const Description& d = m.desc;
  os << "\n## Axes\n\n| coordinate | body | type | axis | twist ξ = (ω, v) | unit | range |\n"
        "| --- | --- | --- | --- | --- | --- | --- |\n";
  for (std::size_t b = 0; b < d.bodies.size(); ++b) {
    const Joint& j = d.bodies[b].joint;
    if (j.type == JointType::Fixed) continue;
    const bool revolute = j.type == JointType::Revolute;
    std::string axis = "[" + format_literal(j.axis[0]) + ", " + format_literal(j.axis[1]) + ", " +
                       format_literal(j.axis[2]) + "]";
    if (revolute &&
        !(j.through[0].is_number() && j.through[0].number == 0 && j.through[1].is_number() &&
          j.through[1].number == 0 && j.through[2].is_number() && j.through[2].number == 0)) {
      axis += " through [" + j.through[0].str() + ", " + j.through[1].str() + ", " +
              j.through[2].str() + "]";
    }
    os << "| " << j.coordinate << " | " << d.bodies[b].name << " | "
       << (revolute ? "revolute" : "prismatic") << " | " << axis << " | "
       << (j.twist.empty() ? "·" : j.twist) << " | " << j.unit << " | "
       << (j.link ? "linked: " + j.coordinate + " = " + j.link->str()
                  : format_literal(j.min) + " … " + format_literal(j.max))
       << " |\n";
  }
}

// Chain points, directions, derived quantities and the output transform, when the machine
// file has them.
void markdown_derived(std::ostream& os, const SymbolicModel& m) {
  const Description& d = m.desc;
  if (!d.points.empty() || !d.directions.empty() || !d.derived.empty() || d.output) {
    os << "\n## Derived quantities\n\n";
    if (!d.points.empty()) {
      os << "Chain points (deviation P(e) − P(0) in the base frame, mm; `name.x` …):\n\n"
            "| point | body | point in the body (mm) |\n| --- | --- | --- |\n";
      for (const ChainPoint& p : d.points)
        os << "| " << p.name << " | " << d.bodies[p.at.body].name << " | [" << p.at.point[0].str()
           << ", " << p.at.point[1].str() << ", " << p.at.point[2].str() << "] |\n";
      os << "\n";
    }
    if (!d.directions.empty()) {
      os << "Chain directions (nominal unit vector in the base frame at the pose, no unit; "
            "`name.x` …):\n\n| direction | body | direction in the body |\n| --- | --- | --- |\n";
      for (const ChainDirection& u : d.directions)
        os << "| " << u.name << " | " << d.bodies[u.body].name << " | ["
           << format_literal(u.direction[0]) << ", " << format_literal(u.direction[1]) << ", "
           << format_literal(u.direction[2]) << "] |\n";
      os << "\n";
    }
    if (!d.derived.empty()) {
      os << "Derived quantities, in evaluation order:\n\n```text\n";
      for (const Derived& q : d.derived)
        os << q.name << " = " << q.value.str()
           << (q.description.empty() ? "" : "    # " + q.description) << "\n";
      os << "```\n\n";
    }
    if (d.output) {
      os << "Output transform P = ";
      for (const TransformStep& st : d.output->steps) {
        if (st.kind == TransformStep::Kind::Translate) {
          os << "Trans(" << st.translation[0].str() << ", " << st.translation[1].str() << ", "
             << st.translation[2].str() << ") · ";
        } else {
          os << "exp(ξ^·" << st.amount.str() << ") [ξ = (" << format_literal(st.omega[0]) << ", "
             << format_literal(st.omega[1]) << ", " << format_literal(st.omega[2]) << ", "
             << st.v[0].str() << ", " << st.v[1].str() << ", " << st.v[2].str() << ")] · ";
        }
      }
      os << "Trans(" << d.output->point[0].str() << ", " << d.output->point[1].str() << ", "
         << d.output->point[2].str() << ")\n";
    }
  }
}

void markdown_parameters_and_notes(std::ostream& os, const SymbolicModel& m) {
  const Description& d = m.desc;
  if (!d.parameters.empty()) {
    os << "\n## Parameters\n\n| name | default | unit | description |\n| --- | --- | --- | --- |\n";
    const auto defaults = d.parameter_defaults();
    for (const auto& p : d.parameters)
      os << "| " << p.name << " | " << format_literal(defaults.at(p.name)) << " | " << p.unit
         << " | " << p.description << " |\n";
  }
  if (!d.notes.empty()) os << "\n## Notes\n\n" << d.notes << (d.notes.back() == '\n' ? "" : "\n");
}

}  // namespace

std::string emit_report_markdown(const SymbolicModel& m, const std::string& source_label) {
  std::ostringstream os;
  markdown_intro(os, m, source_label);
  markdown_closed_forms(os, m, source_label);
  markdown_coefficients(os, m);
  markdown_nominal(os, m);
  markdown_errors(os, m);
  markdown_axes(os, m);
  markdown_derived(os, m);
  markdown_parameters_and_notes(os, m);
  return os.str();
}

}  // namespace weilgen::gen
