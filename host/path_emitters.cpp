// Emitter selection and environment sampling for the path tracer
// (host/path_emitters.h).
#include "path_emitters.h"

#include <algorithm>
#include <cmath>

#include "area_lights.h"

namespace lc::path {
namespace {

constexpr double kPi = 3.14159265358979323846;

double luminance(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

// The texel lc_environment_radiance reads for `dir`, computed with the same
// float operations, so that pdf() and the radiance agree on every direction.
// theta is atan2(sin, cos): acos of a float cos(theta), whose values are
// 6e-8 apart near 1, put samples drawn near the poles of a tall map in the
// next row (with a bright texel one row from the pole of a 2 x 8192 map,
// the path tracer came out 19% dark).
void texel_of(glm::vec3 d, std::uint32_t width, std::uint32_t height, std::uint32_t& row, std::uint32_t& column) {
    constexpr float kPiF = 3.14159265358979f;  // the kernels' kPi
    const float u = 0.5f + std::atan2(d.x, -d.z) * (0.5f / kPiF);
    const float v = std::atan2(std::sqrt(d.x * d.x + d.z * d.z), d.y) * (1.0f / kPiF);
    column = std::min(std::uint32_t(std::max(u, 0.0f) * float(width)), width - 1u);
    row = std::min(std::uint32_t(std::max(v, 0.0f) * float(height)), height - 1u);
}

}  // namespace

// ---- Distribution1D ----

Distribution1D::Distribution1D(const std::vector<double>& weights) {
    cdf_.resize(weights.size() + 1);
    cdf_[0] = 0.0;
    for (std::size_t i = 0; i < weights.size(); ++i) cdf_[i + 1] = cdf_[i] + std::max(weights[i], 0.0);
    total_ = cdf_.back();
    if (!(total_ > 0.0)) return;
    for (double& c : cdf_) c /= total_;  // the last becomes exactly 1
    pmf_.resize(weights.size());
    // The pmf is the width of the interval sample() maps to the entry, so
    // the probability reported and the one sampled agree exactly.
    for (std::size_t i = 0; i < weights.size(); ++i) pmf_[i] = cdf_[i + 1] - cdf_[i];
}

std::uint32_t Distribution1D::sample(double u) const {
    // The first cdf value above u ends the chosen interval [cdf[i], cdf[i+1]),
    // which is empty for entries of zero weight, so they are never chosen.
    const auto above = std::upper_bound(cdf_.begin(), cdf_.end(), u);
    const std::size_t i = std::size_t(std::max<std::ptrdiff_t>(above - cdf_.begin() - 1, 0));
    return std::uint32_t(std::min(i, size() - 1));
}

// ---- EnvironmentSampler ----

EnvironmentSampler::EnvironmentSampler(const Environment& map) : width_(map.width), height_(map.height) {
    if (!map.present()) return;
    cos_edge_.resize(height_ + 1);
    for (std::uint32_t r = 0; r <= height_; ++r) cos_edge_[r] = std::cos(kPi * r / height_);
    cos_edge_[height_] = -1.0;  // exact at the poles
    columns_.reserve(height_);
    std::vector<double> row_weights(height_), weights(width_);
    for (std::uint32_t r = 0; r < height_; ++r) {
        // A texel's solid angle: (2 pi / W)(cos top - cos bottom), exact.
        const double solid_angle = 2.0 * kPi / width_ * (cos_edge_[r] - cos_edge_[r + 1]);
        for (std::uint32_t c = 0; c < width_; ++c) {
            const float* t = &map.rgb[(std::size_t(r) * width_ + c) * 3];
            weights[c] = luminance(std::max(t[0], 0.0f), std::max(t[1], 0.0f), std::max(t[2], 0.0f)) * solid_angle;
        }
        columns_.emplace_back(weights);
        row_weights[r] = columns_.back().total();
    }
    rows_ = Distribution1D(row_weights);
}

float EnvironmentSampler::texel_pdf(std::uint32_t row, std::uint32_t column) const {
    const double solid_angle = 2.0 * kPi / width_ * (cos_edge_[row] - cos_edge_[row + 1]);
    const Distribution1D& columns = columns_[row];
    if (!(columns.total() > 0.0)) return 0.0f;
    return float(rows_.pmf(row) * columns.pmf(column) / solid_angle);
}

glm::vec3 EnvironmentSampler::sample(double u_row, double u_column, float u_theta, float u_phi, float& pdf) const {
    const std::uint32_t row = rows_.sample(u_row);
    const std::uint32_t column = columns_[row].sample(u_column);
    pdf = texel_pdf(row, column);
    // Uniform in solid angle over the texel: cos(theta) uniform between the
    // row's edges, phi uniform across the column; the inverse of
    // texel_of's u = 0.5 + phi / (2 pi), v = theta / pi.
    const double cos_theta = cos_edge_[row] - double(u_theta) * (cos_edge_[row] - cos_edge_[row + 1]);
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    const double phi = 2.0 * kPi * ((column + double(u_phi)) / width_ - 0.5);
    return glm::vec3(float(sin_theta * std::sin(phi)), float(cos_theta), float(-sin_theta * std::cos(phi)));
}

float EnvironmentSampler::pdf(glm::vec3 dir) const {
    if (empty()) return 0.0f;
    std::uint32_t row, column;
    texel_of(dir, width_, height_, row, column);
    return texel_pdf(row, column);
}

// ---- EmitterTable ----

double light_power(const gpu::Light& light, double radius) {
    const double lum = luminance(light.r, light.g, light.b);
    switch (light.type & gpu::kLightTypeMask) {
        case gpu::kLightPoint: return 4.0 * kPi * lum;
        case gpu::kLightSpot: {
            // Never zero: a spot whose cones are both closed still lights its axis.
            const double cos_mid = std::min(0.5 * (double(light.cos_inner) + double(light.cos_outer)), 1.0 - 1e-6);
            return 2.0 * kPi * (1.0 - cos_mid) * lum;
        }
        case gpu::kLightOriented:
        case gpu::kLightVpl: return ((light.type & gpu::kLightTwoSided) != 0u ? 2.0 : 1.0) * kPi * lum;
        case gpu::kLightDirectional: return kPi * radius * radius * lum;
        default: return 0.0;  // the loader admits no other type
    }
}

EmitterTable::EmitterTable(const Scene& scene) : environment_(scene.environment) {
    // The sphere around the geometry, floored so that a scene of one point
    // (or none) still gives directional lights and the sky some weight.
    const double radius =
        std::max(0.5 * glm::length(glm::dvec3(scene.bounds_max) - glm::dvec3(scene.bounds_min)), 1e-30);
    std::vector<double> weights;
    for (std::uint32_t i = 0; i < scene.lights.size(); ++i) {
        const double w = light_power(scene.lights[i], radius);
        if (!(w > 0.0)) continue;  // emits nothing
        emitters_.push_back({EmitterKind::kLight, i});
        weights.push_back(w);
    }
    const std::vector<double> power = TriangleEmission(scene).powers();
    for (std::uint32_t i = 0; i < scene.triangles.size(); ++i) {
        const double w = power[i];
        if (!(w > 0.0)) continue;
        emitters_.push_back({EmitterKind::kTriangle, i});
        weights.push_back(w);
    }
    if (!environment_.empty()) {
        emitters_.push_back({EmitterKind::kEnvironment, 0u});
        weights.push_back(kPi * radius * radius * environment_.luminance_integral());
    }
    if (emitters_.empty()) return;
    power_ = Distribution1D(weights);
    for (std::uint32_t e = 0; e < emitters_.size(); ++e) {
        const float pmf = float(power_.pmf(e));
        if (emitters_[e].kind == EmitterKind::kTriangle) {
            if (triangle_pmf_.empty()) triangle_pmf_.assign(scene.triangles.size(), 0.0f);
            triangle_pmf_[emitters_[e].index] = pmf;
        } else if (emitters_[e].kind == EmitterKind::kEnvironment) {
            environment_pmf_ = pmf;
        }
    }
}

Emitter EmitterTable::pick(double u, float& pmf) const {
    const std::uint32_t e = power_.sample(u);
    pmf = float(power_.pmf(e));
    return emitters_[e];
}

}  // namespace lc::path
