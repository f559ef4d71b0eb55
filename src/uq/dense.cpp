// The one instantiation of the factorisations declared in weilgen/uq/dense.hpp.
#include "weilgen/uq/dense.hpp"

#define WEILGEN_DENSE_DEFINE(...) template __VA_ARGS__;
WEILGEN_DENSE_INSTANTIATIONS(WEILGEN_DENSE_DEFINE)
#undef WEILGEN_DENSE_DEFINE
