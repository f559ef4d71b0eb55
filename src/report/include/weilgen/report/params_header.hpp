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

// `provenance` lines go into the banner (data files, observation counts ...); they must not
// contain dates or paths that vary between runs if the header is to be reproducible.
// Throws std::invalid_argument when a PDGE runs along a linked coordinate (not supported).
std::string params_header(const Model& model, const ErrorParameterisation& param,
                          const std::vector<double>& theta,
                          const std::vector<std::string>& provenance);

}  // namespace weilgen
