// The Compensate solver every generated header carries (docs/compensation.md), as a real C++
// file: the generator emits everything after the marker line below, with
// WEILGEN_TEMPLATE_ORIENTATION replaced by true or false (src/codegen/emit_compensation.cpp).
// It is compiled on its own, with the strict flags of a controller build, against a stand-in
// model by src/codegen/templates/compensate_check.cpp (CTest compensate_template).
//
// Inside a generated header it sees the model's namespace: kNumAxes, kNumErrors, kNumParams,
// NominalPose, NominalJacobian, Deviation, and <array>, <cmath>, <cstddef>.
// clang-format off: the text below is emitted byte for byte (the generated files are golden).
// ---- weilgen template: emitted from the next line ----
// ---- Compensation (docs/compensation.md) -------------------------------------
// Compensate finds the command q whose predicted pose is the nominal pose at the target t:
//   F(q) = NominalPose(q) (+) Deviation(q, e(q)) - NominalPose(t) = 0,
// in weighted least squares W F over the rows the axes can move: the position (mm) and, when
// some axis turns the tool relative to the workpiece (kCompensateOrientation), the orientation:
// the tilt of the tool axis (z of the tool frame) times kCompensationLengthMm, the spin about
// the tool axis times kCompensationSpinWeight * kCompensationLengthMm. The iteration is
// Gauss-Newton with the Jacobian frozen at the target (factored once per call): q_0 = t,
// q_{k+1} = q_k - (A^T A)^-1 A^T W F(q_k), A = W J(t); it stops when the weighted pose is within
// tolerance_mm of the fixed point (by the step, or by the contraction of successive steps).
// Real time: no allocation, no exceptions, at most max_iterations calls of errors_at, Deviation
// and NominalPose.
inline constexpr bool kCompensateOrientation = WEILGEN_TEMPLATE_ORIENTATION;
// 1 rad of tilt of the tool axis counts as this many mm of position error.
inline constexpr double kCompensationLengthMm = 100.0;
// Relative weight of the spin about the tool axis: immaterial for a rotating tool, but a small
// weight keeps the correction bounded where no axis can tilt the tool in some direction (an A/C
// table at A = 0: C turns about the tool axis).
inline constexpr double kCompensationSpinWeight = 0.01;

namespace compensation_detail {
// Minimal traits (the header includes no <type_traits>): the callable overload of Compensate
// must not take a std::array of errors, which the fixed-errors overload handles.
template <typename T>
struct Bare {
  using type = T;
};
template <typename T>
struct Bare<T&> : Bare<T> {};
template <typename T>
struct Bare<T&&> : Bare<T> {};
template <typename T>
struct Bare<const T> : Bare<T> {};
template <typename T>
struct IsArray {
  static constexpr bool value = false;
};
template <typename T, std::size_t N>
struct IsArray<std::array<T, N>> {
  static constexpr bool value = true;
};
template <bool Condition>
struct EnableIf {};
template <>
struct EnableIf<true> {
  using type = int;
};
template <typename F>
using IfCallable = typename EnableIf<!IsArray<typename Bare<F>::type>::value>::type;
}  // namespace compensation_detail

// The corrected command for `target` (kAxes order and units, mm/deg). `errors_at` is
// void(const std::array<Scalar, kNumAxes>& axes, std::array<Scalar, kNumErrors>* errors), the
// errors at a pose in base units (mm, rad), kErrors order. Returns the iterations used (>= 1),
// or -1 when the weighted Jacobian at the target is singular (an axis moves no weighted output
// or only a combination of what the others move), a value is not finite, or the iteration has
// not converged within max_iterations; *command is then the target, uncompensated.
template <typename Scalar, typename ErrorsAt, compensation_detail::IfCallable<ErrorsAt> = 0>
int Compensate(const std::array<Scalar, kNumAxes>& target, ErrorsAt&& errors_at,
               const std::array<Scalar, kNumParams>& params,
               std::array<Scalar, kNumAxes>* const command, const int max_iterations = 10,
               const Scalar tolerance_mm = Scalar(1e-9)) {
  using std::sqrt;
  constexpr std::size_t n = kNumAxes;
  constexpr std::size_t rows = kCompensateOrientation ? 6 : 3;
  if (command == nullptr) return -1;
  *command = target;
  const Scalar length = Scalar(kCompensationLengthMm);

  std::array<Scalar, 3> p_target{};
  std::array<Scalar, 9> r_target{};
  NominalPose(target, params, &p_target, kCompensateOrientation ? &r_target : nullptr);
  // W on an orientation (rad): length * (v - (1 - spin weight) * z (z . v)), z the tool axis.
  const std::array<Scalar, 3> z = {r_target[2], r_target[5], r_target[8]};
  const Scalar keep_spin = Scalar(kCompensationSpinWeight);
  const auto weigh = [&](const std::array<Scalar, 3>& v, Scalar* out, std::size_t stride) {
    const Scalar zv = (Scalar(1) - keep_spin) * (z[0] * v[0] + z[1] * v[1] + z[2] * v[2]);
    for (std::size_t i = 0; i < 3; ++i) out[i * stride] = length * (v[i] - z[i] * zv);
  };

  // A = W J(t): the weighted rows of the nominal Jacobian at the target, row-major [row][axis].
  std::array<Scalar, 6 * kNumAxes> a{};
  NominalJacobian(target, params, &a);
  if (kCompensateOrientation)
    for (std::size_t k = 0; k < n; ++k)
      weigh({a[3 * n + k], a[4 * n + k], a[5 * n + k]}, &a[3 * n + k], n);

  // A^T A in the lower triangle of l, factored in place into L with A^T A = L L^T (Cholesky).
  // A pivot at or below `relative` times its diagonal entry means the axis adds no direction of
  // its own (a zero column, or a combination of the earlier ones): no unique correction.
  std::array<Scalar, kNumAxes * kNumAxes> l{};
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j <= i; ++j)
      for (std::size_t r = 0; r < rows; ++r) l[i * n + j] += a[r * n + i] * a[r * n + j];
  const Scalar relative = sizeof(Scalar) < sizeof(double) ? Scalar(1e-5) : Scalar(1e-10);
  std::array<Scalar, kNumAxes> inverse_diagonal{};  // 1 / L_ii: the solves multiply
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j <= i; ++j) {
      Scalar sum = l[i * n + j];
      for (std::size_t k = 0; k < j; ++k) sum -= l[i * n + k] * l[j * n + k];
      if (j < i) {
        l[i * n + j] = sum * inverse_diagonal[j];
      } else {
        if (!(sum > relative * l[i * n + i])) return -1;  // also a NaN
        l[i * n + i] = sqrt(sum);
        inverse_diagonal[i] = Scalar(1) / l[i * n + i];
      }
    }
  }

  std::array<Scalar, kNumAxes> q = target;
  std::array<Scalar, kNumErrors> errors{};
  std::array<Scalar, 3> p{}, dp{}, dr{};
  std::array<Scalar, 9> r_q{};
  Scalar previous = Scalar(-1);  // |A step|^2 of the previous iteration, none yet
  for (int iteration = 1; iteration <= max_iterations; ++iteration) {
    // f = W F(q): the predicted pose at q minus the nominal pose at the target.
    errors_at(q, &errors);
    if (iteration == 1) {  // q is the target
      p = p_target;
      r_q = r_target;
    } else {
      NominalPose(q, params, &p, kCompensateOrientation ? &r_q : nullptr);
    }
    Deviation(q, errors, params, &dp, kCompensateOrientation ? &dr : nullptr);
    std::array<Scalar, 6> f{};
    for (std::size_t i = 0; i < 3; ++i) f[i] = p[i] - p_target[i] + dp[i];
    if (kCompensateOrientation) {
      // The rotation from the target's nominal orientation to q's: the axial vector of the skew
      // part of R(q) R(t)^T (the rotation vector up to O(angle^3)), plus the predicted deviation.
      const auto rt = [&](std::size_t i, std::size_t j) {
        return r_q[3 * i] * r_target[3 * j] + r_q[3 * i + 1] * r_target[3 * j + 1] +
               r_q[3 * i + 2] * r_target[3 * j + 2];
      };
      const Scalar half = Scalar(0.5);
      weigh({half * (rt(2, 1) - rt(1, 2)) + dr[0], half * (rt(0, 2) - rt(2, 0)) + dr[1],
             half * (rt(1, 0) - rt(0, 1)) + dr[2]},
            &f[3], 1);
    }
    // step = (A^T A)^-1 A^T f: g = A^T f, then L y = g and L^T step = y, in place in s.
    std::array<Scalar, kNumAxes> g{};
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t r = 0; r < rows; ++r) g[i] += a[r * n + i] * f[r];
    std::array<Scalar, kNumAxes> s = g;
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t k = 0; k < i; ++k) s[i] -= l[i * n + k] * s[k];
      s[i] *= inverse_diagonal[i];
    }
    for (std::size_t i = n; i-- > 0;) {
      for (std::size_t k = i + 1; k < n; ++k) s[i] -= l[k * n + i] * s[k];
      s[i] *= inverse_diagonal[i];
    }
    // |A step|^2 = step^T A^T A step = step^T g: how far the step moves the weighted pose (mm^2).
    Scalar moved = Scalar(0);
    for (std::size_t i = 0; i < n; ++i) {
      moved += s[i] * g[i];
      q[i] -= s[i];
    }
    if (!(moved >= Scalar(0))) return -1;  // a NaN
    // Converged when the step is within tolerance, or when the steps contract (rate rho) so that
    // the distance left to the fixed point, at most |step| rho / (1 - rho), is.
    bool converged = moved <= tolerance_mm * tolerance_mm;
    if (!converged && moved < previous) {
      const Scalar rho = sqrt(moved / previous);
      converged = sqrt(moved) * rho <= tolerance_mm * (Scalar(1) - rho);
    }
    if (converged) {
      *command = q;
      return iteration;
    }
    previous = moved;
  }
  return -1;
}

// The same with errors that do not depend on the pose (constants, or errors frozen for a cycle).
template <typename Scalar>
int Compensate(const std::array<Scalar, kNumAxes>& target,
               const std::array<Scalar, kNumErrors>& errors,
               const std::array<Scalar, kNumParams>& params,
               std::array<Scalar, kNumAxes>* const command, const int max_iterations = 10,
               const Scalar tolerance_mm = Scalar(1e-9)) {
  const auto fixed = [&errors](const std::array<Scalar, kNumAxes>&,
                               std::array<Scalar, kNumErrors>* const out) { *out = errors; };
  return Compensate(target, fixed, params, command, max_iterations, tolerance_mm);
}
