// Overflow checks for the float sums and boxes the renderer builds (float_limits.h).
#include "float_limits.h"

#include "light_records.h"

namespace lc::loader {
namespace {

constexpr const char* kAxisNames[] = {"x", "y", "z"};
constexpr const char* kChannelNames[] = {"red", "green", "blue"};
constexpr const char* kFloatRange = "the float range (3.4e38)";
constexpr const char* kExtentRange = "1e19 (the renderer squares distances in float and sums three such squares)";

}  // namespace

std::string extent_problem(const Box& box) {
    if (box.empty()) return {};
    for (int a = 0; a < 3; ++a) {
        if (!fits_float(box.lo[a]) || !fits_float(box.hi[a])) {
            return std::string("the ") + kAxisNames[a] + " coordinate is outside " + kFloatRange;
        }
        if (!(box.hi[a] - box.lo[a] <= kMaxExtent)) {
            return std::string("the extent along ") + kAxisNames[a] + " exceeds " + kExtentRange;
        }
    }
    return {};
}

LightLimits::Problem LightLimits::add(const gpu::Light& light) {
    const std::uint32_t type = light.type & gpu::kLightTypeMask;
    if (type < gpu::kLightTypeCount) {
        glm::dvec3& total = totals_[type];
        total += glm::dvec3(light.r, light.g, light.b);
        for (int c = 0; c < 3; ++c) {
            if (fits_float(total[c])) continue;
            return {Fault::total, std::string("total ") + kChannelNames[c] + " " + light_total_name(type) +
                                      " exceeds " + kFloatRange};
        }
    }
    // A directional light has a direction, not a position: no box to grow.
    if (type == gpu::kLightDirectional) return {};
    const glm::dvec3 p(light.x, light.y, light.z);
    if (!fits_float(p)) return {Fault::position, "position is not finite"};
    const Box before = box_;
    box_.grow(p);
    // A box that passed and did not grow still passes (most lights of a
    // large file lie inside the box of those before them).
    if (box_checked_ && box_.lo == before.lo && box_.hi == before.hi) return {};
    std::string problem = extent_problem(box_);
    box_checked_ = problem.empty();
    if (problem.empty()) return {};
    return {Fault::position, "too far from the geometry and the other lights: " + problem};
}

}  // namespace lc::loader
