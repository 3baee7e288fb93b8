// Linear RGB float images, OpenEXR and PNG files, and image comparison.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "lc_shared/color.h"

namespace lc {

// Row-major, row 0 at the top, three floats per pixel.
struct Image {
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    std::vector<float> rgb;

    Image() = default;
    Image(std::uint32_t w, std::uint32_t h) : width(w), height(h), rgb(std::size_t(w) * h * 3, 0.0f) {}
    glm::vec3 at(std::uint32_t x, std::uint32_t y) const {
        const float* p = &rgb[(std::size_t(y) * width + x) * 3];
        return {p[0], p[1], p[2]};
    }
    void set(std::uint32_t x, std::uint32_t y, glm::vec3 c) {
        float* p = &rgb[(std::size_t(y) * width + x) * 3];
        p[0] = c.x; p[1] = c.y; p[2] = c.z;
    }
};

// Rec.709 luminance, as the kernels compute it.
inline float luminance(glm::vec3 c) { return gpu::lc_luminance(c); }

// File writers go through a temporary name in the same folder and rename on
// success, so a failed write never leaves a half-written file. They throw
// std::runtime_error naming the file on failure.
void write_exr(const std::filesystem::path& file, const Image& image);   // RGB float32
// Reads an OpenEXR file's RGB (HALF or FLOAT). Throws InputError naming the
// file when it cannot be read, or when its header declares more than
// max_pixels pixels (checked before anything is allocated for them: tinyexr
// allocates what a header declares). The default is the largest image the
// renderer writes, 16384 x 16384.
inline constexpr std::uint64_t kMaxExrPixels = std::uint64_t(16384) * 16384;
// `origin`, where given, gets the data window's first pixel (x, y): an
// image's pixels start there in the file's coordinates (0, 0 as this
// renderer writes them).
Image read_exr(const std::filesystem::path& file, std::uint64_t max_pixels = kMaxExrPixels,
               glm::ivec2* origin = nullptr);
// read_exr laid out over the file's display window, the image's extent,
// which the data window of the pixels it stores need not fill: pixels the
// file does not store are black, stored ones outside it are dropped.
// max_pixels bounds both windows. Environment maps are read this way:
// their lat-long mapping spans the display window.
Image read_exr_display_window(const std::filesystem::path& file, std::uint64_t max_pixels = kMaxExrPixels);
void write_png_rgb8(const std::filesystem::path& file, std::uint32_t width, std::uint32_t height,
                    const std::vector<std::uint8_t>& rgb8);
// Tone-mapped sRGB preview: exposure * value, clamped to [0,1], sRGB-encoded.
// exposure <= 0 picks one that maps the 99th percentile luminance to 1.
void write_png_tonemapped(const std::filesystem::path& file, const Image& image, float exposure = 0.0f);

// The bytes the writers above write, for a caller that places them itself
// (OutputSet's temporaries). `file` only names the output in errors.
std::string encode_exr(const Image& image, const std::filesystem::path& file);
std::string encode_png_rgb8(std::uint32_t width, std::uint32_t height, const std::vector<std::uint8_t>& rgb8,
                            const std::filesystem::path& file);
std::string encode_png_tonemapped(const Image& image, float exposure, const std::filesystem::path& file);

// Writes `bytes` to `file` (created or truncated), every byte or an error:
// a short write, a full disk or a failing close throws std::runtime_error
// naming the file (or `shown_as`, where a temporary stands for it) and the
// system's reason. OutputSet writes through it.
void write_file(const std::filesystem::path& file, std::string_view bytes,
                const std::filesystem::path& shown_as = {});

// The temporary the writers write before renaming onto `file`:
// "<file>.tmp-<pid>-<n>", in the same folder so the rename stays within one
// file system, and unique per process and call; for a file name too long to
// take the suffix within 255 bytes, its start. Thread-safe. OutputSet names
// its temporaries with it too, so one pattern finds every leftover.
std::filesystem::path temporary_path_for(const std::filesystem::path& file);

// The longest file name (one path component) Linux's file systems take, in bytes.
inline constexpr std::size_t kMaxFileNameBytes = 255;

struct CompareResult {
    double relative_rmse = 0.0;       // sqrt(sum (a-r)^2 / sum r^2), all pixels and channels
    double fraction_above_1pct = 0.0; // of pixels whose relative luminance error exceeds 1%
    double fraction_above_2pct = 0.0;
    double fraction_above_5pct = 0.0;
    double max_relative_error = 0.0;
    // Mean luminance of the image over the reference's, minus 1: the bias
    // of the whole image (e.g. what a VPL clamp takes away).
    double mean_difference = 0.0;
    std::vector<float> per_pixel;     // relative luminance error per pixel
};

// Relative luminance error per pixel: |Y(a) - Y(r)| / max(Y(r), 1e-3 * mean Y(r)).
// Throws std::invalid_argument if the sizes differ. A pixel that is not
// finite makes the metrics NaN or infinite (`lightcuts compare` refuses
// such images first, naming the pixel).
CompareResult compare_images(const Image& image, const Image& reference);

// False-colour PNG of values in [0, max_value] (above max is clamped) with a
// colour bar and its scale drawn along the bottom. Used for error and cut-size maps.
void write_heatmap_png(const std::filesystem::path& file, std::uint32_t width, std::uint32_t height,
                       const std::vector<float>& values, float max_value);
std::string encode_heatmap_png(std::uint32_t width, std::uint32_t height, const std::vector<float>& values,
                               float max_value, const std::filesystem::path& file);

}  // namespace lc
