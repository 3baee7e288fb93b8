// glTF 2.0 import (host/scene/gltf_*.cpp): one small file per feature and per
// kind of malformed input (tests/data/gltf, written by make_cases.py), and
// the shipped room as glTF against the same room as JSON + OBJ.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>

#include <sys/stat.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cpu_kernel.h"
#include "gltf_room.h"
#include "lightcuts/error.h"
#include "lightcuts/render.h"
#include "lightcuts/scene.h"
#include "test_util.h"

namespace lc {
namespace {

using test::normal;
using test::vertex;
using test::winding_normal;

namespace fs = std::filesystem;

const fs::path kData = fs::path(LC_TEST_DATA_DIR) / "gltf";

Scene load(const std::string& name, const std::string& camera = "") {
    SceneOptions options;
    options.camera = camera;
    return load_scene(kData / name, options);
}

// A test file's glTF JSON, to edit and write elsewhere.
nlohmann::json json_of(const std::string& name) {
    std::ifstream in(kData / name, std::ios::binary);
    return nlohmann::json::parse(in);
}

// The InputError message of loading `name`; fails the test when it loads.
std::string error_of(const std::string& name, const std::string& camera = "") {
    try {
        load(name, camera);
    } catch (const InputError& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << name << ": expected lc::InputError, got: " << e.what();
        return "";
    }
    ADD_FAILURE() << name << ": loaded, expected lc::InputError";
    return "";
}

bool has_note(const Scene& s, const std::string& part) {
    return std::any_of(s.load_notes.begin(), s.load_notes.end(),
                       [&](const std::string& line) { return line.find(part) != std::string::npos; });
}

void expect_near(glm::vec3 a, glm::vec3 b, float tolerance, const std::string& what) {
    EXPECT_LE(glm::length(a - b), tolerance) << what << ": (" << a.x << ", " << a.y << ", " << a.z << ") vs ("
                                             << b.x << ", " << b.y << ", " << b.z << ")";
}

glm::vec3 position(const gpu::Light& l) { return {l.x, l.y, l.z}; }
glm::vec3 value(const gpu::Light& l) { return {l.r, l.g, l.b}; }

TEST(Gltf, OneTriangleGetsItsFaceNormalTheDefaultMaterialAndADefaultFraming) {
    const Scene s = load("triangle.gltf");
    ASSERT_EQ(s.triangles.size(), 1u);
    for (int k = 0; k < 3; ++k) expect_near(normal(s.normals[0], k), {0, 0, 1}, 1e-7f, "face normal");
    ASSERT_EQ(s.uvs.size(), 1u);
    EXPECT_EQ(s.uvs[0].u1, 0.0f);
    // glTF's default material: white, metallic 1, roughness 1.
    ASSERT_EQ(s.materials.size(), 1u);
    const gpu::Material& m = s.materials[0];
    EXPECT_NE(m.flags & gpu::kMaterialDisney, 0u);
    EXPECT_EQ(glm::vec3(m.kd_r, m.kd_g, m.kd_b), glm::vec3(1.0f));
    EXPECT_EQ(m.metallic, 1.0f);
    EXPECT_EQ(m.roughness, 1.0f);
    EXPECT_EQ(m.flags & (gpu::kMaterialTextured | gpu::kMaterialEmissive), 0u);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, gpu::kLightPoint);
    expect_near(position(s.lights[0]), {0.2f, 0.2f, 1.0f}, 1e-7f, "light");
    expect_near(value(s.lights[0]), glm::vec3(2.0f), 0.0f, "intensity");
    // No camera: along -Z at the bounding sphere (centre (0.5, 0.5, 0),
    // radius sqrt(2)/2) from r / sin(20 degrees).
    const float distance = std::sqrt(0.5f) / std::sin(glm::radians(20.0f));
    expect_near(s.camera.position, {0.5f, 0.5f, distance}, 1e-5f, "camera");
    expect_near(s.camera.look_at, {0.5f, 0.5f, 0.0f}, 1e-6f, "look_at");
    EXPECT_EQ(s.camera.fov_y_degrees, 40.0f);
    EXPECT_TRUE(has_note(s, "no perspective camera"));
    EXPECT_EQ(s.render.method, "lightcuts");
}

TEST(Gltf, BinaryGlbLoadsTheSameSceneAsItsGltf) {
    const Scene a = load("triangle.gltf"), b = load("triangle.glb");
    ASSERT_EQ(b.triangles.size(), a.triangles.size());
    for (int k = 0; k < 3; ++k) EXPECT_EQ(vertex(b.triangles[0], k), vertex(a.triangles[0], k));
    ASSERT_EQ(b.lights.size(), 1u);
    EXPECT_EQ(position(b.lights[0]), position(a.lights[0]));
}

TEST(Gltf, AccessorsOfEveryIndexTypeStrideNormalizedUvsAndSparse) {
    const Scene s = load("accessors.gltf");
    // u8 indices: two triangles, u16 one, u32 one, the sparse primitive two.
    ASSERT_EQ(s.triangles.size(), 6u);
    expect_near(vertex(s.triangles[0], 2), {1, 1, 0}, 0.0f, "u8");
    expect_near(vertex(s.triangles[1], 2), {0, 1, 0}, 0.0f, "u8");
    expect_near(vertex(s.triangles[2], 1), {1, 0, 0}, 0.0f, "u16");
    expect_near(vertex(s.triangles[3], 1), {1, 1, 0}, 0.0f, "u32");
    // The interleaved normals (byteStride 24, byteOffset 12).
    for (int k = 0; k < 3; ++k) expect_near(normal(s.normals[0], k), {0, 0, 1}, 0.0f, "normal");
    // Normalized UNSIGNED_SHORT: 65535 -> 1, 32768 -> 32768 / 65535.
    EXPECT_EQ(s.uvs[0].u2, 1.0f);
    EXPECT_EQ(s.uvs[0].v2, 1.0f);
    EXPECT_FLOAT_EQ(s.uvs[1].v2, 32768.0f / 65535.0f);
    // Sparse: vertex 2 moved to z = 0.5, the others from the bufferView.
    expect_near(vertex(s.triangles[4], 2), {1, 1, 0.5f}, 0.0f, "sparse");
    expect_near(vertex(s.triangles[4], 1), {1, 0, 0}, 0.0f, "sparse base");
}

TEST(Gltf, NodeTransformsMultiplyDownTheHierarchyAndNormalsUseTheInverseTranspose) {
    const Scene s = load("hierarchy.gltf");
    // The node outside the scene is not drawn.
    ASSERT_EQ(s.triangles.size(), 2u);
    // Child: scale x by 3, up by 1; parent: scale 2, 90 degrees about y, x + 10.
    expect_near(vertex(s.triangles[0], 0), {10, 2, 0}, 1e-5f, "v0");
    expect_near(vertex(s.triangles[0], 1), {10, 2, -6}, 1e-5f, "v1");
    expect_near(vertex(s.triangles[0], 2), {10, 4, 0}, 1e-5f, "v2");
    for (int k = 0; k < 3; ++k) expect_near(normal(s.normals[0], k), {1, 0, 0}, 1e-6f, "rotated normal");
    // Mirrored in x: the vertex normal (0, 0, 1) stays, and so does the side
    // the winding faces (the side an emissive triangle emits from), the
    // last two corners swapped: the file's (1, 0, 0) is the second.
    expect_near(vertex(s.triangles[1], 2), {-1, 0, 0}, 0.0f, "mirrored");
    for (int k = 0; k < 3; ++k) expect_near(normal(s.normals[1], k), {0, 0, 1}, 1e-6f, "mirrored normal");
    expect_near(winding_normal(s.triangles[1]), {0, 0, 1}, 1e-6f, "mirrored winding");
}

TEST(Gltf, StripsAndFansAreTriangulatedPointsAndLinesSkippedWithANote) {
    const Scene s = load("modes.gltf");
    // Five vertices: a strip of 3 triangles and a fan of 3.
    ASSERT_EQ(s.triangles.size(), 6u);
    // The strip keeps one winding: every face normal is -z.
    for (int t = 0; t < 3; ++t) expect_near(normal(s.normals[std::size_t(t)], 0), {0, 0, -1}, 1e-6f, "strip");
    expect_near(vertex(s.triangles[1], 1), {1, 1, 0}, 0.0f, "strip triangle 1 is (v1, v3, v2)");
    expect_near(vertex(s.triangles[3], 2), {0, 0, 0}, 0.0f, "fan triangles end at v0");
    EXPECT_TRUE(has_note(s, "primitives[2].mode: POINTS is not drawn"));
    EXPECT_TRUE(has_note(s, "primitives[3].mode: LINES is not drawn"));
}

// The Disney sheen colour of a material before metallic's share takes its
// part: what glTF's sheenColorFactor describes.
glm::vec3 sheen_colour(const gpu::Material& m) {
    cpu::ShadeKernel kernel{};
    return m.sheen * glm::mix(glm::vec3(1.0f), kernel.lc_disney_tint(m), m.sheen_tint);
}

void expect_near3(glm::vec3 got, glm::vec3 want) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-6f * std::max(1.0f, want[c])) << "channel " << c;
}

TEST(Gltf, MetallicRoughnessAndExtensionsBecomeDisneyParameters) {
    const Scene s = load("materials.gltf");
    ASSERT_EQ(s.triangles.size(), 3u);
    ASSERT_EQ(s.materials.size(), 3u);
    const gpu::Material& m = s.materials[s.triangles[0].material];
    EXPECT_NE(m.flags & gpu::kMaterialDisney, 0u);
    EXPECT_EQ(glm::vec3(m.kd_r, m.kd_g, m.kd_b), glm::vec3(0.5f, 0.25f, 0.125f));
    EXPECT_EQ(m.metallic, 0.75f);
    EXPECT_FLOAT_EQ(m.roughness, 0.4f);
    EXPECT_FLOAT_EQ(m.alpha, 0.16f);
    EXPECT_EQ(m.specular, 0.5f);
    EXPECT_FLOAT_EQ(m.clearcoat, 0.6f);
    EXPECT_FLOAT_EQ(m.clearcoat_gloss, 0.8f);
    EXPECT_NE(m.flags & gpu::kMaterialHasClearcoat, 0u);
    // A sheen colour of the base colour's hue: fully tinted, and the colour
    // the BRDF uses (before metallic's share) is the glTF one.
    EXPECT_FLOAT_EQ(m.sheen_tint, 1.0f);
    expect_near3(sheen_colour(m), glm::vec3(0.5f, 0.25f, 0.125f));
    // emissiveFactor x emissiveStrength 8, both sides (doubleSided).
    EXPECT_EQ(glm::vec3(m.emission_r, m.emission_g, m.emission_b), glm::vec3(8.0f, 4.0f, 2.0f));
    EXPECT_NE(m.flags & gpu::kMaterialEmitsBothSides, 0u);

    const gpu::Material& noted = s.materials[s.triangles[1].material];
    // Grey sheen on a white base: no tint.
    EXPECT_EQ(noted.sheen, 0.5f);
    EXPECT_EQ(noted.sheen_tint, 0.0f);
    expect_near3(sheen_colour(noted), glm::vec3(0.5f));
    EXPECT_EQ(noted.base_color_texture, gpu::kInvalidIndex);  // TEXCOORD_1: left out
    EXPECT_EQ(noted.flags & gpu::kMaterialEmissive, 0u);
    for (const char* note : {"texCoord: uses TEXCOORD_1", "alphaMode: BLEND", "occlusionTexture",
                             "samplers[1].minFilter: is 9984: minified lookups are trilinear",
                             "samplers[0].minFilter: is linear but magFilter nearest"})
        EXPECT_TRUE(has_note(s, note)) << note;
    EXPECT_FALSE(has_note(s, "KHR_texture_transform"));
    // The primitive without a material: the default one.
    EXPECT_EQ(s.materials[s.triangles[2].material].metallic, 1.0f);
}

// The kernel tints sheen by the base colour over its luminance, which is
// brighter than the base's largest component: a blue sheen on a blue base
// came out 13.9 times too bright when the fit took the tint as the base
// over its largest component. Sheens of the base's hue and grey ones come
// out exactly; one between them keeps its largest component and lies
// between the two in every channel.
TEST(Gltf, SheenColourIsTheFilesWhereDisneysSheenCanTakeIt) {
    test::TempDir dir;
    const nlohmann::json doc = json_of("materials.gltf");
    struct Case {
        glm::vec3 base, sheen;
    };
    for (const Case& c : {Case{{0.0f, 0.0f, 1.0f}, {0.0f, 0.0f, 1.0f}}, Case{{1.0f, 0.05f, 0.05f}, {1.0f, 0.05f, 0.05f}},
                          Case{{1.0f, 0.05f, 0.05f}, {0.3f, 0.3f, 0.3f}}, Case{{0.2f, 0.6f, 0.1f}, {0.1f, 0.3f, 0.05f}},
                          Case{{0.0f, 0.0f, 0.0f}, {0.2f, 0.4f, 0.8f}}}) {
        nlohmann::json edited = doc;
        nlohmann::json& material = edited["materials"][0];
        material["pbrMetallicRoughness"]["baseColorFactor"] = {c.base.r, c.base.g, c.base.b, 1.0};
        material["extensions"]["KHR_materials_sheen"]["sheenColorFactor"] = {c.sheen.r, c.sheen.g, c.sheen.b};
        const Scene s = load_scene(dir.write("sheen.gltf", edited.dump()));
        const gpu::Material& m = s.materials[s.triangles[0].material];
        SCOPED_TRACE(testing::Message() << "base " << c.base.r << " " << c.base.g << " " << c.base.b);
        EXPECT_GE(m.sheen, 0.0f);
        EXPECT_LE(m.sheen, 1.0f);
        // A black base has a white tint: the sheen's grey nearest the file's.
        if (c.base == glm::vec3(0.0f)) {
            expect_near3(sheen_colour(m), glm::vec3(0.8f));
        } else {
            expect_near3(sheen_colour(m), c.sheen);
        }
    }
    // Between grey and the base's hue: the largest component is the file's,
    // the colour partly tinted.
    nlohmann::json edited = doc;
    edited["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {0.0, 0.0, 1.0, 1.0};
    edited["materials"][0]["extensions"]["KHR_materials_sheen"]["sheenColorFactor"] = {0.5, 0.5, 1.0};
    const Scene s = load_scene(dir.write("between.gltf", edited.dump()));
    const gpu::Material& m = s.materials[s.triangles[0].material];
    EXPECT_GT(m.sheen_tint, 0.0f);
    EXPECT_LT(m.sheen_tint, 1.0f);
    const glm::vec3 got = sheen_colour(m);
    EXPECT_NEAR(got.b, 1.0f, 1e-6f);
    EXPECT_NEAR(got.r, 0.5f, 1e-6f);  // the least-squares fit of (0.5, 0.5, 1) on mix(white, blue, u)
    EXPECT_NEAR(got.g, 0.5f, 1e-6f);
}

TEST(Gltf, TexturesAreAddedOncePerImageWithTheirTexelsAndUvs) {
    const Scene s = load("materials.gltf");
    const gpu::Material& m = s.materials[s.triangles[0].material];
    const gpu::Material& noted = s.materials[s.triangles[1].material];
    // A record for each way an image is sampled, its texels stored once:
    // image 0 as it is (base colour, emission), through sampler 0 (clamped
    // in u, nearest) and transformed; image 1 as it is (the normal map)
    // and through sampler 1 (mirrored, bilinear: magFilter decides).
    ASSERT_EQ(s.textures.size(), 5u);
    EXPECT_NE(m.flags & gpu::kMaterialTextured, 0u);
    EXPECT_EQ(m.base_color_texture, 0u);
    EXPECT_EQ(m.metallic_roughness_texture, 1u);
    EXPECT_EQ(m.emissive_texture, 0u);
    EXPECT_EQ(m.normal_texture, 2u);
    EXPECT_EQ(m.normal_scale, 0.5f);
    EXPECT_EQ(noted.metallic_roughness_texture, 3u);
    EXPECT_EQ(noted.normal_texture, 4u);
    EXPECT_EQ(s.textures[0].sampling, gpu::kTextureWrapRepeat | gpu::kTextureWrapRepeat << gpu::kTextureWrapVShift);
    // Sampler 0's minFilter LINEAR asks for no mipmaps.
    EXPECT_EQ(s.textures[1].sampling, gpu::kTextureWrapClamp | gpu::kTextureNearest | gpu::kTextureNoMipmaps);
    EXPECT_EQ(s.textures[3].sampling,
              gpu::kTextureWrapClamp | gpu::kTextureNearest | gpu::kTextureTransformed | gpu::kTextureNoMipmaps);
    EXPECT_EQ(s.textures[4].sampling, gpu::kTextureWrapMirror | gpu::kTextureWrapMirror << gpu::kTextureWrapVShift);
    for (const std::size_t t : {1, 3}) EXPECT_EQ(s.textures[t].offset, s.textures[0].offset) << t;
    EXPECT_EQ(s.textures[4].offset, s.textures[2].offset);
    // The extension's example: offset (0, 1), rotation pi/2, scale 0.5
    // maps the unit square onto the image's lower-left quarter,
    // u' = v / 2 and v' = 1 - u / 2.
    const float* t = s.textures[3].uv_transform;
    const auto transformed = [t](float u, float v) {
        return glm::vec2(t[0] * u + t[1] * v + t[2], t[3] * u + t[4] * v + t[5]);
    };
    for (const glm::vec2 uv : {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(0, 1), glm::vec2(0.5f, 0.25f)}) {
        const glm::vec2 expected(0.5f * uv.y, 1.0f - 0.5f * uv.x);
        EXPECT_NEAR(transformed(uv.x, uv.y).x, expected.x, 1e-6f);
        EXPECT_NEAR(transformed(uv.x, uv.y).y, expected.y, 1e-6f);
    }
    // Image 0 is 2 x 2, row 0 at the top: red, green / blue, white (R in the low byte).
    EXPECT_EQ(s.textures[0].width, 2u);
    EXPECT_EQ(s.textures[0].height, 2u);
    ASSERT_EQ(s.texels.size(), 5u);
    EXPECT_EQ(s.texels[s.textures[0].offset + 0], 0xFF0000FFu);
    EXPECT_EQ(s.texels[s.textures[0].offset + 1], 0xFF00FF00u);
    EXPECT_EQ(s.texels[s.textures[0].offset + 2], 0xFFFF0000u);
    EXPECT_EQ(s.texels[s.textures[0].offset + 3], 0xFFFFFFFFu);
    EXPECT_EQ(s.texels[s.textures[2].offset], 0xFFFF8080u);
    // TEXCOORD_0 as written (glTF's convention is the renderer's: no flip).
    EXPECT_EQ(s.uvs[0].u0, 0.0f);
    EXPECT_EQ(s.uvs[0].u1, 1.0f);
    EXPECT_EQ(s.uvs[0].v2, 1.0f);
}

TEST(Gltf, PunctualLightsArePlacedByTheirNodes) {
    const Scene s = load("lights.gltf");
    ASSERT_EQ(s.lights.size(), 3u);
    const gpu::Light& point = s.lights[0];
    EXPECT_EQ(point.type, gpu::kLightPoint);
    expect_near(position(point), {1, 2, 3}, 0.0f, "point");
    expect_near(value(point), {4, 2, 1}, 0.0f, "color x intensity");
    EXPECT_TRUE(has_note(s, "lights[0].range: ignored"));
    const gpu::Light& spot = s.lights[1];
    EXPECT_EQ(spot.type, gpu::kLightSpot);
    expect_near(position(spot), {0, 3, 0}, 1e-6f, "spot");
    expect_near({spot.axis_x, spot.axis_y, spot.axis_z}, {0, -1, 0}, 1e-6f, "spot shines along -Z of its node");
    EXPECT_FLOAT_EQ(spot.cos_inner, std::cos(glm::radians(10.0f)));
    EXPECT_FLOAT_EQ(spot.cos_outer, std::cos(glm::radians(30.0f)));
    expect_near(value(spot), {1, 2, 2}, 0.0f, "spot value");
    const gpu::Light& sun = s.lights[2];
    EXPECT_EQ(sun.type, gpu::kLightDirectional);
    // Travels along the node's -Z, here -x; stored towards the light.
    expect_near(position(sun), {1, 0, 0}, 1e-6f, "directional");
    expect_near(value(sun), glm::vec3(3.0f), 0.0f, "irradiance");
}

// pi/2 written as a float, 1.5707964, lies a hair above pi/2: exporters
// that keep angles in floats write it, and it means a hemisphere.
TEST(Gltf, SpotConeOfFloatHalfPiIsAHemisphere) {
    const Scene s = load("spot_float_half_pi.gltf");
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, gpu::kLightSpot);
    EXPECT_NEAR(s.lights[0].cos_outer, 0.0f, 1e-7f);
    EXPECT_EQ(s.lights[0].cos_inner, s.lights[0].cos_outer);
}

TEST(Gltf, FirstPerspectiveCameraOrTheOneNamed) {
    const Scene s = load("lights.gltf");
    EXPECT_TRUE(has_note(s, "cameras[0]: camera type \"orthographic\" is skipped"));
    expect_near(s.camera.position, {0, 0, 5}, 0.0f, "wide");
    expect_near(glm::normalize(s.camera.look_at - s.camera.position), {0, 0, -1}, 1e-6f, "looks along -Z");
    EXPECT_FLOAT_EQ(s.camera.fov_y_degrees, 90.0f);
    EXPECT_EQ(s.camera.width, 512u);  // aspectRatio 2
    EXPECT_EQ(s.camera.height, 256u);
    const Scene near = load("lights.gltf", "near");
    expect_near(near.camera.position, {0, 0, 7}, 0.0f, "near");
    EXPECT_FLOAT_EQ(near.camera.fov_y_degrees, 30.0f);
    EXPECT_EQ(near.camera.width, 256u);  // no aspectRatio
    const std::string e = error_of("lights.gltf", "nope");
    EXPECT_NE(e.find("lights.gltf: --camera: no perspective camera named 'nope' (the file has 'wide', 'near')"),
              std::string::npos)
        << e;
}

// An image no material reads (a texture of it is not enough) is not
// decoded: stb_image would take the memory and time of its pixels for
// nothing, and a broken one is no error.
TEST(Gltf, UnusedImagesAreNotDecoded) {
    const Scene s = load("unused_image_corrupt.gltf");
    EXPECT_EQ(s.textures.size(), 1u);
}

// materials.gltf with a WebP image its texture offers through
// EXT_texture_webp, its PNG the fallback, as the extension's example does.
nlohmann::json with_webp_offered(const fs::path& folder) {
    nlohmann::json doc = json_of("materials.gltf");
    for (const nlohmann::json& image : doc["images"])
        if (image.contains("uri") && !image["uri"].get<std::string>().starts_with("data:"))
            fs::copy_file(kData / image["uri"].get<std::string>(), folder / image["uri"].get<std::string>());
    std::ofstream(folder / "t.webp", std::ios::binary) << "RIFF\x1a\0\0\0WEBPVP8 ";
    doc["images"].push_back({{"uri", "t.webp"}});
    doc["textures"][0]["extensions"]["EXT_texture_webp"] = {{"source", doc["images"].size() - 1}};
    doc["extensionsUsed"].push_back("EXT_texture_webp");
    return doc;
}

// An image no material reads need not be PNG or JPEG: a file offering WebP
// with a PNG fallback loads, its texture the PNG's. Where the file requires
// the extension, that is what the error names (it named the WebP image).
TEST(Gltf, AnOfferedWebpImageFallsBackToItsPng) {
    test::TempDir dir;
    nlohmann::json doc = with_webp_offered(dir.path());
    const fs::path used = dir.write("used.gltf", doc.dump());
    const Scene s = load_scene(used);
    EXPECT_EQ(s.textures.size(), load("materials.gltf").textures.size());
    EXPECT_TRUE(has_note(s, "extensionsUsed: EXT_texture_webp is not supported"));
    // The same WebP embedded: tinygltf decodes no image/webp data URI, and
    // took it for a file name; no material reads it, so a note, no error.
    nlohmann::json embedded = doc;
    embedded["images"].back()["uri"] = "data:image/webp;base64,UklGRhoAAABXRUJQVlA4IA==";
    const Scene with_data = load_scene(dir.write("embedded.gltf", embedded.dump()));
    EXPECT_EQ(with_data.textures.size(), s.textures.size());
    EXPECT_TRUE(has_note(with_data, "a data URI of a type that is not read, and no material reads it"));
    EXPECT_FALSE(has_note(with_data, "File not found"));
    // Read by a material, it is an error naming its type.
    embedded["textures"][0]["source"] = embedded["images"].size() - 1;
    const fs::path read = dir.write("read.gltf", embedded.dump());
    EXPECT_NE(error_of(read.string()).find("a data URI of type 'image/webp', which is not read"), std::string::npos);
    doc["extensionsRequired"] = {"EXT_texture_webp"};
    const fs::path required = dir.write("required.gltf", doc.dump());
    EXPECT_EQ(error_of(required.string()),
              required.string() + ": extensionsRequired[0]: EXT_texture_webp is required by the file but not "
                                  "supported (supported: KHR_lights_punctual, KHR_materials_emissive_strength, "
                                  "KHR_materials_clearcoat, KHR_materials_sheen, KHR_texture_transform)");
}

// --camera takes the first camera node of its name, in node order, and
// notes that there are others.
TEST(Gltf, CameraOnTwoNodesIsTakenFromTheFirstWithANote) {
    const Scene s = load("camera_on_two_nodes.gltf", "a");
    expect_near(s.camera.position, {0, 0, 3}, 0.0f, "the first node's");
    EXPECT_TRUE(has_note(s, "--camera: 2 camera nodes are named 'a'; the first in node order is used"));
    EXPECT_FALSE(has_note(load("lights.gltf", "near"), "--camera"));
}

// A camera 1e8 from the origin keeps its view direction (a look-at point a
// unit away was rounded onto the camera, and the load failed as if up
// were parallel to the view).
TEST(Gltf, FarCameraKeepsItsDirection) {
    const Scene s = load("far_camera.gltf");
    expect_near(s.camera.position, {0, 0, 1e8f}, 0.0f, "position");
    const float a = glm::radians(10.0f);
    expect_near(glm::vec3(glm::normalize(glm::dvec3(s.camera.look_at) - glm::dvec3(s.camera.position))),
                {0.0f, std::sin(a), -std::cos(a)}, 1e-6f, "direction");
}

// An aspect ratio of 100 would make 25600 columns at 256 rows: the image is
// scaled to 16384 x 164 (the same shape), with a note.
TEST(Gltf, AWideCameraKeepsItsShapeWithinTheImageLimit) {
    const Scene s = load("wide_camera.gltf");
    EXPECT_EQ(s.camera.width, 16384u);
    EXPECT_EQ(s.camera.height, 164u);
    EXPECT_TRUE(has_note(s, "cameras[0].perspective.aspectRatio: the camera's image is 16384x164")) << s.load_notes.size();
}

TEST(Gltf, UnsupportedPartsAreSkippedWithOneNoteEach) {
    const Scene s = load("unsupported.gltf");
    EXPECT_EQ(s.triangles.size(), 1u);
    for (const char* note : {"animations: 1 animation(s) ignored", "targets: morph targets are not supported",
                             "COLOR_0: vertex colours are not read", "EXT_unknown_feature is not supported",
                             "primitives[0].attributes.TEXCOORD_0: missing, but the material has textures"})
        EXPECT_TRUE(has_note(s, note)) << note;
}

// A node whose transform flattens its mesh to nothing (tools hide objects
// with a scale of 0) is left out with a note naming it; the scene's other
// instance of the same mesh is drawn. With nothing else left the load fails
// naming the node (GltfBadInput, bad_scale_tiny).
TEST(Gltf, NodeScaledToNothingIsLeftOutWithANote) {
    const Scene s = load("hidden_node.gltf");
    EXPECT_EQ(s.triangles.size(), 1u);
    EXPECT_EQ(s.degenerate_triangles_dropped, 1u);
    EXPECT_TRUE(has_note(s, "nodes[2]: its transform makes every triangle of meshes[0] degenerate"));
}

TEST(Gltf, EmissiveMaterialAloneLightsTheScene) {
    const Scene s = load("emissive_only.gltf");
    EXPECT_TRUE(s.lights.empty());
    EXPECT_NE(s.materials.at(s.triangles.at(0).material).flags & gpu::kMaterialEmissive, 0u);
    EXPECT_EQ(s.materials[0].flags & gpu::kMaterialEmitsBothSides, 0u);
}

TEST(Gltf, SceneJsonListsGltfMeshesWithTransformsBesideObjAndItsOwnLights) {
    const Scene s = load_scene(kData / "with_json.json");
    // tri.obj, hierarchy.gltf (2 triangles, moved by z - 1), triangle.glb.
    ASSERT_EQ(s.triangles.size(), 4u);
    ASSERT_EQ(s.uvs.size(), 4u);  // the OBJ's triangle has zeros
    expect_near(vertex(s.triangles[1], 0), {10, 2, -1}, 1e-5f, "transformed glTF");
    // The glTF lights (placed by the same transform) come before the JSON's.
    ASSERT_EQ(s.lights.size(), 3u);
    expect_near(position(s.lights[0]), {0, 5, 4}, 1e-6f, "hierarchy.gltf light");
    expect_near(position(s.lights[1]), {0.2f, 0.2f, 1.0f}, 1e-7f, "triangle.glb light");
    expect_near(position(s.lights[2]), {0, 1, 1}, 0.0f, "JSON light");
    EXPECT_EQ(s.camera.width, 16u);  // the JSON's camera
}

TEST(Gltf, SceneJsonGltfEntryTakesNoMaterialOverride) {
    const std::string e = error_of("bad_json_gltf_material.json");
    EXPECT_NE(e.find("bad_json_gltf_material.json: meshes[0].material: unknown key"), std::string::npos) << e;
}

TEST(Gltf, CameraOptionIsRefusedForAJsonScene) {
    const std::string e = error_of("with_json.json", "main");
    EXPECT_NE(e.find("--camera picks a camera of a glTF scene"), std::string::npos) << e;
}

// A file past GLB's 32-bit lengths is refused from its size, before it is
// read (a sparse file here: no disk is used).
TEST(Gltf, FilePastFourGibibytesIsRefusedBeforeItIsRead) {
    test::TempDir dir;
    const fs::path file = dir.write("huge.glb", "glTF");
    fs::resize_file(file, (std::uintmax_t(1) << 32) + 4096);
    EXPECT_EQ(error_of(file.string()), file.string() + ": the file is 4294971392 bytes; a glTF file holds at most "
                                                       "4294967295 (GLB's lengths are 32-bit)");
}

// Without a camera the loader frames the geometry; where no float camera
// can (the geometry 1e8 out along z, where floats lie 8 apart, so the
// camera's position rounded onto the centre), the error says so, naming
// the file; the scene rendered with a NaN view before.
TEST(Gltf, ADefaultFramingThatFloatsCannotHoldIsRefused) {
    test::TempDir dir;
    nlohmann::json doc = json_of("triangle.gltf");
    doc["nodes"][0]["translation"] = {0.0, 0.0, 1e8};
    doc["nodes"][1]["translation"] = {0.2, 0.2, 1e8 + 16.0};
    const fs::path file = dir.write("far.gltf", doc.dump());
    EXPECT_EQ(error_of(file.string()),
              file.string() + ": cameras: no perspective camera, and a default one cannot frame this geometry in float "
                              "(camera.look_at must differ from camera.position): add a camera");
}

// Without a `scene` the first of the scenes is drawn, as viewers do (every
// root node was, the scenes' overlaid, and nodes of no scene too); a file
// with no scenes draws its root nodes.
TEST(Gltf, WithoutADefaultSceneTheFirstIsDrawn) {
    test::TempDir dir;
    nlohmann::json doc = json_of("triangle.gltf");
    doc.erase("scene");
    doc["nodes"].push_back({{"mesh", 0}, {"translation", {3.0, 0.0, 0.0}}});
    doc["scenes"].push_back({{"nodes", {1, 2}}});
    const fs::path file = dir.write("two.gltf", doc.dump());
    const Scene first = load_scene(file);
    EXPECT_EQ(first.triangles.size(), 1u);
    EXPECT_TRUE(has_note(first, "scenes: the file names no default scene (`scene`); the first of its 2 scenes is drawn"));
    doc["scene"] = 1;
    const Scene second = load_scene(dir.write("second.gltf", doc.dump()));
    ASSERT_EQ(second.triangles.size(), 1u);
    EXPECT_EQ(second.triangles[0].v0_x, first.triangles[0].v0_x + 3.0f);
    doc.erase("scene");
    doc.erase("scenes");
    EXPECT_EQ(load_scene(dir.write("none.gltf", doc.dump())).triangles.size(), 2u);
}

// --camera naming an orthographic camera says that it is one (it said the
// file had no cameras).
TEST(Gltf, CameraNamingAnOrthographicOneSaysSo) {
    test::TempDir dir;
    nlohmann::json doc = json_of("triangle.gltf");
    doc["cameras"] = {{{"type", "orthographic"},
                       {"name", "ortho"},
                       {"orthographic", {{"xmag", 1.0}, {"ymag", 1.0}, {"znear", 0.1}, {"zfar", 10.0}}}}};
    doc["nodes"].push_back({{"camera", 0}, {"translation", {0.0, 0.0, 3.0}}});
    doc["scenes"][0]["nodes"].push_back(2);
    const fs::path file = dir.write("ortho.gltf", doc.dump());
    EXPECT_EQ(error_of(file.string(), "ortho"),
              file.string() + ": --camera: 'ortho' is an orthographic camera; only perspective cameras are read");
}

// A buffer must hold its byteLength, in a file or a data URI (a file may
// hold more): tinygltf
// said "File size mismatch" naming no field, or "Failed to decode 'uri'"
// with the whole data URI (1.4 MB of message for a 1 MiB buffer). And a
// '+' in a URI, which tinygltf reads as a space, is pointed out where the
// file with the '+' is there.
TEST(Gltf, BuffersMustHoldTheirByteLength) {
    test::TempDir dir;
    nlohmann::json doc = json_of("triangle.gltf");
    const std::string data = doc["buffers"][0]["uri"].get<std::string>();
    ASSERT_TRUE(data.starts_with("data:"));
    const std::uint64_t length = doc["buffers"][0]["byteLength"].get<std::uint64_t>();
    doc["buffers"][0]["byteLength"] = length + 1;
    fs::path file = dir.write("long.gltf", doc.dump());
    EXPECT_EQ(error_of(file.string()), file.string() + ": buffers[0].byteLength: " + std::to_string(length + 1) +
                                           ", but its data URI holds " + std::to_string(length) + " bytes");
    // The same bytes in a file of their own, one byte short.
    std::string bytes(length - 1, '\0');
    std::ofstream(dir.path() / "a+b.bin", std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    doc["buffers"][0] = {{"uri", "a%2Bb.bin"}, {"byteLength", length}};
    file = dir.write("short.gltf", doc.dump());
    EXPECT_EQ(error_of(file.string()), file.string() + ": buffers[0].byteLength: " + std::to_string(length) +
                                           ", but 'a%2Bb.bin' holds " + std::to_string(length - 1) + " bytes");
    // Longer than byteLength is allowed (glTF 2.0, "Buffers"), and loads;
    // tinygltf wanted the file exactly byteLength long. (The data URI's
    // bytes, decoded here, then nine more.)
    std::string decoded;
    std::uint32_t bits = 0;
    int held_bits = 0;
    for (const char c : data.substr(data.find(',') + 1)) {
        const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        if (c == '=') break;
        bits = bits << 6 | std::uint32_t(alphabet.find(c));
        if ((held_bits += 6) >= 8) decoded += char(bits >> (held_bits -= 8) & 0xFFu);
    }
    ASSERT_EQ(decoded.size(), length);
    decoded.append(9, 'x');
    std::ofstream(dir.path() / "long.bin", std::ios::binary).write(decoded.data(), std::streamsize(decoded.size()));
    doc["buffers"][0]["uri"] = "long.bin";
    EXPECT_EQ(load_scene(dir.write("long.gltf", doc.dump())).triangles.size(),
              load_scene(kData / "triangle.gltf").triangles.size());
    doc["buffers"][0]["uri"] = "a+b.bin";
    file = dir.write("plus.gltf", doc.dump());
    EXPECT_EQ(error_of(file.string()),
              file.string() + ": buffers[0].uri: 'a+b.bin' not found next to the glTF (the glTF loader, tinygltf, "
                              "reads '+' in a URI as a space; write it as %2B)");
}

// A buffer read from a device or a pipe could go on for ever: such URIs are
// refused before tinygltf opens them (it reads a pipe until its writer
// closes it, which here is never).
TEST(Gltf, BufferAndImageUrisMustNameRegularFiles) {
    test::TempDir dir;
    std::ifstream in(kData / "bad_missing_buffer.gltf", std::ios::binary);
    const std::string doc{std::istreambuf_iterator<char>(in), {}};
    const std::size_t at = doc.find("missing.bin");
    ASSERT_NE(at, std::string::npos);
    auto with_buffer = [&](const std::string& uri) {
        std::string changed = doc;
        return dir.write("scene.gltf", changed.replace(at, std::string("missing.bin").size(), uri));
    };
    fs::create_symlink("/dev/zero", dir.path() / "zero.bin");
    ASSERT_EQ(::mkfifo((dir.path() / "pipe.bin").c_str(), 0600), 0);
    for (const auto& [uri, kind] : {std::pair<std::string, std::string>{"zero.bin", "is a device, not a regular file"},
                                    {"pipe.bin", "is a pipe, not a regular file"},
                                    {"sub%20dir", "is a folder, not a file"}}) {
        fs::create_directories(dir.path() / "sub dir");
        const fs::path file = with_buffer(uri);
        try {
            load_scene(file);
            ADD_FAILURE() << uri << ": loaded, expected lc::InputError";
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()), file.string() + ": buffers[0].uri: '" + uri + "' " + kind);
        }
    }
    // A URI is looked for beside the glTF only: tinygltf's own search went
    // on to the current folder, where a folder of that name asked it for
    // 2^63 bytes. Here the current folder holds one; beside the glTF is
    // nothing.
    const fs::path file = with_buffer("elsewhere.bin");
    const fs::path cwd = fs::current_path();
    fs::create_directories(dir.path() / "cwd" / "elsewhere.bin");
    fs::current_path(dir.path() / "cwd");
    std::string message;
    try {
        load_scene(file);
    } catch (const std::exception& e) {
        message = e.what();
    }
    fs::current_path(cwd);
    EXPECT_EQ(message, file.string() + ": buffers[0].uri: 'elsewhere.bin' not found next to the glTF");
    // "%00" decodes to a NUL, which would cut the name short.
    const fs::path nul = with_buffer("missing.bin%00.txt");
    try {
        load_scene(nul);
        ADD_FAILURE() << "a URI with %00 loaded";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), nul.string() + ": buffers[0].uri: 'missing.bin%00.txt' decodes to a file "
                                                        "name with a NUL character");
    }
}

// A finite normal scale past the limit is named with the limit.
TEST(Gltf, NormalTextureScaleOutOfRangeNamesTheLimit) {
    test::TempDir dir;
    std::ifstream in(kData / "materials.gltf", std::ios::binary);
    std::string doc{std::istreambuf_iterator<char>(in), {}};
    const std::size_t at = doc.find("\"scale\": 0.5");
    ASSERT_NE(at, std::string::npos);
    for (const char* scale : {"1e30", "-2e6"}) {
        std::string changed = doc;
        const fs::path file = dir.write("scale.gltf", changed.replace(at, 12, std::string("\"scale\": ") + scale));
        EXPECT_EQ(error_of(file.string()),
                  file.string() + ": materials[0].normalTexture.scale: must be a number from -1e6 to 1e6");
    }
}

struct BadCase {
    const char* file;
    const char* message;  // after "FILE: "
};

class GltfBadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(GltfBadInput, ThrowsInputErrorNamingFileAndGltfPath) {
    const std::string e = error_of(GetParam().file);
    EXPECT_NE(e.find(std::string(GetParam().file) + ": " + GetParam().message), std::string::npos) << e;
}

INSTANTIATE_TEST_SUITE_P(
    Gltf, GltfBadInput,
    ::testing::Values(
        BadCase{"bad_required_draco.gltf", "extensionsRequired[0]: KHR_draco_mesh_compression is required"},
        BadCase{"bad_index_range.gltf", "meshes[0].primitives[0].indices: index 7 at element 2 out of range (3 vertices)"},
        BadCase{"bad_accessor_past_view.gltf", "accessors[0].bufferView: 4 elements of 12 bytes from byte 0 run past"},
        BadCase{"bad_accessor_count_huge.gltf",
                "accessors[0].bufferView: 2147483648 elements of 12 bytes from byte 0 run past"},
        BadCase{"bad_zeros_count.gltf",
                "accessors[0].count: is larger than 16777216 for an accessor without a bufferView"},
        BadCase{"bad_view_past_buffer.gltf", "bufferViews[0]: bytes 8 + 36 run past the end of buffer 0"},
        BadCase{"bad_nan_position.gltf", "meshes[0].primitives[0].attributes.POSITION: element 1 of accessors[0] is not a finite"},
        BadCase{"bad_missing_buffer.gltf", "buffers[0].uri: 'missing.bin' not found next to the glTF"},
        BadCase{"bad_buffer_folder.gltf", "buffers[0].uri: '.' is a folder, not a file"},
        BadCase{"bad_image_folder.gltf", "images[0].uri: '..' is a folder, not a file"},
        BadCase{"bad_data_uri.gltf", "buffers[0].uri: the data URI's base64 holds '@' at character 0 of its data"},
        BadCase{"bad_no_position.gltf", "meshes[0].primitives[0].attributes.POSITION: missing"},
        BadCase{"bad_no_light.gltf", "the scene has no light"},
        BadCase{"bad_node_cycle.gltf", "nodes[3].children[0]: nodes[2] is reached twice"},
        BadCase{"bad_material_index.gltf", "meshes[0].primitives[0].material: material 3 out of range"},
        BadCase{"bad_base_color.gltf", "materials[0].pbrMetallicRoughness.baseColorFactor[0]: must be from 0 to 1"},
        BadCase{"bad_base_alpha.gltf", "materials[0].pbrMetallicRoughness.baseColorFactor[3]: must be from 0 to 1"},
        BadCase{"bad_wrap.gltf", "samplers[0].wrapS: must be 10497 (REPEAT), 33071 (CLAMP_TO_EDGE) or 33648 "
                                 "(MIRRORED_REPEAT), not 12345"},
        BadCase{"bad_image_missing.gltf", "images[1].uri: 'missing.png' not found next to the glTF"},
        BadCase{"bad_image_corrupt.gltf",
                "tinygltf: images[0] ('corrupt.png') cannot be decoded as PNG or JPEG (bad zlib header)"},
        BadCase{"bad_mag_filter.gltf", "samplers[0].magFilter: must be 9728 (NEAREST) or 9729 (LINEAR), not 1"},
        BadCase{"bad_min_filter.gltf", "samplers[0].minFilter: must be 9728 (NEAREST), 9729 (LINEAR) or 9984 to 9987"},
        BadCase{"bad_transform_offset.gltf", "materials[0].pbrMetallicRoughness.baseColorTexture.extensions."
                                             "KHR_texture_transform.offset[0]: must be a number, not a string"},
        BadCase{"bad_transform_scale.gltf", "materials[0].pbrMetallicRoughness.baseColorTexture.extensions."
                                            "KHR_texture_transform.scale[0]: must be a finite number"},
        BadCase{"bad_spot_cone.gltf", "extensions.KHR_lights_punctual.lights[0].spot.outerConeAngle"},
        BadCase{"bad_spot_past_float_half_pi.gltf",
                "extensions.KHR_lights_punctual.lights[0].spot.outerConeAngle: must be from 0 to pi/2"},
        BadCase{"bad_position_type.gltf", "accessors[0].componentType: is UNSIGNED_SHORT, expected FLOAT"},
        BadCase{"bad_json.gltf", "tinygltf: "},
        BadCase{"bad_roughness_string.gltf",
                "materials[0].pbrMetallicRoughness.roughnessFactor: must be a number, not a string"},
        // The value as written, not in 40 digits (std::to_string's %f).
        BadCase{"bad_emissive_strength_huge.gltf", "materials[0].extensions.KHR_materials_emissive_strength."
                                                   "emissiveStrength: must be from 0 to FLT_MAX, got 1e+39"},
        BadCase{"bad_emissive_strength_number.gltf",
                "materials[0].extensions.KHR_materials_emissive_strength: must be an object, not a number"},
        BadCase{"bad_lights_array.gltf", "extensions.KHR_lights_punctual: must be an object, not an array"},
        BadCase{"bad_light_string.gltf", "extensions.KHR_lights_punctual.lights[0]: must be an object, not a string"},
        BadCase{"bad_node_light_number.gltf",
                "nodes[1].extensions.KHR_lights_punctual: must be an object, not a number"},
        BadCase{"bad_negative_view.gltf", "accessors[0].bufferView: must be a whole number >= 0, not -5"},
        BadCase{"bad_aspect_zero.gltf", "cameras[0].perspective.aspectRatio: must be above 0, not 0"},
        BadCase{"bad_yfov_rounds.gltf", "cameras[0].perspective.yfov: is so near pi that it is 180 degrees as a float"},
        BadCase{"bad_camera_too_far.gltf", "nodes[2]: the camera is too far from the origin (3e+38) for a float to keep its view direction"},
        BadCase{"bad_projective_matrix.gltf", "nodes[0].matrix: its last row (elements 3, 7, 11, 15) must be 0, 0, 0, 1"},
        BadCase{"bad_scale_tiny.gltf", "nodes[0]: its transform makes every triangle of its mesh degenerate"},
        BadCase{"missing.gltf", "file not found"}),
    [](const ::testing::TestParamInfo<BadCase>& info) {
        std::string name = info.param.file;
        name = name.substr(0, name.find('.'));
        return name;
    });

// -- the shipped room as glTF (scripts/make_gltf.py) ---------------------------

// Both files hold the same decimal numbers; the OBJ's are parsed by
// tinyobjloader to float, the glTF's written as float32 by Python, and the
// torus's transform is a quaternion in the glTF, three glm rotations in the
// JSON: they may differ by a few float ulps of the 6 m room (measured: not
// at all, tinyobjloader rounds as Python does and the torus's rotation comes
// out the same).
constexpr float kRoomPositionTolerance = 2e-6f;

TEST(GltfRoom, LoadsTheSameTrianglesLightsAndCameraAsTheJsonRoom) {
    const Scene json = load_scene(LC_SOURCE_DIR "/scenes/room/room.json");
    const Scene gltf = load_scene(LC_SOURCE_DIR "/scenes/room/room.gltf");
    ASSERT_EQ(gltf.triangles.size(), json.triangles.size());
    float worst_position = 0.0f, worst_normal = 0.0f;
    for (std::size_t i = 0; i < json.triangles.size(); ++i) {
        for (int k = 0; k < 3; ++k) {
            worst_position = std::max(worst_position, glm::length(vertex(gltf.triangles[i], k) - vertex(json.triangles[i], k)));
            worst_normal = std::max(worst_normal, glm::length(normal(gltf.normals[i], k) - normal(json.normals[i], k)));
        }
    }
    std::printf("[ measured ] positions differ by at most %g m, normals by %g\n", double(worst_position),
                double(worst_normal));
    EXPECT_LE(worst_position, kRoomPositionTolerance);
    EXPECT_LE(worst_normal, 1e-6f);
    ASSERT_EQ(gltf.lights.size(), json.lights.size());
    for (std::size_t i = 0; i < json.lights.size(); ++i) {
        EXPECT_EQ(gltf.lights[i].type, json.lights[i].type);
        expect_near(position(gltf.lights[i]), position(json.lights[i]), 1e-6f, "light " + std::to_string(i));
        const glm::vec3 v = value(json.lights[i]);
        expect_near(value(gltf.lights[i]), v, 1e-6f * glm::length(v), "light value " + std::to_string(i));
    }
    expect_near(gltf.camera.position, json.camera.position, 1e-6f, "camera");
    expect_near(glm::normalize(gltf.camera.look_at - gltf.camera.position),
                glm::normalize(json.camera.look_at - json.camera.position), 1e-6f, "view direction");
    EXPECT_FLOAT_EQ(gltf.camera.fov_y_degrees, json.camera.fov_y_degrees);
    EXPECT_EQ(gltf.camera.width, json.camera.width);
    EXPECT_EQ(gltf.camera.height, json.camera.height);
    // Materials: MTL Kd (or the JSON override's kd) is the base colour.
    for (std::size_t i = 0; i < json.triangles.size(); ++i) {
        const gpu::Material& g = gltf.materials[gltf.triangles[i].material];
        const gpu::Material& j = json.materials[json.triangles[i].material];
        ASSERT_EQ(glm::vec3(g.kd_r, g.kd_g, g.kd_b), glm::vec3(j.kd_r, j.kd_g, j.kd_b)) << "triangle " << i;
        ASSERT_NE(g.flags & gpu::kMaterialDisney, 0u);
    }
}

// The camera's basis (from the glTF node's quaternion, not from look_at) and
// the light values (colour x intensity in double) differ from the JSON's in
// the last float bits: measured at most 2.2e-5 per pixel and channel
// (brute force, 32 x 32); the bound is about 5x that.
constexpr double kRoomPixelRelative = 1e-4;

TEST(GltfRoom, RendersLikeTheJsonRoomOnTheCpu) {
    test::RoomTwins t = test::room_twins();
    RenderOptions o = test::options("brute", 32);
    const Image a = render_cpu(prepare_scene(std::move(t.gltf), 1), o).image;
    const Image b = render_cpu(prepare_scene(std::move(t.json), 1), o).image;
    ASSERT_EQ(a.rgb.size(), b.rgb.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i)
        worst = std::max(worst, std::abs(double(a.rgb[i]) - b.rgb[i]) / (std::abs(double(b.rgb[i])) + 1e-6));
    std::printf("[ measured ] largest relative pixel difference %g\n", worst);
    EXPECT_LE(worst, kRoomPixelRelative);
}

}  // namespace
}  // namespace lc
