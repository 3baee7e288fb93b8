// CSV files of point lights ("x,y,z,r,g,b" per line).
#pragma once

#include <filesystem>
#include <vector>

#include "float_limits.h"

namespace lc::loader {

// load_points_csv (lightcuts/scene.h), with the totals and the box carried
// over from the rest of the scene, so that an overflow is reported at the
// CSV line that caused it.
std::vector<gpu::Light> read_points_csv(const std::filesystem::path& file, LightLimits& limits);

}  // namespace lc::loader
