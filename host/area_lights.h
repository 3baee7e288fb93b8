// Emissive triangles as oriented point lights (Walter et al. 2005, §5: an
// area light becomes many point samples, each a cosine emitter, that go into
// the light tree with every other light).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "lightcuts/light_tree.h"
#include "lightcuts/scene.h"
#include "lc_shared/types.h"

namespace lc {

// What emissive triangles emit, their materials' emissive textures applied
// (shaders/lc_shared/textures.h): at a point, and on average over a triangle.
// Without uvs/textures (empty spans) emission is each material's constant.
class TriangleEmission {
public:
    TriangleEmission(std::span<const gpu::Triangle> triangles, std::span<const gpu::Material> materials,
                     std::span<const gpu::TriangleUvs> uvs = {}, std::span<const gpu::TextureInfo> textures = {},
                     std::span<const std::uint32_t> texels = {});
    explicit TriangleEmission(const Scene& scene)
        : TriangleEmission(scene.triangles, scene.materials, scene.uvs, scene.textures, scene.texels) {}

    // Radiance triangle i emits at barycentrics (b1, b2) on its emitting
    // side(s); black when its material does not emit.
    glm::vec3 at(std::size_t i, float b1, float b2) const;
    // The mean of `at` over the triangle: exact without an emissive texture;
    // with one, the mean over kMeanPoints stratified points.
    glm::vec3 mean(std::size_t i) const;
    // Emitted power pi A lum(mean) per emitting side (0: does not emit);
    // with an emissive texture at least as if one of the points of `mean`
    // had found the brightest texel the triangle's uv box covers (or, past
    // 65,536 texels, the material's emission).
    double power(std::size_t i) const;
    // power(i) of every triangle, on up to `threads` threads (0: every
    // core; one below 16,384 triangles): with an emissive texture each
    // takes 256 texture reads and one of each texel under its uv box (at
    // most 65,536).
    std::vector<double> powers(unsigned threads = 0) const;

    static constexpr std::uint32_t kMeanPoints = 256;

private:
    // The largest luminance of emission x texel over the texels the
    // bilinear filter may read in triangle i's uv box; -1 where that is
    // more than 65,536 texels.
    double brightest_in_footprint(std::size_t i) const;

    std::span<const gpu::Triangle> triangles_;
    std::span<const gpu::Material> materials_;
    std::span<const gpu::TriangleUvs> uvs_;
    std::span<const gpu::TextureInfo> textures_;
    std::span<const std::uint32_t> texels_;
};

// Point (b1, b2) in barycentrics of sample k of m on a triangle, for the
// pattern's random shift (su, sv): the area-preserving square-to-triangle
// map (Shirley and Chiu) of a stratified point set.
glm::vec2 triangle_sample_barycentrics(std::uint32_t k, std::uint32_t m, float shift_u, float shift_v);

// `count` samples over every triangle whose material emits, distributed in
// proportion to power (TriangleEmission::power: mean emitted luminance x
// area, twice for two-sided emitters) by systematic sampling along the
// triangles, and stratified over each triangle. A sample carries
// I = Le(x) * A / m along its triangle's geometric normal (counter-clockwise
// winding, right-handed), Le(x) the radiance at its point (the emissive
// texture's there) and m the samples its triangle got, so the samples'
// power is its triangle's; where a triangle's share of the count is e < 1
// it gets one sample with probability e, carrying Le(x) * A / e, its
// power in expectation. Deterministic for a seed; as count grows the
// lighting converges to the exact area-light integral. Empty when nothing
// emits or count is 0. Made on up to `threads` threads (0: every core; one
// below 65,536 samples), the same lights whatever their number.
UninitializedVector<gpu::Light> sample_area_lights(const TriangleEmission& emission,
                                                   std::span<const gpu::Triangle> triangles,
                                                   std::span<const gpu::Material> materials, std::uint32_t count,
                                                   std::uint32_t seed, unsigned threads = 0);
UninitializedVector<gpu::Light> sample_area_lights(const Scene& scene, std::uint32_t count, std::uint32_t seed,
                                                   unsigned threads = 0);

}  // namespace lc
