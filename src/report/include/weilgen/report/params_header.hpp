// The identified error parameters as a standalone C++ header (`weilgen identify --emit-params`),
// to be included beside the generated model header by a controller: only <array>, <cmath> and
// <cstddef>; constexpr coefficient tables; `Errors(axes, &errors)` gives every error of the model
// (base units mm, rad; kErrors order) at a pose, with no allocation. docs/identify.md.
#pragma once

#include <string>
#include <vector>

#include "weilgen/analysis/identify.hpp"
#include "weilgen/model/model.hpp"

namespace weilgen {

// The banner lines `weilgen identify --emit-params` writes: observations, rank, residual and the
// minimum-norm caveat (no paths or dates: the header is reproducible).
std::vector<std::string> identify_provenance(const IdentifyResult& r);

// Where the errors were identified, per independent axis (Description::axes() order, the axis'
// unit): the result's span of the measured poses, the axis' travel where the result has none.
struct IdentifiedSpan {
  std::vector<double> min, max;
};
IdentifiedSpan identified_span(const Description& desc, const IdentifyResult& result);

// `provenance` lines go into the banner (data files, observation counts ...); they must not
// contain dates or paths that vary between runs if the header is to be reproducible. The header's
// Errors() holds every PDGE at its axis' identified span ends (kSpanMin, kSpanMax).
// Throws std::invalid_argument when a PDGE runs along a linked coordinate (not supported).
std::string params_header(const Model& model, const ErrorParameterisation& param,
                          const IdentifyResult& result, const std::vector<std::string>& provenance);

// The same parameters as a JSON document for a controller that loads them at run time
// (`weilgen identify --emit-params-json`; the LinuxCNC component's params_file, docs/identify.md):
// weilgen_params (format 1), machine, model_key, params (name, unit, value), axes (name, unit,
// span), errors (name, unit of the values: mm or rad, basis: constant | poly | legendre |
// chebyshev | fourier, value, or axis, from, to, period, coefficients). Numbers round-trip.
std::string params_json(const Model& model, const ErrorParameterisation& param,
                        const IdentifyResult& result);

}  // namespace weilgen
