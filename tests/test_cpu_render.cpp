// The CPU reference renderer against analytic answers.
#include <cmath>
#include <functional>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "lightcuts/error.h"
#include "test_util.h"

namespace lc {
namespace {

using test::add_quad;

constexpr float kPi = 3.14159265358979f;

// pbrt-v4's integrator test: a point light of intensity pi at the centre of
// a closed sphere of albedo 0.5 gives radiance 0.5 * cos(theta) / d^2 on the
// sphere. With flat facets d and theta deviate from 1 and 0 by the
// tessellation: for 64 x 128 facets a facet's plane lies within
// 1 - cos(pi/64) = 1.2e-3 of the sphere, so 0.5 holds within 0.5%.
TEST(CpuRender, PointLightInsideSphereGivesHalfEverywhere) {
    Scene s;
    s.materials = {test::lambert(glm::vec3(0.5f))};
    test::add_sphere(s, glm::vec3(0.0f), 1.0f, 64, 128, 0);
    s.lights = {test::point_light(glm::vec3(0.0f), glm::vec3(kPi))};
    s.camera = test::camera({0.0f, 0.0f, 0.5f}, {0.0f, 0.0f, -1.0f}, 90.0f, 32, 32);
    update_bounds(s);
    PreparedScene p = prepare_scene(std::move(s), 1);
    for (const char* method : {"brute", "lightcuts"}) {
        RenderResult r = render_cpu(p, test::options(method, 32));
        for (std::uint32_t y = 0; y < 32; ++y)
            for (std::uint32_t x = 0; x < 32; ++x) {
                glm::vec3 c = r.image.at(x, y);
                ASSERT_NEAR(c.x, 0.5f, 0.0025f) << method << " pixel " << x << "," << y;
                ASSERT_FLOAT_EQ(c.x, c.y);
                ASSERT_FLOAT_EQ(c.x, c.z);
            }
    }
}

// A scene built in code gets the loaders' checks from prepare_scene, with
// an InputError naming the field: before, a light at NaN made lightcuts'
// CPU image black while Vulkan's kept the other light, a camera 0 pixels
// wide rendered an empty image, one of 2^20 x 2^20 ran out of memory, and
// a triangle's material past the scene's read past the array. Its bounds
// come from its triangles, whether or not the caller set them.
TEST(CpuRender, ASceneBuiltInCodeIsCheckedAsALoadedOneIs) {
    const auto problem = [](const std::function<void(Scene&)>& change) -> std::string {
        Scene s = test::room_scene({test::point_light({0.0f, 1.5f, 0.0f}, glm::vec3(1.0f)),
                                    test::point_light({0.5f, 1.5f, 0.0f}, glm::vec3(1.0f))},
                                   8);
        change(s);
        try {
            prepare_scene(std::move(s), 1);
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    };
    EXPECT_EQ(problem([](Scene&) {}), "");
    EXPECT_EQ(problem([](Scene& s) { s.lights[1].y = std::nanf(""); }),
              "scene: lights[1]: position or direction is not finite");
    EXPECT_EQ(problem([](Scene& s) { s.lights[0].g = -1.0f; }),
              "scene: lights[0]: intensity must be finite and not negative");
    EXPECT_EQ(problem([](Scene& s) { s.lights[0].type = 9u; }), "scene: lights[0].type: is not a light type (kLightPoint ... kLightVpl, kLightTwoSided)");
    EXPECT_EQ(problem([](Scene& s) { s.lights[0].r = s.lights[1].r = 3e38f; }),
              "scene: lights: total red intensity of the point lights exceeds the float range (3.4e38)");
    EXPECT_EQ(problem([](Scene& s) { s.camera.width = 0; }), "scene: camera.width: must be from 1 to 16384, got 0");
    EXPECT_EQ(problem([](Scene& s) { s.camera.height = 1u << 20; }),
              "scene: camera.height: must be from 1 to 16384, got 1048576");
    EXPECT_EQ(problem([](Scene& s) { s.camera.look_at = s.camera.position; }),
              "scene: camera.look_at: must differ from camera.position");
    EXPECT_EQ(problem([](Scene& s) { s.camera.fov_y_degrees = 180.0f; }),
              "scene: camera.fov_y_degrees: must be above 0 and below 180");
    EXPECT_EQ(problem([](Scene& s) { s.triangles[5].material = 3; }),
              "scene: triangles[5].material: is 3; the scene has 3 materials");
    EXPECT_EQ(problem([](Scene& s) { s.triangles[2].v1_y = INFINITY; }),
              "scene: triangles[2]: a vertex is not finite");
    const std::size_t triangles = test::room_scene({}, 8).triangles.size();
    EXPECT_EQ(problem([](Scene& s) { s.normals.pop_back(); }),
              "scene: normals: holds " + std::to_string(triangles - 1) + " entries for " + std::to_string(triangles) +
                  " triangles (one per triangle)");
    EXPECT_EQ(problem([](Scene& s) { s.materials[1].kd_g = 1.5f; }), "scene: materials[1].kd_g: must be from 0 to 1");
    EXPECT_EQ(problem([](Scene& s) { s.materials[0].base_color_texture = 0; }), "");  // not textured: not read
    EXPECT_EQ(problem([](Scene& s) {
                  s.materials[0].base_color_texture = 0;
                  s.materials[0].flags |= gpu::kMaterialTextured;
              }),
              "scene: materials[0].base_color_texture: is 0; the scene has 0 textures");
    EXPECT_EQ(problem([](Scene& s) {
                  s.environment.width = 4;
                  s.environment.height = 2;
                  s.environment.rgb.assign(4 * 2 * 3 - 1, 1.0f);
              }),
              "scene: environment.rgb: holds 23 values for 4 x 2 pixels (three each)");
    EXPECT_EQ(problem([](Scene& s) {
                  s.environment.width = s.environment.height = 1;
                  s.environment.rgb = {1.0f, -1.0f, 1.0f};
              }),
              "scene: environment.rgb[1]: radiance must be finite and not negative");
    EXPECT_NE(problem([](Scene& s) { s.render.indirect.vpls = 1u << 30; }).find("scene: render.indirect.vpls: "),
              std::string::npos);
    EXPECT_EQ(problem([](Scene& s) {
                  gpu::Light spot = s.lights[0];
                  spot.type = gpu::kLightSpot;
                  spot.axis_y = -1.0f;
                  spot.cos_inner = 0.5f;
                  spot.cos_outer = 0.9f;
                  s.lights.push_back(spot);
              }),
              "scene: lights[2]: a spot's cosines must satisfy -1 <= cos_outer <= cos_inner <= 1");

    // Bounds left at zero by the caller: the same image as with them set.
    Scene set = test::room_scene({test::point_light({0.0f, 1.5f, 0.0f}, glm::vec3(1.0f))}, 16);
    Scene unset = set;
    unset.bounds_min = unset.bounds_max = glm::vec3(0.0f);
    const RenderResult a = render_cpu(prepare_scene(std::move(set), 1), test::options("brute", 16));
    const RenderResult b = render_cpu(prepare_scene(std::move(unset), 1), test::options("brute", 16));
    EXPECT_EQ(a.image.rgb, b.image.rgb);
}

// Floor plane y = 0 of albedo rho seen from above; the expected radiance is
// computed here independently from the ray/plane intersection in double.
struct PlaneSetup {
    Scene scene;
    glm::dvec3 eye{0.3, 2.0, 2.5};
    glm::dvec3 target{0.0, 0.0, 0.0};
    double fov = 50.0;
    std::uint32_t size = 48;
    glm::vec3 rho{0.8f, 0.5f, 0.2f};

    PlaneSetup() {
        scene.materials = {test::lambert(rho)};
        add_quad(scene, {-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, 0);
        scene.camera = test::camera(glm::vec3(eye), glm::vec3(target), float(fov), size, size);
    }

    // Point on the plane seen through the centre of pixel (x, y).
    glm::dvec3 hit(std::uint32_t x, std::uint32_t y) const {
        glm::dvec3 fwd = glm::normalize(target - eye);
        glm::dvec3 right = glm::normalize(glm::cross(fwd, glm::dvec3(0, 1, 0)));
        glm::dvec3 up = glm::cross(right, fwd);
        double t = std::tan(fov * M_PI / 360.0);
        double u = (2.0 * (x + 0.5) / size - 1.0) * t;
        double v = (1.0 - 2.0 * (y + 0.5) / size) * t;
        glm::dvec3 d = glm::normalize(fwd + u * right + v * up);
        return eye + d * (-eye.y / d.y);
    }
};

TEST(CpuRender, PointLightOverPlaneMatchesInverseSquareCosine) {
    PlaneSetup ps;
    const glm::dvec3 light(0.4, 1.5, -0.2);
    const glm::dvec3 intensity(3.0, 2.0, 1.0);
    ps.scene.lights = {test::point_light(glm::vec3(light), glm::vec3(intensity))};
    update_bounds(ps.scene);
    PreparedScene p = prepare_scene(ps.scene, 1);
    RenderResult r = render_cpu(p, test::options("brute", ps.size));
    for (std::uint32_t y = 0; y < ps.size; ++y)
        for (std::uint32_t x = 0; x < ps.size; ++x) {
            glm::dvec3 h = ps.hit(x, y);
            glm::dvec3 l = light - h;
            double d2 = glm::dot(l, l);
            double cos_theta = l.y / std::sqrt(d2);
            glm::dvec3 expected = glm::dvec3(ps.rho) / M_PI * intensity * cos_theta / d2;
            glm::vec3 got = r.image.at(x, y);
            // The renderer's hit point is its float camera ray's, off this
            // double one by about 2^-24 of the scene's size, which moves d^2
            // and cos theta by a few 1e-7; 1e-4 leaves a wide margin for that
            // and the float shading.
            for (int c = 0; c < 3; ++c)
                ASSERT_NEAR(got[c], expected[c], 1e-4 * expected[c]) << "pixel " << x << "," << y;
        }
}

TEST(CpuRender, DirectionalLightOverPlaneMatchesCosine) {
    PlaneSetup ps;
    const glm::dvec3 travel = glm::normalize(glm::dvec3(0.3, -1.0, 0.5));
    const glm::dvec3 irradiance(2.0, 1.0, 0.5);
    ps.scene.lights = {test::directional_light(glm::vec3(travel), glm::vec3(irradiance))};
    update_bounds(ps.scene);
    PreparedScene p = prepare_scene(ps.scene, 1);
    RenderResult r = render_cpu(p, test::options("brute", ps.size));
    const double cos_theta = -travel.y;
    glm::dvec3 expected = glm::dvec3(ps.rho) / M_PI * irradiance * cos_theta;
    for (std::uint32_t y = 0; y < ps.size; ++y)
        for (std::uint32_t x = 0; x < ps.size; ++x)
            // No dependence on the hit point: a few float operations'
            // rounding, well under 1e-5 (about 80 ulps).
            for (int c = 0; c < 3; ++c) ASSERT_NEAR(r.image.at(x, y)[c], expected[c], 1e-5 * expected[c]);
}

// A square blocker at height 0.5 over the plane, a light at height 1.5: the
// shadow is the blocker's projection from the light. Pixels whose hit point
// is within a margin of the shadow's edge are skipped (the pixel's centre
// decides, the edge's position is exact to within float rounding).
TEST(CpuRender, BlockerCastsShadowWhereGeometrySays) {
    PlaneSetup ps;
    const glm::dvec3 light(0.1, 1.5, 0.1);
    const double blocker_y = 0.5, half = 0.25;
    add_quad(ps.scene, glm::vec3(-half, blocker_y, -half), glm::vec3(half, blocker_y, -half),
             glm::vec3(half, blocker_y, half), glm::vec3(-half, blocker_y, half), 0);
    ps.scene.lights = {test::point_light(glm::vec3(light), glm::vec3(1.0f))};
    update_bounds(ps.scene);
    PreparedScene p = prepare_scene(ps.scene, 1);
    ASSERT_TRUE(p.has_occluders);
    RenderResult r = render_cpu(p, test::options("brute", ps.size));
    int shadowed = 0, lit = 0;
    for (std::uint32_t y = 0; y < ps.size; ++y)
        for (std::uint32_t x = 0; x < ps.size; ++x) {
            glm::dvec3 h = ps.hit(x, y);
            // Where the segment hit -> light crosses the blocker's plane.
            double s = (blocker_y - h.y) / (light.y - h.y);
            glm::dvec3 q = h + s * (light - h);
            double edge = std::max(std::abs(q.x), std::abs(q.z)) - half;
            if (std::abs(edge) < 0.02) continue;
            bool in_shadow = edge < 0.0;
            // The blocker is also seen directly by some pixels: skip those.
            glm::dvec3 d = glm::normalize(h - ps.eye);
            double tb = (blocker_y - ps.eye.y) / d.y;
            glm::dvec3 qb = ps.eye + tb * d;
            if (std::max(std::abs(qb.x), std::abs(qb.z)) < half + 0.02) continue;
            float v = r.image.at(x, y).x;
            if (in_shadow) {
                ASSERT_EQ(v, 0.0f) << "pixel " << x << "," << y;
                ++shadowed;
            } else {
                ASSERT_GT(v, 0.0f) << "pixel " << x << "," << y;
                ++lit;
            }
        }
    EXPECT_GT(shadowed, 50);
    EXPECT_GT(lit, 500);
}

// Lightcuts also with max_cut 40, where some octets reach it and the
// blocks after them in their tiles are cut as quads (shade_tile_by_octets).
TEST(CpuRender, SameImageBitForBitWhateverTheThreadCount) {
    Scene s = test::room_scene(test::random_point_lights(200, {-0.9f, 1.2f, -0.9f}, {0.9f, 1.9f, 0.9f}, 20.0f, 7), 40);
    PreparedScene p = prepare_scene(std::move(s), 3);
    for (const auto& [method, max_cut] : {std::pair{"brute", 1000u}, {"lightcuts", 1000u}, {"lightcuts", 40u}}) {
        RenderOptions o = test::options(method, 40);
        o.spp = 2;
        o.max_cut = max_cut;
        o.threads = 1;
        RenderResult one = render_cpu(p, o);
        if (max_cut == 40u) {
            EXPECT_GT(one.stats.max_cut_pixels, 0u);
        }
        for (unsigned threads : {2u, 3u, 7u}) {
            o.threads = threads;
            RenderResult many = render_cpu(p, o);
            ASSERT_EQ(one.image.rgb, many.image.rgb) << method << " with " << threads << " threads";
            ASSERT_EQ(one.stats.shadow_rays, many.stats.shadow_rays);
        }
    }
}

TEST(CpuRender, UnknownMethodIsRejected) {
    Scene s = test::room_scene({test::point_light({0, 1, 0}, glm::vec3(1))}, 8);
    PreparedScene p = prepare_scene(std::move(s), 1);
    EXPECT_THROW(render_cpu(p, test::options("path_tracing", 8)), std::invalid_argument);
}


// The inverse-square clamp d_min is 1e-4 of the geometry's diagonal. It
// once covered the point lights too: one light at y = 1e4 made d_min 1 m in
// a 2 m room and darkened every surface near a light several times over.
// A far light of tiny intensity must now change neither d_min nor the image
// beyond its own (negligible) contribution.
TEST(CpuRender, FarLightDoesNotChangeTheDistanceClamp) {
    auto lights = test::random_point_lights(50, {-0.9f, 0.05f, -0.9f}, {0.9f, 1.95f, 0.9f}, 10.0f, 5);
    PreparedScene near_only = prepare_scene(test::room_scene(lights, 16), 1);
    lights.push_back(test::point_light({0.0f, 1e4f, 0.0f}, glm::vec3(1e-3f)));
    PreparedScene with_far = prepare_scene(test::room_scene(lights, 16), 1);
    EXPECT_EQ(with_far.min_distance2, near_only.min_distance2);
    const float diagonal = std::sqrt(2.0f * 2.0f * 3.0f);  // the room is 2 x 2 x 2
    EXPECT_NEAR(std::sqrt(with_far.min_distance2), 1e-4f * diagonal, 1e-9f);
    const RenderResult a = render_cpu(near_only, test::options("brute", 16));
    const RenderResult b = render_cpu(with_far, test::options("brute", 16));
    // The far light lies outside the closed room: it adds nothing.
    EXPECT_LT(compare_images(b.image, a.image).relative_rmse, 1e-6);
}

}  // namespace
}  // namespace lc
