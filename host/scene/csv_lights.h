// CSV files of point lights ("x,y,z,r,g,b" per line).
#pragma once

#include <filesystem>
#include <vector>

#include "../../shaders/shared/types.h"

namespace lc::loader {

// load_points_csv (lightcuts/scene.h).
std::vector<gpu::Light> read_points_csv(const std::filesystem::path& file);

}  // namespace lc::loader
