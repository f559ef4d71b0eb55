#include "weilgen/machine/pdge_basis.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {
namespace {

constexpr int kMaxOrder = 200;

// Power-series coefficients (in u) of the first n + 1 Legendre or Chebyshev polynomials:
// m[k][j] = coefficient of u^j in P_k (or T_k).
std::vector<std::vector<double>> monomial_table(BasisKind kind, int n) {
  std::vector<std::vector<double>> m(static_cast<std::size_t>(n) + 1,
                                     std::vector<double>(static_cast<std::size_t>(n) + 1, 0.0));
  m[0][0] = 1;
  if (n >= 1) m[1][1] = 1;
  for (int k = 1; k < n; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    for (int j = 0; j <= n; ++j) {
      const auto ju = static_cast<std::size_t>(j);
      const double shifted = j > 0 ? m[ku][ju - 1] : 0.0;  // u * p_k
      if (kind == BasisKind::Legendre) {
        // (k+1) P_{k+1} = (2k+1) u P_k - k P_{k-1}
        m[ku + 1][ju] = ((2.0 * k + 1) * shifted - k * m[ku - 1][ju]) / (k + 1.0);
      } else {
        // T_{k+1} = 2u T_k - T_{k-1}
        m[ku + 1][ju] = 2 * shifted - m[ku - 1][ju];
      }
    }
  }
  return m;
}

}  // namespace

const char* basis_kind_name(BasisKind kind) {
  switch (kind) {
    case BasisKind::Polynomial:
      return "poly";
    case BasisKind::Fourier:
      return "fourier";
    case BasisKind::Legendre:
      return "legendre";
    case BasisKind::Chebyshev:
      return "chebyshev";
  }
  return "?";
}

std::size_t basis_size(BasisKind kind, int order) {
  if (order < 0) return 0;
  const auto n = static_cast<std::size_t>(order);
  return kind == BasisKind::Fourier ? 2 * n + 1 : n + 1;
}

int max_order_for_points(BasisKind kind, std::size_t points) {
  if (points == 0) return -1;
  const int p = static_cast<int>(std::min<std::size_t>(points, 100000));
  return kind == BasisKind::Fourier ? (p - 1) / 2 : p - 1;
}

Basis Basis::make(BasisKind kind, int order, double a, double b, double period_mm) {
  Basis basis;
  basis.kind = kind;
  basis.order = order;
  basis.a = a;
  basis.b = b;
  basis.period_mm = period_mm;
  basis.validate();
  return basis;
}

void Basis::validate() const {
  if (!std::isfinite(a) || !std::isfinite(b))
    throw std::invalid_argument("travel [" + format_short(a, 10) + ", " + format_short(b, 10) +
                                "] mm is not finite");
  if (!(b > a)) {
    throw std::invalid_argument("travel [" + format_short(a, 10) + ", " + format_short(b, 10) +
                                "] mm has " +
                                (a == b ? std::string("zero length") : "its end before its start") +
                                ": a basis needs a travel a < b");
  }
  if (order < 0 || order > kMaxOrder) {
    throw std::invalid_argument(std::string("basis ") + basis_kind_name(kind) + ": order " +
                                std::to_string(order) + " is outside 0.." +
                                std::to_string(kMaxOrder));
  }
  if (kind == BasisKind::Fourier && !std::isnan(period_mm) &&
      !(std::isfinite(period_mm) && period_mm > 0)) {
    throw std::invalid_argument("basis fourier: period " + format_short(period_mm, 10) +
                                " mm must be a finite length > 0");
  }
}

std::size_t Basis::size() const { return basis_size(kind, order); }

double Basis::period() const { return std::isnan(period_mm) ? b - a : period_mm; }

std::string Basis::name() const {
  std::string s = std::string(basis_kind_name(kind)) + ":" + std::to_string(order);
  if (kind == BasisKind::Fourier && !std::isnan(period_mm)) s += ":" + format_short(period_mm, 10);
  return s;
}

void Basis::evaluate(double x, double* out) const {
  const int n = order;
  switch (kind) {
    case BasisKind::Polynomial: {
      const double u = scaled(x);
      double p = 1;
      for (int k = 0; k <= n; ++k, p *= u) out[k] = p;
      return;
    }
    case BasisKind::Legendre: {
      const double u = scaled(x);
      out[0] = 1;
      if (n >= 1) out[1] = u;
      for (int k = 1; k < n; ++k)
        out[k + 1] = ((2.0 * k + 1) * u * out[k] - k * out[k - 1]) / (k + 1.0);
      return;
    }
    case BasisKind::Chebyshev: {
      const double u = scaled(x);
      out[0] = 1;
      if (n >= 1) out[1] = u;
      for (int k = 1; k < n; ++k) out[k + 1] = 2 * u * out[k] - out[k - 1];
      return;
    }
    case BasisKind::Fourier: {
      const double w = 2 * kPi * x / period();
      out[0] = 1;
      for (int k = 1; k <= n; ++k) {
        out[2 * k - 1] = std::cos(k * w);
        out[2 * k] = std::sin(k * w);
      }
      return;
    }
  }
}

double Basis::value(const double* c, double x) const {
  // Small orders in practice: a fixed buffer avoids allocation up to kMaxOrder.
  double terms[2 * kMaxOrder + 1];
  evaluate(x, terms);
  double s = 0;
  for (std::size_t k = 0; k < size(); ++k) s += c[k] * terms[k];
  return s;
}

std::vector<std::string> Basis::term_names() const {
  std::vector<std::string> names;
  for (int k = 0; k <= order; ++k) {
    switch (kind) {
      case BasisKind::Polynomial:
        names.push_back(k == 0 ? "1" : k == 1 ? "u" : "u^" + std::to_string(k));
        break;
      case BasisKind::Legendre:
        names.push_back("P" + std::to_string(k) + "(u)");
        break;
      case BasisKind::Chebyshev:
        names.push_back("T" + std::to_string(k) + "(u)");
        break;
      case BasisKind::Fourier:
        if (k == 0) {
          names.push_back("1");
        } else {
          names.push_back("cos(2pi*" + std::to_string(k) + "*x/L)");
          names.push_back("sin(2pi*" + std::to_string(k) + "*x/L)");
        }
        break;
    }
  }
  return names;
}

std::vector<double> Basis::power_coefficients(const std::vector<double>& c) const {
  if (kind == BasisKind::Fourier)
    throw std::invalid_argument("basis " + name() + ": a Fourier series has no power series");
  if (c.size() != size()) {
    throw std::invalid_argument("basis " + name() + ": " + std::to_string(c.size()) +
                                " coefficients given, " + std::to_string(size()) + " expected");
  }
  const auto n = static_cast<std::size_t>(order);
  // 1. Power series in u.
  std::vector<double> cu(n + 1, 0.0);
  if (kind == BasisKind::Polynomial) {
    cu = c;
  } else {
    const auto m = monomial_table(kind, order);
    for (std::size_t k = 0; k <= n; ++k)
      for (std::size_t j = 0; j <= k; ++j) cu[j] += c[k] * m[k][j];
  }
  // 2. u = alpha x + beta: u^k = sum_j C(k, j) alpha^j x^j beta^(k-j).
  const double alpha = 2 / (b - a), beta = -(a + b) / (b - a);
  std::vector<double> d(n + 1, 0.0);
  for (std::size_t k = 0; k <= n; ++k) {
    double binom = 1;  // C(k, j)
    for (std::size_t j = 0; j <= k; ++j) {
      d[j] += cu[k] * binom * std::pow(alpha, static_cast<double>(j)) *
              std::pow(beta, static_cast<double>(k - j));
      binom = binom * static_cast<double>(k - j) / static_cast<double>(j + 1);
    }
  }
  return d;
}

std::string BasisSpec::str() const {
  std::string s = std::string(basis_kind_name(kind)) + ":" +
                  (order < 0 ? std::string("auto") : std::to_string(order));
  if (kind == BasisKind::Fourier) {
    if (period_search)
      s += ":auto";
    else if (!std::isnan(period_mm))
      s += ":" + format_short(period_mm, 10);
  }
  return s;
}

Basis BasisSpec::on(double a, double b) const {
  if (order < 0)
    throw std::invalid_argument("basis " + str() + ": the order must be given to place it");
  if (period_search)
    throw std::invalid_argument("basis " + str() +
                                ": the period is to be searched (PeriodSearch), not placed");
  return Basis::make(kind, order, a, b, period_search ? NAN : period_mm);
}

BasisSpec parse_basis(const std::string& text, bool allow_auto) {
  const std::string quoted = "basis \"" + text + "\": ";
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t colon = text.find(':', start);
    parts.push_back(trim(text.substr(start, colon - start)));
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  BasisSpec spec;
  const std::string kind = lower(parts[0]);
  if (kind == "poly" || kind == "polynomial") {
    spec.kind = BasisKind::Polynomial;
  } else if (kind == "fourier") {
    spec.kind = BasisKind::Fourier;
  } else if (kind == "legendre") {
    spec.kind = BasisKind::Legendre;
  } else if (kind == "chebyshev" || kind == "cheb") {
    spec.kind = BasisKind::Chebyshev;
  } else {
    throw std::invalid_argument(
        quoted + (kind.empty() ? "kind missing" : "unknown kind \"" + parts[0] + "\"") +
        " (expected poly, fourier, legendre or chebyshev, e.g. poly:3)");
  }
  const std::size_t max_parts = spec.kind == BasisKind::Fourier ? 3 : 2;
  if (parts.size() > max_parts) {
    throw std::invalid_argument(
        quoted + (spec.kind == BasisKind::Fourier
                      ? "too many fields (expected fourier[:ORDER[:PERIOD]], e.g. fourier:3:20mm)"
                      : std::string("too many fields (expected ") + basis_kind_name(spec.kind) +
                            ":ORDER; only fourier takes a period)"));
  }
  const std::string example = std::string(basis_kind_name(spec.kind)) + ":3";
  if (parts.size() < 2 || parts[1].empty() || lower(parts[1]) == "auto") {
    if (!allow_auto) {
      throw std::invalid_argument(quoted +
                                  (parts.size() < 2 || parts[1].empty()
                                       ? "the order is missing"
                                       : "order auto is not allowed here") +
                                  ": give a whole number (e.g. " + example + ")");
    }
    spec.order = -1;
  } else {
    const std::string& o = parts[1];
    bool digits = !o.empty() && o.size() <= 4;
    for (char ch : o) digits = digits && std::isdigit(static_cast<unsigned char>(ch));
    if (!digits || std::atoi(o.c_str()) > kMaxOrder) {
      throw std::invalid_argument(quoted + "order \"" + o + "\" must be a whole number 0.." +
                                  std::to_string(kMaxOrder) + (allow_auto ? " or auto" : "") +
                                  " (e.g. " + example + ")");
    }
    spec.order = std::atoi(o.c_str());
  }
  if (parts.size() == 3) {
    std::string p = parts[2];
    if (lower(p) == "auto") {
      spec.period_search = true;
    } else {
      if (p.size() > 2 && p.compare(p.size() - 2, 2, "mm") == 0)
        p = trim(p.substr(0, p.size() - 2));
      char* end = nullptr;
      const double v = std::strtod(p.c_str(), &end);
      if (p.empty() || end != p.c_str() + p.size() || !std::isfinite(v) || v <= 0) {
        throw std::invalid_argument(quoted + "period \"" + parts[2] +
                                    "\" must be a length > 0 in mm (e.g. 20 or 20mm) or auto");
      }
      spec.period_mm = v;
    }
  }
  return spec;
}

std::string default_pdge_basis(const Joint& j) {
  return j.type == JointType::Revolute ? "fourier:2" : "poly:3";
}

Basis basis_on_joint(const BasisSpec& spec, const Joint& j) {
  BasisSpec placed = spec;
  if (spec.kind == BasisKind::Fourier && !spec.period_search && std::isnan(spec.period_mm) &&
      j.type == JointType::Revolute)
    placed.period_mm = j.unit == "deg" ? 360.0 : 2 * kPi / j.to_base;  // one turn, joint unit
  return placed.on(j.min, j.max);
}

}  // namespace weilgen
