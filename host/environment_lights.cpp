// Environment map to directional lights (host/environment_lights.h).
#include "environment_lights.h"

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "shared/color.h"

namespace lc {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A rectangle of texels [x0, x1) x [y0, y1).
struct Region {
    std::uint32_t x0, x1, y0, y1;
};

// What a region holds: irradiance (RGB integral of L dw), its luminance,
// and the luminance-weighted sum of directions.
struct Totals {
    glm::dvec3 irradiance{0.0};
    double power = 0.0;
    glm::dvec3 direction{0.0};
};

class Splitter {
public:
    Splitter(const Environment& map, std::vector<gpu::Light>& out) : map_(map), out_(out) {
        // Exact solid angle of a texel of each row: (2 pi / W)(cos top - cos bottom).
        row_solid_angle_.resize(map.height);
        for (std::uint32_t y = 0; y < map.height; ++y)
            row_solid_angle_[y] = 2.0 * kPi / map.width *
                                  (std::cos(kPi * y / map.height) - std::cos(kPi * (y + 1) / map.height));
    }

    void split(Region r, std::uint32_t samples) {
        const Totals t = totals(r);
        if (!(t.power > 0.0) || samples == 0) return;
        if (samples == 1) {
            // One light along the region's luminance-weighted mean direction;
            // where the directions all but cancel (a region spread all round,
            // as a whole map of one light is), that mean is rounding noise or
            // NaN, and the region's brightest texel gives the direction.
            const double length = glm::length(t.direction);
            return emit(length > 1e-3 * t.power ? t.direction / length : brightest_direction(r), t.irradiance);
        }
        if (r.x1 - r.x0 == 1 && r.y1 - r.y0 == 1) return emit_texel(r, t, samples);
        // Halve the side that is longer in angle.
        const double mid_sin = std::sin(kPi * 0.5 * (r.y0 + r.y1) / map_.height);
        const double width = (r.x1 - r.x0) * 2.0 * kPi / map_.width * mid_sin;
        const double height = (r.y1 - r.y0) * kPi / map_.height;
        Region a = r, b = r;
        if ((width >= height && r.x1 - r.x0 > 1) || r.y1 - r.y0 == 1) {
            a.x1 = b.x0 = (r.x0 + r.x1) / 2;
        } else {
            a.y1 = b.y0 = (r.y0 + r.y1) / 2;
        }
        const double power_a = totals(a).power;
        const double share = power_a / t.power;
        auto samples_a = std::uint32_t(std::lround(share * samples));
        // Every part with power keeps at least one sample.
        if (power_a > 0.0) samples_a = std::max(samples_a, 1u);
        if (power_a < t.power) samples_a = std::min(samples_a, samples - 1);
        split(a, samples_a);
        split(b, samples - samples_a);
    }

private:
    glm::dvec3 texel_direction(double u, double v) const {
        float d[3];
        environment_direction(float(u), float(v), d);
        return {d[0], d[1], d[2]};
    }

    glm::dvec3 brightest_direction(Region r) const {
        double most = -1.0;
        glm::dvec3 towards(0.0, 1.0, 0.0);
        for (std::uint32_t y = r.y0; y < r.y1; ++y)
            for (std::uint32_t x = r.x0; x < r.x1; ++x) {
                const float* c = &map_.rgb[(std::size_t(y) * map_.width + x) * 3];
                const double power = gpu::lc_luminance(glm::vec3(c[0], c[1], c[2])) * row_solid_angle_[y];
                if (power > most) {
                    most = power;
                    towards = texel_direction((x + 0.5) / map_.width, (y + 0.5) / map_.height);
                }
            }
        return towards;
    }

    Totals totals(Region r) const {
        Totals t;
        for (std::uint32_t y = r.y0; y < r.y1; ++y)
            for (std::uint32_t x = r.x0; x < r.x1; ++x) {
                const float* c = &map_.rgb[(std::size_t(y) * map_.width + x) * 3];
                const glm::dvec3 e = glm::dvec3(c[0], c[1], c[2]) * row_solid_angle_[y];
                const double power = gpu::lc_luminance(glm::vec3(e));
                t.irradiance += e;
                t.power += power;
                t.direction += power * texel_direction((x + 0.5) / map_.width, (y + 0.5) / map_.height);
            }
        return t;
    }

    // Several samples in one texel: rows of samples, each spread evenly in
    // angle around the pole across the texel, the rows' boundaries evenly in
    // cos theta and as tall as their share of the samples, so that every
    // sample stands for the same solid angle and carries the same share of
    // the texel's irradiance. (A grid even in the map's v, which is theta,
    // put too many of a tall texel's samples near the poles, where a
    // texel's row has less solid angle: a constant sky, a 1 x 1 map, lit an
    // upward plane 28% too brightly.) The grid has about the square root of
    // the samples in columns, unless the texel is so tall (its height in
    // angle over its mean width, its solid angle over its height) that
    // cells about as tall as wide need at least twice the rows: then that
    // many rows, rounded up. (Square-root columns put every sample of a
    // texel spanning pole to pole, an 8 x 1 map's, on one latitude: an
    // upward plane saw two samples of each on the horizon and nothing.
    // Rows from the aspect for every texel laid the shipped sky's sun out
    // 31 x 25 instead of 28 x 28 and, for reasons not looked into, its
    // Lightcuts error against brute force went from 0.0100 to 0.0184.)
    void emit_texel(Region r, const Totals& t, std::uint32_t samples) {
        const double cos_top = std::cos(kPi * r.y0 / map_.height);
        const double cos_bottom = std::cos(kPi * (r.y0 + 1) / map_.height);
        const double height = kPi / map_.height;
        const double mean_width = row_solid_angle_[r.y0] / height;
        const auto rows_wanted = std::uint32_t(
            std::clamp(std::ceil(std::sqrt(samples * height / mean_width) - 1e-9), 1.0, double(samples)));
        std::uint32_t cols = std::uint32_t(std::ceil(std::sqrt(double(samples))));
        if ((samples + cols - 1) / cols * 2 <= rows_wanted) cols = (samples + rows_wanted - 1) / rows_wanted;
        const std::uint32_t rows = (samples + cols - 1) / cols;
        std::uint32_t before = 0;  // samples in the rows above
        for (std::uint32_t row = 0; row < rows; ++row) {
            const std::uint32_t n = std::min(cols, samples - before);
            // The middle of the row's share of the texel's solid angle.
            const double share = (before + 0.5 * n) / samples;
            const double v = std::acos(std::clamp(cos_top + share * (cos_bottom - cos_top), -1.0, 1.0)) / kPi;
            for (std::uint32_t k = 0; k < n; ++k)
                emit(texel_direction((r.x0 + (k + 0.5) / n) / map_.width, v), t.irradiance / double(samples));
            before += n;
        }
    }

    void emit(glm::dvec3 towards, glm::dvec3 irradiance) {
        gpu::Light l{};
        l.x = float(towards.x); l.y = float(towards.y); l.z = float(towards.z);
        l.r = float(irradiance.x); l.g = float(irradiance.y); l.b = float(irradiance.z);
        l.type = gpu::kLightDirectional;
        out_.push_back(l);
    }

    const Environment& map_;
    std::vector<gpu::Light>& out_;
    std::vector<double> row_solid_angle_;
};

}  // namespace

void environment_direction(float u, float v, float out[3]) {
    const double phi = 2.0 * kPi * (double(u) - 0.5);  // atan2(d.x, -d.z)
    const double theta = kPi * double(v);              // acos(d.y)
    out[0] = float(std::sin(theta) * std::sin(phi));
    out[1] = float(std::cos(theta));
    out[2] = float(-std::sin(theta) * std::cos(phi));
}

std::vector<gpu::Light> environment_lights(const Environment& map, std::uint32_t count) {
    std::vector<gpu::Light> lights;
    if (map.width == 0 || map.height == 0 || count == 0) return lights;
    lights.reserve(count);
    Splitter(map, lights).split({0, map.width, 0, map.height}, count);
    return lights;
}

}  // namespace lc
