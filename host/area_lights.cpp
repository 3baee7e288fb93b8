// Area-light sampling (host/area_lights.h).
#include "area_lights.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <thread>
#include <vector>

#include <glm/glm.hpp>

#include "cpu_kernel.h"
#include "run_on_threads.h"
#include "scene/float_limits.h"
#include "scene/huge_pages.h"
#include "scene/light_records.h"
#include "lc_shared/color.h"

namespace lc {
namespace {

glm::vec3 vertex(const gpu::Triangle& t, int i) {
    return i == 0 ? glm::vec3(t.v0_x, t.v0_y, t.v0_z)
                  : i == 1 ? glm::vec3(t.v1_x, t.v1_y, t.v1_z) : glm::vec3(t.v2_x, t.v2_y, t.v2_z);
}

glm::vec3 emission(const gpu::Material& m) { return {m.emission_r, m.emission_g, m.emission_b}; }

bool emits(const gpu::Material& m) { return (m.flags & gpu::kMaterialEmissive) != 0u; }

bool has_emissive_texture(const gpu::Material& m) {
    return (m.flags & gpu::kMaterialTextured) != 0u && m.emissive_texture != gpu::kInvalidIndex;
}

// Radical inverse in base 2 (van der Corput): with (k + jitter) / m in the
// other coordinate, m points stratified over the unit square.
float radical_inverse(std::uint32_t k) {
    std::uint32_t bits = k;
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    return float(bits) * 2.3283064e-10f;
}

// m stratified samples on one triangle, written to out[0, samples), each
// carrying its point's emission times area / `share`.
void sample_triangle(const TriangleEmission& source, std::size_t index, const gpu::Triangle& t,
                     const gpu::Material& m, std::uint32_t samples, float share, std::uint32_t hash,
                     gpu::Light* out) {
    const glm::vec3 a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
    // In double: for a tiny triangle (edges below about 1e-10) the float
    // cross product's squared length underflows, which shortened the area
    // and gave the samples an axis up to 1.5 long, past the cluster bounds'
    // cone (an audit's search).
    const glm::dvec3 cross = glm::cross(glm::dvec3(b) - glm::dvec3(a), glm::dvec3(c) - glm::dvec3(a));
    const float area = float(0.5 * glm::length(cross));
    glm::vec3 normal(0.0f, 0.0f, 1.0f);
    loader::unit_vector(cross, normal);  // the loader keeps no triangle without a normal
    const bool textured = has_emissive_texture(m);
    const glm::vec3 constant = emission(m) * (area / share);
    // A random shift of the whole pattern (Cranley-Patterson rotation).
    const float shift_u = gpu::lc_unit_float(hash), shift_v = gpu::lc_unit_float(gpu::lc_hash(hash));
    for (std::uint32_t k = 0; k < samples; ++k) {
        const glm::vec2 bary = triangle_sample_barycentrics(k, samples, shift_u, shift_v);
        const glm::vec3 p = (1.0f - bary.x - bary.y) * a + bary.x * b + bary.y * c;
        const glm::vec3 intensity =
            textured ? source.at(index, bary.x, bary.y) * (area / share) : constant;
        gpu::Light l{};
        l.x = p.x; l.y = p.y; l.z = p.z;
        const glm::vec3 c = loader::without_subnormals(intensity);
        l.r = c.r; l.g = c.g; l.b = c.b;
        l.axis_x = normal.x; l.axis_y = normal.y; l.axis_z = normal.z;
        l.type = gpu::kLightOriented | ((m.flags & gpu::kMaterialEmitsBothSides) ? gpu::kLightTwoSided : 0u);
        out[k] = l;
    }
}

}  // namespace

glm::vec2 triangle_sample_barycentrics(std::uint32_t k, std::uint32_t m, float shift_u, float shift_v) {
    const float u = std::fmod((float(k) + 0.5f) / float(m) + shift_u, 1.0f);
    const float v = std::fmod(radical_inverse(k) + shift_v, 1.0f);
    const float su = std::sqrt(u);
    return {su * (1.0f - v), su * v};
}

TriangleEmission::TriangleEmission(std::span<const gpu::Triangle> triangles, std::span<const gpu::Material> materials,
                                   std::span<const gpu::TriangleUvs> uvs, std::span<const gpu::TextureInfo> textures,
                                   std::span<const std::uint32_t> texels)
    : triangles_(triangles), materials_(materials), uvs_(uvs), textures_(textures), texels_(texels) {}

glm::vec3 TriangleEmission::at(std::size_t i, float b1, float b2) const {
    const gpu::Material& m = materials_[triangles_[i].material];
    if (!emits(m)) return glm::vec3(0.0f);
    if (!has_emissive_texture(m) || uvs_.size() != triangles_.size()) return emission(m);
    cpu::TextureKernel k;
    k.materials = materials_.data();
    k.uvs = uvs_.data();
    k.textures = textures_.data();
    k.texels = texels_.data();
    const glm::vec2 uv = k.lc_triangle_uv(std::uint32_t(i), b1, b2);
    return emission(m) * glm::vec3(k.lc_texture_sample(m.emissive_texture, uv, true));
}

glm::vec3 TriangleEmission::mean(std::size_t i) const {
    const gpu::Material& m = materials_[triangles_[i].material];
    if (!emits(m)) return glm::vec3(0.0f);
    if (!has_emissive_texture(m) || uvs_.size() != triangles_.size()) return emission(m);
    glm::dvec3 sum(0.0);
    for (std::uint32_t k = 0; k < kMeanPoints; ++k) {
        const glm::vec2 b = triangle_sample_barycentrics(k, kMeanPoints, 0.0f, 0.5f / float(kMeanPoints));
        sum += glm::dvec3(at(i, b.x, b.y));
    }
    return glm::vec3(sum / double(kMeanPoints));
}

double TriangleEmission::brightest_in_footprint(std::size_t i) const {
    const gpu::Material& m = materials_[triangles_[i].material];
    const gpu::TextureInfo& info = textures_[m.emissive_texture];
    // The triangle's texture coordinates as the lookup takes them: an
    // affine transform maps the triangle to a triangle, so the box of its
    // transformed corners bounds every point's.
    const gpu::TriangleUvs& t = uvs_[i];
    std::array<glm::dvec2, 3> uv{glm::dvec2(t.u0, t.v0), glm::dvec2(t.u1, t.v1), glm::dvec2(t.u2, t.v2)};
    if ((info.sampling & gpu::kTextureTransformed) != 0u)
        for (glm::dvec2& c : uv)
            c = glm::dvec2(double(info.uv_transform[0]) * c.x + double(info.uv_transform[1]) * c.y + info.uv_transform[2],
                           double(info.uv_transform[3]) * c.x + double(info.uv_transform[4]) * c.y + info.uv_transform[5]);
    // Along one axis, the texels the bilinear filter may read anywhere in
    // [lo, hi] of n texels: from the one left of (below) the first centre
    // to the one right of the last, wrapped as lc_wrap_texel wraps them;
    // a repeat's n and a mirror's 2n cover every texel. (The nearest
    // texel is among them.) None where there are too many (or NaN).
    const auto texels = [](double lo, double hi, std::uint32_t n, std::uint32_t wrap) {
        std::vector<std::uint32_t> out;
        double first = std::floor(lo * n - 0.5), last = std::floor(hi * n - 0.5) + 1;
        if (wrap == gpu::kTextureWrapClamp) {  // every texel past an edge is the edge's
            first = std::clamp(first, 0.0, double(n - 1));
            last = std::clamp(last, 0.0, double(n - 1));
        }
        const double period = wrap == gpu::kTextureWrapMirror ? 2.0 * n : double(n);
        const double count = std::min(last - first + 1, period);
        if (!(count <= 65536.0)) return out;
        for (double p = first; p < first + count; ++p) {
            if (wrap == gpu::kTextureWrapClamp) {
                out.push_back(std::uint32_t(p));
                continue;
            }
            const double q = std::fmod(std::fmod(p, period) + period, period);
            out.push_back(std::uint32_t(q < n ? q : period - 1 - q));
        }
        return out;
    };
    const auto [u_lo, u_hi] = std::minmax({uv[0].x, uv[1].x, uv[2].x});
    const auto [v_lo, v_hi] = std::minmax({uv[0].y, uv[1].y, uv[2].y});
    const std::vector<std::uint32_t> columns = texels(u_lo, u_hi, info.width, info.sampling & 3u);
    const std::vector<std::uint32_t> rows =
        texels(v_lo, v_hi, info.height, (info.sampling >> gpu::kTextureWrapVShift) & 3u);
    if (columns.empty() || rows.empty() || double(columns.size()) * double(rows.size()) > 65536.0)
        return -1.0;  // too many to look at (or NaN coordinates)
    cpu::TextureKernel k;
    k.textures = textures_.data();
    k.texels = texels_.data();
    float brightest = 0.0f;
    for (const std::uint32_t y : rows)
        for (const std::uint32_t x : columns) {
            const glm::vec4 c = k.lc_texel(info, x, y, true);
            brightest = std::max(brightest, gpu::lc_luminance(emission(m) * glm::vec3(c)));
        }
    return brightest;
}

double TriangleEmission::power(std::size_t i) const {
    const gpu::Triangle& t = triangles_[i];
    const gpu::Material& m = materials_[t.material];
    if (!emits(m)) return 0.0;
    const glm::dvec3 a(vertex(t, 0)), b(vertex(t, 1)), c(vertex(t, 2));
    const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
    const double sides = (m.flags & gpu::kMaterialEmitsBothSides) ? 2.0 : 1.0;
    double luminance = gpu::lc_luminance(mean(i));
    // The points can miss a texture's small bright features, or graze
    // them; a triangle with no power gets no samples, so its light would be
    // lost (a black 64 x 64 emissive texture with one white texel lit
    // nothing), and one whose points only graze the feature got a share
    // hundreds of times below a neighbour's that had none and took the
    // floor below (a quad lit from its wrong half, 0 to 3 times too
    // bright over seeds). Where the texels under the triangle's uv box are
    // not all black it gets at least as much as one of the points would
    // have found on the brightest of them: its samples carry the texture
    // at their own points, so any share that is not zero keeps the
    // estimate unbiased.
    if (has_emissive_texture(m) && uvs_.size() == triangles_.size()) {
        const double brightest = brightest_in_footprint(i);
        const double floor = brightest < 0.0 ? gpu::lc_luminance(emission(m)) : brightest;
        luminance = std::max(luminance, floor / kMeanPoints);
    }
    return 3.14159265358979323846 * area * sides * luminance;
}

std::vector<double> TriangleEmission::powers(unsigned threads) const {
    std::vector<double> power(triangles_.size(), 0.0);
    const unsigned most = threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
    threads = triangles_.size() < 16384 ? 1u : std::min(16u, most);
    run_on_threads(threads, [&](unsigned t) {
        const std::size_t begin = power.size() * t / threads, end = power.size() * (t + 1) / threads;
        for (std::size_t i = begin; i < end; ++i) power[i] = this->power(i);
    });
    return power;
}

UninitializedVector<gpu::Light> sample_area_lights(const Scene& scene, std::uint32_t count, std::uint32_t seed,
                                                   unsigned threads) {
    return sample_area_lights(TriangleEmission(scene), scene.triangles, scene.materials, count, seed, threads);
}

UninitializedVector<gpu::Light> sample_area_lights(const TriangleEmission& emission,
                                                   std::span<const gpu::Triangle> triangles,
                                                   std::span<const gpu::Material> materials, std::uint32_t count,
                                                   std::uint32_t seed, unsigned threads) {
    UninitializedVector<gpu::Light> lights;
    if (count == 0) return lights;  // before the powers: a textured one takes 256 texture reads
    // Power of each emitting triangle, in double: many small triangles add up.
    const std::vector<double> power = emission.powers(threads);
    double total = 0.0;
    for (const double p : power) total += p;
    if (!(total > 0.0)) return lights;
    // Systematic sampling: sample k stands at (k + offset) / count of the
    // cumulative power; a triangle gets the samples that fall on its share.
    const double offset = gpu::lc_unit_float(gpu::lc_hash(seed ^ 0x9E3779B9u));
    std::size_t last_emitter = 0;
    for (std::size_t i = 0; i < triangles.size(); ++i)
        if (power[i] > 0.0) last_emitter = i;
    struct Share {
        std::size_t triangle, first;  // its samples are lights [first, first + samples)
        std::uint32_t samples;
        float share;                  // what each sample's area is divided by
    };
    std::vector<Share> shares;
    std::size_t placed = 0;
    double before = 0.0;
    for (std::size_t i = 0; i < triangles.size(); ++i) {
        if (power[i] <= 0.0) continue;
        // The last share ends at the total exactly, so no sample is lost to rounding.
        const double after = i == last_emitter ? total : before + power[i];
        const double first = std::floor(before / total * count - offset + 1.0);
        const double last = std::floor(after / total * count - offset + 1.0);
        // A triangle expecting e >= 1 samples gets floor(e) or ceil(e), each
        // carrying 1/m of its power, so exactly its power. One expecting e < 1
        // gets one sample with probability e (systematic sampling), which
        // carries 1/e of its power, so its power in expectation (with 1/m it
        // was e times its power: an emitter of 80,000 triangles lit the room
        // 18% too dimly with 65,536 samples).
        const double expected = (after - before) / total * count;
        before = after;
        const auto samples = std::uint32_t(std::max(0.0, last - first));
        if (samples == 0) continue;
        shares.push_back({i, placed, samples, expected < 1.0 ? float(expected) : float(samples)});
        placed += samples;
    }
    // The triangles' samples on every core, each thread the shares that
    // start in its range of the samples; each sample depends on its
    // triangle alone, so the lights are the same whatever the threads. The
    // array is not zeroed first: the threads that write it fault its pages
    // in (10^7 samples are 480 MB).
    reserve_huge(lights, placed);
    lights.resize(placed);
    // Below 65,536 samples one thread: starting more costs more than they save.
    const unsigned most = threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
    threads = placed < 65536 ? 1u : std::min(16u, most);
    auto run = [&](unsigned t) {
        const std::size_t begin = placed * t / threads, end = placed * (t + 1) / threads;
        auto starts_before = [](const Share& share, std::size_t at) { return share.first < at; };
        auto it = std::lower_bound(shares.begin(), shares.end(), begin, starts_before);
        for (; it != shares.end() && it->first < end; ++it) {
            const gpu::Triangle& tri = triangles[it->triangle];
            sample_triangle(emission, it->triangle, tri, materials[tri.material], it->samples, it->share,
                            gpu::lc_hash(seed ^ gpu::lc_hash(std::uint32_t(it->triangle))), lights.data() + it->first);
        }
    };
    run_on_threads(threads, run);
    return lights;
}

}  // namespace lc
