// CSV files of lights: points_csv ("x,y,z,r,g,b" per line) and spots_csv
// ("x,y,z,dx,dy,dz,r,g,b,inner_cone_degrees,outer_cone_degrees").
#pragma once

#include <cstddef>
#include <filesystem>
#include <vector>

#include "float_limits.h"

namespace lc::loader {

// The file is parsed in chunks of about this many bytes, on `threads`
// threads (0: one per core).
inline constexpr std::size_t kCsvChunkBytes = std::size_t(1) << 20;

// load_points_csv (lightcuts/scene.h), with the totals and the box carried
// over from the rest of the scene, so that an overflow is reported at the
// CSV line that caused it. (chunk_bytes: tests cut small files into many
// chunks; the lights and the first error are the same for any size.)
std::vector<gpu::Light> read_points_csv(const std::filesystem::path& file, LightLimits& limits, unsigned threads,
                                        std::size_t chunk_bytes = kCsvChunkBytes);

// The same for spot lights, checked as a JSON spot is (light_records.h).
std::vector<gpu::Light> read_spots_csv(const std::filesystem::path& file, LightLimits& limits, unsigned threads,
                                       std::size_t chunk_bytes = kCsvChunkBytes);

}  // namespace lc::loader
