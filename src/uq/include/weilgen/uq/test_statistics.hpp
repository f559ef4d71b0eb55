// Tail probabilities and quantiles of the test statistics the runtime reports (F, Student t):
// Boost.Math underneath, compiled once in uq/test_statistics.cpp rather than in each file that
// tests a hypothesis (about 2 s of compile time per file). The standard normal's are in
// distribution.hpp (normal_cdf, normal_quantile).
#pragma once

namespace weilgen {

// P(F > f) for F ~ F(d1, d2), f >= 0, d1, d2 > 0.
double fisher_f_sf(double f, double d1, double d2);
// The p-quantile of Student's t with `dof` > 0 degrees of freedom, 0 < p < 1.
double students_t_quantile(double dof, double p);

}  // namespace weilgen
