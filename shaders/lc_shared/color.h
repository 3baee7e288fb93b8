// Small functions the host code and the kernels share at namespace scope:
// luminance and the PCG hash. Compiles as GLSL (included by the kernels
// before the other shared headers) and as C++ (free inline functions in
// lc::gpu, over glm vectors).
#ifndef LC_SHARED_COLOR_H
#define LC_SHARED_COLOR_H

#ifdef __cplusplus
#include <glm/glm.hpp>
#include "types.h"
namespace lc::gpu {
#define LC_SHARED_FN inline
#define LC_VEC3 glm::vec3
#else
#define LC_SHARED_FN
#define LC_VEC3 vec3
#endif

// Rec. 709 luminance: the scalar every error bound, cluster weight and
// image metric is measured in.
LC_SHARED_FN float lc_luminance(LC_VEC3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// PCG hash (Jarzynski and Olano, JCGT 2020): pixel jitter on both devices
// and the light tree's representative choice.
LC_SHARED_FN uint lc_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The top 24 bits of a hash as a float in [0, 1).
LC_SHARED_FN float lc_unit_float(uint h) { return float(h >> 8u) * (1.0f / 16777216.0f); }

#undef LC_SHARED_FN
#undef LC_VEC3
#ifdef __cplusplus
}  // namespace lc::gpu
#endif
#endif
