// Image comparison metrics and false-colour heat maps.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "lightcuts/image.h"

namespace lc {

namespace {

double luminance_d(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

}  // namespace

// Accumulates in double. Non-finite input never throws:
//  - relative_rmse is NaN when any difference or reference value is NaN (an
//    Inf in both images gives Inf - Inf = NaN too), +Inf when the reference is
//    all zero but the image is not, 0 when both are all zero.
//  - A pixel whose error is NaN counts as above every threshold, and then
//    max_relative_error is NaN as well.
//  - The per-pixel denominator floor is 1e-3 * |mean Y(r)|; when that mean
//    is zero or not finite (an all-black or non-finite reference) the floor
//    is 1e-30, so black reference pixels give huge errors, not NaN.
CompareResult compare_images(const Image& image, const Image& reference) {
    if (image.width != reference.width || image.height != reference.height)
        throw std::invalid_argument("compare_images: sizes differ (" + std::to_string(image.width) + "x" +
                                    std::to_string(image.height) + " vs reference " +
                                    std::to_string(reference.width) + "x" + std::to_string(reference.height) + ")");
    const std::size_t pixels = std::size_t(image.width) * image.height;
    if (image.rgb.size() != pixels * 3 || reference.rgb.size() != pixels * 3)
        throw std::invalid_argument("compare_images: Image::rgb does not hold width * height * 3 floats");

    CompareResult result;
    double sum_diff2 = 0.0, sum_ref2 = 0.0, sum_ref_lum = 0.0;
    for (std::size_t i = 0; i < pixels * 3; ++i) {
        const double a = image.rgb[i], r = reference.rgb[i];
        sum_diff2 += (a - r) * (a - r);
        sum_ref2 += r * r;
    }
    for (std::size_t p = 0; p < pixels; ++p) sum_ref_lum += luminance_d(&reference.rgb[p * 3]);

    if (std::isnan(sum_diff2) || std::isnan(sum_ref2))
        result.relative_rmse = std::numeric_limits<double>::quiet_NaN();
    else if (sum_ref2 == 0.0)
        result.relative_rmse = sum_diff2 == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
    else
        result.relative_rmse = std::sqrt(sum_diff2 / sum_ref2);

    const double mean_lum = pixels ? sum_ref_lum / double(pixels) : 0.0;
    // The magnitude: a negative reference (an EXR from elsewhere) floors
    // its pixels at its own scale, not at 1e-30.
    const double lum_floor =
        (mean_lum != 0.0 && std::isfinite(mean_lum)) ? 1e-3 * std::abs(mean_lum) : 1e-30;

    result.per_pixel.resize(pixels);
    double sum_image_lum = 0.0;
    for (std::size_t p = 0; p < pixels; ++p) sum_image_lum += luminance_d(&image.rgb[p * 3]);
    // Relative to the reference's magnitude, so that an image darker than a
    // negative reference (an EXR from elsewhere) comes out negative too.
    if (std::isnan(sum_ref_lum) || std::isnan(sum_image_lum))
        result.mean_difference = std::numeric_limits<double>::quiet_NaN();
    else if (sum_ref_lum > 0.0)
        result.mean_difference = sum_image_lum / sum_ref_lum - 1.0;
    else if (sum_ref_lum < 0.0)
        result.mean_difference = (sum_image_lum - sum_ref_lum) / -sum_ref_lum;
    else if (sum_image_lum == 0.0)
        result.mean_difference = 0.0;
    else
        result.mean_difference = std::copysign(std::numeric_limits<double>::infinity(), sum_image_lum);
    std::size_t above1 = 0, above2 = 0, above5 = 0;
    double max_error = 0.0;
    bool any_nan = false;
    for (std::size_t p = 0; p < pixels; ++p) {
        const double ya = luminance_d(&image.rgb[p * 3]);
        const double yr = luminance_d(&reference.rgb[p * 3]);
        const double e = std::abs(ya - yr) / std::max(yr, lum_floor);
        result.per_pixel[p] = float(e);
        // Written as !(e <= t) so that NaN counts as above.
        above1 += !(e <= 0.01);
        above2 += !(e <= 0.02);
        above5 += !(e <= 0.05);
        if (std::isnan(e))
            any_nan = true;
        else
            max_error = std::max(max_error, e);
    }
    if (pixels) {
        result.fraction_above_1pct = double(above1) / double(pixels);
        result.fraction_above_2pct = double(above2) / double(pixels);
        result.fraction_above_5pct = double(above5) / double(pixels);
    }
    result.max_relative_error = any_nan ? std::numeric_limits<double>::quiet_NaN() : max_error;
    return result;
}

namespace {

using Rgb = std::array<std::uint8_t, 3>;

// Viridis-like ramp: perceptually ordered, readable in grey scale and by
// colour-blind viewers. Nine samples of matplotlib's viridis, interpolated.
Rgb ramp(float t) {
    static constexpr std::array<std::array<float, 3>, 9> kStops = {{{68, 1, 84},
                                                                  {72, 36, 117},
                                                                  {59, 82, 139},
                                                                  {44, 114, 142},
                                                                  {33, 145, 140},
                                                                  {39, 173, 129},
                                                                  {94, 201, 98},
                                                                  {170, 220, 50},
                                                                  {253, 231, 37}}};
    const float x = std::clamp(t, 0.0f, 1.0f) * float(kStops.size() - 1);
    const std::size_t i = std::min(std::size_t(x), kStops.size() - 2);
    const float f = x - float(i);
    Rgb c;
    for (std::size_t k = 0; k < 3; ++k)
        c[k] = std::uint8_t(kStops[i][k] + f * (kStops[i + 1][k] - kStops[i][k]) + 0.5f);
    return c;
}

constexpr Rgb kNanColour = {255, 0, 255};
constexpr Rgb kLegendBackground = {24, 24, 24};
constexpr Rgb kLegendInk = {235, 235, 235};

// 3x5 bitmap font: five rows of three bits, most significant bit = left column.
constexpr int kGlyphW = 3, kGlyphH = 5;
std::array<std::uint8_t, 5> glyph(char ch) {
    switch (ch) {
        case '0': return {7, 5, 5, 5, 7};
        case '1': return {2, 6, 2, 2, 7};
        case '2': return {7, 1, 7, 4, 7};
        case '3': return {7, 1, 7, 1, 7};
        case '4': return {5, 5, 7, 1, 1};
        case '5': return {7, 4, 7, 1, 7};
        case '6': return {7, 4, 7, 5, 7};
        case '7': return {7, 1, 1, 1, 1};
        case '8': return {7, 5, 7, 5, 7};
        case '9': return {7, 5, 7, 1, 7};
        case '.': return {0, 0, 0, 0, 2};
        case '-': return {0, 0, 7, 0, 0};
        case '+': return {0, 2, 7, 2, 0};
        case 'e': return {2, 5, 7, 4, 3};
        case '%': return {5, 1, 2, 4, 5};
        default: return {0, 0, 0, 0, 0};
    }
}

// Short label: three significant digits, exponent without '+' or leading zeros.
std::string format_label(double v) {
    if (v == 0.0) return "0";
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%.3g", v);
    std::string s = buf;
    const std::size_t e = s.find('e');
    if (e == std::string::npos) return s;
    std::string mantissa = s.substr(0, e), exponent = s.substr(e + 1);
    const bool negative = !exponent.empty() && exponent[0] == '-';
    if (!exponent.empty() && (exponent[0] == '-' || exponent[0] == '+')) exponent.erase(0, 1);
    exponent.erase(0, std::min(exponent.find_first_not_of('0'), exponent.size() - 1));
    return mantissa + "e" + (negative ? "-" : "") + exponent;
}

struct Canvas {
    std::uint32_t width, height;
    std::vector<std::uint8_t> rgb;
    void put(long x, long y, Rgb c) {
        if (x < 0 || y < 0 || x >= long(width) || y >= long(height)) return;
        std::uint8_t* p = &rgb[(std::size_t(y) * width + std::size_t(x)) * 3];
        p[0] = c[0]; p[1] = c[1]; p[2] = c[2];
    }
    void text(long x, long y, const std::string& s, long scale) {
        for (char ch : s) {
            const auto rows = glyph(ch);
            for (long gy = 0; gy < kGlyphH * scale; ++gy)
                for (long gx = 0; gx < kGlyphW * scale; ++gx)
                    if (rows[std::size_t(gy / scale)] & (4 >> (gx / scale))) put(x + gx, y + gy, kLegendInk);
            x += (kGlyphW + 1) * scale;
        }
    }
};

long text_width(const std::string& s, long scale) {
    return s.empty() ? 0 : long(s.size()) * (kGlyphW + 1) * scale - scale;
}

// The heatmap's pixels: the map, then its legend below it. A max_value
// that is not positive and finite falls back to 1. NaN values are drawn
// magenta. The legend is a colour bar with ticks labelled 0, max/2 and max;
// labels that do not fit the width are dropped, the middle one first.
Canvas heatmap_canvas(std::uint32_t width, std::uint32_t height, const std::vector<float>& values, float max_value,
                      const std::filesystem::path& file) {
    if (values.size() != std::size_t(width) * height)
        throw std::invalid_argument("heatmap " + file.string() + ": expected width * height values");
    if (!(max_value > 0.0f && std::isfinite(max_value))) max_value = 1.0f;

    const long scale = std::clamp(long(width) / 160, 1L, 4L);
    const long pad = 2 * scale, bar_h = 8 * scale, tick_h = 2 * scale, text_h = kGlyphH * scale;
    const long legend_h = pad + bar_h + tick_h + scale + text_h + pad;

    Canvas canvas{width, height + std::uint32_t(legend_h), {}};
    canvas.rgb.resize(std::size_t(canvas.width) * canvas.height * 3);
    for (std::uint32_t y = 0; y < height; ++y)
        for (std::uint32_t x = 0; x < width; ++x) {
            const float v = values[std::size_t(y) * width + x];
            canvas.put(x, y, std::isnan(v) ? kNanColour : ramp(v / max_value));
        }
    for (long y = long(height); y < long(canvas.height); ++y)
        for (long x = 0; x < long(width); ++x) canvas.put(x, y, kLegendBackground);

    // Colour bar across the full width, left = 0, right = max.
    const long bar_y = long(height) + pad;
    for (long x = 0; x < long(width); ++x) {
        const Rgb c = ramp(width > 1 ? float(x) / float(width - 1) : 0.0f);
        for (long y = 0; y < bar_h; ++y) canvas.put(x, bar_y + y, c);
    }
    // Ticks under 0, max/2 and max.
    const long tick_y = bar_y + bar_h;
    const long tick_x[3] = {0, long(width - 1) / 2, long(width) - 1};
    for (long x : tick_x)
        for (long y = 0; y < tick_h; ++y)
            for (long dx = 0; dx < scale; ++dx) canvas.put(x + (x == tick_x[2] ? -dx : dx), tick_y + y, kLegendInk);

    // Labels: left-aligned, centred, right-aligned.
    const std::string labels[3] = {format_label(0.0), format_label(0.5 * double(max_value)),
                                   format_label(double(max_value))};
    const long w[3] = {text_width(labels[0], scale), text_width(labels[1], scale), text_width(labels[2], scale)};
    const long lx[3] = {0, tick_x[1] - w[1] / 2, long(width) - w[2]};
    const long gap = 2 * scale;
    const bool ends_fit = lx[0] + w[0] + gap <= lx[2];
    const bool middle_fits = ends_fit && lx[0] + w[0] + gap <= lx[1] && lx[1] + w[1] + gap <= lx[2];
    const long text_y = tick_y + tick_h + scale;
    if (ends_fit) {
        canvas.text(lx[0], text_y, labels[0], scale);
        canvas.text(lx[2], text_y, labels[2], scale);
    }
    if (middle_fits) canvas.text(lx[1], text_y, labels[1], scale);

    return canvas;
}

}  // namespace

void write_heatmap_png(const std::filesystem::path& file, std::uint32_t width, std::uint32_t height,
                       const std::vector<float>& values, float max_value) {
    const Canvas canvas = heatmap_canvas(width, height, values, max_value, file);
    write_png_rgb8(file, canvas.width, canvas.height, canvas.rgb);
}

std::string encode_heatmap_png(std::uint32_t width, std::uint32_t height, const std::vector<float>& values,
                               float max_value, const std::filesystem::path& file) {
    const Canvas canvas = heatmap_canvas(width, height, values, max_value, file);
    return encode_png_rgb8(canvas.width, canvas.height, canvas.rgb, file);
}

}  // namespace lc
