// Environment map to directional lights (host/environment_lights.h).
#include "environment_lights.h"

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "scene/light_records.h"
#include "lc_shared/color.h"

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

// The splitter works on the map's texel rows each cut into `sub` bands
// ("rows" below) of equal solid angle, their boundaries evenly spaced in
// cos theta, so that no row is much taller in angle than the part of the
// sphere one direction stands for (a square of 4 pi / count steradians):
// a part of the map with one direction is then compact, and its mean
// direction stands for it. (Whole texel rows of a map 1 to 8 texels tall
// reach from pole to pole, or most of the way; a part of one such row put
// its light on the row's middle latitude: under a constant 65536 x 1 sky
// an upward plane was black, under a 4096 x 2 one 41% too bright.) For any
// count, not only for fewer directions than texels: a texel given a single
// direction put it on the horizon the same way (black at 65536 x 1 with
// 65536 directions). Where a cell still gets several directions, they
// spread over its latitudes (emit_texel). Maps of the usual 2:1 shape with
// H rows keep sub = 1 up to about 1.3 H^2 directions (83,000 for the
// shipped sky's 512 x 256, rendered with 3000; a 64 x 32 map gets two
// bands a row from about 1300).
//
// Columns are cut the same way, into `csub` bands of equal azimuth, where a
// texel column is at least two directions' squares wide at the equator (and
// the map has more than one row or band): a map 1
// to 4 texels wide put each texel's light on its column's middle azimuth,
// so under a constant 1 x 4096 sky a plane facing -Z got 2.9 times its
// light and one facing +Z none, and the single texel of a `color` sky gave
// its 3000 directions 17 azimuths, whose shadows were spokes. A 2:1 map W
// texels wide keeps csub = 1 up to about 4 W^2 / pi directions (334,000
// for the shipped sky).
class Splitter {
public:
    Splitter(const Environment& map, std::uint32_t count, std::vector<gpu::Light>& out) : map_(map), out_(out) {
        // The tallest texel row in cos theta (the one at the equator).
        double tallest = 0.0;
        for (std::uint32_t y = 0; y < map.height; ++y)
            tallest = std::max(tallest, std::cos(kPi * y / map.height) - std::cos(kPi * (y + 1) / map.height));
        const double side = std::sqrt(count / (4.0 * kPi));  // directions along a radian
        const double wanted = std::ceil(tallest * side - 1e-9);
        const double column_width = 2.0 * kPi / map.width * side;  // in directions' sides, at the equator
        // At most 2^22 rows x columns beyond the map's own (each level of the
        // split passes over them all), the rows' bands taken first.
        const double texels = double(map.width) * map.height;
        const double allowed = std::floor(std::max(texels, 4194304.0) / texels);
        sub_ = std::uint32_t(std::clamp(std::min(wanted, allowed), 1.0, double(count)));
        // Where a texel row straddles the equator (an odd number of rows),
        // an even number of bands puts a boundary on it, the horizon of a
        // plane facing a pole.
        if (sub_ > 1 && map.height % 2 == 1) sub_ += sub_ % 2;
        // Only where a column is at least two directions wide, and where the
        // rows are cut too or the map has several: a column band of a single
        // row reaches from pole to pole, and its one direction would sit on
        // the equator (a 1 x 1 map with 2 directions lit neither an upward
        // nor a downward plane); and a direction's part of a few bands takes
        // their mean direction, nearer the pole than their middle (a 2 x 1
        // map with 4 directions, cut, lit an upward plane 26% too brightly).
        if (map.height * sub_ >= 2 && column_width >= 2.0)
            csub_ = std::uint32_t(
                std::clamp(std::min(std::ceil(column_width - 1e-9), std::floor(allowed / sub_)), 1.0, double(count)));
        // Likewise a boundary at every quarter of the azimuth (u = 0, 1/4,
        // 1/2, 3/4), the horizons of planes facing +-X and +-Z, where the
        // room allows.
        if (csub_ > 1)
            while ((std::uint64_t(map.width) * csub_) % 4 != 0 && double(sub_) * (csub_ + 1) <= allowed) ++csub_;
        rows_ = map.height * sub_;
        cols_ = map.width * csub_;
        // Each row's top and bottom (cos theta, theta), the exact solid angle
        // of a texel of it, (2 pi / W)(cos top - cos bottom), and the sines
        // and cosines of each row's and column's middle, computed as
        // environment_direction computes them.
        cos_.resize(rows_ + 1);
        theta_.resize(rows_ + 1);
        for (std::uint32_t y = 0; y <= rows_; ++y) {
            const std::uint32_t t = y / sub_, k = y % sub_;
            const double top = std::cos(kPi * t / map.height), bottom = std::cos(kPi * (t + 1) / map.height);
            cos_[y] = top + (bottom - top) * k / sub_;
            theta_[y] = k == 0 ? kPi * t / map.height : std::acos(std::clamp(cos_[y], -1.0, 1.0));
        }
        cos_[rows_] = -1.0;
        row_solid_angle_.resize(rows_);
        row_v_.resize(rows_);
        row_sin_.resize(rows_);
        row_cos_.resize(rows_);
        for (std::uint32_t y = 0; y < rows_; ++y) {
            row_solid_angle_[y] = 2.0 * kPi / cols_ * (cos_[y] - cos_[y + 1]);
            // The texel row's middle where it is whole (as the maps of sub =
            // 1 always did); a band's middle cosine where it is cut.
            row_v_[y] = sub_ == 1 ? (y + 0.5) / rows_
                                  : std::acos(std::clamp(0.5 * (cos_[y] + cos_[y + 1]), -1.0, 1.0)) / kPi;
            const double theta = kPi * double(float(row_v_[y]));
            row_sin_[y] = std::sin(theta);
            row_cos_[y] = std::cos(theta);
        }
        column_sin_.resize(cols_);
        column_cos_.resize(cols_);
        for (std::uint32_t x = 0; x < cols_; ++x) {
            const double phi = 2.0 * kPi * (double(float((x + 0.5) / cols_)) - 0.5);
            column_sin_[x] = std::sin(phi);
            column_cos_[x] = std::cos(phi);
        }
    }

    std::uint32_t rows() const { return rows_; }
    std::uint32_t columns() const { return cols_; }

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
        // (Where no row is cut, in the arithmetic it always had, so that
        // those maps' lights stay the same to the last bit.)
        const double mid_theta = sub_ == 1 ? kPi * 0.5 * (r.y0 + r.y1) / rows_ : 0.5 * (theta_[r.y0] + theta_[r.y1]);
        const double width = (r.x1 - r.x0) * 2.0 * kPi / cols_ * std::sin(mid_theta);
        const double height = sub_ == 1 ? (r.y1 - r.y0) * kPi / rows_ : theta_[r.y1] - theta_[r.y0];
        Region a = r, b = r;
        // (Where columns are cut, a square region is halved across its rows,
        // so that a direction of it stays in one hemisphere: halved down
        // its columns, a 2 x 1 map's four directions each took a pole to
        // pole half of a column, and sat on the equator.)
        const bool across = csub_ == 1 ? width >= height : width > height;
        if ((across && r.x1 - r.x0 > 1) || r.y1 - r.y0 == 1) {
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

    // texel_direction of the middle of row y's texel x, from the tables.
    glm::dvec3 middle_direction(std::uint32_t x, std::uint32_t y) const {
        return {float(row_sin_[y] * column_sin_[x]), float(row_cos_[y]), float(-row_sin_[y] * column_cos_[x])};
    }

    const float* texel(std::uint32_t x, std::uint32_t y) const {
        return &map_.rgb[(std::size_t(y / sub_) * map_.width + x / csub_) * 3];
    }

    glm::dvec3 brightest_direction(Region r) const {
        double most = -1.0;
        glm::dvec3 towards(0.0, 1.0, 0.0);
        for (std::uint32_t y = r.y0; y < r.y1; ++y)
            for (std::uint32_t x = r.x0; x < r.x1; ++x) {
                const float* c = texel(x, y);
                const double power = gpu::lc_luminance(glm::vec3(c[0], c[1], c[2])) * row_solid_angle_[y];
                if (power > most) {
                    most = power;
                    towards = middle_direction(x, y);
                }
            }
        return towards;
    }

    Totals totals(Region r) const {
        Totals t;
        for (std::uint32_t y = r.y0; y < r.y1; ++y)
            for (std::uint32_t x = r.x0; x < r.x1; ++x) {
                const float* c = texel(x, y);
                const glm::dvec3 e = glm::dvec3(c[0], c[1], c[2]) * row_solid_angle_[y];
                const double power = gpu::lc_luminance(glm::vec3(e));
                t.irradiance += e;
                t.power += power;
                t.direction += power * middle_direction(x, y);
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
        const double cos_top = cos_[r.y0];
        const double cos_bottom = cos_[r.y0 + 1];
        const double height = sub_ == 1 ? kPi / rows_ : theta_[r.y0 + 1] - theta_[r.y0];
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
                emit(texel_direction((r.x0 + (k + 0.5) / n) / cols_, v), t.irradiance / double(samples));
            before += n;
        }
    }

    void emit(glm::dvec3 towards, glm::dvec3 irradiance) {
        gpu::Light l{};
        l.x = float(towards.x); l.y = float(towards.y); l.z = float(towards.z);
        const glm::vec3 c = loader::without_subnormals(glm::vec3(irradiance));
        l.r = c.r; l.g = c.g; l.b = c.b;
        l.type = gpu::kLightDirectional;
        out_.push_back(l);
    }

    const Environment& map_;
    std::vector<gpu::Light>& out_;
    std::uint32_t sub_ = 1, rows_ = 0, csub_ = 1, cols_ = 0;
    std::vector<double> cos_, theta_, row_solid_angle_, row_v_, row_sin_, row_cos_, column_sin_, column_cos_;
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
    Splitter splitter(map, count, lights);
    splitter.split({0, splitter.columns(), 0, splitter.rows()}, count);
    return lights;
}

}  // namespace lc
