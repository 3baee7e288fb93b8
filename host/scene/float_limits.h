// What the renderer adds up in 32-bit floats must stay finite there.
//
// Every value in a scene is a finite float on its own, but the light tree
// sums intensities per light type and unites light boxes, and the distance
// clamp takes the diagonal of the scene bounds: two lights of 2e38 make an
// infinite root intensity, coordinates near ±1e38 an infinite extent and then
// NaN. The loader sums and unites in double as it reads, and refuses the input
// where a float would overflow, naming the value that tipped it over.
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <string>

#include <glm/glm.hpp>

#include "lc_shared/types.h"

namespace lc::loader {

inline constexpr double kFloatMax = std::numeric_limits<float>::max();

// The unit vector along v, its length taken in double: a float's square
// underflows below about 1e-19 (the cross product of a tiny triangle's
// edges, say), so a length taken in float comes out short and v divided by
// it is not of unit length. False where v has no direction (zero, or not
// finite).
inline bool unit_vector(glm::dvec3 v, glm::vec3& unit) {
    const double length = glm::length(v);
    if (!(length > 0.0) || !std::isfinite(length)) return false;
    unit = glm::vec3(v / length);
    return true;
}

// A triangle's unit face normal (its winding's side) from the exact cross
// product of its float corners; false where it has none (the corners are
// collinear, or not finite).
inline bool face_normal(const std::array<glm::vec3, 3>& v, glm::vec3& unit) {
    const glm::dvec3 a(v[0]), b(v[1]), c(v[2]);
    return unit_vector(glm::cross(b - a, c - a), unit);
}

enum class TriangleShape { ok, degenerate, too_large };

// A triangle's corners as the renderer stores them: degenerate where a
// corner is not finite or its edges' cross product has no length or
// direction (dropped and counted); too large where the length of that
// cross product, taken in float as the kernels take such lengths,
// overflows (edges of about 4e9 or more: refused, naming the triangle; it
// was dropped as degenerate). `face` is the unit face normal where ok.
inline TriangleShape triangle_shape(const std::array<glm::vec3, 3>& v, glm::vec3& face) {
    for (const glm::vec3& p : v)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return TriangleShape::degenerate;
    const float twice_area = glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
    if (!std::isfinite(twice_area)) return TriangleShape::too_large;
    if (!(twice_area > 0.0f) || !face_normal(v, face)) return TriangleShape::degenerate;
    return TriangleShape::ok;
}

// What an InputError says of a TriangleShape::too_large triangle.
inline constexpr const char* kTriangleTooLarge =
    "too large for the renderer's float arithmetic: its area's square overflows (edges of about 4e9 or more); "
    "scale the scene down";

// Finite and within ±FLT_MAX (false for NaN).
inline bool fits_float(double v) { return v >= -kFloatMax && v <= kFloatMax; }
inline bool fits_float(glm::dvec3 p) { return fits_float(p.x) && fits_float(p.y) && fits_float(p.z); }

// An axis-aligned box in double; empty until the first point. glm::min and
// glm::max skip NaN, so check points with fits_float before growing.
struct Box {
    glm::dvec3 lo{std::numeric_limits<double>::infinity()};
    glm::dvec3 hi{-std::numeric_limits<double>::infinity()};

    bool empty() const { return lo.x > hi.x; }
    void grow(glm::dvec3 p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
};

// The largest extent of the scene along an axis, geometry and lights
// together: the kernels square distances and sums of three squared
// coordinates in float (3 x 1e38 still fits). Past it a cluster's cosine
// bound came out 0 (inf under a square root) and its lights were skipped,
// and the light tree's metric NaN, which built a chain in O(n^2).
inline constexpr double kMaxExtent = 1e19;

// "" when the box's corners are finite as floats and its extent (max -
// min) along every axis at most kMaxExtent; otherwise which axis is not,
// for an error message.
std::string extent_problem(const Box& box);

// Running totals over the lights of a scene, in file order: intensity per
// light type and colour channel, and the box around the geometry and every
// point light so far.
class LightLimits {
public:
    explicit LightLimits(const Box& geometry = {}) : box_(geometry) {}

    enum class Fault { none, total, position };
    struct Problem {
        Fault fault = Fault::none;
        std::string text;  // for the InputError; empty when fault is none
    };

    // Adds one light; reports the first total it pushes past FLT_MAX, or
    // extent past kMaxExtent.
    Problem add(const gpu::Light& light);

private:
    Box box_;
    bool box_checked_ = false;  // extent_problem(box_) was "" for this box
    std::array<glm::dvec3, gpu::kLightTypeCount> totals_{};
};

}  // namespace lc::loader
