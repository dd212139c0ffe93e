#pragma once
// The rough-refraction pass's Gaussian sum reduction and 2x2 covariance helpers
// (render/passes/rough/gsr.glsl) in C++: the shader's code compiled with glm types, for tests.
#include <cmath>

#include <glm/glm.hpp>

namespace mirage::render::gsr {

using glm::any;
using glm::dot;
using glm::isinf;
using glm::isnan;
using glm::max;
using glm::vec2;
using glm::vec3;
using std::atan2;
using std::floor;
using std::sqrt;
inline float atan(float y, float x) {
    return std::atan2(y, x);
}

#define MIRAGE_GLSL_INLINE inline
#include "render/passes/rough/gsr.glsl"
#undef MIRAGE_GLSL_INLINE

}  // namespace mirage::render::gsr
