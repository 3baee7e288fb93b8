// The same room translated by 1e5 units, and scaled down to 1e-4 units,
// against the untransformed render.
//
// What float precision allows (justification of the limits below):
//  - Scaled by 1e-4 about the origin, with point intensities scaled by
//    1e-8 so radiance is unchanged: a float has the same relative precision
//    at every magnitude, so the only change is the rounding of each
//    coordinate to its nearest float (2^-24 relative), far below anything
//    visible. Shading points are offset off their surface by a distance
//    relative to the triangle's coordinates (shaders/lc_shared/trace.h), so
//    that also scales. Measured below; limits at about 3x that.
//  - Translated by 1e5: coordinates near 1e5 are floats spaced 2^-7 =
//    0.0078 apart, so every vertex and light moves by up to 0.0039 per
//    axis (0.0068 in 3D) when the test translates it: 0.34% of the 2-unit
//    room. A light at distance d changes 1/d^2 and the cosine by about
//    2 * 0.0068 / d, i.e. about 1.4% at d = 1 and 5% at d = 0.3. The
//    renderer then moves the scene back to the origin (prepare_scene), so
//    nothing else is lost: before it did, hit points were shaded a few
//    ulps (0.03) off their surfaces where the untranslated room has 3e-5.
#include <ostream>
#include <random>

#include <gtest/gtest.h>

#include "stress_checks.h"
#include "test_util.h"

namespace lc {
namespace {

// Lights in the top of the room, at least 0.1 (5% of the room) from every
// surface, so no pixel is dominated by one light a few ulps away.
Scene base_room() {
    auto lights = test::random_point_lights(500, {-0.9f, 1.4f, -0.9f}, {0.9f, 1.9f, 0.9f}, 20.0f, 31);
    lights.push_back(test::directional_light({0.2f, -1.0f, 0.1f}, glm::vec3(0.5f)));
    return test::room_scene(std::move(lights), 24);
}

// x -> scale * x + offset for every position; point intensities scaled by
// scale^2 so that the inverse-square falloff gives the same radiance.
Scene transformed(Scene s, float scale, glm::vec3 offset) {
    auto map = [&](float& x, float& y, float& z) {
        const glm::vec3 p = scale * glm::vec3(x, y, z) + offset;
        x = p.x; y = p.y; z = p.z;
    };
    for (auto& t : s.triangles) {
        map(t.v0_x, t.v0_y, t.v0_z);
        map(t.v1_x, t.v1_y, t.v1_z);
        map(t.v2_x, t.v2_y, t.v2_z);
    }
    for (auto& l : s.lights) {
        if (l.type != gpu::kLightPoint) continue;
        map(l.x, l.y, l.z);
        l.r *= scale * scale; l.g *= scale * scale; l.b *= scale * scale;
    }
    s.camera.position = scale * s.camera.position + offset;
    s.camera.look_at = scale * s.camera.look_at + offset;
    update_bounds(s);
    return s;
}

struct TransformCase {
    const char* name;
    float base_scale;                // the room, scaled by this, is the untransformed scene
    float scale;                     // then this transform gives the stressed one
    glm::vec3 offset;
    double max_rmse;                 // against the untransformed render; < 0: not compared
    double max_fraction_above_1pct;
    stress::LightcutsLimits limits;  // lightcuts against brute force, same scene
    // Vulkan against the CPU: {RMSE, fraction above 1%} for brute force, then
    // lightcuts, on lavapipe (llvmpipe), then on other devices.
    double lavapipe[2][2];
    double vulkan[2][2];
};

// TranslatedBy1e5 moves a 100-unit hall (the room scaled by 50): at 1e5 it
// is 12800 float steps across, and its vertices and lights move by up to
// 0.0068 when translated; the nearest light is 5 units away. Measured:
// relative RMSE 1.2e-4 (brute) and 4.4e-5 (lightcuts), largest pixel error
// 0.4%, no pixel above 1% (0.0038, 0.0040, 3.5% and 4% of pixels above 1%
// when the renderer shaded it where it lay, 8 to 16 ulps, 0.06 to 0.12,
// off its surfaces). Limits: RMSE 4e-4 (3x), one pixel of 576 above 1%.
//
// SmallRoomTranslatedBy1e5 moves the 2-unit room itself: only 256 float
// steps across, with the nearest light 0.1 (13 steps) from a surface, so
// the translation's rounding alone changes its image by percents (measured
// against the untranslated room: relative RMSE 0.024 brute, 0.030
// lightcuts, 29% and 75% of pixels above 1%); it is held to every
// per-case check but not compared with the untranslated room.
//
// ScaledTo1em4: measured RMSE 2.8e-7 (brute force) and 3.0e-7 (lightcuts),
// largest pixel error 1.6e-6, no pixel above 1%; limits RMSE 1e-6 and one
// pixel of 576 above 1%.
//
// Vulkan against the CPU {RMSE, fraction above 1%}, about 3x the lavapipe
// measurement, and one pixel of 576 (0.002) where none was above 1%:
// TranslatedBy1e5 brute 1.3e-7, lightcuts 1.4e-7, none (1.9e-4 and 1.3e-4
// shaded where it lay); SmallRoomTranslatedBy1e5 brute 8.9e-8, lightcuts
// 9.8e-8, none (0.0070 and 0.0069 shaded where it lay, 11% and 13%);
// ScaledTo1em4 brute 1.8e-7, none; lightcuts 2.1e-5, none (when first
// measured; 1.5e-7 for both on a later host, where no cut differed). Those
// are lavapipe's limits. On other devices the translated cases keep the
// hall's limits from before the move, far above lavapipe's figures: on a
// GPU a shadow ray that FMA or its sqrt turns the other way moves a pixel
// of the hall's 500 lights by about 0.2%, and no GPU run has measured them
// yet.
const TransformCase kTransforms[] = {
    // Lightcuts against brute force measured 0.0127, 0.0087 (5 pixels of 576 above 5%) with the quads' cuts
    // refined largest first throughout; 0.0126, 0.0139 (8 pixels) since they are refined in passes while the
    // list has room (host/quad_cut.h; on the shipped scenes no larger error and no more pixels above 2%, the
    // gallery's 54.0% against 55.0% aside: docs/results/speed.md). Limits 1.5 times the measurement.
    {"TranslatedBy1e5", 50.0f, 1.0f, {1e5f, 1e5f, -1e5f}, 4e-4, 0.002, {0.019, 0.021}, {{4e-7, 0.002}, {4.5e-7, 0.002}},
     {{5.5e-4, 0.005}, {4e-4, 0.002}}},
    // 0.0115, 0.0104 with a heap the tree cannot fill; 0.0115, 0.0208 with the default heap of 64 slots
    {"SmallRoomTranslatedBy1e5", 1.0f, 1.0f, {1e5f, 1e5f, -1e5f}, -1.0, 0.0, {0.018, 0.03}, {{3e-7, 0.002}, {3e-7, 0.002}},
     {{5.5e-4, 0.005}, {4e-4, 0.002}}},
    {"ScaledTo1em4", 1.0f, 1e-4f, {0.0f, 0.0f, 0.0f}, 1e-6, 0.002, {0.019, 0.013}, {{5e-7, 0.002}, {6e-5, 0.002}},
     {{5e-7, 0.002}, {6e-5, 0.002}}},  // 0.0125, 0.0104 (0.0126, 0.0087 largest first)
};

// gtest prints a parameter next to the test's name (and ctest shows it).
void PrintTo(const TransformCase& c, std::ostream* os) { *os << c.name; }

class Transformed : public ::testing::TestWithParam<TransformCase> {};

TEST_P(Transformed, CpuMatchesUntransformed) {
    const TransformCase& c = GetParam();
    const Scene room = transformed(base_room(), c.base_scale, glm::vec3(0.0f));
    const PreparedScene base = prepare_scene(room, 1);
    const PreparedScene moved = prepare_scene(transformed(room, c.scale, c.offset), 1);
    const RenderOptions o = test::options("lightcuts", base.scene.camera.width);
    const stress::CpuRenders r = stress::run_cpu_checks(moved, o, c.limits, {}, c.name);
    if (c.max_rmse < 0.0) return;
    const RenderResult base_brute = render_cpu(base, test::options("brute", o.width));
    const RenderResult base_lightcuts = render_cpu(base, o);
    stress::expect_images_agree(r.brute.image, base_brute.image, c.max_rmse, c.max_fraction_above_1pct,
                                std::string(c.name) + " brute vs untransformed");
    stress::expect_images_agree(r.lightcuts.image, base_lightcuts.image, c.max_rmse, c.max_fraction_above_1pct,
                                std::string(c.name) + " lightcuts vs untransformed");
}

// Tolerances per case, measured (see above).
TEST_P(Transformed, VulkanMatchesCpu) {
    const TransformCase& c = GetParam();
    const Scene room = transformed(base_room(), c.base_scale, glm::vec3(0.0f));
    const PreparedScene moved = prepare_scene(transformed(room, c.scale, c.offset), 1);
    for (const char* method : {"brute", "lightcuts"}) {
        const RenderOptions o = test::options(method, moved.scene.camera.width);
        std::optional<RenderResult> gpu = stress::render_vulkan_if_available(moved, o);
        if (!gpu) GTEST_SKIP() << "no Vulkan device (or a build without the Vulkan path)";
        const RenderResult cpu = stress::render_cpu_as_vulkan(moved, o);
        const bool brute = std::string(method) == "brute";
        const bool llvmpipe = gpu->stats.device.find("llvmpipe") != std::string::npos;
        const double* tolerance = (llvmpipe ? c.lavapipe : c.vulkan)[brute ? 0 : 1];
        stress::expect_images_agree(gpu->image, cpu.image, tolerance[0], tolerance[1],
                                    std::string(c.name) + " vulkan " + method);
    }
}

INSTANTIATE_TEST_SUITE_P(Stress, Transformed, ::testing::ValuesIn(kTransforms),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace lc
