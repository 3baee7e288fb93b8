// Unit vectors packed into 32 bits, octahedral (Cigolle et al., "A Survey of
// Efficient Representations for Independent Unit Vectors", JCGT 2014).
// Decoded identically by the host and the kernels; only the host encodes
// (host/light_bounds.cpp), and it widens every cone by the angle its axis
// moved, so bounds stay conservative. Compiles as GLSL and as C++ (free
// inline functions in lc::gpu, over glm).
#ifndef LC_SHARED_OCTAHEDRAL_H
#define LC_SHARED_OCTAHEDRAL_H

#ifdef __cplusplus
#include <glm/glm.hpp>
#include "types.h"
namespace lc::gpu {
using glm::abs;
using glm::clamp;
using glm::normalize;
using glm::vec2;
using glm::vec3;
#define LC_SHARED_FN inline
#else
#define LC_SHARED_FN
#endif

// The two signed 16-bit halves of v as floats in [-1, 1] (GLSL's
// unpackSnorm2x16, written out so that C++ computes exactly the same).
LC_SHARED_FN vec2 lc_unpack_snorm16x2(uint v) {
    int lo = int(v << 16u) >> 16;
    int hi = int(v) >> 16;
    return clamp(vec2(float(lo), float(hi)) / 32767.0f, -1.0f, 1.0f);
}

LC_SHARED_FN vec3 lc_decode_axis(uint packed) {
    vec2 e = lc_unpack_snorm16x2(packed);
    vec3 v = vec3(e.x, e.y, 1.0f - abs(e.x) - abs(e.y));
    if (v.z < 0.0f) {
        float x = (1.0f - abs(v.y)) * (v.x >= 0.0f ? 1.0f : -1.0f);
        float y = (1.0f - abs(v.x)) * (v.y >= 0.0f ? 1.0f : -1.0f);
        v.x = x;
        v.y = y;
    }
    return normalize(v);
}

#undef LC_SHARED_FN
#ifdef __cplusplus
}  // namespace lc::gpu
#endif
#endif
