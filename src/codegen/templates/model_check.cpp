// The model header template (templates/model.hpp) compiled on its own, as the stand-in model its
// blocks hold, with the strict flags of a controller build (CTest model_template): its fixed
// text is valid C++ and its tables agree with its counts.
#include "model.hpp"

namespace model = weilgen_models::standin;

static_assert(model::kAxes.size() == model::kNumAxes, "kAxes has kNumAxes rows");
static_assert(model::kErrors.size() == model::kNumErrors, "kErrors has kNumErrors rows");
static_assert(model::kParams.size() == model::kNumParams, "kParams has kNumParams rows");
static_assert(model::kOutputs.size() == 6 && model::kOutputUnits.size() == 6, "six outputs");
static_assert(model::kHigherTerms.size() == model::kNumHigherTerms, "no higher terms");

// Pack<L> compiled with these flags (its code is only checked where it is instantiated): each
// operation lane by lane, sin/cos within 1 ulp of the C library's (the whole pack from the library
// when a lane is beyond 1e6 rad). The generated functions over it:
// tests/test_generated_headers.cpp.
template <std::size_t L>
bool pack_ok(const double* in) {
  using P = weilgen_models::Pack<L>;
  const P x = P::Load(in);
  const P y = (x * 2.0 + 1.0) / x - (-x);
  P z = x;
  z += y;
  z -= x;
  z *= 2.0;
  const P s = sin(x), c = cos(x), r = sqrt(x * x);
  double ys[L], zs[L], ss[L], cs[L], rs[L];
  y.Store(ys);
  z.Store(zs);
  s.Store(ss);
  c.Store(cs);
  r.Store(rs);
  bool ok = true;
  for (std::size_t i = 0; i < L; ++i) {
    ok = ok && ys[i] == (in[i] * 2.0 + 1.0) / in[i] - (-in[i]) &&
         zs[i] == ((in[i] + ys[i]) - in[i]) * 2.0 && rs[i] == std::sqrt(in[i] * in[i]);
    ok = ok && std::fabs(ss[i] - std::sin(in[i])) <= 2.3e-16 &&
         std::fabs(cs[i] - std::cos(in[i])) <= 2.3e-16;
  }
  return ok;
}

int main() {
  // The rotary axis' unit factor is deg -> rad, the error's um -> mm.
  bool ok = model::kAxes[1].revolute && model::kAxes[1].to_base > 0.0174 &&
            model::kAxes[1].to_base < 0.0175 && model::kErrors[0].to_base == 0.001;
  const double in[8] = {0.5, -1.25, 3.0, 0.7853981633974483, 2.356194490192345, -4.0, 100.0, 6.0};
  const double far[8] = {0.5, -1.25, 3.0, 1e7, 2.356194490192345, -4.0, 100.0, 6.0};
  ok = ok && pack_ok<2>(in) && pack_ok<4>(in) && pack_ok<8>(in) && pack_ok<4>(far) &&
       pack_ok<8>(far);
  return ok ? 0 : 1;
}
