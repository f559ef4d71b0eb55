// The generated headers evaluated directly, without any weilgen library: the reference that the
// Python module's Model must equal bit for bit (tests/python/test_model.py).
//   reference_model MACHINE names
//       prints the header's axes, errors, parameters and outputs with their units, one line each
//   reference_model MACHINE eval N AXES ERRORS PARAMS DEVIATION COEFFICIENTS
//       reads N x kNumAxes, N x kNumErrors and kNumParams float64 values (raw, native order),
//       writes N x 6 deviations and N x 6 x kNumErrors coefficients the same way
#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "reference_models.inc"  // generated: the shipped machines' headers and their list

namespace {

std::vector<double> read(const char* path, std::size_t count) {
  std::vector<double> v(count);
  FILE* f = std::fopen(path, "rb");
  if (!f || std::fread(v.data(), sizeof(double), count, f) != count) {
    std::fprintf(stderr, "reference_model: cannot read %zu values from %s\n", count, path);
    std::exit(3);
  }
  std::fclose(f);
  return v;
}

void write(const char* path, const std::vector<double>& v) {
  FILE* f = std::fopen(path, "wb");
  if (!f || std::fwrite(v.data(), sizeof(double), v.size(), f) != v.size()) {
    std::fprintf(stderr, "reference_model: cannot write %s\n", path);
    std::exit(3);
  }
  std::fclose(f);
}

template <typename Info, std::size_t N>
void print_names(const char* what, const std::array<Info, N>& items) {
  std::printf("%s", what);
  for (const auto& i : items) std::printf(" %s", i.name);
  std::printf("\n");
}

template <typename Info, std::size_t N>
void print_units(const char* what, const std::array<Info, N>& items) {
  std::printf("%s", what);
  for (const auto& i : items) std::printf(" %s", i.unit);
  std::printf("\n");
}

#define WEILGEN_REFERENCE(machine)                                                          \
  if (name == #machine) {                                                                   \
    namespace m = weilgen_models::machine;                                                  \
    if (argc == 3 && std::string(argv[2]) == "names") {                                     \
      print_names("axes", m::kAxes);                                                        \
      print_units("axis_units", m::kAxes);                                                  \
      print_names("errors", m::kErrors);                                                    \
      std::printf("error_units");                                                           \
      for (const auto& e : m::kErrors) std::printf(" %s", e.rotation ? "rad" : "mm");       \
      std::printf("\n");                                                                    \
      print_names("params", m::kParams);                                                    \
      print_units("param_units", m::kParams);                                               \
      std::printf("outputs");                                                               \
      for (const char* o : m::kOutputs) std::printf(" %s", o);                              \
      std::printf("\noutput_units");                                                        \
      for (const char* u : m::kOutputUnits) std::printf(" %s", u);                          \
      std::printf("\n");                                                                    \
      return 0;                                                                             \
    }                                                                                       \
    if (argc != 9 || std::string(argv[2]) != "eval") return 2;                              \
    const std::size_t n = std::strtoull(argv[3], nullptr, 10);                              \
    const auto axes = read(argv[4], n * m::kNumAxes);                                       \
    const auto errors = read(argv[5], n * m::kNumErrors);                                   \
    const auto params = read(argv[6], m::kNumParams);                                       \
    std::array<double, m::kNumParams> p{};                                                  \
    for (std::size_t j = 0; j < m::kNumParams; ++j) p[j] = params[j];                       \
    std::vector<double> deviation(n * 6), coefficients(n * 6 * m::kNumErrors);              \
    for (std::size_t i = 0; i < n; ++i) {                                                   \
      std::array<double, m::kNumAxes> a{};                                                  \
      std::array<double, m::kNumErrors> e{};                                                \
      for (std::size_t j = 0; j < m::kNumAxes; ++j) a[j] = axes[i * m::kNumAxes + j];       \
      for (std::size_t j = 0; j < m::kNumErrors; ++j) e[j] = errors[i * m::kNumErrors + j]; \
      std::array<double, 3> pos{}, ori{};                                                   \
      m::Deviation<double>(a, e, p, &pos, &ori);                                            \
      for (std::size_t j = 0; j < 3; ++j) {                                                 \
        deviation[i * 6 + j] = pos[j];                                                      \
        deviation[i * 6 + 3 + j] = ori[j];                                                  \
      }                                                                                     \
      std::array<double, 3 * m::kNumErrors> pc{}, oc{};                                     \
      m::Coefficients<double>(a, p, &pc, &oc);                                              \
      double* c = &coefficients[i * 6 * m::kNumErrors];                                     \
      for (std::size_t j = 0; j < pc.size(); ++j) c[j] = pc[j];                             \
      for (std::size_t j = 0; j < oc.size(); ++j) c[pc.size() + j] = oc[j];                 \
    }                                                                                       \
    write(argv[7], deviation);                                                              \
    write(argv[8], coefficients);                                                           \
    return 0;                                                                               \
  }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: reference_model MACHINE names | eval N A E P DEV COEFF\n");
    return 2;
  }
  const std::string name = argv[1];
  WEILGEN_SHIPPED_REFERENCES
  std::fprintf(stderr, "reference_model: no shipped machine '%s'\n", name.c_str());
  return 2;
}
