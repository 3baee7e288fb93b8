// Scene loading: the shipped scenes, every documented input error, the CSV
// light format, materials, transforms and degenerate geometry.
#include <limits>

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <sys/stat.h>

#include <glm/glm.hpp>

#include "lightcuts/error.h"
#include "lightcuts/image.h"
#include "lightcuts/scene.h"
#include "scene/polygon.h"
#include "test_util.h"
#include "lightcuts/settings.h"
#include "scene/csv_lights.h"

namespace lc {
namespace {

using test::normal;
using test::vertex;
using test::winding_normal;

namespace fs = std::filesystem;
using test::TempDir;

const fs::path kFixtures = fs::path(LC_TEST_DATA_DIR) / "scenes";
const fs::path kScenes = fs::path(LC_SOURCE_DIR) / "scenes";

// Runs `load` and returns the InputError message; fails the test if nothing
// (or something else) was thrown.
template <typename Fn>
std::string input_error_of(Fn&& load) {
    try {
        load();
    } catch (const InputError& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "expected lc::InputError, got: " << e.what();
        return {};
    }
    ADD_FAILURE() << "expected lc::InputError, nothing was thrown";
    return {};
}

void expect_near(glm::vec3 actual, glm::vec3 expected, float tolerance = 1e-5f) {
    EXPECT_NEAR(actual.x, expected.x, tolerance);
    EXPECT_NEAR(actual.y, expected.y, tolerance);
    EXPECT_NEAR(actual.z, expected.z, tolerance);
}

// ---------------------------------------------------------------------------
// Shipped scenes
// ---------------------------------------------------------------------------

TEST(SceneLoader, LoadsDefaultRoomScene) {
    const Scene scene = load_scene(kScenes / "room" / "room.json");
    EXPECT_EQ(scene.camera.width, 256u);
    EXPECT_EQ(scene.camera.height, 256u);
    EXPECT_EQ(scene.render.method, "lightcuts");
    EXPECT_EQ(scene.render.spp, 1u);
    EXPECT_EQ(scene.lights.size(), 1000u);
    EXPECT_EQ(scene.count_lights(gpu::kLightPoint), 1000u);
    EXPECT_EQ(scene.count_lights(gpu::kLightDirectional), 0u);
    // 6 wall quads + 2 boxes of 6 quads = 36 triangles, plus the 72 x 24 torus.
    EXPECT_EQ(scene.triangles.size(), 36u + 2u * 72u * 24u);
    EXPECT_EQ(scene.normals.size(), scene.triangles.size());
    EXPECT_EQ(scene.degenerate_triangles_dropped, 0u);

    std::size_t specular = 0;
    for (const gpu::Material& m : scene.materials) specular += (m.flags & gpu::kMaterialHasSpecular) ? 1 : 0;
    EXPECT_GE(specular, 1u);
    for (const gpu::Triangle& t : scene.triangles) ASSERT_LT(t.material, scene.materials.size());

    // Closed room: the camera is inside the bounds (of the walls).
    for (int a = 0; a < 3; ++a) {
        EXPECT_LT(scene.bounds_min[a], scene.camera.position[a]);
        EXPECT_GT(scene.bounds_max[a], scene.camera.position[a]);
    }
    expect_near(scene.bounds_min, {-2.5f, 0.0f, -3.0f});
    expect_near(scene.bounds_max, {2.5f, 3.0f, 3.0f});
}

TEST(SceneLoader, RoomScalingVariantsReferenceTheirLightSets) {
    // The lights_1eN.csv sets are generated on demand (gitignored); either they
    // load with the right count or the error names the missing file.
    for (const auto& [name, count] : {std::pair{"1e3", 1000u}, {"1e4", 10000u}, {"1e5", 100000u}}) {
        const fs::path scene_file = kScenes / "room" / (std::string("room_") + name + ".json");
        const fs::path csv = kScenes / "room" / (std::string("lights_") + name + ".csv");
        if (fs::exists(csv)) {
            EXPECT_EQ(load_scene(scene_file).count_lights(gpu::kLightPoint), count) << scene_file;
        } else {
            const std::string message = input_error_of([&] { load_scene(scene_file); });
            EXPECT_NE(message.find(csv.filename().string()), std::string::npos) << message;
        }
    }
}

TEST(SceneLoader, LoadsBunnySceneWhenFetched) {
    if (!fs::exists(kScenes / "bunny" / "bunny.obj")) {
        GTEST_SKIP() << "scenes/bunny/bunny.obj missing; run scripts/fetch-bunny.sh";
    }
    const Scene scene = load_scene(kScenes / "bunny" / "bunny.json");
    EXPECT_EQ(scene.count_lights(gpu::kLightPoint), 1000u);
    EXPECT_GT(scene.triangles.size(), 3000u);
    EXPECT_NEAR(scene.bounds_min.y, 0.0f, 1e-3f);  // the floor
}

// ---------------------------------------------------------------------------
// Good input
// ---------------------------------------------------------------------------

TEST(SceneLoader, MinimalSceneUsesDefaults) {
    const Scene scene = load_scene(kFixtures / "minimal.json");
    const Camera defaults;
    const RenderSettings render;
    EXPECT_EQ(scene.file, kFixtures / "minimal.json");
    EXPECT_FLOAT_EQ(scene.camera.fov_y_degrees, defaults.fov_y_degrees);
    expect_near(scene.camera.up, defaults.up);
    EXPECT_EQ(scene.camera.width, 32u);
    EXPECT_EQ(scene.render.method, render.method);
    EXPECT_EQ(scene.render.spp, render.spp);
    EXPECT_FLOAT_EQ(scene.render.relative_error, render.relative_error);
    EXPECT_EQ(scene.render.max_cut, render.max_cut);
    EXPECT_EQ(scene.render.seed, render.seed);

    ASSERT_EQ(scene.triangles.size(), 1u);
    ASSERT_EQ(scene.lights.size(), 1u);
    const gpu::Light& light = scene.lights[0];
    EXPECT_EQ(light.type, gpu::kLightPoint);
    expect_near({light.x, light.y, light.z}, {0, 2, 1});
    expect_near({light.r, light.g, light.b}, {1, 1, 1});
}

TEST(SceneLoader, DefaultMaterialIsGreyLambert) {
    const Scene scene = load_scene(kFixtures / "minimal.json");
    ASSERT_EQ(scene.materials.size(), 1u);
    const gpu::Material& m = scene.materials[0];
    expect_near({m.kd_r, m.kd_g, m.kd_b}, glm::vec3(0.8f));
    expect_near({m.ks_r, m.ks_g, m.ks_b}, glm::vec3(0.0f));
    EXPECT_EQ(m.flags & gpu::kMaterialHasSpecular, 0u);
    EXPECT_EQ(scene.triangles[0].material, 0u);
    // No vertex normals in the OBJ: the face normal, three times.
    for (int i = 0; i < 3; ++i) expect_near(normal(scene.normals[0], i), {0, 0, 1});
}

TEST(SceneLoader, AllLightTypesInFileOrderAndRenderBlock) {
    const Scene scene = load_scene(kFixtures / "all_lights.json");
    // point, directional, 3 from the CSV, directional.
    ASSERT_EQ(scene.lights.size(), 6u);
    EXPECT_EQ(scene.count_lights(gpu::kLightPoint), 4u);
    EXPECT_EQ(scene.count_lights(gpu::kLightDirectional), 2u);

    const gpu::Light& sun = scene.lights[1];
    EXPECT_EQ(sun.type, gpu::kLightDirectional);
    // Light travels along -y: stored as the unit vector towards the light.
    expect_near({sun.x, sun.y, sun.z}, {0, 1, 0});
    expect_near({sun.r, sun.g, sun.b}, glm::vec3(0.5f));
    const gpu::Light& side = scene.lights[5];
    expect_near({side.x, side.y, side.z}, {-0.6f, 0.0f, 0.8f});

    EXPECT_EQ(scene.lights[2].type, gpu::kLightPoint);
    expect_near({scene.lights[2].x, scene.lights[2].y, scene.lights[2].z}, {1, 2, 3});

    EXPECT_EQ(scene.render.method, "lightcuts");
    EXPECT_EQ(scene.render.spp, 4u);
    EXPECT_FLOAT_EQ(scene.render.relative_error, 0.01f);
    EXPECT_EQ(scene.render.max_cut, 64u);
    EXPECT_EQ(scene.render.seed, 4000000000u);
}

TEST(SceneLoader, MtlMaterialsGiveLambertAndGgx) {
    const Scene scene = load_scene(kFixtures / "materials.json");
    // lambert, glossy_ns, glossy_pr from the MTL, then the default (first use).
    ASSERT_EQ(scene.materials.size(), 4u);
    ASSERT_EQ(scene.triangles.size(), 4u);
    EXPECT_EQ(scene.triangles[0].material, 3u);  // face before any usemtl
    EXPECT_EQ(scene.triangles[1].material, 0u);
    EXPECT_EQ(scene.triangles[2].material, 1u);
    EXPECT_EQ(scene.triangles[3].material, 2u);

    const gpu::Material& lambert = scene.materials[0];
    expect_near({lambert.kd_r, lambert.kd_g, lambert.kd_b}, {0.2f, 0.4f, 0.6f});
    EXPECT_EQ(lambert.flags & gpu::kMaterialHasSpecular, 0u);

    const gpu::Material& ns = scene.materials[1];
    EXPECT_NE(ns.flags & gpu::kMaterialHasSpecular, 0u);
    expect_near({ns.ks_r, ns.ks_g, ns.ks_b}, glm::vec3(0.25f));
    EXPECT_NEAR(ns.alpha, std::sqrt(2.0f / 100.0f), 1e-6f);

    const gpu::Material& pr = scene.materials[2];
    EXPECT_NE(pr.flags & gpu::kMaterialHasSpecular, 0u);
    EXPECT_NEAR(pr.alpha, 0.25f, 1e-6f);

    expect_near({scene.materials[3].kd_r, scene.materials[3].kd_g, scene.materials[3].kd_b},
                glm::vec3(0.8f));
}

// tinyobjloader reads a number it cannot parse as 0 and says nothing: a
// NaN, an infinity or a typo in a vertex or an MTL value is refused naming
// the file, the line and the key, and a vertex line short of numbers too
// (the OBJs' lines count from their mtllib line, line 1).
TEST(SceneLoader, ObjAndMtlNumbersThatAreNotNumbersAreRefused) {
    struct Bad {
        const char* vertices;  // the OBJ's lines before its face
        const char* mtl;       // the MTL's text
        const char* file;      // the file the error names
        const char* start;     // what follows "FILE: "
    };
    const char* kVertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    const char* kMtl = "newmtl m\nKd 0.5 0.5 0.5\n";
    for (const Bad& b : {Bad{"v 0 0 0\nv 1 nan 0\nv 0 1 0\n", kMtl, "m.obj", "line 3 (v): 'nan' is not a number"},
                         Bad{"v 0 0 0\nv 1 0 0\nv 0 1 inf\n", kMtl, "m.obj", "line 4 (v): 'inf' is not a number"},
                         Bad{"v 0 0 0\nv 1,5 0 0\nv 0 1 0\n", kMtl, "m.obj", "line 3 (v): '1,5' is not a number"},
                         Bad{"v 0 0 0\nv 1 0\nv 0 1 0\n", kMtl, "m.obj", "line 3 (v): needs 3 numbers, has 2"},
                         Bad{"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 abc\n", kMtl, "m.obj", "line 5 (vn): 'abc'"},
                         Bad{"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt NaN 0\n", kMtl, "m.obj", "line 5 (vt): 'NaN'"},
                         // tinyobjloader converts indices and joint ids with int(): they wrapped.
                         Bad{"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -99999999999\n", kMtl, "m.obj",
                             "line 5 (f): corner '-99999999999': index '-99999999999' is not a whole number"},
                         Bad{"v 0 0 0\nv 1 0 0\nv 0 1 0\nvw 1 44444444444 0.5\n", kMtl, "m.obj",
                             "line 5 (vw): '44444444444' is not a whole number within 2^31"},
                         Bad{kVertices, "newmtl m\nKd nan 0.5 0.5\n", "m.mtl", "line 2 (Kd): 'nan' is not a number"},
                         Bad{kVertices, "newmtl m\nKd 0.5\n", "m.mtl", "line 2 (Kd): needs 3 numbers, has 1"},
                         Bad{kVertices, "newmtl m\nKd 0.5 0.5 0.5\nNs inf\n", "m.mtl", "line 3 (Ns): 'inf'"},
                         Bad{kVertices, "newmtl m\n\tPm 0.5x\n", "m.mtl", "line 2 (Pm): '0.5x'"},
                         // Past float's range, which tinyobjloader reads as infinity (or, at
                         // 1e99999, as 0: the triangle was dropped as degenerate); and a
                         // value too small for to_string's six decimals.
                         Bad{kVertices, "newmtl m\nKd 1e39 0.5 0.5\n", "m.mtl",
                             "line 2 (Kd): '1e39' is past the largest float (3.4e38)"},
                         Bad{"v 1e99999 0 0\nv 1 0 0\nv 0 1 0\n", kMtl, "m.obj",
                             "line 2 (v): '1e99999' is past the largest float (3.4e38)"},
                         Bad{"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 -4e38 0\n", kMtl, "m.obj",
                             "line 5 (vn): '-4e38' is past the largest float (3.4e38)"},
                         Bad{kVertices, "newmtl m\nKd -1e-7 0.5 0.5\n", "m.obj",
                             "material 'm'.Kd: components must be in [0, 1], got -1e-07"},
                         Bad{kVertices, "newmtl m\nKd 1.0000001 0.5 0.5\n", "m.obj",
                             "material 'm'.Kd: components must be in [0, 1], got 1.0000001"}}) {
        TempDir dir;
        dir.write("m.obj", std::string("mtllib m.mtl\n") + b.vertices + "usemtl m\nf 1 2 3\n");
        dir.write("m.mtl", b.mtl);
        const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "m.obj"}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
        const std::string message = input_error_of([&] { load_scene(scene); });
        const std::string start = (dir.path() / b.file).lexically_normal().string() + ": " + b.start;
        EXPECT_EQ(message.rfind(start, 0), 0u) << message << "\n  wanted: " << start;
    }
    // What the check lets through: signs, exponents, comments, tabs, CRLF
    // and lone CR line ends, a vertex with a w or a colour, the largest
    // float as its shortest text (above FLT_MAX as a double), a vertex normal
    // of NaNs (the face normal replaces it), and MTL keys the renderer does
    // not read, whatever they hold.
    TempDir dir;
    dir.write("m.obj", "mtllib m.mtl\r\nv -0 +0 0.0 # a comment\r\nv\t1.e0 0 0 1\rv .5 1E+0 -0e-3 1 0.5 0\n"
                       "vt 0.5\nvt 3.4028235e38 0\nvn nan -nan(ind) INF\nusemtl m\nf 1//1 2//1 3//1\n");
    dir.write("m.mtl", "newmtl m\nKd 0.5 0.5 0.5\nd -halo 1\nNs 10\nKa spectral ident.rfl 1\nTf xyz 1 1 1\nKa 0.2\n");
    const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "m.obj"}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
    const Scene loaded = load_scene(scene);
    ASSERT_EQ(loaded.triangles.size(), 1u);
    EXPECT_EQ(loaded.triangles[0].v2_y, 1.0f);
    EXPECT_NEAR(loaded.materials.at(loaded.triangles[0].material).kd_g, 0.5f, 1e-6f);
    // A normal with only some words NaN or infinite counts as none too:
    // tinyobjloader read each of them as 0 and kept (1, 0, 1).
    for (const char* vn : {"vn 1 nan 1", "vn 1 inf 1", "vn 0 0 -inf"}) {
        dir.write("m.obj", std::string("v 0 0 0\nv 1 0 0\nv 0 1 0\n") + vn + "\nf 1//1 2//1 3//1\n");
        const Scene flat = load_scene(scene);
        ASSERT_EQ(flat.normals.size(), 1u);
        EXPECT_EQ(flat.normals[0].n0_x, 0.0f) << vn;
        EXPECT_EQ(flat.normals[0].n0_z, 1.0f) << vn;
    }
}

// Some editors start a file with a UTF-8 byte order mark. tinyobjloader
// read it as part of line 1's keyword and dropped the line without a word:
// here the OBJ's first vertex (shifting every face index by one, so the
// triangle came out as vertices 2, 3, 4) and the MTL's newmtl (so usemtl
// named an unknown material).
TEST(SceneLoader, ObjAndMtlByteOrderMarksAreSkipped) {
    TempDir dir;
    dir.write("m.obj", "\xEF\xBB\xBF" "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nmtllib m.mtl\nusemtl red\nf 1 2 3\n");
    dir.write("m.mtl", "\xEF\xBB\xBF" "newmtl red\nKd 0.9 0.1 0.1\n");
    const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "m.obj"}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
    const Scene loaded = load_scene(scene);
    ASSERT_EQ(loaded.triangles.size(), 1u);
    expect_near(vertex(loaded.triangles[0], 0), {0, 0, 0});
    expect_near(vertex(loaded.triangles[0], 1), {1, 0, 0});
    expect_near(vertex(loaded.triangles[0], 2), {0, 1, 0});
    EXPECT_NEAR(loaded.materials.at(loaded.triangles[0].material).kd_r, 0.9f, 1e-6f);
    // The number check counts lines as before: the mark is not a line.
    dir.write("m.obj", "\xEF\xBB\xBF" "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
    const std::string message = input_error_of([&] { load_scene(scene); });
    EXPECT_NE(message.find("m.obj: line 2 (v): 'nan' is not a number"), std::string::npos) << message;
    // A UTF-16 OBJ or MTL is refused as such (the OBJ read as having no
    // usable triangles).
    dir.write("m.obj", std::string("\xFF\xFE") + "v\0 \0" "0\0");
    EXPECT_NE(input_error_of([&] { load_scene(scene); }).find("m.obj: is UTF-16 text"), std::string::npos);
    dir.write("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nmtllib m.mtl\nusemtl red\nf 1 2 3\n");
    dir.write("m.mtl", std::string("\xFE\xFF") + "\0n\0e\0w");
    EXPECT_NE(input_error_of([&] { load_scene(scene); }).find("m.mtl: is UTF-16 text"), std::string::npos);
}

// Polygons are cut into triangles inside them, each keeping the face's
// winding: tinyobjloader cut a concave quad (a dart) along its shorter
// diagonal, outside the quad, and its ear clipping filled in concave
// polygons (an L, a U) or left parts out, by where they lay.
TEST(ObjPolygons, TrianglesCoverEveryPolygonExactly) {
    // Twice the signed area of (a, b, c), and the polygon's by the shoelace
    // formula, in double.
    const auto turn = [](glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
        return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    };
    const auto area = [&](const std::vector<glm::vec2>& p) {
        double a = 0.0;
        for (std::size_t i = 1; i + 1 < p.size(); ++i) a += turn(p[0], p[i], p[i + 1]);
        return 0.5 * a;
    };
    const std::vector<std::vector<glm::vec2>> shapes = {
        {{-0.3f, -0.8f}, {0.0f, -0.5f}, {0.3f, -0.8f}, {0.0f, 0.8f}},  // dart: its shorter diagonal lies outside
        {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 3}, {0, 3}},                // L
        {{0, 0}, {3, 0}, {3, 3}, {2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}},  // U
        {{0, 0}, {5, 0}, {5, 1}, {4, 1}, {4, 3}, {3, 3}, {3, 1}, {2, 1}, {2, 3}, {1, 3}, {1, 1}, {0, 1}},  // comb
    };
    for (std::size_t s = 0; s < shapes.size(); ++s)
        for (bool clockwise : {false, true})
            for (std::size_t start = 0; start < shapes[s].size(); ++start)
                for (const glm::vec3 offset : {glm::vec3(0.0f), glm::vec3(100.0f, -40.0f, 7.0f)}) {
                    // The shape turned, started at another corner, moved, and
                    // placed in a tilted plane.
                    std::vector<glm::vec2> flat;
                    for (std::size_t k = 0; k < shapes[s].size(); ++k)
                        flat.push_back(shapes[s][(start + (clockwise ? shapes[s].size() - k : k)) % shapes[s].size()]);
                    const glm::vec3 ax = glm::normalize(glm::vec3(1.0f, 0.2f, 0.3f));
                    const glm::vec3 ay = glm::normalize(glm::cross(glm::vec3(0.1f, 0.3f, 1.0f), ax));
                    std::vector<glm::vec3> corners;
                    for (const glm::vec2 q : flat) corners.push_back(offset + q.x * ax + q.y * ay);
                    const double want = area(flat);
                    double covered = 0.0;
                    const auto triangles = loader::triangulate_polygon(corners);
                    // One fewer for each straight corner, none with no area.
                    ASSERT_LE(triangles.size(), flat.size() - 2) << s;
                    for (const auto& [a, b, c] : triangles) {
                        const double t = 0.5 * turn(flat[a], flat[b], flat[c]);
                        // Each triangle turns as the polygon does, so none
                        // reaches outside it and together they cover it.
                        EXPECT_GT(t * want, 0.0) << "shape " << s << " clockwise " << clockwise << " start " << start;
                        covered += t;
                    }
                    EXPECT_NEAR(covered, want, 1e-9 * std::abs(want) + 1e-12) << "shape " << s;
                }
}

// Through the loader: the dart quad's two triangles cover its area only,
// and a corner index out of range is an error, as in a triangle
// (tinyobjloader dropped the quad's face with a warning).
TEST(ObjPolygons, ConcaveQuadLoadsInsideAndBadIndicesAreRefused) {
    TempDir dir;
    const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0]},
 "meshes": [{"obj": "m.obj"}], "lights": [{"type": "point", "position": [0, 0, 2], "intensity": [1, 1, 1]}]})");
    dir.write("m.obj", "v -0.3 -0.8 0\nv 0 -0.5 0\nv 0.3 -0.8 0\nv 0 0.8 0\nf 1 2 3 4\n");
    const Scene loaded = load_scene(scene);
    ASSERT_EQ(loaded.triangles.size(), 2u);
    double covered = 0.0;
    for (const gpu::Triangle& t : loaded.triangles) {
        const glm::vec3 a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
        const double z = 0.5 * glm::cross(b - a, c - a).z;
        EXPECT_GT(z, 0.0);  // the face's counter-clockwise winding
        covered += z;
    }
    EXPECT_NEAR(covered, 0.48 - 0.09, 1e-6);  // the triangle round it, less the notch
    dir.write("m.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 2 3 9\n");
    EXPECT_NE(input_error_of([&] { load_scene(scene); }).find("m.obj: face 2: vertex index 9 out of range (4 vertices)"),
              std::string::npos);
    // Relative indices reaching back before the first element, one too far
    // included, which tinyobjloader would read as "no normal".
    dir.write("m.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf -1 -2 -4\n");
    EXPECT_NE(input_error_of([&] { load_scene(scene); })
                  .find("m.obj: line 4 (f): corner '-4': relative index -4 reaches back before the first of the 3 "
                        "vertices read so far"),
              std::string::npos);
    dir.write("m.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nvn 0 0 1\nf 1//1 2//1 3//-2\n");
    EXPECT_NE(input_error_of([&] { load_scene(scene); })
                  .find("m.obj: line 5 (f): corner '3//-2': relative index -2 reaches back before the first of the 1 "
                        "normals read so far"),
              std::string::npos);
    // Faces of one or two corners have no surface: skipped, with a note.
    dir.write("m.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 2\nf 3\n");
    const Scene short_faces = load_scene(scene);
    EXPECT_EQ(short_faces.triangles.size(), 1u);
    EXPECT_TRUE(std::any_of(short_faces.load_notes.begin(), short_faces.load_notes.end(), [](const std::string& n) {
        return n.find("m.obj: 2 faces have fewer than 3 corners (a point or a line, no surface): skipped") !=
               std::string::npos;
    }));
    std::string big = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf";
    for (int k = 0; k < 256; ++k) big.append(" ").append(std::to_string(k % 3 + 1));
    dir.write("m.obj", big + "\n");
    EXPECT_NE(input_error_of([&] { load_scene(scene); }).find("m.obj: line 4 (f): a face of 256 corners; at most 255"),
              std::string::npos);
}

// A material library must be a regular file: tinyobjloader read a folder as
// an empty library and /dev/zero until memory ran out (and a pipe until its
// writer closes it). Refused with or without a material override.
// Every library a `mtllib` line names is read (tinyobjloader read only the
// first it found, so `usemtl blue` of the second was an error).
TEST(SceneLoader, MtllibReadsEveryLibraryOfItsLine) {
    TempDir dir;
    dir.write("a.mtl", "newmtl red\nKd 0.9 0.1 0.1\n");
    dir.write("b.mtl", "newmtl blue\nKd 0.1 0.1 0.9\n");
    dir.write("m.obj", "mtllib a.mtl missing.mtl b.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl blue\nf 1 2 3\n"
                       "usemtl red\nf 1 2 3\n");
    const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "m.obj"}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
    const Scene loaded = load_scene(scene);
    ASSERT_EQ(loaded.triangles.size(), 2u);
    EXPECT_NEAR(loaded.materials.at(loaded.triangles[0].material).kd_b, 0.9f, 1e-6f);
    EXPECT_NEAR(loaded.materials.at(loaded.triangles[1].material).kd_r, 0.9f, 1e-6f);
}

// Libraries apart by tabs, a line that ends in a space or a tab, and a
// library named on two lines, with another after it on the second: each
// library is read (tinyobjloader splits at spaces only, so a tab stayed in
// the name and a trailing space named the OBJ's folder; and the second
// line's other library was never read).
TEST(SceneLoader, MtllibLinesSplitAtAnyBlankAndRepeatNames) {
    TempDir dir;
    dir.write("a.mtl", "newmtl red\nKd 0.9 0.1 0.1\n");
    dir.write("b.mtl", "newmtl blue\nKd 0.1 0.1 0.9\n");
    dir.write("c.mtl", "newmtl green\nKd 0.1 0.9 0.1\n");
    const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "m.obj"}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
    for (const char* libraries : {"mtllib a.mtl\tb.mtl \nmtllib c.mtl\t\n", "mtllib a.mtl b.mtl\nmtllib b.mtl c.mtl\n",
                                  "mtllib a.mtl \r\nmtllib b.mtl\tc.mtl\r\n"}) {
        dir.write("m.obj", std::string(libraries) + "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n"
                                                      "usemtl blue\nf 1 2 3\nusemtl green\nf 1 2 3\n");
        const Scene loaded = load_scene(scene);
        ASSERT_EQ(loaded.triangles.size(), 3u) << libraries;
        EXPECT_NEAR(loaded.materials.at(loaded.triangles[0].material).kd_r, 0.9f, 1e-6f) << libraries;
        EXPECT_NEAR(loaded.materials.at(loaded.triangles[1].material).kd_b, 0.9f, 1e-6f) << libraries;
        EXPECT_NEAR(loaded.materials.at(loaded.triangles[2].material).kd_g, 0.9f, 1e-6f) << libraries;
    }
}

// A usemtl in an OBJ without any mtllib line says so (it said "not found in
// .mtl", naming a file that was never asked for), as does one before the
// OBJ's first mtllib line.
TEST(SceneLoader, UsemtlWithoutMtllibSaysSo) {
    TempDir dir;
    dir.write("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl foo\nf 1 2 3\n");
    const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "m.obj"}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
    EXPECT_EQ(input_error_of([&] { load_scene(scene); }),
              (dir.path() / "m.obj").lexically_normal().string() +
                  ": usemtl: tinyobjloader: material [ 'foo' ] not found: the OBJ has no mtllib line");
    // ... and one before the mtllib line that would define it says that.
    dir.write("m.mtl", "newmtl foo\nKd 0.5 0.5 0.5\n");
    dir.write("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl foo\nf 1 2 3\nmtllib m.mtl\n");
    EXPECT_EQ(input_error_of([&] { load_scene(scene); }),
              (dir.path() / "m.obj").lexically_normal().string() +
                  ": usemtl: tinyobjloader: material [ 'foo' ] not found in .mtl (line 4's usemtl comes before "
                  "line 6's mtllib, which reads the library)");
}

// A `mtllib` line needs one of its files to exist (the others are read
// where they exist too); the message names a file of the line that found
// none, not one an earlier line skipped on its way to a file it found.
TEST(SceneLoader, MissingMtllibNamesTheLineThatFoundNone) {
    TempDir dir;
    dir.write("b.mtl", "newmtl m\nKd 0.5 0.5 0.5\n");
    dir.write("m.obj", "mtllib a.mtl b.mtl\nmtllib c.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "m.obj"}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
    EXPECT_EQ(input_error_of([&] { load_scene(scene); }),
              (dir.path() / "m.obj").lexically_normal().string() + ": mtllib: 'c.mtl' not found next to the OBJ");
}

TEST(SceneLoader, MtllibMustNameARegularFile) {
    TempDir dir;
    fs::create_directories(dir.path() / "sub");
    fs::create_symlink("/dev/zero", dir.path() / "zero.mtl");
    ASSERT_EQ(::mkfifo((dir.path() / "pipe.mtl").c_str(), 0600), 0);
    for (const auto& [library, problem] : {std::pair<const char*, const char*>{".", "is a folder, not a file"},
                                           {"sub", "is a folder, not a file"},
                                           {"zero.mtl", "is a device, not a regular file"},
                                           {"pipe.mtl", "is a pipe, not a regular file"}}) {
        for (const char* material : {"", R"(, "material": {"kd": [0.5, 0.5, 0.5]})"}) {
            dir.write("m.obj", std::string("mtllib ") + library + "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
            const fs::path scene = dir.write("s.json", std::string(R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "m.obj")") + material + R"(}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
            const std::string message = input_error_of([&] { load_scene(scene); });
            EXPECT_EQ(message,
                      (dir.path() / "m.obj").lexically_normal().string() + ": mtllib: '" + library + "' " + problem)
                << library << material;
        }
    }
}

// A mesh file that cannot be looked at says why, not "file not found"; an
// empty name is refused as such (it named the scene's folder).
TEST(SceneLoader, MeshFileProblemsSayWhat) {
    TempDir dir;
    fs::create_symlink("loop_b.obj", dir.path() / "loop_a.obj");
    fs::create_symlink("loop_a.obj", dir.path() / "loop_b.obj");
    for (const auto& [obj, problem] :
         {std::pair<std::string, std::string>{"loop_a.obj", "meshes[0].obj: '" +
                                                                (dir.path() / "loop_a.obj").lexically_normal().string() +
                                                                "' cannot be looked at: Too many levels of symbolic links"},
          {"", "meshes[0].obj: is empty: it must name a file"}}) {
        const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": ")" + obj + R"("}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
        const std::string message = input_error_of([&] { load_scene(scene); });
        EXPECT_NE(message.find(problem), std::string::npos) << message;
    }
}

// camera.up only gives a direction: one whose float length under- or
// overflows (its square is out of float range) is used, as a unit vector;
// only zero is refused.
TEST(SceneLoader, CameraUpOfAnyNonZeroLengthIsUsed) {
    TempDir dir;
    fs::copy_file(kFixtures / "tri.obj", dir.path() / "tri.obj");
    auto with_up = [&](const char* up) {
        return dir.write("s.json", std::string(R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0], "up": )") +
                                       up + R"(}, "meshes": [{"obj": "tri.obj"}],
 "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
    };
    for (const char* up : {"[0, 1e-30, 0]", "[0, 1e30, 0]", "[0, 3e38, 0]", "[0, 1e-45, 0]", "[0, 2, 0]"})
        expect_near(load_scene(with_up(up)).camera.up, {0, 1, 0});
    const fs::path zero = with_up("[0, 0, 0]");
    EXPECT_EQ(input_error_of([&] { load_scene(zero); }), zero.lexically_normal().string() + ": camera.up: must not be zero");
}

// Scene::input_files lists every file the loader read, so that no render
// output can replace one of them (reserve_render_outputs).
TEST(SceneLoader, InputFilesListEveryFileRead) {
    auto names = [](const Scene& s) {
        std::set<std::string> out;
        for (const fs::path& f : s.input_files) out.insert(f.filename().string());
        return out;
    };
    EXPECT_EQ(names(load_scene(kFixtures / "materials.json")),
              (std::set<std::string>{"materials.json", "materials.obj", "materials.mtl"}));
    EXPECT_EQ(names(load_scene(kScenes / "room" / "room.gltf")), (std::set<std::string>{"room.gltf", "room.bin"}));
    const std::set<std::string> room = names(load_scene(kScenes / "room" / "room.json"));
    for (const char* f : {"room.json", "room.obj", "room.mtl", "torus.obj", "room_lights.csv"})
        EXPECT_EQ(room.count(f), 1u) << f;
    // An environment map (read by tinyexr), a glTF's images (by tinygltf).
    TempDir dir;
    fs::copy_file(kFixtures / "tri.obj", dir.path() / "tri.obj");
    fs::copy_file(kScenes / "sky" / "sky.exr", dir.path() / "sky.exr");
    const fs::path sky = dir.write("sky.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "tri.obj"}], "lights": [{"type": "environment", "file": "sky.exr"}]})");
    EXPECT_EQ(names(load_scene(sky)), (std::set<std::string>{"sky.json", "tri.obj", "sky.exr"}));
    const std::set<std::string> textured = names(load_scene(kScenes / "gltf" / "textured.gltf"));
    for (const char* f : {"textured.gltf", "textured.bin", "checker.png", "metal_rough.png", "glow.png", "bumps.png"})
        EXPECT_EQ(textured.count(f), 1u) << f;
}

// tinyobj's Pr is 0 when the MTL has none; any other value was given and
// is checked (a negative one was taken for "none").
TEST(SceneLoader, MtlRoughnessOutOfRangeIsRefused) {
    for (const char* pr : {"-0.5", "1.5"}) {
        TempDir dir;
        dir.write("m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n");
        dir.write("m.mtl", std::string("newmtl m\nKd 0.5 0.5 0.5\nKs 0.2 0.2 0.2\nPr ") + pr + "\n");
        const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "m.obj"}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
        const std::string message = input_error_of([&] { load_scene(scene); });
        EXPECT_NE(message.find("m.obj: material 'm'.Pr: must be in [0, 1]"), std::string::npos) << pr << ": " << message;
    }
}

// A look_at so far from the position that their distance overflows a float
// is named as that, not as "must differ from camera.position".
TEST(SceneLoader, CameraDistanceBeyondFloatIsNamed) {
    TempDir dir;
    fs::copy_file(kFixtures / "tri.obj", dir.path() / "tri.obj");
    const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 3e38, 7], "look_at": [0, -3e38, 0]},
 "meshes": [{"obj": "tri.obj"}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
    const std::string message = input_error_of([&] { load_scene(scene); });
    EXPECT_NE(message.find("camera.look_at: is too far from camera.position"), std::string::npos) << message;
    // And one so close that the square of their distance underflows.
    const fs::path close = dir.write("c.json", R"({"camera": {"position": [0, 0, 1e-30], "look_at": [0, 0, 0]},
 "meshes": [{"obj": "tri.obj"}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
    EXPECT_NE(input_error_of([&] { load_scene(close); }).find("camera.look_at: is too close to camera.position"),
              std::string::npos);
}

// An environment map may hold 2^27 pixels (the images `compare` reads,
// 2^28): the header's size is checked before tinyexr allocates the pixels.
// Here a 2 x 2 map whose header claims 12000 x 12000.
TEST(SceneLoader, EnvironmentMapLargerThanTheLimitIsRefusedFromItsHeader) {
    TempDir dir;
    fs::copy_file(kFixtures / "tri.obj", dir.path() / "tri.obj");
    const fs::path map = dir.path() / "big.exr";
    lc::Image small(2, 2);
    lc::write_exr(map, small);
    test::set_exr_data_window(map, 11999, 11999);
    const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "tri.obj"}], "lights": [{"type": "environment", "file": "big.exr"}]})");
    const std::string message = input_error_of([&] { load_scene(scene); });
    EXPECT_NE(message.find("big.exr: is 12000 x 12000 pixels, more than the 134217728 it may hold"), std::string::npos)
        << message;
}

// A black environment, a map of zeros or a black colour, gets a note, as
// black lights get a word in the report (it was accepted in silence).
TEST(SceneLoader, BlackEnvironmentGetsANote) {
    TempDir dir;
    fs::copy_file(kFixtures / "tri.obj", dir.path() / "tri.obj");
    lc::write_exr(dir.path() / "black.exr", lc::Image(4, 2));
    for (const std::string sky : {R"({"type": "environment", "file": "black.exr"})",
                                  R"({"type": "environment", "color": [0, 0, 0]})"}) {
        const fs::path scene = dir.write("s.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "tri.obj"}], "lights": [)" + sky + "]}");
        const Scene loaded = load_scene(scene);
        EXPECT_TRUE(std::any_of(loaded.load_notes.begin(), loaded.load_notes.end(), [](const std::string& n) {
            return n.find("s.json: lights[0]: the environment is black; it adds no light") != std::string::npos;
        })) << sky;
    }
    const fs::path lit = dir.write("s.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "tri.obj"}], "lights": [{"type": "environment", "color": [0, 0, 1e-30]}]})");
    EXPECT_TRUE(load_scene(lit).load_notes.empty());
}

TEST(SceneLoader, MaterialOverrideReplacesMtlForWholeMesh) {
    const Scene scene = load_scene(kFixtures / "override.json");
    ASSERT_EQ(scene.materials.size(), 2u);  // one per overridden mesh, none from the MTL
    ASSERT_EQ(scene.triangles.size(), 5u);
    for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(scene.triangles[i].material, 0u);
    EXPECT_EQ(scene.triangles[4].material, 1u);

    const gpu::Material& glossy = scene.materials[0];
    expect_near({glossy.kd_r, glossy.kd_g, glossy.kd_b}, {0.3f, 0.2f, 0.1f});
    expect_near({glossy.ks_r, glossy.ks_g, glossy.ks_b}, glm::vec3(0.5f));
    EXPECT_NEAR(glossy.alpha, 0.16f, 1e-6f);  // roughness^2
    EXPECT_NE(glossy.flags & gpu::kMaterialHasSpecular, 0u);

    const gpu::Material& matte = scene.materials[1];
    expect_near({matte.kd_r, matte.kd_g, matte.kd_b}, glm::vec3(0.9f));
    EXPECT_EQ(matte.flags & gpu::kMaterialHasSpecular, 0u);
}

// ---------------------------------------------------------------------------
// Disney materials (docs/scene-format.md): JSON keys and MTL's PBR keys.
// ---------------------------------------------------------------------------

// tri.obj with the given mesh material (JSON object text), in a fresh directory.
fs::path scene_with_material(const TempDir& dir, const std::string& material) {
    fs::copy_file(kFixtures / "tri.obj", dir.path() / "tri.obj", fs::copy_options::overwrite_existing);
    return dir.write("material.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "tri.obj", "material": )" + material + R"(}],
 "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]}
)");
}

TEST(SceneLoader, DisneyKeysMakeADisneyMaterial) {
    TempDir dir;
    const Scene scene = load_scene(scene_with_material(dir, R"({"base_color": [0.9, 0.5, 0.1], "metallic": 0.25,
        "roughness": 0.4, "specular": 0.3, "specular_tint": 0.2, "sheen": 0.7, "sheen_tint": 0.6,
        "clearcoat": 0.8, "clearcoat_gloss": 0.1, "emission": [1, 2, 3]})"));
    ASSERT_EQ(scene.materials.size(), 1u);
    const gpu::Material& m = scene.materials[0];
    EXPECT_NE(m.flags & gpu::kMaterialDisney, 0u);
    EXPECT_NE(m.flags & gpu::kMaterialHasSheen, 0u);
    EXPECT_NE(m.flags & gpu::kMaterialHasClearcoat, 0u);
    EXPECT_NE(m.flags & gpu::kMaterialEmissive, 0u);
    EXPECT_EQ(m.flags & gpu::kMaterialHasSpecular, 0u);
    expect_near({m.kd_r, m.kd_g, m.kd_b}, {0.9f, 0.5f, 0.1f});
    EXPECT_FLOAT_EQ(m.metallic, 0.25f);
    EXPECT_FLOAT_EQ(m.roughness, 0.4f);
    EXPECT_NEAR(m.alpha, 0.16f, 1e-6f);
    EXPECT_FLOAT_EQ(m.specular, 0.3f);
    EXPECT_FLOAT_EQ(m.specular_tint, 0.2f);
    EXPECT_FLOAT_EQ(m.sheen, 0.7f);
    EXPECT_FLOAT_EQ(m.sheen_tint, 0.6f);
    EXPECT_FLOAT_EQ(m.clearcoat, 0.8f);
    EXPECT_FLOAT_EQ(m.clearcoat_gloss, 0.1f);

    // One Disney key is enough; the rest take Burley's defaults, and no
    // sheen or clearcoat means no such lobe.
    const Scene plain = load_scene(scene_with_material(dir, R"({"metallic": 1})"));
    const gpu::Material& p = plain.materials[0];
    EXPECT_NE(p.flags & gpu::kMaterialDisney, 0u);
    EXPECT_EQ(p.flags & (gpu::kMaterialHasSheen | gpu::kMaterialHasClearcoat), 0u);
    expect_near({p.kd_r, p.kd_g, p.kd_b}, glm::vec3(0.8f));
    EXPECT_FLOAT_EQ(p.roughness, 0.5f);
    EXPECT_FLOAT_EQ(p.specular, 0.5f);
    EXPECT_FLOAT_EQ(p.clearcoat_gloss, 1.0f);

    // Roughness alone is shared by both kinds: still Lambert + GGX.
    const Scene lambert = load_scene(scene_with_material(dir, R"({"kd": [0.5, 0.5, 0.5], "roughness": 0.3})"));
    EXPECT_EQ(lambert.materials[0].flags & gpu::kMaterialDisney, 0u);
}

TEST(SceneLoader, BadDisneyMaterialsNameTheField) {
    struct Bad {
        const char* material;
        const char* field;
    };
    for (const Bad& b : {Bad{R"({"base_color": [0.5, 0.5, 0.5], "kd": [0.5, 0.5, 0.5]})", "kd"},
                         Bad{R"({"ks": [0.5, 0.5, 0.5], "sheen": 0.5})", "ks"},
                         Bad{R"({"metallic": 1.5})", "metallic"}, Bad{R"({"metallic": -0.1})", "metallic"},
                         Bad{R"({"specular": 2})", "specular"}, Bad{R"({"specular_tint": "a"})", "specular_tint"},
                         Bad{R"({"sheen": -1})", "sheen"}, Bad{R"({"sheen_tint": 1.01})", "sheen_tint"},
                         Bad{R"({"clearcoat": 1e9})", "clearcoat"}, Bad{R"({"clearcoat_gloss": -0.5})", "clearcoat_gloss"},
                         Bad{R"({"base_color": [0.5, 1.5, 0.5]})", "base_color[1]"},
                         Bad{R"({"metallic": 0.5, "roughness": 0})", "roughness"}}) {
        TempDir dir;
        const fs::path file = scene_with_material(dir, b.material);
        const std::string message = input_error_of([&] { load_scene(file); });
        const std::string start = file.lexically_normal().string() + ": meshes[0].material." + b.field + ": ";
        EXPECT_EQ(message.rfind(start, 0), 0u) << b.material << " -> " << message;
    }
}

TEST(SceneLoader, MtlPbrKeysMakeADisneyMaterial) {
    TempDir dir;
    dir.write("pbr.mtl", R"(newmtl coated
Kd 0.6 0.5 0.4
Ks 0.9 0.9 0.9
Pr 0.3
Pc 0.7
Pcr 0.2

newmtl metal
Kd 0.9 0.8 0.5
Pm 1
Ps 0.4

newmtl plain
Kd 0.2 0.3 0.4
Pr 0.5
)");
    dir.write("pbr.obj", R"(mtllib pbr.mtl
v 0 0 0
v 1 0 0
v 0 1 0
usemtl coated
f 1 2 3
usemtl metal
f 1 2 3
usemtl plain
f 1 2 3
)");
    const Scene scene = load_scene(dir.write("pbr.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "pbr.obj"}],
 "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]}
)"));
    ASSERT_EQ(scene.materials.size(), 3u);
    const gpu::Material& coated = scene.materials[0];
    EXPECT_NE(coated.flags & gpu::kMaterialDisney, 0u);
    EXPECT_NE(coated.flags & gpu::kMaterialHasClearcoat, 0u);
    EXPECT_EQ(coated.flags & gpu::kMaterialHasSheen, 0u);
    expect_near({coated.kd_r, coated.kd_g, coated.kd_b}, {0.6f, 0.5f, 0.4f});
    EXPECT_FLOAT_EQ(coated.roughness, 0.3f);
    EXPECT_FLOAT_EQ(coated.clearcoat, 0.7f);
    EXPECT_FLOAT_EQ(coated.clearcoat_gloss, 0.8f);
    EXPECT_FLOAT_EQ(coated.metallic, 0.0f);

    const gpu::Material& metal = scene.materials[1];
    EXPECT_NE(metal.flags & gpu::kMaterialDisney, 0u);
    EXPECT_NE(metal.flags & gpu::kMaterialHasSheen, 0u);
    EXPECT_FLOAT_EQ(metal.metallic, 1.0f);
    EXPECT_FLOAT_EQ(metal.sheen, 0.4f);
    EXPECT_FLOAT_EQ(metal.roughness, 0.5f);  // no Pr: the default

    const gpu::Material& plain = scene.materials[2];
    EXPECT_EQ(plain.flags & gpu::kMaterialDisney, 0u);  // Pr alone: Lambert + GGX as before
    EXPECT_NEAR(plain.alpha, 0.25f, 1e-6f);

    // Out of range: the error names the key.
    dir.write("pbr.mtl", "newmtl coated\nKd 0.6 0.5 0.4\nPm 1.5\n");
    dir.write("pbr.obj", "mtllib pbr.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl coated\nf 1 2 3\n");
    const fs::path bad = dir.path() / "pbr.json";
    const std::string message = input_error_of([&] { load_scene(bad); });
    EXPECT_NE(message.find("material 'coated'.Pm: "), std::string::npos) << message;
}

TEST(SceneLoader, TransformAppliesScaleThenRotateXyzThenTranslate) {
    const Scene scene = load_scene(kFixtures / "transform.json");
    ASSERT_EQ(scene.triangles.size(), 5u);

    // tri.obj is (0,0,0), (1,0,0), (0,1,0). Scale x2, yaw 90 degrees, move (1,2,3).
    const gpu::Triangle& a = scene.triangles[0];
    expect_near(vertex(a, 0), {1, 2, 3});
    expect_near(vertex(a, 1), {1, 2, 1});
    expect_near(vertex(a, 2), {1, 3, 3});
    for (int i = 0; i < 3; ++i) expect_near(normal(scene.normals[0], i), {1, 0, 0});

    // X first, then Y: (0,1,0) -> X90 -> (0,0,1) -> Y90 -> (1,0,0).
    // (Y first would leave it at (0,0,1).)
    const gpu::Triangle& b = scene.triangles[1];
    expect_near(vertex(b, 1), {0, 0, -1});
    expect_near(vertex(b, 2), {1, 0, 0});

    // Vertex normals go through the inverse transpose and are renormalised:
    // (1,1,0) under scale (2,1,1) becomes (0.5,1,0) / |.|.
    const gpu::TriangleNormals& n = scene.normals[2];
    expect_near(normal(n, 0), glm::normalize(glm::vec3(0.5f, 1.0f, 0.0f)));
    expect_near(normal(n, 1), {0, 0, 1});
    expect_near(normal(n, 2), {0, 1, 0});

    // A mirroring scale flips the winding; the face normal keeps the side the
    // OBJ meant: the inverse transpose of diag(-1,1,1) maps (0,0,1) to (0,0,1).
    // The last two corners are swapped, so the winding faces that side too.
    for (int i = 0; i < 3; ++i) expect_near(normal(scene.normals[3], i), {0, 0, 1});
    expect_near(vertex(scene.triangles[3], 2), {-1, 0, 0});
    expect_near(winding_normal(scene.triangles[3]), {0, 0, 1});

    // A scalar scale is uniform.
    expect_near(vertex(scene.triangles[4], 2), {0, 3, 0});
}

TEST(SceneLoader, DegenerateTrianglesAreDroppedAndCounted) {
    const Scene scene = load_scene(kFixtures / "degenerate.json");
    // degenerate.obj: 1 good + 3 degenerate; tri.obj: 1 good.
    EXPECT_EQ(scene.triangles.size(), 2u);
    EXPECT_EQ(scene.normals.size(), 2u);
    EXPECT_EQ(scene.degenerate_triangles_dropped, 3u);
}

// A triangle too large for float arithmetic (its area's square overflows)
// is refused naming it; it was dropped and counted as degenerate. One
// 1e8 units wide loads.
TEST(SceneLoader, TooLargeTrianglesAreNamed) {
    auto scene_with = [](const TempDir& dir, const std::string& size) {
        dir.write("big.obj", "v -" + size + " 0 -" + size + "\nv " + size + " 0 -" + size + "\nv 0 0 " + size +
                                 "\nf 1 3 2\n");
        return dir.write("s.json", R"({"camera": {"position": [0, 5, 10], "look_at": [0, 0, 0]},
 "meshes": [{"obj": "big.obj"}], "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}]})");
    };
    TempDir dir;
    const Scene ground = load_scene(scene_with(dir, "1e8"));
    EXPECT_EQ(ground.triangles.size(), 1u);
    EXPECT_EQ(ground.degenerate_triangles_dropped, 0u);
    EXPECT_NEAR(ground.normals[0].n0_y, 1.0f, 1e-6f);
    const std::string message = input_error_of([&] { load_scene(scene_with(dir, "1e10")); });
    EXPECT_NE(message.find("big.obj: triangle 1: too large for the renderer's float arithmetic"),
              std::string::npos)
        << message;
}

TEST(SceneLoader, BoundsCoverTrianglesOnlyNotLights) {
    Scene scene = load_scene(kFixtures / "all_lights.json");
    // tri.obj spans [0,1]^2 x {0}; the point lights at (0,2,1), (1,2,3),
    // (-1.5,0.25,0.2) and (4,5,6) lie outside it and must not widen it.
    expect_near(scene.bounds_min, {0.0f, 0.0f, 0.0f});
    expect_near(scene.bounds_max, {1.0f, 1.0f, 0.0f});

    Scene empty;
    empty.lights.push_back(test::point_light({0, 9, 0}, {1, 1, 1}));
    empty.lights.push_back(test::directional_light({0, 0, -1}, {1, 1, 1}));
    update_bounds(empty);  // no triangles: the zero box, whatever the lights
    expect_near(empty.bounds_min, glm::vec3(0.0f));
    expect_near(empty.bounds_max, glm::vec3(0.0f));

    scene.lights.push_back(test::point_light({-10, 0, 0}, {1, 1, 1}));
    update_bounds(scene);
    EXPECT_FLOAT_EQ(scene.bounds_min.x, 0.0f);
}

// Regression: prepare_scene derives the inverse-square clamp from the bounds,
// so one far light used to set d_min = 1e-4 x 1e4 m = 1 m and darken the room.
TEST(SceneLoader, FarPointLightDoesNotChangeTheBounds) {
    const fs::path room_dir = kScenes / "room";
    std::ifstream in(room_dir / "room.json");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    // The copy lives elsewhere: point its relative paths back at scenes/room.
    for (const std::string key : {"\"obj\": \"", "\"file\": \""}) {
        for (auto at = text.find(key); at != std::string::npos; at = text.find(key, at + 1)) {
            text.insert(at + key.size(), room_dir.string() + "/");
        }
    }
    const std::string lights = "\"lights\": [";
    const auto at = text.find(lights);
    ASSERT_NE(at, std::string::npos);
    text.insert(at + lights.size(), R"({"type": "point", "position": [0, 1e4, 0], "intensity": [1, 1, 1]},)");
    TempDir dir;
    const Scene far = load_scene(dir.write("room_far_light.json", text));
    const Scene room = load_scene(room_dir / "room.json");
    ASSERT_EQ(far.lights.size(), room.lights.size() + 1);
    EXPECT_FLOAT_EQ(far.lights[0].y, 1e4f);
    EXPECT_EQ(far.bounds_min, room.bounds_min);
    EXPECT_EQ(far.bounds_max, room.bounds_max);
    expect_near(far.bounds_max, {2.5f, 3.0f, 3.0f});
}

// Tiny triangles keep unit normals: the cross product of edges of 1e-10
// is about 1e-20, whose square underflows a float, so a length taken in
// float came out short (a glTF the fuzzer made, regressions_gltf/
// tiny-triangle-normal.gltf). The face normals and the file's vertex
// normals of that size are normalised in double.
TEST(SceneLoader, TinyTrianglesKeepUnitNormals) {
    TempDir dir;
    dir.write("tiny.obj",
              "v 0 0 0\nv 1e-10 0 0\nv 0 1.3e-10 0\nv 5 0 0\nv 5 1e-10 0\nv 5.0000001 0 1e-10\n"
              "vn 0 0 1e-21\nvn 3e-21 0 1e-21\nvn 0 2e-21 1e-21\n"
              "f 1 2 3\nf 4//1 5//2 6//3\n");
    const Scene scene = load_scene(dir.write("tiny.json", R"({
        "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_y_degrees": 40,
                   "width": 8, "height": 8},
        "meshes": [{"obj": "tiny.obj"}],
        "lights": [{"type": "point", "position": [0, 0, 1], "intensity": [1, 1, 1]}]})"));
    ASSERT_EQ(scene.normals.size(), 2u);
    for (const gpu::TriangleNormals& n : scene.normals)
        for (const glm::vec3 v : {glm::vec3(n.n0_x, n.n0_y, n.n0_z), glm::vec3(n.n1_x, n.n1_y, n.n1_z),
                                  glm::vec3(n.n2_x, n.n2_y, n.n2_z)})
            EXPECT_NEAR(glm::length(v), 1.0f, 1e-6f);
}

TEST(SceneLoader, UpdateBoundsRefusesAnExtentBeyondTheLimit) {
    Scene scene;
    scene.file = "hand_built.json";
    // Each triangle 1e18 across; together 1.2e19.
    scene.triangles.push_back(gpu::Triangle{2e18f, 0, 0, 3e18f, 0, 0, 2e18f, 1, 0, 0, 0, 0});
    scene.triangles.push_back(gpu::Triangle{-8e18f, 0, 0, -8e18f, 1, 0, -9e18f, 0, 0, 0, 0, 0});
    const std::string message = input_error_of([&] { update_bounds(scene); });
    EXPECT_NE(message.find("hand_built.json: triangles[1]: "), std::string::npos) << message;
    EXPECT_NE(message.find("extent along x exceeds 1e19"), std::string::npos) << message;
}

// ---------------------------------------------------------------------------
// Bad input: each case names the file, the field and the problem.
// ---------------------------------------------------------------------------

struct BadInput {
    const char* scene;    // fixture under tests/data/scenes
    const char* file;     // file the message must name
    const char* field;    // JSON path, CSV line or OBJ location
    const char* problem;  // part of the description
};

void PrintTo(const BadInput& c, std::ostream* os) { *os << c.scene; }

class SceneLoaderBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(SceneLoaderBadInput, ThrowsInputErrorNamingFileAndField) {
    const BadInput& c = GetParam();
    const std::string message = input_error_of([&] { load_scene(kFixtures / c.scene); });
    EXPECT_NE(message.find(c.file), std::string::npos) << message;
    EXPECT_NE(message.find(c.field), std::string::npos) << message;
    EXPECT_NE(message.find(c.problem), std::string::npos) << message;
}

const BadInput kBadInputs[] = {
    // Malformed JSON: nlohmann's line/column.
    {"bad_syntax.json", "bad_syntax.json", "line 4", "parse error"},
    {"bad_not_object.json", "bad_not_object.json", "", "expected an object"},
    {"bad_duplicate_key.json", "bad_duplicate_key.json", "camera.width: ", "duplicate key"},
    {"bad_huge_number.json", "bad_huge_number.json", "lights[0].intensity[1]: ", "overflow"},
    // Missing required keys.
    {"bad_missing_camera_position.json", "bad_missing_camera_position.json", "camera.position: ",
     "missing required key"},
    {"bad_missing_lights.json", "bad_missing_lights.json", ": lights: ", "the scene has no light"},
    {"bad_no_light_at_all.json", "bad_no_light_at_all.json", ": lights: ", "no emissive material and no environment"},
    {"bad_missing_light_intensity.json", "bad_missing_light_intensity.json", "lights[0].intensity: ",
     "missing required key"},
    // Unknown keys anywhere.
    {"bad_unknown_top_key.json", "bad_unknown_top_key.json", ": rendr: ", "unknown key"},
    {"bad_unknown_light_key.json", "bad_unknown_light_key.json", "lights[1].colour: ", "unknown key"},
    {"bad_unknown_transform_key.json", "bad_unknown_transform_key.json", "meshes[0].transform.rotate: ",
     "unknown key"},
    {"bad_key_of_other_light_type.json", "bad_key_of_other_light_type.json", "lights[0].direction: ",
     "unknown key"},
    // Wrong types.
    {"bad_type_width.json", "bad_type_width.json", "camera.width: ", "expected a number, got string"},
    {"bad_type_width_float.json", "bad_type_width_float.json", "camera.width: ",
     "must be an integer from 1 to 16384"},
    {"bad_type_vec2.json", "bad_type_vec2.json", "camera.position: ", "3 numbers"},
    {"bad_type_intensity_element.json", "bad_type_intensity_element.json", "lights[0].intensity[1]: ",
     "expected a number"},
    {"bad_type_lights.json", "bad_type_lights.json", ": lights: ", "expected an array"},
    // Unknown light type.
    {"bad_light_type.json", "bad_light_type.json", "lights[0].type: ", "unknown light type \"area\""},
    // Spot lights, environments and emission (the light model).
    {"bad_spot_outer.json", "bad_spot_outer.json", "lights[0].outer_cone_degrees: ", "from 0 to 90"},
    {"bad_spot_inner.json", "bad_spot_inner.json", "lights[0].inner_cone_degrees: ", "from 0 to outer_cone_degrees"},
    {"bad_spot_direction.json", "bad_spot_direction.json", "lights[0].direction: ", "zero-length"},
    {"bad_spots_csv.json", "bad_spots.csv", "line 3: ", "outer_cone_degrees: must be from 0 to 90"},
    {"bad_env_two.json", "bad_env_two.json", "lights[1]: ", "at most one environment"},
    {"bad_env_both.json", "bad_env_both.json", "lights[0]: ", "exactly one of"},
    {"bad_env_missing.json", "nonexistent.exr", "lights[0].file: ", "file not found"},
    {"bad_env_negative.json", "bad_env_negative.json", "lights[0].color[0]: ", "negative"},
    {"bad_env_directions.json", "bad_env_directions.json", "lights[0].directions: ", "from 1 to 16777216"},
    {"bad_env_scale.json", "bad_env_scale.json", "lights[0].scale: ", "must be in (0, "},
    {"bad_env_nan.json", "bad_env_nan.exr", "pixel (1, 0): ", "finite"},
    {"bad_emission_negative.json", "bad_emission_negative.json", "meshes[0].material.emission[0]: ", "negative"},
    {"bad_mtl_ke.json", "bad_ke.obj", "material 'glow'.Ke: ", "from 0 to 3.4e38"},
    {"bad_area_samples.json", "bad_area_samples.json", "render.area_light_samples: ", "from 1 to 16777216"},
    // Missing files.
    {"bad_missing_obj.json", "nonexistent.obj", "meshes[1].obj: ", "file not found"},
    {"bad_missing_csv.json", "nonexistent.csv", "lights[1].file: ", "file not found"},
    // Non-finite and out-of-range values.
    {"bad_csv_nan.json", "nan.csv", "line 4: ", "not finite"},
    {"bad_csv_inf.json", "inf.csv", "line 3: ", "not finite"},
    {"bad_csv_overflow.json", "overflow.csv", "line 2: ", "out of range"},
    {"bad_negative_intensity.json", "bad_negative_intensity.json", "lights[0].intensity[2]: ", "negative"},
    {"bad_negative_irradiance.json", "bad_negative_irradiance.json", "lights[1].irradiance[0]: ",
     "negative"},
    {"bad_zero_direction.json", "bad_zero_direction.json", "lights[1].direction: ", "zero-length"},
    // Sums the light tree would overflow: totals per light type and channel,
    // also where a CSV tips them over, and a light too far from the geometry.
    {"bad_point_total.json", "bad_point_total.json", ": lights: ",
     "total red intensity of the point lights exceeds the float range (3.4e38)"},
    {"bad_directional_total.json", "bad_directional_total.json", ": lights: ",
     "total blue irradiance of the directional lights exceeds the float range (3.4e38)"},
    {"bad_csv_total.json", "total_overflow.csv", "line 5: ",
     "total red intensity of the point lights exceeds the float range (3.4e38)"},
    {"bad_light_far.json", "bad_light_far.json", "lights[1].position: ",
     "extent along y exceeds 1e19 (the renderer squares distances in float and sums three such squares)"},
    // Camera.
    {"bad_zero_width.json", "bad_zero_width.json", "camera.width: ", "must be an integer from 1 to 16384"},
    {"bad_negative_width.json", "bad_negative_width.json", "camera.width: ", "must be an integer from 1 to 16384"},
    {"bad_huge_height.json", "bad_huge_height.json", "camera.height: ", "must be an integer from 1 to 16384"},
    {"bad_fov.json", "bad_fov.json", "camera.fov_y_degrees: ", "(0, 180)"},
    {"bad_up_parallel.json", "bad_up_parallel.json", "camera.up: ", "parallel"},
    {"bad_camera_at_target.json", "bad_camera_at_target.json", "camera.look_at: ", "camera.position"},
    // Empty light list, also when it is empty only after loading the CSVs.
    {"bad_empty_lights.json", "bad_empty_lights.json", ": lights: ", "no lights"},
    {"bad_only_empty_csv.json", "bad_only_empty_csv.json", ": lights: ", "no lights"},
    // Meshes.
    {"bad_meshes_empty.json", "bad_meshes_empty.json", ": meshes: ", "at least one mesh"},
    {"bad_obj_garbage.json", "garbage.obj", "", "tinyobjloader"},
    {"bad_obj_no_faces.json", "no_faces.obj", "", "no usable triangles"},
    {"bad_obj_all_degenerate.json", "all_degenerate.obj", "", "no usable triangles"},
    {"bad_obj_index.json", "bad_index.obj", "triangle 1: ", "vertex index 9 out of range"},
    {"bad_obj_far_apart.json", "far_apart.obj", "triangle 2: ", "extent along x exceeds 1e19 (the renderer squares distances in float and sums three such squares)"},
    {"bad_obj_missing_mtl.json", "missing_mtl.obj", "mtllib: ", "'not_there.mtl' not found"},
    {"bad_obj_unknown_usemtl.json", "unknown_usemtl.obj", "usemtl: ", "no_such_material"},
    {"bad_mtl_kd.json", "bad_kd.obj", "material 'hot'.Kd: ", "[0, 1]"},
    {"bad_scale_zero.json", "bad_scale_zero.json", "meshes[0].transform.scale[1]: ", "zero"},
    {"bad_scale_tiny.json", "bad_scale_tiny.json", "meshes[0].transform: ", "every triangle of"},
    // A transform past float's range made the corners infinite, read as
    // a degenerate triangle and dropped with a warning.
    {"bad_translate_overflow.json", "bad_translate_overflow.json", "meshes[0].transform: ",
     "takes triangle 1 of "},
    {"bad_roughness.json", "bad_roughness.json", "meshes[0].material.roughness: ", "(0, 1]"},
    {"bad_kd_override.json", "bad_kd_override.json", "meshes[0].material.kd[1]: ", "at most 1"},
    // Render block.
    {"bad_render_method.json", "bad_render_method.json", "render.method: ",
     "\"brute\", \"lightcuts\", \"sampled\", \"stochastic\" or \"path\""},
    {"bad_render_spp.json", "bad_render_spp.json", "render.spp: ", "must be an integer from 1 to 65536"},
    {"bad_render_relative_error.json", "bad_render_relative_error.json", "render.relative_error: ",
     "must be a number from 0 to 1"},
    {"bad_render_max_cut.json", "bad_render_max_cut.json", "render.max_cut: ",
     "must be an integer from 1 to 4294967295"},
    {"bad_render_seed.json", "bad_render_seed.json", "render.seed: ", "must be an integer from 0 to 4294967295"},
};

INSTANTIATE_TEST_SUITE_P(Fixtures, SceneLoaderBadInput, ::testing::ValuesIn(kBadInputs),
                         [](const ::testing::TestParamInfo<BadInput>& info) {
                             std::string name = info.param.scene;
                             name = name.substr(0, name.find('.'));
                             for (char& ch : name) ch = std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
                             return name;
                         });

// The limits are per light type and only refuse what a float cannot hold.
TEST(SceneLoader, LightTotalsAreKeptPerTypeUpToFloatMax) {
    const Scene scene = load_scene(kFixtures / "large_totals.json");
    EXPECT_EQ(scene.count_lights(gpu::kLightPoint), 2u);
    EXPECT_EQ(scene.count_lights(gpu::kLightDirectional), 1u);
    EXPECT_FLOAT_EQ(scene.lights[2].x, 9e18f);  // within the extent limit, 1e19
}

// ---------------------------------------------------------------------------
// Render block: the ranges and texts of lightcuts/settings.h, as the CLI
// ---------------------------------------------------------------------------

// minimal.json with the given "render" block, in a fresh directory.
fs::path scene_with_render(const TempDir& dir, const std::string& render) {
    fs::copy_file(kFixtures / "tri.obj", dir.path() / "tri.obj", fs::copy_options::overwrite_existing);
    return dir.write("render.json", R"({"camera": {"position": [0, 0.5, 3], "look_at": [0, 0.5, 0]},
 "meshes": [{"obj": "tri.obj"}],
 "lights": [{"type": "point", "position": [0, 2, 1], "intensity": [1, 1, 1]}],
 "render": )" + render + "}\n");
}

struct BadSetting {
    const char* key;
    const char* json;  // the value as written in the file
    double value;      // the same value, for setting_problem
};

void PrintTo(const BadSetting& c, std::ostream* os) { *os << c.key << " = " << c.json; }

class RenderSettingRange : public ::testing::TestWithParam<BadSetting> {};

TEST_P(RenderSettingRange, RefusedWithTheSettingsText) {
    const BadSetting& c = GetParam();
    TempDir dir;
    const fs::path file = scene_with_render(dir, std::string(R"({")") + c.key + R"(": )" + c.json + "}");
    const std::string message = input_error_of([&] { load_scene(file); });
    const std::string problem = setting_problem(c.key, c.value);
    ASSERT_FALSE(problem.empty());
    EXPECT_EQ(message, file.lexically_normal().string() + ": render." + c.key + ": " + problem);
}

const BadSetting kBadSettings[] = {
    {"spp", "65537", 65537.0},
    {"spp", "2.5", 2.5},
    {"max_cut", "0", 0.0},
    {"relative_error", "1.5", 1.5},
    {"relative_error", "-0.1", -0.1},
    {"seed", "4294967296", 4294967296.0},
    {"light_samples", "0", 0.0},
    {"light_samples", "65537", 65537.0},
    {"max_bounces", "1025", 1025.0},
    {"max_bounces", "-1", -1.0},
    {"time_limit", "-2", -2.0},
    {"time_limit", "1e39", 1e39},
};

INSTANTIATE_TEST_SUITE_P(Cases, RenderSettingRange, ::testing::ValuesIn(kBadSettings),
                         [](const ::testing::TestParamInfo<BadSetting>& info) {
                             return std::string(info.param.key) + "_" + std::to_string(info.index);
                         });

// A finite value past the limit is named with the limit, not called
// "not a finite number".
TEST(SceneLoader, TimeLimitAndClampPastTheFloatRangeNameTheLimit) {
    TempDir dir;
    for (const auto& [json, field] : {std::pair<const char*, const char*>{R"({"time_limit": 1e308})", "render.time_limit"},
                                      {R"({"indirect": {"clamp": 1e300}})", "render.indirect.clamp"},
                                      {R"({"time_limit": -1})", "render.time_limit"}}) {
        const fs::path file = scene_with_render(dir, json);
        EXPECT_EQ(input_error_of([&] { load_scene(file); }),
                  file.lexically_normal().string() + ": " + field +
                      ": must be a number from 0 to 3.4e38 (the largest float)");
    }
}

// The largest float as the stats JSON spells it (3.4028235e+38, a little
// above FLT_MAX as a double) reads back; a positive clamp that a float
// rounds to 0, which would mean "none", is refused.
TEST(SceneLoader, TimeLimitAndClampRoundTripTheirFloats) {
    TempDir dir;
    const Scene scene = load_scene(
        scene_with_render(dir, R"({"time_limit": 3.4028235e+38, "indirect": {"clamp": 3.4028235e38}})"));
    EXPECT_EQ(scene.render.time_limit, 3.4028235e38);
    EXPECT_EQ(scene.render.indirect.clamp, std::numeric_limits<float>::max());
    const fs::path file = scene_with_render(dir, R"({"indirect": {"clamp": 1e-46}})");
    EXPECT_EQ(input_error_of([&] { load_scene(file); }),
              file.lexically_normal().string() +
                  ": render.indirect.clamp: must be 0 (none) or at least 1.4e-45 (the smallest float)");
    // Halfway between the largest float and the next power of two rounds
    // to infinity (ties to even); the double below it to the largest float.
    const double halfway = double(std::numeric_limits<float>::max()) + 0x1p103;
    EXPECT_EQ(static_cast<float>(std::nextafter(halfway, 0.0)), std::numeric_limits<float>::max());
    EXPECT_EQ(setting_problem(kSettingClamp, std::nextafter(halfway, 0.0)), "");
    EXPECT_NE(setting_problem(kSettingClamp, halfway), "");
}

TEST(SceneLoader, RenderSettingsAcceptTheFullRange) {
    TempDir dir;
    const Scene scene = load_scene(scene_with_render(
        dir, R"({"method": "brute", "spp": 65536, "relative_error": 1, "max_cut": 4000000000, "seed": 0})"));
    EXPECT_EQ(scene.render.spp, 65536u);
    EXPECT_FLOAT_EQ(scene.render.relative_error, 1.0f);
    EXPECT_EQ(scene.render.max_cut, 4000000000u);
    EXPECT_EQ(scene.render.seed, 0u);
}

TEST(SceneLoader, SamplingSettings) {
    TempDir dir;
    const Scene scene = load_scene(
        scene_with_render(dir, R"({"method": "sampled", "light_samples": 65536, "light_pick": "power"})"));
    EXPECT_EQ(scene.render.method, "sampled");
    EXPECT_EQ(scene.render.light_samples, 65536u);
    EXPECT_EQ(scene.render.light_pick, "power");
    const fs::path bad = scene_with_render(dir, R"({"light_pick": "random"})");
    EXPECT_EQ(input_error_of([&] { load_scene(bad); }),
              bad.lexically_normal().string() + ": render.light_pick: " + light_pick_problem("random"));
}

TEST(SceneLoader, CutSharingSetting) {
    TempDir dir;
    EXPECT_EQ(load_scene(scene_with_render(dir, R"({"method": "lightcuts"})")).render.cut_sharing, "auto");
    EXPECT_EQ(load_scene(scene_with_render(dir, R"({"cut_sharing": "pixel"})")).render.cut_sharing, "pixel");
    EXPECT_EQ(load_scene(scene_with_render(dir, R"({"cut_sharing": "quad"})")).render.cut_sharing, "quad");
    EXPECT_EQ(load_scene(scene_with_render(dir, R"({"cut_sharing": "octet"})")).render.cut_sharing, "octet");
    const fs::path bad = scene_with_render(dir, R"({"cut_sharing": "tiles"})");
    EXPECT_EQ(input_error_of([&] { load_scene(bad); }),
              bad.lexically_normal().string() + ": render.cut_sharing: " + cut_sharing_problem("tiles"));
    const fs::path wrong_type = scene_with_render(dir, R"({"cut_sharing": 4})");
    EXPECT_NE(input_error_of([&] { load_scene(wrong_type); }).find("render.cut_sharing"), std::string::npos);
}

TEST(SceneLoader, IndirectAndPathSettings) {
    TempDir dir;
    const Scene scene = load_scene(scene_with_render(
        dir, R"({"method": "path", "max_bounces": 4, "time_limit": 2.5,
                 "indirect": {"vpls": 16777216, "max_bounces": 0, "clamp": 0.05}})"));
    EXPECT_EQ(scene.render.method, "path");
    EXPECT_EQ(scene.render.max_bounces, 4u);
    EXPECT_DOUBLE_EQ(scene.render.time_limit, 2.5);
    EXPECT_EQ(scene.render.indirect.vpls, 16777216u);
    EXPECT_EQ(scene.render.indirect.max_bounces, 0u);
    EXPECT_FLOAT_EQ(scene.render.indirect.clamp, 0.05f);
    // Absent: direct light only, 3 bounces, no clamp.
    const Scene plain = load_scene(scene_with_render(dir, R"({"method": "lightcuts"})"));
    EXPECT_EQ(plain.render.indirect.vpls, 0u);
    EXPECT_EQ(plain.render.indirect.max_bounces, 3u);
    EXPECT_EQ(plain.render.indirect.clamp, 0.0f);
    // Each bad value is named with its path inside the block.
    struct Bad {
        const char* json;
        const char* field;
        std::string problem;
    };
    for (const Bad& b : {Bad{R"({"indirect": {"vpls": 16777217}})", "render.indirect.vpls",
                             setting_problem(kSettingVpls, 16777217.0)},
                         Bad{R"({"indirect": {"vpls": 1.5}})", "render.indirect.vpls",
                             setting_problem(kSettingVpls, 1.5)},
                         Bad{R"({"indirect": {"clamp": -1}})", "render.indirect.clamp",
                             setting_problem(kSettingClamp, -1.0)},
                         Bad{R"({"indirect": {"max_bounces": 2000}})", "render.indirect.max_bounces",
                             setting_problem(kSettingMaxBounces, 2000.0)},
                         Bad{R"({"indirect": {"vpl": 10}})", "render.indirect.vpl", ""},
                         Bad{R"({"indirect": 100})", "render.indirect", ""}}) {
        const fs::path file = scene_with_render(dir, b.json);
        const std::string message = input_error_of([&] { load_scene(file); });
        const std::string start = file.lexically_normal().string() + ": " + b.field + ": ";
        EXPECT_EQ(message.rfind(start, 0), 0u) << message;
        if (!b.problem.empty()) {
            EXPECT_EQ(message, start + b.problem);
        }
    }
}

TEST(SceneLoader, RenderSettingProblemTextMatchesTheCommandLine) {
    TempDir dir;
    const fs::path file = scene_with_render(dir, R"({"spp": 65537})");
    EXPECT_EQ(input_error_of([&] { load_scene(file); }),
              file.lexically_normal().string() + ": render.spp: must be an integer from 1 to 65536");
    // A type error stays the JSON reader's.
    const fs::path typed = scene_with_render(dir, R"({"spp": "4"})");
    EXPECT_EQ(input_error_of([&] { load_scene(typed); }),
              typed.lexically_normal().string() + ": render.spp: expected a number, got string");
}

TEST(SceneLoader, MissingSceneFileIsAnInputError) {
    const std::string message = input_error_of([] { load_scene(kFixtures / "nonexistent.json"); });
    EXPECT_NE(message.find("nonexistent.json"), std::string::npos) << message;
    EXPECT_NE(message.find("file not found"), std::string::npos) << message;
}

// A NUL in a file name would end it where the system reads it (so
// "tri.obj\0garbage" opened tri.obj), and a NUL in a key or a value cut
// the message short where it is printed: the one is refused, the other
// written as "\0".
TEST(SceneLoader, NulCharactersAreRefusedInFileNamesAndEscapedInMessages) {
    TempDir dir;
    fs::copy_file(kFixtures / "tri.obj", dir.path() / "tri.obj");
    const fs::path named = dir.write("named.json", R"({"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0]},
 "meshes": [{"obj": "tri.obj\u0000garbage"}], "lights": [{"type": "point", "position": [0, 1, 1], "intensity": [1, 1, 1]}]})");
    EXPECT_EQ(input_error_of([&] { load_scene(named); }),
              named.lexically_normal().string() + ": meshes[0].obj: the file name contains a NUL character");
    const fs::path key = dir.write("key.json", R"({"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0]},
 "meshes": [{"obj": "tri.obj"}], "lights": [{"type": "point", "position": [0, 1, 1], "intensity": [1, 1, 1]}],
 "render": {"meth\u0000od": "x"}})");
    const std::string message = input_error_of([&] { load_scene(key); });
    EXPECT_NE(message.find("render.meth\\0od"), std::string::npos) << message;
    EXPECT_EQ(std::string(message.c_str()), message) << "the message holds a NUL";
}

TEST(SceneLoader, ErrorMessageReadsFileFieldProblem) {
    const std::string message = input_error_of([] { load_scene(kFixtures / "bad_zero_width.json"); });
    const std::string expected_start = (kFixtures / "bad_zero_width.json").lexically_normal().string() +
                                       ": camera.width: must be";
    EXPECT_EQ(message.rfind(expected_start, 0), 0u) << message;
}

// ---------------------------------------------------------------------------
// points_csv
// ---------------------------------------------------------------------------

TEST(PointsCsv, SkipsHeaderCommentsAndBlankLines) {
    const std::vector<gpu::Light> lights = load_points_csv(kFixtures / "lights_header.csv");
    ASSERT_EQ(lights.size(), 3u);
    expect_near({lights[0].x, lights[0].y, lights[0].z}, {1, 2, 3});
    expect_near({lights[0].r, lights[0].g, lights[0].b}, {0.1f, 0.2f, 0.3f});
    expect_near({lights[1].x, lights[1].y, lights[1].z}, {-1.5f, 0.25f, 0.2f});
    expect_near({lights[2].r, lights[2].g, lights[2].b}, glm::vec3(0.0f));
    for (const gpu::Light& l : lights) EXPECT_EQ(l.type, gpu::kLightPoint);
}

TEST(PointsCsv, AcceptsCrLfMissingFinalNewlineAndTinyNumbers) {
    TempDir dir;
    const fs::path file = dir.write("crlf.csv", "x,y,z,r,g,b\r\n1,2,3,4,5,6\r\n7,8,9,1e-60,1e-40,1");
    const std::vector<gpu::Light> lights = load_points_csv(file);
    ASSERT_EQ(lights.size(), 2u);
    expect_near({lights[0].r, lights[0].g, lights[0].b}, {4, 5, 6});
    EXPECT_EQ(lights[1].r, 0.0f);  // underflow is zero, not an error
    EXPECT_EQ(lights[1].g, 0.0f);  // and so is a subnormal float
    EXPECT_FLOAT_EQ(lights[1].b, 1.0f);
}

// Spreadsheets start a CSV with a UTF-8 byte order mark; it is not part of
// the first line (which was refused: "'\xEF\xBB\xBF0' is not a number").
TEST(PointsCsv, AByteOrderMarkIsSkipped) {
    TempDir dir;
    for (const char* text : {"\xEF\xBB\xBF" "0,1,2,3,4,5\n", "\xEF\xBB\xBF" "x,y,z,r,g,b\n0,1,2,3,4,5\n"}) {
        const std::vector<gpu::Light> lights = load_points_csv(dir.write("bom.csv", text));
        ASSERT_EQ(lights.size(), 1u) << text;
        expect_near({lights[0].x, lights[0].y, lights[0].z}, {0, 1, 2});
    }
}

TEST(PointsCsv, EmptyFileGivesNoLights) {
    TempDir dir;
    EXPECT_TRUE(load_points_csv(dir.write("empty.csv", "")).empty());
    EXPECT_TRUE(load_points_csv(kFixtures / "header_only.csv").empty());
}

// ... and the scene says so, naming the file (before: not a word).
TEST(PointsCsv, SceneNotesAFileOfNoLights) {
    TempDir dir;
    dir.write("empty.csv", "x,y,z,r,g,b\n# nothing yet\n");
    dir.write("t.obj", "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 3 2\n");
    const fs::path scene = dir.write("scene.json", R"({"camera": {"position": [0, 1, 3], "look_at": [0, 0, 0]},
        "meshes": [{"obj": "t.obj"}],
        "lights": [{"type": "point", "position": [0, 2, 0], "intensity": [1, 1, 1]},
                   {"type": "points_csv", "file": "empty.csv"}]})");
    const Scene s = load_scene(scene);
    EXPECT_EQ(s.lights.size(), 1u);
    ASSERT_EQ(s.load_notes.size(), 1u);
    EXPECT_NE(s.load_notes[0].find("scene.json: lights[1].file: "), std::string::npos) << s.load_notes[0];
    EXPECT_NE(s.load_notes[0].find("empty.csv holds no lights"), std::string::npos) << s.load_notes[0];
}

// UTF-16 (a spreadsheet's "Unicode text") is refused by name, not read as
// a header of one field.
TEST(PointsCsv, Utf16IsRefused) {
    TempDir dir;
    const std::string utf16("\xFF\xFE" "1\0,\0" "2\0", 8);
    const fs::path file = dir.write("u16.csv", utf16);
    const std::string message = input_error_of([&] { load_points_csv(file); });
    EXPECT_NE(message.find("u16.csv: is UTF-16 text"), std::string::npos) << message;
}

struct CsvError {
    const char* name;
    const char* text;
    const char* line;
    const char* problem;
};

class PointsCsvError : public ::testing::TestWithParam<CsvError> {};

TEST_P(PointsCsvError, NamesFileAndLine) {
    const CsvError& c = GetParam();
    TempDir dir;
    const fs::path file = dir.write(std::string(c.name) + ".csv", c.text);
    const std::string message = input_error_of([&] { load_points_csv(file); });
    EXPECT_NE(message.find(file.filename().string()), std::string::npos) << message;
    EXPECT_NE(message.find(c.line), std::string::npos) << message;
    EXPECT_NE(message.find(c.problem), std::string::npos) << message;
}

const CsvError kCsvErrors[] = {
    {"too_few_fields", "# c\n\n1,2,3,4,5\n", "line 3: ", "found 5 fields"},
    {"too_many_fields", "1,2,3,4,5,6,7\n", "line 1: ", "found 7 fields"},
    {"empty_field", "1,2,,4,5,6\n", "line 1: ", "column 3 (z): '' is not a number"},
    {"not_a_number", "1,2,3,4,5,6\n1,2,3,4,five,6\n", "line 2: ", "'five' is not a number"},
    {"trailing_junk", "1,2,3,4,5,6x\n", "line 1: ", "is not a number"},
    {"sign_after_plus", "1,2,3,4,5,6\n+-1,2,3,4,5,6\n", "line 2: ", "column 1 (x): '+-1' is not a number"},
    {"signs_after_plus", "1,2,3,++0,5,6\n", "line 1: ", "column 4 (r): '++0' is not a number"},
    {"typo_in_first_line_is_not_a_header", "1,2,3,4,5,x\n1,2,3,4,5,6\n", "line 1: ", "'x' is not a number"},
    {"second_header", "x,y,z,r,g,b\n1,2,3,4,5,6\nx,y,z,r,g,b\n", "line 3: ", "is not a number"},
    // A first line of no number is a header only with the format's column
    // count: a file of semicolons (one field a line), or a spots file's
    // header, was skipped as one, and a one-line file then gave no light.
    {"semicolons", "0;2.5;-1;1;1;1\n", "line 1: ", "a header of 1 field (no number in it), where the 6 columns are"},
    {"spots_header", "# spots\nx,y,z,r,g,b,dx,dy,dz,inner,outer\n1,2,3,4,5,6\n", "line 2: ",
     "a header of 11 fields"},
    {"nan", "1,2,3,nan,5,6\n", "line 1: ", "column 4 (r): 'nan' is not finite"},
    {"inf", "1,2,3,4,5,6\n-inf,2,3,4,5,6\n", "line 2: ", "is not finite"},
    {"overflow", "1,2,3,4,5,1e999\n", "line 1: ", "out of range"},
    {"negative", "1,2,3,4,-5,6\n", "line 1: ", "column 5 (g): intensity must not be negative"},
    {"total_overflow", "0,0,0,0,0,3e38\n1,1,1,0,0,1\n2,2,2,0,0,3e38\n", "line 3: ",
     "total blue intensity of the point lights exceeds the float range (3.4e38)"},
    {"far_apart", "0,6e18,0,1,1,1\n0,0,0,1,1,1\n0,-6e18,0,1,1,1\n", "line 3: ",
     "extent along y exceeds 1e19 (the renderer squares distances in float and sums three such squares)"},
};

// The reader parses a file in chunks on every core (host/scene/csv_lights.cpp);
// cut into chunks of a few bytes, each case must fail at the same line
// with the same message as in one piece.
TEST_P(PointsCsvError, SameErrorInChunks) {
    const CsvError& c = GetParam();
    TempDir dir;
    const fs::path file = dir.write(std::string(c.name) + ".csv", c.text);
    const std::string whole = input_error_of([&] { load_points_csv(file); });
    for (std::size_t chunk_bytes : {1u, 2u, 3u, 5u, 8u, 13u}) {
        SCOPED_TRACE(chunk_bytes);
        const std::string chunked = input_error_of([&] {
            loader::LightLimits limits;
            loader::read_points_csv(file, limits, 0u, chunk_bytes);
        });
        EXPECT_EQ(chunked, whole);
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, PointsCsvError, ::testing::ValuesIn(kCsvErrors),
                         [](const ::testing::TestParamInfo<CsvError>& info) { return std::string(info.param.name); });

// Chunks of any size give the lights of the file in its order: a header,
// comments, blank lines, CRLF, a byte order mark and a last line with no
// newline, wherever the cuts fall.
TEST(PointsCsv, SameLightsInChunks) {
    TempDir dir;
    std::string text = "\xEF\xBB\xBF# lights\r\n\n  x , y , z , r , g , b\r\n";
    for (int i = 0; i < 200; ++i) {
        text += std::to_string(i) + "," + std::to_string(-i) + ",0.5," + std::to_string(i % 7) + ",1,2";
        text += i % 5 == 0 ? " # a comment\r\n" : "\n";
        if (i % 11 == 0) text += "\n   \n# x,y,z,r,g,b\n";
    }
    text += "9,9,9,1,1,1";  // no newline at the end
    const fs::path file = dir.write("chunks.csv", text);
    const std::vector<gpu::Light> whole = load_points_csv(file);
    ASSERT_EQ(whole.size(), 201u);
    for (std::size_t chunk_bytes : {1u, 7u, 64u, 1000u})
        for (unsigned threads : {0u, 1u, 3u}) {
            SCOPED_TRACE(std::to_string(chunk_bytes) + " bytes, " + std::to_string(threads) + " threads");
            loader::LightLimits limits;
            const std::vector<gpu::Light> chunked = loader::read_points_csv(file, limits, threads, chunk_bytes);
            ASSERT_EQ(chunked.size(), whole.size());
            EXPECT_EQ(std::memcmp(chunked.data(), whole.data(), whole.size() * sizeof(gpu::Light)), 0);
        }
    EXPECT_EQ(whole.back().x, 9.0f);
    EXPECT_EQ(whole[199].y, -199.0f);
}

// A header-like line anywhere but first is an error at its line, however
// the file is cut; the error is the first in file order even when a later
// chunk fails too.
TEST(PointsCsv, FirstErrorInFileOrderInChunks) {
    TempDir dir;
    std::string text = "x,y,z,r,g,b\n";
    for (int i = 0; i < 50; ++i) text += "1,2,3,4,5,6\n";
    text += "x,y,z,r,g,b\n";                 // line 52
    for (int i = 0; i < 50; ++i) text += "1,2,3,4,5,6\n";
    text += "1,2,3,4,oops,6\n";              // line 103
    const fs::path file = dir.write("late_header.csv", text);
    for (std::size_t chunk_bytes : {1u, 12u, 100u, 600u, 1u << 20}) {
        SCOPED_TRACE(chunk_bytes);
        const std::string message = input_error_of([&] {
            loader::LightLimits limits;
            loader::read_points_csv(file, limits, 0u, chunk_bytes);
        });
        EXPECT_NE(message.find("line 52: "), std::string::npos) << message;
        EXPECT_NE(message.find("'x' is not a number"), std::string::npos) << message;
    }
}

TEST(PointsCsv, MissingFileIsAnInputError) {
    const std::string message = input_error_of([] { load_points_csv(kFixtures / "nonexistent.csv"); });
    EXPECT_NE(message.find("nonexistent.csv"), std::string::npos) << message;
}

TEST(PointsCsv, LoadsHundredThousandLines) {
    TempDir dir;
    constexpr std::size_t kCount = 100000;
    std::string text = "# generated by the test\nx,y,z,r,g,b\n";
    text.reserve(kCount * 40);
    char line[128];
    for (std::size_t i = 0; i < kCount; ++i) {
        const double t = static_cast<double>(i);
        std::snprintf(line, sizeof line, "%.6g,%.6g,%.6g,%.6g,0.5,1e-5\n", t * 0.001, -t, t * 1e-7, t);
        text += line;
    }
    const fs::path file = dir.write("big.csv", text);
    const std::vector<gpu::Light> lights = load_points_csv(file);
    ASSERT_EQ(lights.size(), kCount);
    const gpu::Light& last = lights.back();
    EXPECT_NEAR(last.x, 99.999f, 1e-3f);
    EXPECT_FLOAT_EQ(last.y, -99999.0f);
    EXPECT_FLOAT_EQ(last.r, 99999.0f);
    EXPECT_FLOAT_EQ(last.g, 0.5f);
    EXPECT_FLOAT_EQ(last.b, 1e-5f);
}


// Spot, spots_csv, environment, emission from JSON and from MTL Ke, all in
// one scene, as docs/scene-format.md describes them.
TEST(SceneLoader, LightModelKeys) {
    const Scene s = load_scene(kFixtures / "light_kinds.json");
    ASSERT_EQ(s.lights.size(), 3u);  // the spot and the two CSV spots
    const gpu::Light& spot = s.lights[0];
    EXPECT_EQ(spot.type, gpu::kLightSpot);
    EXPECT_FLOAT_EQ(spot.axis_y, -1.0f);
    EXPECT_NEAR(spot.cos_inner, std::cos(20.0 * 3.14159265358979 / 180.0), 1e-6);
    EXPECT_NEAR(spot.cos_outer, std::cos(30.0 * 3.14159265358979 / 180.0), 1e-6);
    EXPECT_FLOAT_EQ(s.lights[1].axis_y, -1.0f);  // (0, -2, 0) normalised
    EXPECT_FLOAT_EQ(s.lights[1].g, 2.0f);
    EXPECT_NEAR(s.lights[2].cos_inner, 0.0f, 1e-6);  // 90 degrees
    ASSERT_TRUE(s.environment.present());
    EXPECT_EQ(s.environment.width, 1u);
    EXPECT_EQ(s.environment.directions, 64u);
    EXPECT_FLOAT_EQ(s.environment.rgb[2], 0.6f);  // 0.3 scaled by 2
    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_EQ(s.materials[0].flags & (gpu::kMaterialEmissive | gpu::kMaterialEmitsBothSides),
              gpu::kMaterialEmissive | gpu::kMaterialEmitsBothSides);
    EXPECT_FLOAT_EQ(s.materials[0].emission_b, 6.0f);
    EXPECT_EQ(s.materials[1].flags & (gpu::kMaterialEmissive | gpu::kMaterialEmitsBothSides), gpu::kMaterialEmissive);
    EXPECT_FLOAT_EQ(s.materials[1].emission_r, 3.0f);  // MTL Ke
    EXPECT_EQ(s.render.area_light_samples, 100u);
}

// Emissive surfaces are light enough: no "lights" key is needed.
TEST(SceneLoader, EmissiveSurfacesAloneLightAScene) {
    const Scene s = load_scene(kFixtures / "emissive_only.json");
    EXPECT_TRUE(s.lights.empty());
    EXPECT_NE(s.materials[0].flags & gpu::kMaterialEmissive, 0u);
}

}  // namespace
}  // namespace lc
