// Overflow checks for the float boxes the renderer builds (float_limits.h).
#include "float_limits.h"

namespace lc::loader {
namespace {

constexpr const char* kAxisNames[] = {"x", "y", "z"};
constexpr const char* kFloatRange = "the float range (3.4e38)";

}  // namespace

std::string extent_problem(const Box& box) {
    if (box.empty()) return {};
    for (int a = 0; a < 3; ++a) {
        if (!fits_float(box.lo[a]) || !fits_float(box.hi[a])) {
            return std::string("the ") + kAxisNames[a] + " coordinate is outside " + kFloatRange;
        }
        if (!fits_float(box.hi[a] - box.lo[a])) {
            return std::string("the extent along ") + kAxisNames[a] + " exceeds " + kFloatRange;
        }
    }
    return {};
}

}  // namespace lc::loader
