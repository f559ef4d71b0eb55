#include "weilgen/uq/test_statistics.hpp"

#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/students_t.hpp>

namespace weilgen {

double fisher_f_sf(double f, double d1, double d2) {
  return boost::math::cdf(
      boost::math::complement(boost::math::fisher_f_distribution<double>(d1, d2), f));
}

double students_t_quantile(double dof, double p) {
  return boost::math::quantile(boost::math::students_t_distribution<double>(dof), p);
}

}  // namespace weilgen
