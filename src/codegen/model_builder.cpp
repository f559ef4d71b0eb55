#include "weilgen/codegen/model_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <utility>

#include "weilgen/base/text.hpp"
#include "weilgen/codegen/cse.hpp"
#include "weilgen/codegen/sparse_poly.hpp"

namespace weilgen::gen {

using GiNaC::ex;

GiNaC::numeric exact_decimal(double v) {
  if (!std::isfinite(v)) throw std::invalid_argument("non-finite number in machine description");
  char buf[64];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*e", digits - 1, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  // buf = "-d.ddde±XX": mantissa digits and a decimal exponent, both exact.
  std::string s(buf);
  const auto epos = s.find('e');
  const int exponent = std::stoi(s.substr(epos + 1));
  std::string mant = s.substr(0, epos);
  const bool negative = !mant.empty() && mant[0] == '-';
  if (negative) mant.erase(0, 1);
  int frac_digits = 0;
  if (auto dot = mant.find('.'); dot != std::string::npos) {
    frac_digits = static_cast<int>(mant.size() - dot - 1);
    mant.erase(dot, 1);
  }
  GiNaC::numeric r(mant.c_str());
  const int scale = exponent - frac_digits;
  r *= GiNaC::ex_to<GiNaC::numeric>(GiNaC::pow(GiNaC::numeric(10), scale));
  return negative ? -r : r;
}

ex to_ginac(const Expr& e, const Description& desc, const std::vector<GiNaC::symbol>& params) {
  switch (e.kind) {
    case Expr::Kind::Number:
      return exact_decimal(e.number);
    case Expr::Kind::Param: {
      if (e.name == "pi") return GiNaC::Pi;
      for (std::size_t i = 0; i < desc.parameters.size(); ++i)
        if (desc.parameters[i].name == e.name) return params[i];
      throw std::invalid_argument("unknown parameter '" + e.name + "'");
    }
    case Expr::Kind::Neg:
      return -to_ginac(*e.a, desc, params);
    case Expr::Kind::Add:
      return to_ginac(*e.a, desc, params) + to_ginac(*e.b, desc, params);
    case Expr::Kind::Sub:
      return to_ginac(*e.a, desc, params) - to_ginac(*e.b, desc, params);
    case Expr::Kind::Mul:
      return to_ginac(*e.a, desc, params) * to_ginac(*e.b, desc, params);
    case Expr::Kind::Div:
      return to_ginac(*e.a, desc, params) / to_ginac(*e.b, desc, params);
    case Expr::Kind::Pow:
      return GiNaC::pow(to_ginac(*e.a, desc, params), to_ginac(*e.b, desc, params));
  }
  return 0;
}

namespace {

struct Builder {
  const Description& d;
  SymbolicModel& model;
  const Algebra& alg;
  CanonicalText& canon;
  // as_fraction by coefficient: at order 3 the same coefficient recurs in many monomials.
  std::map<ex, ex, GiNaC::ex_is_less>& fractions;
  // Each reciprocal's atom and its divisor in SparsePoly form (nothing when the divisor is not a
  // polynomial in symbols), by reciprocal: converted once, not for every coefficient.
  std::vector<std::pair<std::uint16_t, std::optional<SparsePoly>>>& sparse_divisors;

  void unit_vector(const Vec3& v, ex (&u)[3]) const {
    for (int i = 0; i < 3; ++i) u[i] = exact_decimal(v[i]);
  }

  Mat4 offset(const Offset& off) const {
    ex t[3];
    for (int i = 0; i < 3; ++i) t[i] = to_ginac(off.translation[i], d, model.params);
    Mat4 m = translation(t);
    for (const auto& rot : off.rotations) {
      ex u[3];
      unit_vector(rot.axis, u);
      const ex angle = to_ginac(rot.angle_deg, d, model.params) * GiNaC::Pi / 180;
      m = m.mul(rotation_cs(u, GiNaC::cos(angle), GiNaC::sin(angle), alg), alg);
    }
    return m;
  }

  Mat4 error_transform(int body, ErrorPlacement placement) const {
    Mat4 m = Mat4::identity();
    for (int ei : d.bodies[body].errors) {
      const ErrorDef& e = d.errors[ei];
      if (e.placement != placement) continue;
      ex u[3];
      unit_vector(e.direction, u);
      const Poly sym = Poly::error(static_cast<std::uint16_t>(ei));
      m = m.mul(e.effect == ErrorEffect::Translation ? translation_by(sym, u, alg)
                                                     : rotation_small(u, sym, alg),
                alg);
    }
    return m;
  }

  // A joint coordinate's nominal value in its unit: the symbol of an independent coordinate, the
  // expression of a linked one.
  ex coordinate_value(int body) const {
    const Joint& j = d.bodies[body].joint;
    if (j.link) return nominal(*j.link);
    const auto it = std::find_if(model.axes.begin(), model.axes.end(),
                                 [&](const AxisSymbols& a) { return a.body == body; });
    return it->coordinate;
  }

  // Expr over parameters and coordinates (links, twist axes) → GiNaC.
  ex nominal(const Expr& e) const {
    const Poly p = value(e, {});
    if (!p.is_constant())
      throw std::logic_error("nominal expression depends on errors: " + e.str());
    return p.constant();
  }

  // cos and sin of revolute joint `body`: the trigonometric symbols of an independent coordinate;
  // for a linked one the symbols of the coordinate it equals (±C), else cos/sin of the expression.
  std::pair<ex, ex> cos_sin(int body) const {
    const Joint& j = d.bodies[body].joint;
    const auto sym = [&](int b) {
      return std::find_if(model.axes.begin(), model.axes.end(),
                          [&](const AxisSymbols& a) { return a.body == b; });
    };
    if (!j.link) return {sym(body)->cos, sym(body)->sin};
    const Expr* e = &*j.link;
    const bool negated = e->kind == Expr::Kind::Neg;
    if (negated) e = e->a.get();
    if (e->kind == Expr::Kind::Param) {
      const int other = d.coordinate_body(e->name);
      if (other >= 0 && !d.bodies[other].joint.link &&
          d.bodies[other].joint.type == JointType::Revolute &&
          d.bodies[other].joint.to_base == j.to_base) {
        const auto it = sym(other);
        return {it->cos, negated ? ex(-it->sin) : ex(it->sin)};
      }
    }
    const ex angle = coordinate_value(body) * exact_decimal(j.to_base);
    return {GiNaC::cos(angle), GiNaC::sin(angle)};
  }

  Mat4 joint(int body) const {
    const Joint& j = d.bodies[body].joint;
    if (j.type == JointType::Fixed) return Mat4::identity();
    ex u[3];
    unit_vector(j.axis, u);
    if (j.type == JointType::Prismatic) {
      const Poly q(coordinate_value(body) * exact_decimal(j.to_base));
      return translation_by(q, u, alg);
    }
    const auto [c, s] = cos_sin(body);
    const Mat4 r = rotation_cs(u, c, s, alg);
    ex q[3], minus_q[3];
    bool origin = true;
    for (int i = 0; i < 3; ++i) {
      q[i] = to_ginac(j.through[i], d, model.params);
      minus_q[i] = -q[i];
      origin &= q[i].is_zero();
    }
    if (origin) return r;
    return translation(q).mul(r, alg).mul(translation(minus_q), alg);
  }

  // ---- Chain points, derived quantities, the output transform -------------------------------

  // An expression of a derived quantity or output step as an algebra element; `names` holds the
  // point components and derived quantities evaluated so far.
  Poly value(const Expr& e, const std::map<std::string, Poly>& names) const {
    switch (e.kind) {
      case Expr::Kind::Number:
        return Poly(exact_decimal(e.number));
      case Expr::Kind::Param: {
        if (const auto it = names.find(e.name); it != names.end()) return it->second;
        if (const int b = d.coordinate_body(e.name); b >= 0) return Poly(coordinate_value(b));
        return Poly(to_ginac(e, d, model.params));
      }
      case Expr::Kind::Neg:
        return -value(*e.a, names);
      case Expr::Kind::Add:
        return value(*e.a, names) + value(*e.b, names);
      case Expr::Kind::Sub:
        return value(*e.a, names) - value(*e.b, names);
      case Expr::Kind::Mul:
        return value(*e.a, names).mul(value(*e.b, names), alg);
      case Expr::Kind::Div: {
        // The loader admits only nominal divisors (machine/derived.hpp).
        const Poly den = value(*e.b, names);
        return value(*e.a, names).scaled(reciprocal(den.constant()), alg);
      }
      case Expr::Kind::Pow: {
        const Poly base = value(*e.a, names);
        const double k = e.b->number;
        if (base.is_constant()) return Poly(GiNaC::pow(base.constant(), exact_decimal(k)));
        Poly p(1);
        for (int i = 0; i < static_cast<int>(k); ++i) p = p.mul(base, alg);
        return p;
      }
    }
    return {};
  }

  // 1/den: a number, or ±_invK for the divisor's canonical sign (one symbol per divisor).
  ex reciprocal(const ex& den) const {
    const ex e = den.expand();
    if (GiNaC::is_a<GiNaC::numeric>(e)) return 1 / e;
    ex canonical = e;
    bool negated = false;
    if (GiNaC::is_a<GiNaC::add>(e)) {
      const CanonicalText::Signed r = canon.canonical_sign(e);
      canonical = r.value;
      negated = r.negated;
    }
    const std::string& key = canon.of(canonical);
    for (const Reciprocal& r : model.reciprocals)
      if (canon.of(r.divisor) == key) return negated ? ex(-r.symbol) : ex(r.symbol);
    model.reciprocals.push_back(
        {GiNaC::symbol("_inv" + std::to_string(model.reciprocals.size())), canonical});
    const ex sym = model.reciprocals.back().symbol;
    return negated ? -sym : sym;
  }

  // A coefficient with reciprocals as one fraction over a single divisor when it has one:
  // 1 + (L01 + x − L04)·_inv0 with _inv0 = 1/(L04 − L01 − x − LW) becomes −LW·_inv0. With one
  // reciprocal r = 1/D in c = Σ_k a_k r^k (k ≤ K): N = Σ_k a_k D^(K−k), so c = N r^K; D is divided
  // out of N while it divides exactly (no gcd per coefficient). With several reciprocals the
  // same, divisor by divisor. Anything else (several divisors left, or a power of one) stays as
  // it is.
  ex as_fraction(const ex& c) const {
    if (const auto fast = as_fraction_sparse(c)) return *fast;
    std::vector<const Reciprocal*> present;
    for (const Reciprocal& r : model.reciprocals)
      if (c.has(r.symbol)) present.push_back(&r);
    if (present.empty()) return c;
    const auto it = fractions.find(c);
    if (it != fractions.end()) return it->second;
    return fractions.emplace(c, over_divisors(c, present)).first->second;
  }

  // as_fraction over SparsePoly forms when c and the divisors present are polynomials in symbols
  // (then GiNaC's exact division could not throw and over_divisors decides the same); nothing
  // otherwise.
  std::optional<ex> as_fraction_sparse(const ex& c) const {
    const auto s = alg.to_sparse(c);
    if (!s || !s->symbols_only(alg.atoms())) return std::nullopt;
    while (sparse_divisors.size() < model.reciprocals.size()) {
      const Reciprocal& r = model.reciprocals[sparse_divisors.size()];
      auto den = alg.to_sparse(r.divisor.expand());
      if (den && !den->symbols_only(alg.atoms())) den.reset();
      sparse_divisors.emplace_back(alg.atoms().index(r.symbol), std::move(den));
    }
    std::vector<SparseReciprocal> present;
    for (const auto& [atom, den] : sparse_divisors) {
      if (s->degree(atom, alg.atoms()) == 0) continue;
      if (!den) return std::nullopt;
      present.push_back({atom, *den});
    }
    if (present.empty()) return c;
    const auto it = fractions.find(c);
    if (it != fractions.end()) return it->second;
    const auto f = gen::over_divisors(*s, present, alg.atoms());
    return fractions.emplace(c, f ? alg.from_sparse(*f) : c).first->second;
  }

  static bool is_monomial(const ex& d) {
    if (GiNaC::is_a<GiNaC::symbol>(d) || GiNaC::is_a<GiNaC::numeric>(d)) return true;
    if (GiNaC::is_a<GiNaC::power>(d))
      return GiNaC::is_a<GiNaC::symbol>(d.op(0)) && d.op(1).info(GiNaC::info_flags::posint);
    if (!GiNaC::is_a<GiNaC::mul>(d)) return false;
    for (std::size_t i = 0; i < d.nops(); ++i)
      if (!is_monomial(d.op(i))) return false;
    return true;
  }

  // n = d·q with q a polynomial. A monomial divisor (2·y) divides when every term has its
  // powers; a sum is tried by the cheap test first, then by GiNaC's exact division.
  static bool divides_exactly(const ex& n, const ex& d, ex& q) {
    if (is_monomial(d)) {
      GiNaC::exset syms;
      collect_symbols(d, syms);
      for (const ex& s : syms)
        if (n.ldegree(s) < d.degree(s)) return false;
      q = (n / d).expand();
      return true;
    }
    return may_divide(n, d) && GiNaC::divide(n, d, q);
  }

  // False when d certainly does not divide n: n does not vanish at a rational point of d = 0 (every
  // symbol but one at a fixed rational value, the last one, in which d is linear, at d's root).
  // GiNaC's exact division is far dearer than this evaluation, and most divisions fail.
  static bool may_divide(const ex& n, const ex& d) {
    // Whatever point is drawn, the answer is the same (a divisor vanishes everywhere on d = 0).
    GiNaC::exset syms;
    collect_symbols(d, syms);
    collect_symbols(n, syms);
    GiNaC::exmap at;
    int k = 0;
    for (const ex& s : syms) {
      at[s] = GiNaC::numeric(2 * (k % 7) + 3, 13 + 2 * k);
      ++k;
    }
    for (const ex& s : syms) {
      if (d.degree(s) != 1 || !GiNaC::is_a<GiNaC::numeric>(d.coeff(s, 1))) continue;
      GiNaC::exmap rest = at;
      rest.erase(s);
      const ex a = d.coeff(s, 1);
      rest[s] = (-(d - a * s) / a).subs(rest, GiNaC::subs_options::no_pattern).expand();
      if (!GiNaC::is_a<GiNaC::numeric>(rest[s])) return true;
      const ex v = n.subs(rest, GiNaC::subs_options::no_pattern).expand();
      return !GiNaC::is_a<GiNaC::numeric>(v) || v.is_zero();
    }
    return true;
  }

  static void collect_symbols(const ex& e, GiNaC::exset& out) {
    if (GiNaC::is_a<GiNaC::symbol>(e)) {
      out.insert(e);
      return;
    }
    for (std::size_t i = 0; i < e.nops(); ++i) collect_symbols(e.op(i), out);
  }

  // The reciprocals r_i = 1/D_i present in c: c = N / Π D_i^K_i with N a polynomial; each D_i is
  // divided out of N while it divides exactly (no gcd: the divisors are distinct, and a divisor is
  // removed only when it divides N). A polynomial, or N·r_i over one remaining D_i, replaces c;
  // anything else stays as it is.
  ex over_divisors(const ex& c, const std::vector<const Reciprocal*>& present) const {
    ex num = c.expand();
    std::vector<int> k(present.size(), 0);
    std::vector<ex> den(present.size());
    for (std::size_t i = 0; i < present.size(); ++i) {
      den[i] = present[i]->divisor.expand();
      k[i] = num.degree(present[i]->symbol);
      if (k[i] <= 0) continue;
      ex acc = 0;
      for (int j = 0; j <= k[i]; ++j)
        acc += num.coeff(present[i]->symbol, j) * GiNaC::pow(den[i], k[i] - j);
      num = acc.expand();
    }
    if (num.is_zero()) return 0;  // c vanishes: the reciprocals' terms cancel
    try {
      for (std::size_t i = 0; i < present.size(); ++i)
        for (ex q; k[i] > 0 && divides_exactly(num, den[i], q); --k[i]) num = q;
    } catch (const std::exception&) {
      return c;  // not a polynomial over the rationals (a function of a linked angle): as it is
    }
    const Reciprocal* left = nullptr;
    for (std::size_t i = 0; i < present.size(); ++i) {
      if (k[i] == 0) continue;
      if (k[i] > 1 || left) return c;
      left = present[i];
    }
    return alg.normalize(left ? num * left->symbol : num);
  }

  // P = Π steps · Trans(point), with the chain points' deviations P(e) − P(0) (base frame) and the
  // derived quantities in scope.
  Mat4 output_transform() const {
    std::map<std::string, Poly> names;
    for (const ChainPoint& p : d.points) {
      const Mat4 m = branch(p.at);
      for (int i = 0; i < 3; ++i)
        names[p.name + "." + static_cast<char>('x' + i)] = m.m[i][3].without_constant();
    }
    for (const ChainDirection& u : d.directions) {
      const Mat4 r = nominal_frame(u.body);
      for (int i = 0; i < 3; ++i) {
        ex c = 0;
        for (int k = 0; k < 3; ++k) c += r.m[i][k].constant() * exact_decimal(u.direction[k]);
        names[u.name + "." + static_cast<char>('x' + i)] = Poly(alg.normalize(c));
      }
    }
    for (const Derived& q : d.derived) names[q.name] = value(q.value, names);
    Mat4 m = Mat4::identity();
    for (const TransformStep& s : d.output->steps) {
      if (s.kind == TransformStep::Kind::Translate) {
        Mat4 t = Mat4::identity();
        for (int i = 0; i < 3; ++i) t.m[i][3] = value(s.translation[i], names);
        m = m.mul(t, alg);
        continue;
      }
      const Poly amount = value(s.amount, names);
      ex v[3], w[3];
      for (int i = 0; i < 3; ++i) v[i] = nominal(s.v[i]);
      unit_vector(s.omega, w);
      if (s.omega == Vec3{0, 0, 0}) {
        m = m.mul(translation_by(amount, v, alg), alg);
        continue;
      }
      // exp(ξ^ a) = Trans(q) · Rot(ω, a) · Trans(−q) · Trans(ω (ω·v) a), q = ω × v.
      ex q[3], minus_q[3];
      q[0] = w[1] * v[2] - w[2] * v[1];
      q[1] = w[2] * v[0] - w[0] * v[2];
      q[2] = w[0] * v[1] - w[1] * v[0];
      for (int i = 0; i < 3; ++i) minus_q[i] = -q[i];
      const ex a0 = amount.constant();
      Mat4 r = rotation_small(w, amount - Poly(a0), alg);
      if (!a0.is_zero()) r = rotation_cs(w, GiNaC::cos(a0), GiNaC::sin(a0), alg).mul(r, alg);
      const ex pitch = (w[0] * v[0] + w[1] * v[1] + w[2] * v[2]).expand();
      // A twist through the origin (q = 0): no translations, whose products would only copy m.
      const bool through_origin = q[0].is_zero() && q[1].is_zero() && q[2].is_zero();
      m = through_origin ? m.mul(r, alg)
                         : m.mul(translation(q), alg).mul(r, alg).mul(translation(minus_q), alg);
      if (!pitch.is_zero()) m = m.mul(translation_by(amount.scaled(pitch, alg), w, alg), alg);
    }
    ex t[3];  // nominal (checked by the loader)
    for (int i = 0; i < 3; ++i) t[i] = value(d.output->point[i], names).constant();
    return m.mul(translation(t), alg);
  }

  // T = Offset · E_before · (E_axis · J · E_axis⁻¹) · E_after
  Mat4 body_transform(int body) const {
    Mat4 m = offset(d.bodies[body].offset);
    m = m.mul(error_transform(body, ErrorPlacement::Before), alg);
    const Mat4 axis = error_transform(body, ErrorPlacement::Axis);
    m = m.mul(axis, alg).mul(joint(body), alg).mul(neumann_inverse(axis, alg), alg);
    return m.mul(error_transform(body, ErrorPlacement::After), alg);
  }

  // Base -> body at zero errors (Offset · J per body): the nominal frame of a chain direction.
  Mat4 nominal_frame(int body) const {
    Mat4 m = Mat4::identity();
    for (int b : d.chain_to(body)) m = m.mul(offset(d.bodies[b].offset), alg).mul(joint(b), alg);
    return m;
  }

  // Base -> end.body, then Trans(end.point).
  Mat4 branch(const PointSpec& end) const {
    Mat4 m = Mat4::identity();
    for (int b : d.chain_to(end.body)) m = m.mul(body_transform(b), alg);
    ex t[3];
    for (int i = 0; i < 3; ++i) t[i] = to_ginac(end.point[i], d, model.params);
    return m.mul(translation(t), alg);
  }
};

std::vector<Monomial> relation_monomials(const Description& d) {
  std::vector<Monomial> out;
  auto in_group = [&](const std::string& g) {
    std::vector<std::uint16_t> idx;
    for (std::size_t i = 0; i < d.errors.size(); ++i)
      if (d.errors[i].group == g) idx.push_back(static_cast<std::uint16_t>(i));
    return idx;
  };
  auto index = [&](const std::string& n) {
    const int i = d.error_index(n);
    if (i < 0) throw InputError(SourceLoc{d.source_file, 0, 0}, "relation names no error: " + n);
    return static_cast<std::uint16_t>(i);
  };
  for (const Relation& r : d.algebra.relations) {
    switch (r.kind) {
      case Relation::Kind::Squares:
        if (r.names.empty()) {
          for (std::size_t i = 0; i < d.errors.size(); ++i)
            out.push_back({static_cast<std::uint16_t>(i), static_cast<std::uint16_t>(i)});
        } else {
          for (const auto& n : r.names) out.push_back({index(n), index(n)});
        }
        break;
      case Relation::Kind::Within: {
        for (const auto& g : r.names) {
          const auto idx = in_group(g);
          for (std::size_t a = 0; a < idx.size(); ++a)
            for (std::size_t b = a; b < idx.size(); ++b) out.push_back({idx[a], idx[b]});
        }
        break;
      }
      case Relation::Kind::Between: {
        const auto ga = in_group(r.names.at(0)), gb = in_group(r.names.at(1));
        for (auto a : ga)
          for (auto b : gb) out.push_back({std::min(a, b), std::max(a, b)});
        break;
      }
      case Relation::Kind::Pair:
      case Relation::Kind::Monomial: {
        Monomial m;
        for (const auto& n : r.names) m.push_back(index(n));
        std::sort(m.begin(), m.end());
        out.push_back(m);
        break;
      }
    }
  }
  return out;
}

// de/dq_axis in the axis' base unit (per mm, per rad). The chain rule through the symbols that
// stand for functions of the coordinate: cos(q), sin(q) of a revolute one (d cos = −sin·dq,
// d sin = cos·dq with q in rad) and the reciprocals (d(1/D) = −(1/D)²·dD); GiNaC differentiates
// the rest (the coordinate itself, in its unit, and cos/sin functions of linked coordinates).
ex axis_derivative(const SymbolicModel& m, const Algebra& alg, const ex& e, std::size_t axis) {
  const AxisSymbols& a = m.axes[axis];
  ex d = e.diff(a.coordinate) / exact_decimal(m.desc.bodies[a.body].joint.to_base);
  if (a.revolute) d += e.diff(a.cos) * (-a.sin) + e.diff(a.sin) * a.cos;
  for (const Reciprocal& r : m.reciprocals) {
    const ex dr = e.diff(r.symbol);
    if (!dr.is_zero()) d -= dr * GiNaC::pow(r.symbol, 2) * axis_derivative(m, alg, r.divisor, axis);
  }
  return alg.normalize(d);
}

// The nominal pose P0 of `p` and its Jacobian (SymbolicModel::nominal, nominal_jacobian).
void set_nominal_kinematics(SymbolicModel& model, const Mat4& p, const Algebra& alg) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) model.nominal[i][j] = alg.normalize(p.m[i][j].constant());
  const std::size_t n = model.axes.size();
  model.nominal_jacobian.assign(6 * n, ex(0));
  for (std::size_t k = 0; k < n; ++k) {
    std::array<std::array<ex, 3>, 3> dr;  // dR0/dq
    for (int i = 0; i < 3; ++i) {
      model.nominal_jacobian[i * n + k] = axis_derivative(model, alg, model.nominal[i][3], k);
      for (int j = 0; j < 3; ++j) dr[i][j] = axis_derivative(model, alg, model.nominal[i][j], k);
    }
    // Ω = dR0/dq · R0ᵀ is skew (R0 stays a rotation); its axial vector is the rotation rate. The
    // antisymmetric part keeps it exact even where cos² + sin² of a linked angle is not reduced.
    const auto omega = [&](int i, int j) {
      ex s = 0;
      for (int l = 0; l < 3; ++l) s += dr[i][l] * model.nominal[j][l];
      return s;
    };
    const GiNaC::numeric half(1, 2);
    model.nominal_jacobian[3 * n + k] = alg.normalize(half * (omega(2, 1) - omega(1, 2)));
    model.nominal_jacobian[4 * n + k] = alg.normalize(half * (omega(0, 2) - omega(2, 0)));
    model.nominal_jacobian[5 * n + k] = alg.normalize(half * (omega(1, 0) - omega(0, 1)));
  }
}

}  // namespace

bool SymbolicModel::axes_turn_output() const {
  const std::size_t n = axes.size();
  for (std::size_t i = 3 * n; i < nominal_jacobian.size(); ++i)
    if (!nominal_jacobian[i].is_zero()) return true;
  return false;
}

ex SymbolicModel::with_divisors(const ex& c) const {
  if (reciprocals.empty()) return c;
  GiNaC::exmap m;
  for (const Reciprocal& r : reciprocals) m[r.symbol] = GiNaC::pow(r.divisor, -1);
  return c.subs(m, GiNaC::subs_options::no_pattern);  // symbols only: no pattern matching
}

ex SymbolicModel::coefficient(int o, const Monomial& m) const {
  const auto& t = outputs[o].terms();
  auto it = t.find(m);
  return it == t.end() ? ex(0) : it->second;
}

std::vector<Monomial> SymbolicModel::higher_monomials() const {
  std::vector<Monomial> out;
  for (const auto& p : outputs)
    for (const auto& [m, c] : p.terms())
      if (m.size() >= 2) out.push_back(m);
  std::sort(out.begin(), out.end(), [](const Monomial& a, const Monomial& b) {
    return a.size() != b.size() ? a.size() < b.size() : a < b;
  });
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::string SymbolicModel::monomial_name(const Monomial& m) const {
  std::string s;
  for (std::size_t i = 0; i < m.size();) {
    std::size_t j = i;
    while (j < m.size() && m[j] == m[i]) ++j;
    if (!s.empty()) s += "·";
    s += desc.errors[m[i]].name;
    if (j - i > 1) s += "^" + std::to_string(j - i);
    i = j;
  }
  return s.empty() ? "1" : s;
}

SymbolicModel build_model(const Description& desc, int order_override) {
  SymbolicModel model;
  model.desc = desc;
  model.order = order_override > 0 ? order_override : desc.algebra.order;
  if (model.order < 1) throw std::invalid_argument("algebra order must be >= 1");

  GiNaC::exmap trig_rules;
  for (int b : desc.axes()) {
    const Joint& j = desc.bodies[b].joint;
    AxisSymbols a;
    a.body = b;
    a.revolute = j.type == JointType::Revolute;
    const std::string n = lower(j.coordinate);
    a.coordinate = GiNaC::symbol(n);
    if (a.revolute) {
      a.cos = GiNaC::symbol("cos(" + n + ")", "\\cos " + n);
      a.sin = GiNaC::symbol("sin(" + n + ")", "\\sin " + n);
      trig_rules[GiNaC::pow(a.cos, 2)] = 1 - GiNaC::pow(a.sin, 2);
    }
    model.axes.push_back(a);
  }
  for (const auto& e : desc.errors) model.errors.emplace_back(e.name);
  for (const auto& p : desc.parameters) model.params.emplace_back(p.name);

  const Algebra alg(model.order, relation_monomials(desc), trig_rules);
  model.relations = alg.relations();
  CanonicalText canon;
  std::map<ex, ex, GiNaC::ex_is_less> fractions;
  std::vector<std::pair<std::uint16_t, std::optional<SparsePoly>>> sparse_divisors;
  const Builder b{desc, model, alg, canon, fractions, sparse_divisors};

  // P: the tool frame (at the tool point) in the workpiece frame, or the output transform.
  const Mat4 p = desc.output
                     ? b.output_transform()
                     : neumann_inverse(b.branch(desc.workpiece), alg).mul(b.branch(desc.tool), alg);

  for (int i = 0; i < 3; ++i) model.outputs[i] = p.m[i][3].without_constant();

  // Orientation: rotation vector of ΔR = R·R0ᵀ, via log(I + A) = Σ (−1)^{k+1} A^k / k.
  Mat4 r = p, r0t;
  for (int i = 0; i < 3; ++i) {
    r.m[i][3] = Poly();
    for (int j = 0; j < 3; ++j) r0t.m[i][j] = Poly(p.m[j][i].constant());
  }
  r.m[3][3] = Poly(1);
  r0t.m[3][3] = Poly(1);
  const Mat4 a = r.mul(r0t, alg) - Mat4::identity();
  Mat4 log = Mat4::zero(), power = a;
  for (int k = 1; k <= model.order; ++k) {
    Mat4 term;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        term.m[i][j] = power.m[i][j].scaled(GiNaC::numeric(k % 2 == 1 ? 1 : -1, k), alg);
    log = log + term;
    power = power.mul(a, alg);
  }
  const GiNaC::numeric half(1, 2);
  model.outputs[3] = (log.m[2][1] - log.m[1][2]).scaled(half, alg);
  model.outputs[4] = (log.m[0][2] - log.m[2][0]).scaled(half, alg);
  model.outputs[5] = (log.m[1][0] - log.m[0][1]).scaled(half, alg);
  // Ratios with nominal divisors (derived quantities) expand into sums of fractions over the
  // same divisor; one fraction numerator/denominator reads better and costs fewer operations.
  for (Poly& out : model.outputs) out = out.mapped([&](const ex& c) { return b.as_fraction(c); });
  set_nominal_kinematics(model, p, alg);
  return model;
}

}  // namespace weilgen::gen
