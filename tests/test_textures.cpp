// Textures (shaders/lc_shared/textures.h, host/scene/textures.h): lookups
// against hand-made textures with known texels (texel centres, bilinear
// weights, wrapping, sRGB decoding), mipmap chains and the levels a ray
// cone's footprint reads, the material at a point, normal maps,
// MTL texture maps and their errors, textured area lights, and a textured
// plane rendered against its closed form.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <stb_image_write.h>

#include "area_lights.h"
#include "cpu_kernel.h"
#include "lightcuts/error.h"
#include "lightcuts/render.h"
#include "lightcuts/scene.h"
#include "scene/materials.h"
#include "scene/textures.h"
#include "test_util.h"

namespace lc {
namespace {

using test::TempDir;

std::vector<std::uint8_t> rgba_bytes(const std::vector<std::uint32_t>& texels) {
    std::vector<std::uint8_t> bytes;
    for (std::uint32_t t : texels)
        for (int c = 0; c < 4; ++c) bytes.push_back(std::uint8_t(t >> (8 * c)));
    return bytes;
}

std::uint32_t rgba(std::uint32_t r, std::uint32_t g, std::uint32_t b, std::uint32_t a = 255) {
    return r | g << 8 | b << 16 | a << 24;
}

// A scene holding textures and materials, and the kernel that reads them.
struct TextureScene {
    Scene scene;
    cpu::TextureKernel k;

    std::uint32_t add(std::uint32_t w, std::uint32_t h, const std::vector<std::uint32_t>& texels) {
        return loader::add_texture(scene, w, h, rgba_bytes(texels).data(), "test", "texture");
    }
    cpu::TextureKernel& kernel() {
        k.materials = scene.materials.data();
        k.uvs = scene.uvs.data();
        k.textures = scene.textures.data();
        k.texels = scene.texels.data();
        return k;
    }
};

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// 2 x 2 texels, row 0 on top: A B / C D.
const std::vector<std::uint32_t> kTwoByTwo = {rgba(10, 20, 30, 40), rgba(50, 60, 70, 80), rgba(90, 100, 110, 120),
                                              rgba(130, 140, 150, 160)};

glm::vec4 unpack(std::uint32_t t) {
    return glm::vec4(float(t & 255u), float(t >> 8 & 255u), float(t >> 16 & 255u), float(t >> 24)) / 255.0f;
}

void expect_vec4_near(glm::vec4 got, glm::vec4 want, float tol, const std::string& what) {
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], want[c], tol) << what << " channel " << c;
}

TEST(TextureLookup, TexelCentresGiveTheTexels) {
    TextureScene t;
    const std::uint32_t tex = t.add(2, 2, kTwoByTwo);
    auto& k = t.kernel();
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x) {
            const glm::vec2 uv((float(x) + 0.5f) / 2.0f, (float(y) + 0.5f) / 2.0f);
            expect_vec4_near(k.lc_texture_sample(tex, uv, false), unpack(kTwoByTwo[std::size_t(2 * y + x)]), 1e-6f,
                             "texel " + std::to_string(x) + "," + std::to_string(y));
        }
}

TEST(TextureLookup, BilinearWeightsBetweenCentres) {
    TextureScene t;
    const std::uint32_t tex = t.add(2, 2, kTwoByTwo);
    auto& k = t.kernel();
    const glm::vec4 a = unpack(kTwoByTwo[0]), b = unpack(kTwoByTwo[1]), c = unpack(kTwoByTwo[2]),
                    d = unpack(kTwoByTwo[3]);
    // Halfway between A and B on row 0; the centre of all four; a quarter
    // of the way from A towards D in both directions.
    expect_vec4_near(k.lc_texture_sample(tex, {0.5f, 0.25f}, false), 0.5f * (a + b), 1e-6f, "A-B");
    expect_vec4_near(k.lc_texture_sample(tex, {0.5f, 0.5f}, false), 0.25f * (a + b + c + d), 1e-6f, "centre");
    const glm::vec4 quarter = 0.75f * (0.75f * a + 0.25f * b) + 0.25f * (0.75f * c + 0.25f * d);
    expect_vec4_near(k.lc_texture_sample(tex, {0.375f, 0.375f}, false), quarter, 1e-6f, "quarter");
}

TEST(TextureLookup, WrapsInBothDirections) {
    TextureScene t;
    const std::uint32_t tex = t.add(2, 2, kTwoByTwo);
    auto& k = t.kernel();
    const glm::vec4 a = unpack(kTwoByTwo[0]), b = unpack(kTwoByTwo[1]), c = unpack(kTwoByTwo[2]);
    // u = 0 lies between the last column's centre and the first's.
    expect_vec4_near(k.lc_texture_sample(tex, {0.0f, 0.25f}, false), 0.5f * (a + b), 1e-6f, "u edge");
    expect_vec4_near(k.lc_texture_sample(tex, {0.25f, 0.0f}, false), 0.5f * (a + c), 1e-6f, "v edge");
    for (glm::vec2 shift : {glm::vec2(3.0f, -2.0f), glm::vec2(-1.0f, 5.0f), glm::vec2(-7.0f, -7.0f)})
        for (glm::vec2 uv : {glm::vec2(0.25f, 0.75f), glm::vec2(0.6f, 0.1f), glm::vec2(0.9f, 0.95f)})
            expect_vec4_near(k.lc_texture_sample(tex, uv + shift, false), k.lc_texture_sample(tex, uv, false), 2e-5f,
                             "shifted by " + std::to_string(shift.x) + "," + std::to_string(shift.y));
}

// glTF's CLAMP_TO_EDGE and MIRRORED_REPEAT on a 4 x 1 texture whose texels
// are 0, 1, 2, 3 (in red), against what each wrapping reads: the edge
// texel beyond the edges; the image mirrored in every other period.
TEST(TextureLookup, ClampedAndMirroredWrapping) {
    TextureScene t;
    const std::uint32_t image = t.add(4, 1, {rgba(0, 0, 0), rgba(1, 0, 0), rgba(2, 0, 0), rgba(3, 0, 0)});
    loader::TextureSampling clamp, mirror;
    clamp.wrap_u = gpu::kTextureWrapClamp;
    mirror.wrap_u = gpu::kTextureWrapMirror;
    const std::uint32_t clamped = loader::sampled_texture(t.scene, image, clamp);
    const std::uint32_t mirrored = loader::sampled_texture(t.scene, image, mirror);
    EXPECT_EQ(loader::sampled_texture(t.scene, image, clamp), clamped) << "made once";
    EXPECT_EQ(loader::sampled_texture(t.scene, image, loader::TextureSampling{}), image);
    ASSERT_EQ(t.scene.textures.size(), 3u);
    auto& k = t.kernel();
    const auto red = [&](std::uint32_t tex, float u) { return k.lc_texture_sample(tex, {u, 0.5f}, false).x * 255.0f; };
    struct Case {
        float u, repeat, clamp, mirror;
    };
    // Texel centres at u = 0.125, 0.375, ...: between the first and the
    // last centre all three agree; outside, repeat blends 3 and 0, clamp
    // holds the edge texel, mirror reflects about the edge.
    for (const Case c : {Case{0.25f, 0.5f, 0.5f, 0.5f}, Case{0.0f, 1.5f, 0.0f, 0.0f}, Case{1.0f, 1.5f, 3.0f, 3.0f},
                         Case{-0.125f, 3.0f, 0.0f, 0.0f}, Case{1.125f, 0.0f, 3.0f, 3.0f}, Case{-0.375f, 2.0f, 0.0f, 1.0f},
                         Case{1.375f, 1.0f, 3.0f, 2.0f}, Case{2.125f, 0.0f, 3.0f, 0.0f}, Case{-1.875f, 0.0f, 0.0f, 0.0f},
                         Case{-7.875f, 0.0f, 0.0f, 0.0f}, Case{5.0f, 1.5f, 3.0f, 3.0f}, Case{-0.875f, 0.0f, 0.0f, 3.0f}}) {
        EXPECT_NEAR(red(image, c.u), c.repeat, 1e-4f) << "repeat at u = " << c.u;
        EXPECT_NEAR(red(clamped, c.u), c.clamp, 1e-4f) << "clamp at u = " << c.u;
        EXPECT_NEAR(red(mirrored, c.u), c.mirror, 1e-4f) << "mirror at u = " << c.u;
    }
    // v keeps its own wrapping (repeat): a 1-texel-tall image reads the same anywhere.
    EXPECT_NEAR(k.lc_texture_sample(clamped, {-3.0f, 7.3f}, false).x * 255.0f, 0.0f, 1e-4f);
}

// magFilter NEAREST: the texel the point lies in, wrapped as the sampler says.
TEST(TextureLookup, NearestFilteringReadsOneTexel) {
    TextureScene t;
    const std::uint32_t image = t.add(2, 2, kTwoByTwo);
    loader::TextureSampling nearest;
    nearest.nearest = true;
    nearest.wrap_v = gpu::kTextureWrapClamp;
    const std::uint32_t tex = loader::sampled_texture(t.scene, image, nearest);
    auto& k = t.kernel();
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x)
            for (const glm::vec2 within : {glm::vec2(0.01f, 0.01f), glm::vec2(0.49f, 0.3f), glm::vec2(0.2f, 0.49f)}) {
                const glm::vec2 uv = (glm::vec2(float(x), float(y)) + within) * 0.5f;
                expect_vec4_near(k.lc_texture_sample(tex, uv, false), unpack(kTwoByTwo[std::size_t(2 * y + x)]), 1e-7f,
                                 "texel " + std::to_string(x) + "," + std::to_string(y));
            }
    // u repeats (u = -0.1 is in column 1), v clamps (v = 1.7 is in row 1).
    // (1e-7: the kernel's x * (1 / 255) against unpack's x / 255; the
    // nearest neighbour's texel differs by more than 0.15.)
    expect_vec4_near(k.lc_texture_sample(tex, {-0.1f, 1.7f}, false), unpack(kTwoByTwo[3]), 1e-7f, "wrapped");
}

// A uv transform applies before the wrapping; one whose products overflow
// reads the texture at 0 rather than at a NaN's texel.
TEST(TextureLookup, TransformedCoordinates) {
    TextureScene t;
    const std::uint32_t image = t.add(2, 2, kTwoByTwo);
    loader::TextureSampling swap;  // u' = v + 0.5, v' = u
    swap.uv_transform = {0.0f, 1.0f, 0.5f, 1.0f, 0.0f, 0.0f};
    const std::uint32_t swapped = loader::sampled_texture(t.scene, image, swap);
    EXPECT_NE(t.scene.textures[swapped].sampling & gpu::kTextureTransformed, 0u);
    auto& k = t.kernel();
    for (const glm::vec2 uv : {glm::vec2(0.25f, 0.75f), glm::vec2(0.6f, 0.1f), glm::vec2(-3.3f, 9.9f)})
        expect_vec4_near(k.lc_texture_sample(swapped, uv, false),
                         k.lc_texture_sample(image, glm::vec2(uv.y + 0.5f, uv.x), false), 1e-6f, "swapped");
    loader::TextureSampling huge;
    huge.uv_transform = {3e38f, 3e38f, 0.0f, 0.0f, 1.0f, 0.0f};
    const std::uint32_t overflowing = loader::sampled_texture(t.scene, image, huge);
    auto& k2 = t.kernel();
    expect_vec4_near(k2.lc_texture_sample(overflowing, {1.0f, 0.25f}, false),
                     k2.lc_texture_sample(image, {0.0f, 0.25f}, false), 0.0f, "u' = inf reads as 0");
}

TEST(TextureLookup, SrgbDecodedPerTexelBeforeFiltering) {
    TextureScene t;
    const std::uint32_t tex = t.add(2, 1, {rgba(188, 10, 255, 128), rgba(0, 0, 0, 0)});
    auto& k = t.kernel();
    const glm::vec4 c = k.lc_texture_sample(tex, {0.25f, 0.5f}, true);
    EXPECT_NEAR(c.x, srgb_to_linear(188.0 / 255.0), 1e-6);  // 0.5029
    EXPECT_NEAR(c.y, 10.0 / 255.0 / 12.92, 1e-7);            // the linear segment
    EXPECT_NEAR(c.z, 1.0, 1e-6);
    EXPECT_NEAR(c.w, 128.0 / 255.0, 1e-7);                   // alpha is linear
    // Halfway between 255 and 0: the mean of the decoded values (0.5),
    // not the decoding of the mean (0.21).
    EXPECT_NEAR(k.lc_texture_sample(tex, {0.5f, 0.5f}, true).z, 0.5, 1e-6);
    EXPECT_NEAR(k.lc_texture_sample(tex, {0.25f, 0.5f}, false).x, 188.0 / 255.0, 1e-6);
}

// Mipmap chains (loader::add_mipmaps): each level's texels the box-filtered
// mean of the level above's, colour averaged as linear values.
double linear_to_srgb(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }

std::uint32_t byte_of(double v) { return std::uint32_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); }

TEST(Mipmaps, LevelsAreBoxFilteredMeansOfTheLevelAbove) {
    TextureScene t;
    // A 4 x 4 checker of sRGB 255 and 0 (alpha 0 and 255) as base colour;
    // a 5 x 1 row as a metallic-roughness map (linear); a third image no
    // material reads; a fourth whose sampler asks for no mipmaps.
    std::vector<std::uint32_t> checker(16);
    for (std::uint32_t i = 0; i < 16; ++i)
        checker[i] = (i % 4 + i / 4) % 2 == 0 ? rgba(255, 255, 255, 0) : rgba(0, 0, 0, 255);
    const std::uint32_t colour = t.add(4, 4, checker);
    const std::uint32_t row = t.add(5, 1, {rgba(0, 0, 0), rgba(50, 0, 0), rgba(100, 0, 0), rgba(150, 0, 0), rgba(255, 0, 0)});
    const std::uint32_t unused = t.add(2, 2, kTwoByTwo);
    loader::TextureSampling without;
    without.mipmaps = false;
    const std::uint32_t plain = loader::sampled_texture(t.scene, t.add(2, 2, kTwoByTwo), without);
    gpu::Material m = loader::make_material(glm::vec3(1.0f), glm::vec3(0.0f), 1.0f);
    loader::set_texture(m, &gpu::Material::base_color_texture, colour);
    loader::set_texture(m, &gpu::Material::metallic_roughness_texture, row);
    loader::set_texture(m, &gpu::Material::normal_texture, plain);
    t.scene.materials = {m};
    const std::size_t base = t.scene.texels.size();
    loader::add_mipmaps(t.scene);
    // 2 x 2 + 1 x 1 for the checker, 2 x 1 + 1 x 1 for the row.
    ASSERT_EQ(t.scene.texels.size(), base + 5 + 3);
    for (const std::uint32_t none : {unused, plain})
        EXPECT_EQ(t.scene.textures[none].sampling & gpu::kTextureMipmapped, 0u) << none;
    const gpu::TextureInfo& c = t.scene.textures[colour];
    ASSERT_NE(c.sampling & gpu::kTextureMipmapped, 0u);
    // Every 2 x 2 block holds two of each: linear 0.5, stored as sRGB;
    // alpha as it is. Level 2 is the mean of level 1.
    const std::uint32_t half = byte_of(linear_to_srgb(0.5));
    for (std::uint32_t i = 0; i < 5; ++i)
        EXPECT_EQ(t.scene.texels[c.mip_offset + i], rgba(half, half, half, 128)) << "texel " << i;
    // The row, 5 texels into 2: weights 0.4, 0.4, 0.2 and 0.2, 0.4, 0.4.
    const gpu::TextureInfo& r = t.scene.textures[row];
    ASSERT_NE(r.sampling & gpu::kTextureMipmapped, 0u);
    const double left = (0.4 * 0 + 0.4 * 50 + 0.2 * 100) / 255.0, right = (0.2 * 100 + 0.4 * 150 + 0.4 * 255) / 255.0;
    EXPECT_EQ(t.scene.texels[r.mip_offset], rgba(byte_of(left), 0, 0));
    EXPECT_EQ(t.scene.texels[r.mip_offset + 1], rgba(byte_of(right), 0, 0));
    EXPECT_EQ(t.scene.texels[r.mip_offset + 2], rgba(byte_of((byte_of(left) + byte_of(right)) / 510.0), 0, 0));
}

// One image read as base colour (sRGB) by one material and as a
// metallic-roughness map (linear) by another, through one texture record:
// a chain for each way, the second reader pointed at a copy of the record
// (a 0/255 checker's mean is sRGB 188 as colour, 128 as data; one chain
// averaged as colour read 0.737 as roughness).
TEST(Mipmaps, AnImageReadAsColourAndAsDataGetsAChainEach) {
    TextureScene t;
    std::vector<std::uint32_t> checker(4);
    for (std::uint32_t i = 0; i < 4; ++i) checker[i] = (i % 2 + i / 2) % 2 == 0 ? rgba(255, 255, 255) : rgba(0, 0, 0);
    const std::uint32_t tex = t.add(2, 2, checker);
    gpu::Material colour = loader::make_material(glm::vec3(1.0f), glm::vec3(0.0f), 1.0f);
    loader::set_texture(colour, &gpu::Material::base_color_texture, tex);
    gpu::Material data = colour;
    data.base_color_texture = gpu::kInvalidIndex;
    loader::set_texture(data, &gpu::Material::metallic_roughness_texture, tex);
    t.scene.materials = {colour, data, colour};
    loader::add_mipmaps(t.scene);
    ASSERT_EQ(t.scene.textures.size(), 2u);
    const std::uint32_t copy = t.scene.materials[1].metallic_roughness_texture;
    EXPECT_EQ(t.scene.materials[0].base_color_texture, tex);
    EXPECT_EQ(t.scene.materials[2].base_color_texture, tex);
    EXPECT_EQ(copy, 1u);
    const std::uint32_t half = byte_of(linear_to_srgb(0.5));
    EXPECT_EQ(t.scene.texels[t.scene.textures[tex].mip_offset], rgba(half, half, half));
    EXPECT_EQ(t.scene.texels[t.scene.textures[copy].mip_offset], rgba(128, 128, 128));
}

// The level a lookup reads follows its footprint: under a texel, level 0
// as the sampler says; a texel of level l wide, level l; between two
// levels, a blend; wider than the image, its mean. A transform that
// stretches the coordinates stretches the footprint. A footprint longer
// than it is wide averages lookups along its long axis.
TEST(Mipmaps, FootprintPicksTheLevel) {
    TextureScene t;
    std::vector<std::uint32_t> texels(16);
    for (std::uint32_t i = 0; i < 16; ++i) texels[i] = rgba(16 * i, 255 - 16 * i, (i * 97) % 256, 255);
    const std::uint32_t tex = t.add(4, 4, texels);
    loader::TextureSampling doubled;
    doubled.uv_transform = {2.0f, 0.0f, 0.0f, 0.0f, 2.0f, 0.0f};
    const std::uint32_t stretched = loader::sampled_texture(t.scene, tex, doubled);
    loader::TextureSampling point;
    point.nearest = true;
    const std::uint32_t nearest = loader::sampled_texture(t.scene, tex, point);
    gpu::Material m = loader::make_material(glm::vec3(1.0f), glm::vec3(0.0f), 1.0f);
    loader::set_texture(m, &gpu::Material::metallic_roughness_texture, tex);
    loader::set_texture(m, &gpu::Material::normal_texture, stretched);
    gpu::Material m2 = m;
    loader::set_texture(m2, &gpu::Material::normal_texture, nearest);
    t.scene.materials = {m, m2};
    loader::add_mipmaps(t.scene);
    cpu::TextureKernel& k = t.kernel();
    const gpu::TextureInfo& info = t.scene.textures[tex];
    ASSERT_EQ(t.scene.textures[stretched].mip_offset, info.mip_offset);
    const auto level_texel = [&](std::uint32_t offset) { return unpack(t.scene.texels[offset]); };
    // A round footprint `width` across, in texture coordinates.
    const auto round = [](float width) { return glm::vec4(width, 0.0f, 0.0f, width); };
    const glm::vec2 uv(0.25f, 0.25f);  // level 1's first texel centre
    const glm::vec4 full = k.lc_texture_sample(tex, uv, false);
    expect_vec4_near(k.lc_texture_sample(tex, uv, false, round(0.25f)), full, 0.0f, "a texel wide: level 0");
    expect_vec4_near(k.lc_texture_sample(tex, uv, false, round(std::nanf(""))), full, 0.0f, "NaN: level 0");
    expect_vec4_near(k.lc_texture_sample(tex, uv, false, round(0.5f)), level_texel(info.mip_offset), 1e-6f, "level 1");
    const glm::vec4 mean = level_texel(info.mip_offset + 4);
    expect_vec4_near(k.lc_texture_sample(tex, uv, false, round(1.0f)), mean, 1e-6f, "the image wide: level 2");
    expect_vec4_near(k.lc_texture_sample(tex, uv, false, round(1e30f)), mean, 1e-6f, "wider: level 2");
    expect_vec4_near(k.lc_texture_sample(tex, uv, false, round(std::exp2(-0.25f))),
                     0.25f * level_texel(info.mip_offset) + 0.75f * mean, 1e-6f, "three quarters to level 2");
    // Doubled coordinates: (0.125, 0.125) is (0.25, 0.25), and a footprint
    // of a quarter there is one of a half, level 1.
    expect_vec4_near(k.lc_texture_sample(stretched, uv * 0.5f, false, round(0.25f)), level_texel(info.mip_offset),
                     1e-6f, "stretched: level 1");
    // Two texels long, half a texel wide: two bilinear lookups at level 0,
    // a texel apart along the long axis (along u, given second: the axes
    // are taken in either order).
    const glm::vec2 p(0.4f, 0.45f);
    expect_vec4_near(k.lc_texture_sample(tex, p, false, glm::vec4(0.0f, 0.125f, 0.5f, 0.0f)),
                     0.5f * (k.lc_texture_sample(tex, p - glm::vec2(0.125f, 0.0f), false) +
                             k.lc_texture_sample(tex, p + glm::vec2(0.125f, 0.0f), false)),
                     1e-6f, "anisotropic");
    // So magnified (a texel apart), a nearest sampler's lookups read one
    // texel each.
    ASSERT_NE(t.scene.textures[nearest].sampling & gpu::kTextureMipmapped, 0u);
    expect_vec4_near(k.lc_texture_sample(nearest, p, false, glm::vec4(0.0f, 0.125f, 0.5f, 0.0f)),
                     0.5f * (k.lc_texture_sample(nearest, p - glm::vec2(0.125f, 0.0f), false) +
                             k.lc_texture_sample(nearest, p + glm::vec2(0.125f, 0.0f), false)),
                     1e-6f, "anisotropic, nearest");
    expect_vec4_near(k.lc_texture_sample(nearest, p - glm::vec2(0.125f, 0.0f), false), unpack(texels[5]), 1e-6f,
                     "one texel");
}

// A ray cone's footprint in texture coordinates: across the ray the cone's
// width, along it the width over the cosine, mapped by the triangle's
// texture coordinates.
TEST(Mipmaps, ConeFootprintOnATriangle) {
    TextureScene t;
    cpu::TextureKernel& k = t.kernel();
    // u = x / 2 and v = z / 4 on the plane y = 0.
    const gpu::TriangleUvs uvs{0, 0, 1, 0, 0, 1};
    const glm::vec3 v0(0, 0, 0), v1(2, 0, 0), v2(0, 0, 4);
    const auto expect_near = [](glm::vec4 got, glm::vec4 want, const char* what) {
        for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], want[c], 1e-6f) << what << " " << c;
    };
    // Head on, a circle (its axes' directions are the triangle's choice).
    const glm::vec4 down = k.lc_uv_footprint(0.5f, {0, -1, 0}, v0, v1, v2, uvs);
    EXPECT_NEAR(std::hypot(2.0f * down.x, 4.0f * down.y), 0.5f, 1e-6f);
    EXPECT_NEAR(std::hypot(2.0f * down.z, 4.0f * down.w), 0.5f, 1e-6f);
    // At 60 degrees in the x-y plane: twice as long along x; across, z.
    const float s60 = std::sqrt(3.0f) / 2.0f;
    const glm::vec4 slanted = k.lc_uv_footprint(0.5f, {s60, -0.5f, 0}, v0, v1, v2, uvs);
    expect_near(glm::abs(slanted), glm::vec4(0.5f, 0.0f, 0.0f, 0.125f), "60 degrees");
    // Edge-on the stretch stops at 1000 times.
    const glm::vec4 grazing = k.lc_uv_footprint(0.5f, {1, 0, 0}, v0, v1, v2, uvs);
    EXPECT_NEAR(std::abs(grazing.x), 250.0f, 1e-3f);
    // Degenerate texture coordinates: no footprint at all (level 0).
    EXPECT_EQ(k.lc_uv_footprint(0.5f, {0, -1, 0}, v0, v1, v2, gpu::TriangleUvs{}), glm::vec4(0.0f));
    // Triangles of any size: a cone as many times wider on a triangle as
    // many times larger has the same footprint (the cross product's square
    // overflowed a float at 1e10 and underflowed at 1e-10).
    for (const float scale : {1e-15f, 1e-10f, 1e10f, 1e15f})
        expect_near(k.lc_uv_footprint(0.5f * scale, {s60, -0.5f, 0}, v0 * scale, v1 * scale, v2 * scale, uvs),
                    slanted, "scaled");
}

TEST(TextureLookup, MaterialAtAppliesTheTexturesOfReflection) {
    TextureScene t;
    const std::uint32_t colour = t.add(1, 1, {rgba(188, 255, 0)});
    const std::uint32_t mr = t.add(1, 1, {rgba(0, 128, 64)});
    const std::uint32_t glow = t.add(1, 1, {rgba(255, 188, 0)});
    loader::DisneyParams d;
    d.base_color = {0.5f, 0.8f, 1.0f};
    d.roughness = 0.6f;
    d.metallic = 0.9f;
    gpu::Material m = loader::make_disney_material(d);
    loader::set_emission(m, {2.0f, 4.0f, 8.0f}, false);
    loader::set_texture(m, &gpu::Material::base_color_texture, colour);
    loader::set_texture(m, &gpu::Material::metallic_roughness_texture, mr);
    loader::set_texture(m, &gpu::Material::emissive_texture, glow);
    t.scene.materials = {m};
    const gpu::Material at = t.kernel().lc_material_at(0, {0.3f, 0.7f}, glm::vec4(0.0f));
    const double c188 = srgb_to_linear(188.0 / 255.0);
    EXPECT_NEAR(at.kd_r, 0.5 * c188, 1e-6);
    EXPECT_NEAR(at.kd_g, 0.8, 1e-6);
    EXPECT_EQ(at.kd_b, 0.0f);
    EXPECT_NEAR(at.roughness, 0.6 * 128.0 / 255.0, 1e-6);  // green
    EXPECT_NEAR(at.metallic, 0.9 * 64.0 / 255.0, 1e-6);    // blue
    EXPECT_NEAR(at.alpha, at.roughness * at.roughness, 1e-7);
    // The emission is the record's: lc_surface_emission applies the
    // emissive texture where a surface's emission is asked for.
    EXPECT_EQ(at.emission_r, 2.0f);
    EXPECT_EQ(at.emission_g, 4.0f);
    EXPECT_EQ(at.emission_b, 8.0f);
    // A black roughness texel cannot take alpha below the floor.
    t.scene.texels[t.scene.textures[mr].offset] = rgba(0, 0, 0);
    EXPECT_EQ(t.kernel().lc_material_at(0, {0.3f, 0.7f}, glm::vec4(0.0f)).alpha, 1e-3f);
}

// A triangle in the z = 0 plane facing +z, u along +x and v along -y (v
// grows downwards in the image, so the image's "up" is +y).
struct NormalMapCase {
    TextureScene t;
    glm::vec3 v0{0, 0, 0}, v1{1, 0, 0}, v2{0, 1, 0};
    gpu::TriangleUvs uvs{0.0f, 1.0f, 1.0f, 1.0f, 0.0f, 0.0f};

    glm::vec3 bent(std::uint32_t texel, float scale = 1.0f) {
        t.scene.textures.clear();
        t.scene.texels.clear();
        const std::uint32_t tex = t.add(1, 1, {texel});
        gpu::Material m = loader::make_material(glm::vec3(0.5f), glm::vec3(0.0f), 1.0f);
        loader::set_texture(m, &gpu::Material::normal_texture, tex);
        m.normal_scale = scale;
        t.scene.materials = {m};
        return t.kernel().lc_normal_mapped(m, {0.3f, 0.4f}, glm::vec4(0.0f), {0, 0, 1}, v0, v1, v2, uvs);
    }
};

TEST(NormalMap, TangentSpaceFollowsUAndImageUp) {
    NormalMapCase c;
    const glm::vec3 flat = c.bent(rgba(128, 128, 255));
    EXPECT_NEAR(flat.z, 1.0f, 1e-4f);
    const glm::vec3 right = c.bent(rgba(255, 128, 128));  // +x in tangent space: +u
    EXPECT_GT(right.x, 0.99f);
    const glm::vec3 up = c.bent(rgba(128, 255, 128));     // +y: image up, -v, here +y
    EXPECT_GT(up.y, 0.99f);
    const glm::vec3 tilted = c.bent(rgba(218, 128, 218));  // 45 degrees towards +u
    EXPECT_NEAR(tilted.x, tilted.z, 1e-2f);
    EXPECT_NEAR(glm::length(tilted), 1.0f, 1e-5f);
    // normal_scale scales the tangent part.
    const glm::vec3 scaled = c.bent(rgba(218, 128, 218), 0.0f);
    EXPECT_NEAR(scaled.z, 1.0f, 1e-5f);
    // Mirrored UVs (u running along -x) turn the tangent round.
    c.uvs = {1.0f, 1.0f, 0.0f, 1.0f, 1.0f, 0.0f};
    EXPECT_LT(c.bent(rgba(255, 128, 128)).x, -0.99f);
    // Degenerate UVs keep the interpolated normal.
    c.uvs = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
    EXPECT_EQ(c.bent(rgba(255, 128, 128)), glm::vec3(0, 0, 1));
}

void write_png(const std::filesystem::path& file, int w, int h, const std::vector<std::uint32_t>& texels) {
    const std::vector<std::uint8_t> bytes = rgba_bytes(texels);
    ASSERT_NE(stbi_write_png(file.string().c_str(), w, h, 4, bytes.data(), w * 4), 0);
}

const char* kTexturedObj =
    "mtllib quad.mtl\n"
    "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "usemtl paint\n"
    "f 1/1 4/4 3/3\nf 1/1 3/3 2/2\n";

std::string quad_scene_json() {
    return R"({"camera": {"position": [0, 3, 0.01], "look_at": [0, 0, 0], "fov_y_degrees": 60, "width": 8, "height": 8},
               "meshes": [{"obj": "quad.obj"}],
               "lights": [{"type": "point", "position": [0, 2, 0], "intensity": [1, 1, 1]}]})";
}

// A folder holding paint.png (2 x 1: red, blue), quad.obj (kTexturedObj
// unless given) and scene.json (quad_scene_json()); load() writes quad.mtl
// and loads the scene.
struct TexturedQuad {
    TempDir dir;
    explicit TexturedQuad(const char* obj = kTexturedObj) {
        write_png(dir.path() / "paint.png", 2, 1, {rgba(255, 0, 0), rgba(0, 0, 255)});
        dir.write("quad.obj", obj);
        dir.write("scene.json", quad_scene_json());
    }
    Scene load(const std::string& mtl) {
        dir.write("quad.mtl", mtl);
        return load_scene(dir.path() / "scene.json");
    }
    std::string obj() const { return (dir.path() / "quad.obj").lexically_normal().string(); }
};

TEST(ObjTextures, MapKdLoadsAndVtTurnsToGrowDownwards) {
    TexturedQuad quad;
    const Scene s = quad.load("newmtl paint\nKd 1 1 1\nmap_Kd paint.png\n");
    ASSERT_EQ(s.textures.size(), 1u);
    EXPECT_EQ(s.textures[0].width, 2u);
    EXPECT_EQ(s.textures[0].height, 1u);
    ASSERT_EQ(s.texels.size(), 2u);
    EXPECT_EQ(s.texels[1], rgba(0, 0, 255));
    ASSERT_EQ(s.uvs.size(), s.triangles.size());
    // Corner 1 has vt (0, 0): v = 1 after the turn; corner 4 has (0, 1): v = 0.
    EXPECT_EQ(s.uvs[0].u0, 0.0f);
    EXPECT_EQ(s.uvs[0].v0, 1.0f);
    EXPECT_EQ(s.uvs[0].v1, 0.0f);
    const gpu::Material& m = s.materials[s.triangles[0].material];
    EXPECT_NE(m.flags & gpu::kMaterialTextured, 0u);
    EXPECT_EQ(m.base_color_texture, 0u);
    EXPECT_EQ(m.normal_texture, gpu::kInvalidIndex);
}

// A texture path in an MTL is relative to the MTL (in a folder of its own
// here), and an image that two meshes name, or one OBJ listed twice, is
// stored once in the scene (it was read again for every mesh: nine copies
// of a 4096 x 4096 image passed the texel limit).
TEST(ObjTextures, PathsAreTheMtlsAndEachImageIsStoredOnce) {
    TempDir dir;
    std::filesystem::create_directories(dir.path() / "materials");
    write_png(dir.path() / "materials" / "paint.png", 2, 1, {rgba(255, 0, 0), rgba(0, 0, 255)});
    dir.write("materials/quad.mtl", "newmtl paint\nKd 1 1 1\nmap_Kd paint.png\n");
    std::string obj = kTexturedObj;
    obj.replace(obj.find("mtllib quad.mtl"), 15, "mtllib materials/quad.mtl");
    dir.write("quad.obj", obj);
    std::string json = quad_scene_json();
    json.replace(json.find(R"({"obj": "quad.obj"})"), 19,
                 R"({"obj": "quad.obj"}, {"obj": "quad.obj", "transform": {"translate": [0, -1, 0]}})");
    const Scene s = load_scene(dir.write("scene.json", json));
    ASSERT_EQ(s.textures.size(), 1u);
    EXPECT_EQ(s.texels.size(), 2u);
    ASSERT_EQ(s.triangles.size(), 4u);
    for (const auto& t : s.triangles) EXPECT_EQ(s.materials[t.material].base_color_texture, 0u);
}

// What an MTL asks for that is not done gets a note: a map's options but
// -s, -o and -clamp, maps the renderer has no use for (tinyobjloader reads
// them all), and transparency (d below 1).
TEST(ObjTextures, UnusedMapsAndOptionsAreNoted) {
    TexturedQuad quad;
    const Scene scene = quad.load("newmtl paint\nKd 1 1 1\nmap_Kd -colorspace linear paint.png\nmap_Bump paint.png\n"
                                  "map_Ks paint.png\nd 0.5\n");
    const std::string obj = quad.obj();
    EXPECT_EQ(scene.load_notes,
              (std::vector<std::string>{obj + ": material 'paint'.d (or Tr): transparency is not rendered, the surface is opaque",
                                        obj + ": material 'paint'.map_Bump is not used (a normal map is read from norm)",
                                        obj + ": material 'paint'.map_Ks is not used",
                                        obj + ": material 'paint'.map_Kd: options other than -s, -o and -clamp are "
                                              "not applied (sRGB, bilinear)"}));
    EXPECT_TRUE(quad.load("newmtl paint\nKd 1 1 1\nmap_Kd -clamp on -s 2 3 1 -o 0.25 0.5 0 paint.png\n")
                    .load_notes.empty());
    EXPECT_TRUE(quad.load("newmtl paint\nKd 1 1 1\nmap_Kd paint.png\n").load_notes.empty());
}

// Faces without vt whose material has textures read them at (0, 0): a
// note says so, once per material.
TEST(ObjTextures, TexturedFacesWithoutTextureCoordinatesAreNoted) {
    TexturedQuad quad("mtllib quad.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nusemtl paint\nf 1 4 3\nf 1 3 2\n");
    const Scene s = quad.load("newmtl paint\nKd 1 1 1\nmap_Kd paint.png\n");
    const auto noted = std::count_if(s.load_notes.begin(), s.load_notes.end(), [](const std::string& note) {
        return note.find("has no texture coordinates (vt) at some corner, but its material has textures") !=
               std::string::npos;
    });
    EXPECT_EQ(noted, 1) << "one note for the material's two faces";
    EXPECT_TRUE(TexturedQuad().load("newmtl paint\nKd 1 1 1\nmap_Kd paint.png\n").load_notes.empty());
}

// tinyobjloader reads -s and -o as three numbers; with two, the file name
// goes into the third and the map names no file: refused, not a material
// without its texture.
TEST(ObjTextures, MapWhoseOptionsTookItsFileNameIsRefused) {
    TexturedQuad quad;
    for (const char* map : {"map_Kd -s 2 2 paint.png", "map_Ke -o 0.5 0.5 paint.png", "norm -s 1 1 paint.png"}) {
        const std::string key = std::string(map).substr(0, std::string(map).find(' '));
        try {
            quad.load(std::string("newmtl paint\nKd 1 1 1\n") + map + "\n");
            ADD_FAILURE() << map << " loaded";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("quad.mtl: material 'paint'." + key +
                                                 ": names no texture file (its -s and -o options take three numbers"),
                      std::string::npos)
                << e.what();
        }
    }
}

// The numbers of -s and -o must be numbers: tinyobjloader read "nan" as
// the option's default and "inf" and "0,5" as 0, silently.
TEST(ObjTextures, MapOptionsThatAreNoNumbersAreRefused) {
    TexturedQuad quad;
    for (const char* map : {"map_Kd -s nan 1 1 paint.png", "map_Ke -o 0 inf 0 paint.png", "norm -s 0,5 1 1 paint.png"}) {
        const std::string key = std::string(map).substr(0, std::string(map).find(' '));
        try {
            quad.load(std::string("newmtl paint\nKd 1 1 1\n") + map + "\n");
            ADD_FAILURE() << map << " loaded";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("quad.mtl: line 3 (" + key + "): -"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("takes three numbers"), std::string::npos) << e.what();
        }
    }
}

// An MTL map_Kd without a Kd is the base colour itself, whatever came
// before it in the file (tinyobjloader gives it 0.6 where no Kd came
// before, and its default, black, where one did).
TEST(ObjTextures, MapKdWithoutKdIsTheTextureItself) {
    TexturedQuad quad;
    for (const char* mtl : {"newmtl paint\nmap_Kd paint.png\n",
                            "newmtl other\nKd 0.5 0.5 0.5\nnewmtl paint\nmap_Kd paint.png\n",
                            "newmtl paint\nmap_Kd paint.png\nKd 0.25 0.25 0.25\n"}) {
        const Scene s = quad.load(mtl);
        const gpu::Material& m = s.materials[s.triangles[0].material];
        const float expected = std::string(mtl).find("Kd 0.25") != std::string::npos ? 0.25f : 1.0f;
        EXPECT_EQ(glm::vec3(m.kd_r, m.kd_g, m.kd_b), glm::vec3(expected)) << mtl;
    }
}

// -s and -o scale and move an MTL map's texture coordinates, which OBJ
// counts from the bottom (v up): u' = s_u u + o_u, v' = s_v v + o_v there;
// -clamp on clamps both. The file is loaded once for both uses.
TEST(ObjTextures, ScaleOffsetAndClampOptionsApply) {
    TexturedQuad quad;
    const Scene s = quad.load("newmtl paint\nKd 1 1 1\nmap_Kd -clamp on -s 2 3 1 -o 0.25 0.5 0 paint.png\n"
                              "map_Ke paint.png\n");
    ASSERT_EQ(s.textures.size(), 2u);
    ASSERT_EQ(s.texels.size(), 2u);
    const gpu::Material& m = s.materials[s.triangles[0].material];
    const gpu::TextureInfo& kd = s.textures[m.base_color_texture];
    EXPECT_EQ(s.textures[m.emissive_texture].sampling, 0u);
    EXPECT_EQ(kd.sampling, gpu::kTextureWrapClamp | gpu::kTextureWrapClamp << gpu::kTextureWrapVShift |
                               gpu::kTextureTransformed);
    EXPECT_EQ(kd.offset, s.textures[m.emissive_texture].offset);
    // OBJ's (u, v) is the renderer's (u, 1 - v); the transform takes the
    // renderer's to the renderer's, (u', 1 - (s_v (1 - v) + o_v)).
    for (const glm::vec2 obj_uv : {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(0.3f, 0.8f)}) {
        const glm::vec2 uv(obj_uv.x, 1.0f - obj_uv.y);
        const float* t = kd.uv_transform;
        EXPECT_NEAR(t[0] * uv.x + t[1] * uv.y + t[2], 2.0f * obj_uv.x + 0.25f, 1e-6f);
        EXPECT_NEAR(t[3] * uv.x + t[4] * uv.y + t[5], 1.0f - (3.0f * obj_uv.y + 0.5f), 1e-6f);
    }
    try {
        quad.load("newmtl paint\nKd 1 1 1\nmap_Kd -s 1e39 1 1 paint.png\n");
        FAIL() << "a scale past the float range loaded";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("quad.mtl: line 3 (map_Kd): -s takes three numbers within float's "
                                             "range: '1e39' is not one"),
                  std::string::npos)
            << e.what();
    }
}

// JPEG as well as PNG: a uniform 8 x 8 JPEG decodes to (nearly) its colour.
TEST(ObjTextures, JpegTexturesLoad) {
    TempDir dir;
    const std::vector<std::uint8_t> bytes = rgba_bytes(std::vector<std::uint32_t>(64, rgba(200, 100, 50)));
    std::vector<std::uint8_t> rgb;
    for (std::size_t i = 0; i < bytes.size(); i += 4) rgb.insert(rgb.end(), {bytes[i], bytes[i + 1], bytes[i + 2]});
    ASSERT_NE(stbi_write_jpg((dir.path() / "paint.jpg").string().c_str(), 8, 8, 3, rgb.data(), 95), 0);
    dir.write("quad.mtl", "newmtl paint\nKd 1 1 1\nmap_Kd paint.jpg\n");
    dir.write("quad.obj", kTexturedObj);
    const Scene s = load_scene(dir.write("scene.json", quad_scene_json()));
    ASSERT_EQ(s.textures.size(), 1u);
    EXPECT_EQ(s.textures[0].width, 8u);
    ASSERT_EQ(s.texels.size(), 64u);
    const glm::vec4 c = unpack(s.texels[27]) * 255.0f;
    EXPECT_NEAR(c.x, 200.0f, 3.0f);
    EXPECT_NEAR(c.y, 100.0f, 3.0f);
    EXPECT_NEAR(c.z, 50.0f, 3.0f);
    EXPECT_EQ(c.w, 255.0f);
}

TEST(ObjTextures, MissingOrBrokenTextureNamesTheFiles) {
    TempDir dir;
    dir.write("quad.obj", kTexturedObj);
    dir.write("quad.mtl", "newmtl paint\nKd 1 1 1\nmap_Kd nowhere.png\n");
    const std::filesystem::path scene = dir.write("scene.json", quad_scene_json());
    const std::string obj = (dir.path() / "quad.obj").lexically_normal().string();
    try {
        load_scene(scene);
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), obj + ": material 'paint'.map_Kd: texture '" +
                                             (dir.path() / "nowhere.png").lexically_normal().string() + "' not found");
    }
    dir.write("garbage.png", "this is not an image");
    dir.write("quad.mtl", "newmtl paint\nKd 1 1 1\nnorm garbage.png\n");
    try {
        load_scene(scene);
        FAIL() << "no error";
    } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.rfind(obj + ": material 'paint'.norm: texture '", 0), 0u) << message;
        EXPECT_NE(message.find("garbage.png' is neither a PNG nor a JPEG file"), std::string::npos) << message;
    }
    dir.write("broken.jpg", "\xFF\xD8\xFF\xE0 then no JPEG");
    dir.write("quad.mtl", "newmtl paint\nKd 1 1 1\nmap_Kd broken.jpg\n");
    try {
        load_scene(scene);
        FAIL() << "no error";
    } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("broken.jpg' cannot be decoded as PNG or JPEG"), std::string::npos) << message;
    }
}

// A PNG chunk: its length, type, data and CRC-32 (big-endian).
std::string png_chunk(const std::string& type, const std::string& data, std::uint32_t length) {
    auto be32 = [](std::uint32_t v) {
        return std::string{char(v >> 24), char(v >> 16 & 0xFF), char(v >> 8 & 0xFF), char(v & 0xFF)};
    };
    std::uint32_t crc = 0xFFFFFFFFu;
    for (const char c : type + data) {
        crc ^= std::uint8_t(c);
        for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return be32(length) + type + data + be32(~crc);
}

// A PNG of a signature, an IHDR chunk declaring width x height RGBA8 and,
// before IEND, `middle`: no pixels, which is all a look at the size reads.
std::string png_header(std::uint32_t width, std::uint32_t height, const std::string& middle = "") {
    std::string ihdr;
    for (const std::uint32_t v : {width, height})
        ihdr += std::string{char(v >> 24), char(v >> 16 & 0xFF), char(v >> 8 & 0xFF), char(v & 0xFF)};
    ihdr += std::string{8, 6, 0, 0, 0};  // 8 bits, RGBA, deflate, no filter variant, not interlaced
    return std::string("\x89PNG\r\n\x1A\n", 8) + png_chunk("IHDR", ihdr, 13) + middle + png_chunk("IEND", "", 0);
}

// An image whose header declares more texels than textures may hold is
// refused from its header, before stb_image allocates its pixels (a 1 MB
// PNG of 16384 x 16384 zeros took 2 GB and 8.5 s to be refused after
// decoding); so is a PNG whose chunk claims more bytes than the file has
// (stb_image reserved them first). Through an MTL and through glTF.
TEST(TextureLimits, OversizedOrTruncatedImagesAreRefusedFromTheirHeaders) {
    const auto problem = [](const std::string& bytes) {
        return loader::encoded_image_problem(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
    };
    const std::string small = png_header(2, 2);
    EXPECT_EQ(problem(small), "");
    // A size stb_image does not say (over 2^24 a side), from the PNG's
    // header chunk.
    EXPECT_EQ(problem(png_header(100000, 100000)),
              "is 100000 x 100000 texels, more than the 134217728 that textures may hold in all");
    // Few texels, but a side longer than stb_image decodes (which it
    // reports only as "too large").
    EXPECT_EQ(problem(png_header(33554432, 1)),
              "is 33554432 x 1 texels, more than the 16777216 a side that the image decoder reads");
    // Cut between chunks (stb_image's reason named the last chunk type it
    // read, bytes of the file): the IHDR chunk and nothing after it.
    EXPECT_EQ(problem(small.substr(0, 8 + 25)),
              "is a corrupt or truncated PNG: it ends after 1 chunk without the IEND chunk that closes a PNG");

    TempDir dir;
    dir.write("big.png", png_header(16384, 16384));
    dir.write("cut.png", png_header(2, 2, png_chunk("IDAT", "x", 1u << 30)));
    dir.write("quad.obj", kTexturedObj);
    const std::filesystem::path scene = dir.write("scene.json", quad_scene_json());
    const std::string obj = (dir.path() / "quad.obj").lexically_normal().string();
    for (const char* image : {"big.png", "cut.png"}) {
        dir.write("quad.mtl", std::string("newmtl paint\nKd 1 1 1\nmap_Kd ") + image + "\n");
        try {
            load_scene(scene);
            FAIL() << "no error for " << image;
        } catch (const InputError& e) {
            const std::string message = e.what();
            EXPECT_EQ(message.rfind(obj + ": material 'paint'.map_Kd: texture '", 0), 0u) << message;
            EXPECT_NE(message.find(image == std::string("big.png")
                                       ? "big.png' is 16384 x 16384 texels, more than the 134217728 that "
                                         "textures may hold in all"
                                       : "cut.png' is a corrupt or truncated PNG: chunk 2 claims 1073741824 "
                                         "bytes of data, 1073741836 with its length, type and CRC, and 25 are "
                                         "left"),
                      std::string::npos)
                << message;
        }
    }
    const std::filesystem::path gltf =
        dir.write("big.gltf", R"({"asset": {"version": "2.0"}, "images": [{"uri": "big.png"}],
 "textures": [{"source": 0}], "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]})");
    try {
        load_scene(gltf);
        FAIL() << "no error for the glTF";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), gltf.lexically_normal().string() +
                                             ": tinygltf: images[0] ('big.png') is 16384 x 16384 texels, more than the "
                                             "134217728 that textures may hold in all");
    }
    // Each within the limit, the images the materials read past it
    // together: refused from the second one's header, before it is
    // decoded. A third image no material reads does not count.
    const std::vector<std::uint8_t> white = {255, 255, 255, 255};
    ASSERT_NE(stbi_write_png((dir.path() / "one.png").string().c_str(), 1, 1, 4, white.data(), 4), 0);
    dir.write("wide.png", png_header(16384, 8192));
    const std::filesystem::path two = dir.write("two.gltf", R"({"asset": {"version": "2.0"},
        "images": [{"uri": "wide.png"}, {"uri": "one.png"}, {"uri": "wide.png"}],
        "textures": [{"source": 0}, {"source": 1}, {"source": 2}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}, "normalTexture": {"index": 2}}]})");
    try {
        load_scene(two);
        FAIL() << "no error for the glTF";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), two.lexically_normal().string() +
                                             ": tinygltf: images[2] ('wide.png'): the images the materials read would "
                                             "hold more than 134217728 texels in all");
    }
}

// Textures are PNG or JPEG: stb_image's decoders of other formats (BMP,
// GIF, TGA, PSD, PIC, PNM, HDR) are not reached, whatever the file is
// called. An empty file is neither.
TEST(TextureLimits, OnlyPngAndJpegAreDecoded) {
    const auto problem = [](const std::string& bytes) {
        return loader::encoded_image_problem(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
    };
    const std::string neither = "is neither a PNG nor a JPEG file (textures must be one or the other)";
    EXPECT_EQ(problem(""), neither);
    for (const std::string& bytes : {std::string("BM\x46\0\0\0\0\0\0\0\x36\0\0\0", 14), std::string("GIF89a\x01\0\x01\0"),
                                     std::string("P6\n1 1\n255\nabc"), std::string("#?RADIANCE\n")})
        EXPECT_EQ(problem(bytes), neither) << bytes;
    EXPECT_EQ(problem(std::string("\xFF\xD8\xFF\xE0", 4)), "");  // a JPEG's start: decoding says the rest

    TempDir dir;
    // A real GIF (1x1), which stb_image would decode.
    dir.write("tex.gif", std::string("GIF89a\x01\0\x01\0\x80\0\0\xff\xff\xff\0\0\0,\0\0\0\0\x01\0\x01\0\0\x02\x02D\x01\0;", 35));
    dir.write("quad.obj", kTexturedObj);
    dir.write("quad.mtl", "newmtl paint\nKd 1 1 1\nmap_Kd tex.gif\n");
    const std::filesystem::path scene = dir.write("scene.json", quad_scene_json());
    try {
        load_scene(scene);
        FAIL() << "a GIF texture loaded";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("material 'paint'.map_Kd: texture '" +
                                             (dir.path() / "tex.gif").lexically_normal().string() + "' " + neither),
                  std::string::npos)
            << e.what();
    }
}

// Two triangles share an emissive material whose texture is white on its
// left half and black on its right; one triangle maps into each half. The
// samples all go to the white one, and carry its power.
TEST(TexturedAreaLights, SamplesFollowTheEmissiveTexture) {
    TextureScene t;
    const std::uint32_t tex = t.add(4, 1, {rgba(255, 255, 255), rgba(255, 255, 255), rgba(0, 0, 0), rgba(0, 0, 0)});
    gpu::Material m = loader::make_material(glm::vec3(0.0f), glm::vec3(0.0f), 1.0f);
    loader::set_emission(m, {2.0f, 2.0f, 2.0f}, false);
    loader::set_texture(m, &gpu::Material::emissive_texture, tex);
    t.scene.materials = {m};
    test::add_triangle(t.scene, {0, 1, 0}, {1, 1, 0}, {0, 1, 1}, 0);  // area 0.5
    test::add_triangle(t.scene, {2, 1, 0}, {3, 1, 0}, {2, 1, 1}, 0);
    // Texel centres of the white half are u = 0.125 and 0.375: a triangle
    // between them sees white only.
    t.scene.uvs = {{0.13f, 0.5f, 0.37f, 0.5f, 0.13f, 0.6f}, {0.63f, 0.5f, 0.87f, 0.5f, 0.63f, 0.6f}};
    const TriangleEmission emission(t.scene);
    EXPECT_NEAR(emission.mean(0).x, 2.0f, 1e-5f);
    EXPECT_EQ(emission.mean(1).x, 0.0f);
    EXPECT_GT(emission.power(0), 0.0);
    EXPECT_EQ(emission.power(1), 0.0);
    const auto lights = sample_area_lights(t.scene, 1000, 7);
    ASSERT_EQ(lights.size(), 1000u);
    double total = 0.0;
    for (const gpu::Light& l : lights) {
        EXPECT_LT(l.x, 1.5f);
        total += l.r;
    }
    EXPECT_NEAR(total, 2.0 * 0.5, 1e-4);  // Le * area
}

// An emissive texture black but for one texel that none of the 256 points
// of TriangleEmission::mean falls near: the triangle still gets samples,
// and over seeds they carry its emission (before, it had no power, got no
// samples, and the scene was dark without a word).
TEST(TexturedAreaLights, SmallBrightFeaturesStillGetSamples) {
    TextureScene t;
    std::vector<std::uint32_t> texels(64 * 64, rgba(0, 0, 0));
    texels[30 * 64 + 30] = rgba(255, 255, 255);
    const std::uint32_t tex = t.add(64, 64, texels);
    gpu::Material m = loader::make_material(glm::vec3(0.0f), glm::vec3(0.0f), 1.0f);
    loader::set_emission(m, {1000.0f, 1000.0f, 1000.0f}, false);
    loader::set_texture(m, &gpu::Material::emissive_texture, tex);
    t.scene.materials = {m};
    test::add_triangle(t.scene, {0, 1, 0}, {1, 1, 0}, {0, 1, 1}, 0);  // area 0.5
    t.scene.uvs = {{0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 1.0f}};
    const TriangleEmission emission(t.scene);
    ASSERT_EQ(emission.mean(0).x, 0.0f);  // the points all miss the texel
    EXPECT_GT(emission.power(0), 0.0);
    // The emission over the triangle, A times the mean of a fine grid of points.
    const std::uint32_t fine = 1u << 20;
    double integral = 0.0;
    for (std::uint32_t k = 0; k < fine; ++k) {
        const glm::vec2 b = triangle_sample_barycentrics(k, fine, 0.0f, 0.5f / float(fine));
        integral += emission.at(0, b.x, b.y).x;
    }
    integral *= 0.5 / fine;
    double total = 0.0;
    const int seeds = 400;
    for (int seed = 1; seed <= seeds; ++seed) {
        const auto lights = sample_area_lights(t.scene, 1000, std::uint32_t(seed));
        ASSERT_EQ(lights.size(), 1000u);
        for (const gpu::Light& l : lights) total += l.r;
    }
    std::printf("[ measured ] one bright texel: samples' intensity %.5f over %d seeds, the emission's integral %.5f\n",
                total / seeds, seeds, integral);
    // About 2 of each seed's 1000 samples land where the texel shines, so
    // the mean over 400 seeds has a relative spread of about 3%.
    EXPECT_NEAR(total / seeds, integral, 0.1 * integral);
}

// A quad under a texture black but for one texel: the triangle whose
// points only graze the texel (a mean far below the texel's share) still
// gets at least the floor, as its neighbour with no bright texel under it
// gets nothing. Before, the floor applied only to a mean of exactly 0: the
// half that emits got about 0.4% of the samples and the half that does
// not the rest (the audit: a lamp from 0 to 3 times too bright over seeds,
// black at 16384 samples for 7 of 8 seeds).
TEST(TexturedAreaLights, AGrazedBrightTexelGetsTheFloor) {
    // The audit's lamp: a unit quad of MTL map_Ke, a 64 x 64 texture black
    // but for the texel at column 21, row 40.
    test::TempDir dir;
    std::vector<std::uint32_t> texels(64 * 64, rgba(0, 0, 0));
    texels[40 * 64 + 21] = rgba(255, 255, 255);
    write_png(dir.path() / "dot.png", 64, 64, texels);
    dir.write("lamp.mtl", "newmtl e\nKd 0 0 0\nKe 1 1 1\nmap_Ke dot.png\n");
    dir.write("lamp.obj", "mtllib lamp.mtl\nv -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\n"
                          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl e\nf 1/1 2/2 3/3 4/4\n");
    const Scene s = load_scene(dir.write("lamp.json", R"({"camera": {"position": [0, 3, 4], "look_at": [0, 0.3, 0]},
        "meshes": [{"obj": "lamp.obj"}]})"));
    ASSERT_EQ(s.triangles.size(), 2u);
    const TriangleEmission emission(s);
    std::printf("[ measured ] means %.3g and %.3g, powers %.3g and %.3g\n", double(emission.mean(0).x),
                double(emission.mean(1).x), emission.power(0), emission.power(1));
    // One triangle's points graze the texel, the other's find nothing:
    // both take the floor (their uv boxes both cover the texel).
    EXPECT_GT(std::max(emission.mean(0).x, emission.mean(1).x), 0.0f);
    EXPECT_EQ(std::min(emission.mean(0).x, emission.mean(1).x), 0.0f);
    EXPECT_EQ(emission.power(0), emission.power(1));
    double integral = 0.0;
    const std::uint32_t fine = 1u << 20;
    for (std::uint32_t i = 0; i < 2; ++i)
        for (std::uint32_t k = 0; k < fine; ++k) {
            const glm::vec2 b = triangle_sample_barycentrics(k, fine, 0.0f, 0.5f / float(fine));
            integral += emission.at(i, b.x, b.y).x * (0.5 / fine);
        }
    // About 4096 / 2 / 4096 of a seed's samples land where the texel
    // shines: 2 a seed, so the mean over 200 seeds spreads by about 5%.
    double total = 0.0;
    const int seeds = 200;
    for (int seed = 1; seed <= seeds; ++seed)
        for (const gpu::Light& l : sample_area_lights(s, 4096, std::uint32_t(seed))) total += l.r;
    std::printf("[ measured ] samples' intensity %.6f over %d seeds, the emission's integral %.6f\n",
                total / seeds, seeds, integral);
    EXPECT_NEAR(total / seeds, integral, 0.15 * integral);
}

// The floor above reads the texels the lookups read: through a uv
// transform, and wrapped as the texture's sampler wraps.
TEST(TexturedAreaLights, SmallBrightFeaturesAreFoundThroughTheSampler) {
    std::vector<std::uint32_t> texels(64 * 64, rgba(0, 0, 0));
    texels[30 * 64 + 30] = rgba(255, 255, 255);  // at uv (0.477, 0.477)
    texels[50 * 64 + 0] = rgba(255, 255, 255);   // on the left edge, at v = 0.789
    // The power (and the mean, where asked) of one triangle emitting a
    // w x h texture sampled as `sampling` at `uvs`.
    const auto emitted = [](std::uint32_t w, std::uint32_t h, const std::vector<std::uint32_t>& image,
                            const loader::TextureSampling& sampling, const gpu::TriangleUvs& uvs, float* mean) {
        TextureScene t;
        const std::uint32_t tex = loader::sampled_texture(t.scene, t.add(w, h, image), sampling);
        gpu::Material m = loader::make_material(glm::vec3(0.0f), glm::vec3(0.0f), 1.0f);
        loader::set_emission(m, {1000.0f, 1000.0f, 1000.0f}, false);
        loader::set_texture(m, &gpu::Material::emissive_texture, tex);
        t.scene.materials = {m};
        test::add_triangle(t.scene, {0, 1, 0}, {1, 1, 0}, {0, 1, 1}, 0);
        t.scene.uvs = {uvs};
        const TriangleEmission emission(t.scene);
        if (mean) *mean = emission.mean(0).x;
        return emission.power(0);
    };
    const auto power = [&](const loader::TextureSampling& sampling, const gpu::TriangleUvs& uvs, float* mean) {
        return emitted(64, 64, texels, sampling, uvs, mean);
    };
    // The corner of the texture up to 0.2 holds no bright texel; scaled by
    // 5 it covers the whole texture, and its points are the previous
    // test's, which all miss the texel at (30, 30).
    const gpu::TriangleUvs corner{0.0f, 0.0f, 0.2f, 0.0f, 0.0f, 0.2f};
    EXPECT_EQ(power({}, corner, nullptr), 0.0);
    loader::TextureSampling scaled;
    scaled.uv_transform = {5.0f, 0.0f, 0.0f, 0.0f, 5.0f, 0.0f};
    float mean = -1.0f;
    EXPECT_GT(power(scaled, corner, &mean), 0.0);
    EXPECT_EQ(mean, 0.0f);
    // Left of the texture at u in [-1.6, -1.5]: repeated (and mirrored) that
    // is u in [0.4, 0.5], black; clamped it is the left column, which is
    // white at v = 0.789.
    const gpu::TriangleUvs left{-1.6f, 0.78f, -1.5f, 0.78f, -1.6f, 0.8f};
    EXPECT_EQ(power({}, left, nullptr), 0.0);
    loader::TextureSampling mirror, clamp;
    mirror.wrap_u = gpu::kTextureWrapMirror;
    clamp.wrap_u = gpu::kTextureWrapClamp;
    EXPECT_EQ(power(mirror, left, nullptr), 0.0);
    EXPECT_GT(power(clamp, left, nullptr), 0.0);
    // A clamped uv box wider than the texture reads up to its far edge: a
    // 1024 x 1 texture black but for its last texel, under a triangle
    // from u = -1 to 1 whose points all miss it (the range was counted
    // one period from its start, every texel of which clamped to the
    // first).
    std::vector<std::uint32_t> row(1024, rgba(0, 0, 0));
    row.back() = rgba(255, 255, 255);
    float wide_mean = -1.0f;
    EXPECT_GT(emitted(1024, 1, row, clamp, {-1.0f, 0.5f, -1.0f, 0.5f, 1.0f, 0.5f}, &wide_mean), 0.0);
    EXPECT_EQ(wide_mean, 0.0f);
}

// A 2 x 2 plane at y = 0 whose material (kd 0.5) has `texture` as its base
// colour, u along x and v along z from 0 to 1, lit straight down by a
// directional light of 3, and a camera straight above whose size x size
// image spans the plane (tan(fov / 2) = 1 / 4), +x to the right, -z up.
void make_textured_plane(Scene& s, std::uint32_t texture, std::uint32_t size) {
    gpu::Material m = loader::make_material(glm::vec3(0.5f), glm::vec3(0.0f), 1.0f);
    loader::set_texture(m, &gpu::Material::base_color_texture, texture);
    s.materials = {m};
    test::add_quad(s, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 0);
    s.uvs = {{0, 0, 0, 1, 1, 1}, {0, 0, 1, 1, 1, 0}};
    s.lights = {test::directional_light({0, -1, 0}, glm::vec3(3.0f))};
    s.camera = test::camera({0, 4, 0}, {0, 0, 0}, float(2.0 * std::atan(0.25) * 180.0 / 3.14159265358979), size, size);
    s.camera.up = {0, 0, -1};
}

// Texture coordinates near 1e6 (a float step of 0.0625 there) render as
// those near 0: prepare_scene moves each triangle's by whole periods where
// its textures repeat (before, relative RMSE 0.36 against the same quad at
// 0). Where a texture clamps, nothing moves: clamped, u = 1e6 is u = 1.
TEST(TexturedRender, FarTextureCoordinatesKeepTheirDetail) {
    const auto render = [](float shift, bool clamp, bool u_past_one = false) {
        Scene s;
        std::vector<std::uint32_t> texels(64 * 64);
        for (std::size_t i = 0; i < texels.size(); ++i) texels[i] = rgba(std::uint32_t(i * 37 % 256), 128, 255);
        const std::uint32_t image = loader::add_texture(s, 64, 64, rgba_bytes(texels).data(), "test", "texture");
        loader::TextureSampling sampling;
        if (clamp) sampling.wrap_u = gpu::kTextureWrapClamp;
        make_textured_plane(s, loader::sampled_texture(s, image, sampling), 32);
        for (gpu::TriangleUvs& uv : s.uvs) {
            for (float* c : {&uv.u0, &uv.u1, &uv.u2, &uv.v0, &uv.v1, &uv.v2}) *c += shift;
            // Past 1 by up to a period, the same area in texture space
            // (and so the same mipmap levels).
            if (u_past_one) uv.u0 += 1.0f, uv.u1 += 1.0f, uv.u2 += 1.0f;
        }
        update_bounds(s);
        return render_cpu(prepare_scene(std::move(s), 1), test::options("brute", 32)).image;
    };
    const Image near = render(0.0f, false);
    for (const float shift : {999998.0f, -1e7f}) {  // the corners 0 and 1 still apart
        const Image far = render(shift, false);
        ASSERT_EQ(far.rgb.size(), near.rgb.size());
        for (std::size_t i = 0; i < near.rgb.size(); ++i)
            ASSERT_EQ(far.rgb[i], near.rgb[i]) << "pixel " << i / 3 << " with the coordinates moved by " << shift;
    }
    // Clamped in u, the far quad reads the texture's last column (u = 1)
    // everywhere, and v, which repeats, as near the origin: as the near
    // quad does with u from 1 to 2.
    const Image clamped = render(999998.0f, true);
    EXPECT_NE(clamped.rgb, near.rgb);
    EXPECT_EQ(clamped.rgb, render(0.0f, true, true).rgb);
}

// A plane seen from straight above, lit by a directional light along -y,
// with a base-colour texture of 2 x 2 blocks (white, black / black, white)
// of 4 x 4 texels each: away from the block edges bilinear filtering sees
// one colour, so the radiance is exactly albedo * E / pi or zero.
TEST(TexturedRender, PlaneShowsItsTextureOnBothHalves) {
    Scene s;
    std::vector<std::uint32_t> texels(64);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) texels[std::size_t(8 * y + x)] = (x < 4) == (y < 4) ? rgba(255, 255, 255) : rgba(0, 0, 0);
    make_textured_plane(s, loader::add_texture(s, 8, 8, rgba_bytes(texels).data(), "test", "texture"), 16);
    update_bounds(s);
    PreparedScene p = prepare_scene(std::move(s), 1);
    ASSERT_TRUE(p.has_textures);
    const RenderResult r = render_cpu(p, test::options("brute", 16));
    const float lit = 0.5f * 3.0f / 3.14159265f;
    int white = 0, black = 0;
    for (std::uint32_t y = 0; y < 16; ++y)
        for (std::uint32_t x = 0; x < 16; ++x) {
            // Which block this pixel's hit lies in, from the image: the
            // camera looks down -y with +x to the right and -z up.
            const float px = (float(x) + 0.5f) / 8.0f - 1.0f, pz = (float(y) + 0.5f) / 8.0f - 1.0f;
            // Within half a texel (0.125) of a block edge the filter blends,
            // also across the wrap at the plane's border.
            const float inner = std::min(std::abs(px), std::abs(pz)), outer = std::max(std::abs(px), std::abs(pz));
            if (inner < 0.2f || outer > 0.8f) continue;
            const float value = r.image.at(x, y).x;
            const bool expect_white = (px < 0.0f) == (pz < 0.0f);
            EXPECT_NEAR(value, expect_white ? lit : 0.0f, 1e-5f * lit) << x << "," << y;
            (expect_white ? white : black) += 1;
        }
    EXPECT_GT(white, 10);
    EXPECT_GT(black, 10);
}

// A plane seen from above with a one-texel checker of black and white,
// 15.6 texels to a pixel: with mipmaps every pixel is the checker's mean
// (linear 0.5, stored as sRGB 188: 0.5029); read at full resolution, one
// bilinear lookup a pixel, the pixels alias between black and white.
TEST(TexturedRender, DistantCheckerIsItsMeanWithMipmaps) {
    const auto render = [](bool mipmaps) {
        Scene s;
        constexpr std::uint32_t kSize = 250;
        std::vector<std::uint32_t> texels(kSize * kSize);
        for (std::uint32_t i = 0; i < texels.size(); ++i)
            texels[i] = (i % kSize + i / kSize) % 2 == 0 ? rgba(255, 255, 255) : rgba(0, 0, 0);
        const std::uint32_t image = loader::add_texture(s, kSize, kSize, rgba_bytes(texels).data(), "test", "texture");
        loader::TextureSampling sampling;
        sampling.mipmaps = mipmaps;
        make_textured_plane(s, loader::sampled_texture(s, image, sampling), 16);
        update_bounds(s);
        return render_cpu(prepare_scene(std::move(s), 1), test::options("brute", 16)).image;
    };
    const float mean = 0.5f * 3.0f / 3.14159265f * float(srgb_to_linear(188.0 / 255.0));
    const auto spread = [&](const Image& image) {
        float lo = INFINITY, hi = -INFINITY;
        for (std::uint32_t y = 0; y < 16; ++y)
            for (std::uint32_t x = 0; x < 16; ++x) {
                lo = std::min(lo, image.at(x, y).x);
                hi = std::max(hi, image.at(x, y).x);
            }
        return std::pair(lo, hi);
    };
    const auto [lo, hi] = spread(render(true));
    EXPECT_NEAR(lo, mean, 1e-5f * mean);
    EXPECT_NEAR(hi, mean, 1e-5f * mean);
    const auto [alias_lo, alias_hi] = spread(render(false));
    EXPECT_GT(alias_hi - alias_lo, mean) << "without mipmaps, the pixels alias";
}

// A single plane lets the Vulkan kernels leave shadow rays out
// (PreparedScene::has_occluders false), unless a normal map or its vertex
// normals bend its shading normals: then a light behind it can pass the
// cosine, and only the plane's shadow ray blocks it (tests/vulkan: tilted
// normals rendered).
TEST(NormalMap, PlaneWithBentNormalsCanShadow) {
    enum class Bent { no, mapped, tilted };
    for (const Bent bent : {Bent::no, Bent::mapped, Bent::tilted}) {
        Scene s;
        gpu::Material m = loader::make_material(glm::vec3(0.5f), glm::vec3(0.0f), 1.0f);
        if (bent == Bent::mapped)
            loader::set_texture(m, &gpu::Material::normal_texture,
                                loader::add_texture(s, 2, 2, rgba_bytes(kTwoByTwo).data(), "test", "texture"));
        s.materials = {m};
        test::add_quad(s, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 0);
        if (bent == Bent::tilted) s.normals[1].n2_x = 0.1f;
        s.uvs = {{0, 0, 0, 1, 1, 1}, {0, 0, 1, 1, 1, 0}};
        s.lights = {test::directional_light({0, -1, 0}, glm::vec3(3.0f))};
        s.camera = test::camera({0, 4, 0}, {0, 0, 0}, 40.0f, 8, 8);
        s.camera.up = {0, 0, -1};
        update_bounds(s);
        EXPECT_EQ(prepare_scene(std::move(s), 1).has_occluders, bent != Bent::no) << int(bent);
    }
}

// The cone's angle is a pixel's, over the rows or columns of its grid of
// samples, whichever are fewer (lc_pixel_sample: 16 samples in 4 x 4, 6
// in 3 x 2, 2 in columns of the pixel's height).
TEST(Mipmaps, PixelSpreadFollowsTheFieldOfViewAndTheSamples) {
    Scene s;
    s.materials = {loader::make_material(glm::vec3(0.5f), glm::vec3(0.0f), 1.0f)};
    test::add_quad(s, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 0);
    s.lights = {test::directional_light({0, -1, 0}, glm::vec3(3.0f))};
    s.camera = test::camera({0, 4, 0}, {0, 0, 0}, 90.0f, 64, 32);
    s.camera.up = {0, 0, -1};
    update_bounds(s);
    const PreparedScene p = prepare_scene(std::move(s), 1);
    RenderOptions o = test::options("brute", 0);
    EXPECT_FLOAT_EQ(make_frame_params(p, o).pixel_spread, 2.0f / 32.0f);
    for (const auto& [spp, side] : {std::pair(16u, 4.0f), std::pair(6u, 2.0f), std::pair(2u, 1.0f)}) {
        o.spp = spp;
        EXPECT_FLOAT_EQ(make_frame_params(p, o).pixel_spread, 2.0f / 32.0f / side) << spp;
    }
}

}  // namespace
}  // namespace lc
