// Cuts shared by the four pixels of a 2x2 quad and by the eight of a 4x2
// octet (host/quad_cut.h, the CPU's cut_sharing "quad" and "octet"): the
// points' bounds in vector lanes, the criterion at every point, and blocks
// cut short by the image's edge or by camera rays that miss.
#include <cmath>
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "cpu_kernel.h"
#include "quad_cut.h"
#include "test_util.h"

namespace lc {
namespace {

using Kernel = cpu::ShadeKernel;

// A shaded point at x with a random normal, a view direction on its side
// and a random material: Lambert, or GGX of roughness down to 10^-3, made
// Disney where asked. `k` needs a material array (lc_make_surface's).
Kernel::SurfacePoint random_point(Kernel& k, std::mt19937& rng, glm::vec3 x, bool disney) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const glm::vec3 n = test::random_unit(rng);
    glm::vec3 wo = test::random_unit(rng);
    if (glm::dot(wo, n) < 0.0f) wo = -wo;
    Kernel::SurfacePoint s = k.lc_make_surface(x, n, wo, 0, glm::vec2(0.0f), glm::vec4(0.0f));
    const glm::vec3 kd(u(rng), u(rng), u(rng)), ks(u(rng), u(rng), u(rng));
    s.mat = u(rng) < 0.5f ? test::lambert(kd) : test::glossy(kd, ks, std::pow(10.0f, -3.0f * u(rng)));
    if (disney) {
        // Any Disney material: metal or not, rough or polished, with and
        // without specular, sheen and clearcoat lobes.
        loader::DisneyParams p = test::random_disney_params(rng);
        p.base_color = kd;
        s.mat = loader::make_disney_material(p);
    }
    return s;
}

// Over random clusters (points, VPLs, oriented and directional ones,
// leaves) and quads of random points with random materials (Lambert, GGX,
// Disney) and random active lanes, quad_errors gives lc_cluster_error's
// value bit for bit in every active lane and 0 in the others, and covers
// most of the cases.
TEST(QuadCut, ErrorsAreTheScalarOnesBitForBit) {
    std::mt19937 rng(4242);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const std::vector<gpu::Material> materials = {test::lambert(glm::vec3(0.5f))};
    Kernel k;
    k.materials = materials.data();  // lc_make_surface's; each point's own is set after it
    k.vpl_min_distance2 = 0.01f;
    int trials = 0, covered = 0, checked = 0, nonzero = 0, pairs = 0, cone_lit = 0, cone_dark = 0, disney_lit = 0;
    gpu::LightNode previous{}, earlier{};  // the last two covered clusters
    bool have_previous = false, have_earlier = false;
    int fours = 0;
    for (int trial = 0; trial < 40000; ++trial) {
        const glm::vec3 centre = (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f) * 4.0f;
        // Some boxes past the float range's middle, whose arithmetic gives
        // infinities and NaNs: those must come out as the scalar code's too.
        const float size = trial % 50 == 0 ? 3e38f : u(rng) < 0.2f ? 0.0f : 0.7f;
        const glm::vec3 half = glm::vec3(u(rng), u(rng), u(rng)) * size;
        const float pick = u(rng);
        const std::uint32_t type = pick < 0.55f   ? gpu::kLightPoint
                                   : pick < 0.65f ? gpu::kLightVpl
                                   : pick < 0.75f ? gpu::kLightOriented
                                   : pick < 0.9f  ? gpu::kLightSpot
                                                  : gpu::kLightDirectional;
        gpu::LightNode node = test::node_with_box(centre - half, centre + half, type);
        if (type == gpu::kLightVpl || type == gpu::kLightOriented || type == gpu::kLightSpot) {
            // An emission cone (lc_emission_bound): any axis, a spread of
            // axes from none to nearly everywhere (or everywhere), lights
            // emitting up to theta_e, one-sided or two-sided.
            node.axis_oct = std::uint32_t(rng());
            const float spread = u(rng);
            node.cos_theta_o = spread < 0.1f ? -1.0f : spread < 0.2f ? 1.0f : 1.0f - 1.9f * u(rng);
            node.cos_theta_e = type == gpu::kLightSpot ? 1.0f - 2.0f * u(rng) * u(rng) : std::cos(1.5707964f);
            node.falloff_width = std::max(1e-3f, u(rng));
            if (u(rng) < 0.3f) node.flags |= gpu::kNodeTwoSided;
        }
        if (u(rng) < 0.05f) node.flags |= gpu::kNodeLeaf;
        node.intensity_r = 10.0f * u(rng), node.intensity_g = 10.0f * u(rng), node.intensity_b = 10.0f * u(rng);
        Kernel::SurfacePoint sp[4];
        const unsigned active = trial % 5 == 0 ? unsigned(rng() & 0xFu) : 0xFu;
        // Disney materials at all four points, or at some of them.
        const int disney = trial % 4;  // 0: none, 1: all, 2 and 3: each point at random
        for (Kernel::SurfacePoint& s : sp) {
            glm::vec3 x = (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f) * 6.0f;
            if (u(rng) < 0.1f) x = glm::vec3(node.min_x, node.min_y + 0.5f * (node.max_y - node.min_y), node.max_z);
            s = random_point(k, rng, x, disney == 1 || (disney > 1 && u(rng) < 0.5f));
        }
        const float min_distance2 = u(rng) < 0.5f ? 1e-8f : 0.05f;
        float errors[4] = {-1.0f, -1.0f, -1.0f, -1.0f};
#if defined(__SSE2__)
        const cpu::QuadLanes lanes = cpu::quad_lanes(k, sp, active);
        const bool took = cpu::quad_errors(k, lanes, sp, node, min_distance2, errors);
#else
        const bool took = false;
#endif
        ++trials;
        if (!took) continue;
        ++covered;
        for (unsigned p = 0; p < 4u; ++p) {
            if ((active >> p & 1u) == 0u) {
                ASSERT_EQ(errors[p], 0.0f) << "trial " << trial << " lane " << p;
                continue;
            }
            const float scalar = k.lc_cluster_error(sp[p], sp[p].mat, node, min_distance2);
            ++checked;
            nonzero += scalar > 0.0f ? 1 : 0;
            if (!(node.cos_theta_o <= -1.0f)) ++(scalar > 0.0f ? cone_lit : cone_dark);
            if ((sp[p].mat.flags & gpu::kMaterialDisney) != 0u && scalar > 0.0f) ++disney_lit;
            // Bit for bit: the same float (or both NaN), not merely close.
            ASSERT_TRUE(errors[p] == scalar || (std::isnan(errors[p]) && std::isnan(scalar)))
                << "trial " << trial << " lane " << p << ": " << errors[p] << " against " << scalar;
        }
#if defined(__SSE2__)
        // Both children at once (AVX2, quad_pair_errors): this cluster and
        // the last covered one in the eight lanes, each half its scalar
        // values bit for bit.
        if (cpu::cpu_has_avx2() && have_previous) {
            cpu::quad8::QuadLanes wide;
            cpu::quad8::widen(lanes, wide);
            float first[4], second[4];
            cpu::quad8::quad_pair_errors(k, wide, node, previous, min_distance2, first, second);
            for (unsigned p = 0; p < 4u; ++p) {
                const float scalar = (active >> p & 1u) != 0u
                                         ? k.lc_cluster_error(sp[p], sp[p].mat, previous, min_distance2)
                                         : 0.0f;
                ASSERT_TRUE(first[p] == errors[p] || (std::isnan(first[p]) && std::isnan(errors[p])))
                    << "trial " << trial << " lane " << p << " (pair, first)";
                ASSERT_TRUE(second[p] == scalar || (std::isnan(second[p]) && std::isnan(scalar)))
                    << "trial " << trial << " lane " << p << " (pair, second): " << second[p] << " against " << scalar;
            }
            ++pairs;
            // Four clusters at once (AVX-512, quad16::quad_four_errors, two
            // refinements' children): this one, the last two covered ones
            // and this one again, each quarter its scalar values bit for bit.
            if (cpu::cpu_has_avx512dq() && have_earlier) {
                cpu::quad16::QuadLanes wider;
                cpu::quad16::widen(wide, wider);
                const gpu::LightNode* four[4] = {&node, &previous, &earlier, &node};
                float out[4][4];
                cpu::quad16::quad_four_errors(k, wider, four, min_distance2, out);
                for (unsigned c = 0; c < 4u; ++c)
                    for (unsigned p = 0; p < 4u; ++p) {
                        const float scalar = (active >> p & 1u) != 0u
                                                 ? k.lc_cluster_error(sp[p], sp[p].mat, *four[c], min_distance2)
                                                 : 0.0f;
                        ASSERT_TRUE(out[c][p] == scalar || (std::isnan(out[c][p]) && std::isnan(scalar)))
                            << "trial " << trial << " cluster " << c << " lane " << p << " (four): " << out[c][p]
                            << " against " << scalar;
                    }
                ++fours;
            }
        }
        if (have_previous) {
            earlier = previous;
            have_earlier = true;
        }
        previous = node;
        have_previous = true;
#endif
    }
#if defined(__SSE2__)
    EXPECT_GT(covered, trials / 2);
    EXPECT_GT(nonzero, checked / 3);
    // Clusters with emission cones, lit and unlit by them.
    EXPECT_GT(cone_lit, checked / 20);
    EXPECT_GT(cone_dark, checked / 20);
    EXPECT_GT(disney_lit, checked / 10);  // Disney points with a bound above zero
    if (cpu::cpu_has_avx2()) {
        EXPECT_GT(pairs, covered / 2);
    }
    if (cpu::cpu_has_avx512dq()) {
        EXPECT_GT(fours, covered / 2);
    }
#endif
}

// decode_axis_pair (quad_nodes' decoding of two clusters' axes) gives
// lc_decode_axis's vectors bit for bit: over random packings and every
// combination of the halves' extremes (0, +-1, -32768, +-32767), where the
// octahedron folds and the clamp bites.
TEST(QuadCut, AxisPairIsTheScalarDecodingBitForBit) {
#if defined(__SSE2__)
    std::mt19937 rng(77);
    std::vector<std::uint32_t> packed;
    const std::uint32_t halves[] = {0x0000u, 0x0001u, 0xFFFFu, 0x8000u, 0x8001u, 0x7FFFu, 0x4000u, 0xC000u};
    for (std::uint32_t lo : halves)
        for (std::uint32_t hi : halves) packed.push_back(lo | hi << 16);
    for (int i = 0; i < 200000; ++i) packed.push_back(std::uint32_t(rng()));
    const auto same = [](glm::vec3 a, glm::vec3 b) {
        return std::memcmp(&a, &b, sizeof a) == 0;
    };
    for (std::size_t i = 0; i + 1 < packed.size(); ++i) {
        glm::vec3 a, b;
        cpu::decode_axis_pair(packed[i], packed[i + 1], a, b);
        ASSERT_TRUE(same(a, gpu::lc_decode_axis(packed[i]))) << std::hex << packed[i];
        ASSERT_TRUE(same(b, gpu::lc_decode_axis(packed[i + 1]))) << std::hex << packed[i + 1];
    }
#else
    GTEST_SKIP() << "SSE2 only";
#endif
}

// The same for a representative's contribution: over random point lights,
// spots, cosine emitters and VPLs (and directional lights, which
// quad_light_units leaves to the scalar code), points near and far, in
// front of and behind the light, Lambert,
// GGX and Disney materials and random active lanes, the four units are
// lc_light_unit's bit for bit, with its ray direction and length where the
// unit is not zero.
TEST(QuadCut, LightUnitsAreTheScalarOnesBitForBit) {
    std::mt19937 rng(2024);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const std::vector<gpu::Material> materials = {test::lambert(glm::vec3(0.5f))};
    Kernel k;
    k.materials = materials.data();
    int covered = 0, lanes = 0, lit = 0, trials = 0, lit_cones = 0, lit_disney = 0, pairs = 0, pairs_lit = 0;
    gpu::Light previous{};  // the last covered light
    bool have_previous = false;
    for (int trial = 0; trial < 40000; ++trial) {
        const glm::vec3 at = (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f) * 4.0f;
        // Now and then a spot whose outer cosine rounds to 1, with points on
        // its axis, where the cosine can round above 1 (lc_spot_falloff
        // takes it as 1: the spot lights nothing).
        const bool hair = trial % 6 == 1 && u(rng) < 0.3f;
        // Point lights, spots (narrow to wide, hard-edged too), one- and
        // two-sided cosine emitters, VPLs, and directional lights, which
        // quad_light_units leaves to the scalar code.
        const glm::vec3 intensity = glm::vec3(u(rng), u(rng), u(rng)) * 10.0f;
        gpu::Light light = test::point_light(at, intensity);
        switch (trial % 6) {
            case 1: {
                const float outer = hair ? 0.01f : 1.0f + 89.0f * u(rng);
                light = test::spot_light(at, test::random_unit(rng), intensity, u(rng) < 0.2f ? outer : outer * u(rng),
                                         outer);
                break;
            }
            case 2: light = test::oriented_light(at, test::random_unit(rng), intensity, u(rng) < 0.5f); break;
            case 3:
                light = test::oriented_light(at, test::random_unit(rng), intensity);
                light.type = gpu::kLightVpl;
                break;
            case 4:
                if (u(rng) < 0.3f) light.type = gpu::kLightDirectional;
                break;
            default: break;
        }
        Kernel::SurfacePoint sp[4];
        const unsigned active = trial % 5 == 0 ? unsigned(rng() & 0xFu) : 0xFu;
        // Disney materials at all four points, or at some of them.
        const int disney = trial % 4;  // 0: none, 1: all, 2 and 3: each point at random
        for (Kernel::SurfacePoint& s : sp) {
            // Some points on the light itself (no direction), some close.
            const float spread = u(rng) < 0.3f ? 0.01f : 6.0f;
            glm::vec3 x = u(rng) < 0.02f ? at : at + (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f) * spread;
            if (hair) x = at + glm::vec3(light.axis_x, light.axis_y, light.axis_z) * (0.1f + 3.0f * u(rng));
            s = random_point(k, rng, x, disney == 1 || (disney > 1 && u(rng) < 0.5f));
        }
        const float min_distance2 = u(rng) < 0.5f ? 1e-8f : 0.05f;
        glm::vec3 unit[4], wi[4];
        float t_max[4];
#if defined(__SSE2__)
        const cpu::QuadLanes quad = cpu::quad_lanes(k, sp, active);
        const bool took = cpu::quad_light_units(k, quad, light, min_distance2, unit, wi, t_max);
#else
        const bool took = false;
#endif
        ++trials;
        if (!took) continue;
        ++covered;
        for (unsigned p = 0; p < 4u; ++p) {
            if ((active >> p & 1u) == 0u) {
                ASSERT_EQ(unit[p], glm::vec3(0.0f)) << "trial " << trial << " lane " << p;
                continue;
            }
            glm::vec3 scalar_wi;
            float scalar_t_max;
            const glm::vec3 scalar = k.lc_light_unit(sp[p], light, min_distance2, scalar_wi, scalar_t_max);
            ++lanes;
            ASSERT_EQ(unit[p], scalar) << "trial " << trial << " lane " << p;
            if (!(scalar.x + scalar.y + scalar.z > 0.0f)) continue;
            ++lit;
            lit_cones += (light.type & gpu::kLightTypeMask) != gpu::kLightPoint;
            lit_disney += (sp[p].mat.flags & gpu::kMaterialDisney) != 0u;
            ASSERT_EQ(wi[p], scalar_wi) << "trial " << trial << " lane " << p;
            ASSERT_EQ(t_max[p], scalar_t_max) << "trial " << trial << " lane " << p;
        }
#if defined(__SSE2__)
        // This light and the last covered one at once (AVX2,
        // quad_light_units_pair), each half the scalar values bit for bit.
        if (cpu::cpu_has_avx2() && have_previous) {
            cpu::quad8::QuadLanes wide;
            cpu::quad8::widen(quad, wide);
            glm::vec3 units2[2][4], wi2[2][4];
            float t_max2[2][4];
            ASSERT_TRUE(cpu::quad8::quad_light_units_pair(k, wide, light, previous, min_distance2, units2, wi2, t_max2));
            const gpu::Light* both[2] = {&light, &previous};
            for (unsigned h = 0; h < 2u; ++h)
                for (unsigned p = 0; p < 4u; ++p) {
                    glm::vec3 scalar_wi;
                    float scalar_t_max;
                    const glm::vec3 scalar = (active >> p & 1u) != 0u
                                                 ? k.lc_light_unit(sp[p], *both[h], min_distance2, scalar_wi, scalar_t_max)
                                                 : glm::vec3(0.0f);
                    ASSERT_EQ(units2[h][p], scalar) << "trial " << trial << " light " << h << " lane " << p << " (pair)";
                    if (!(scalar.x + scalar.y + scalar.z > 0.0f)) continue;
                    ++pairs_lit;
                    ASSERT_EQ(wi2[h][p], scalar_wi) << "trial " << trial << " light " << h << " lane " << p << " (pair)";
                    ASSERT_EQ(t_max2[h][p], scalar_t_max) << "trial " << trial << " light " << h << " lane " << p;
                }
            ++pairs;
        }
        previous = light;
        have_previous = true;
#endif
    }
#if defined(__SSE2__)
    EXPECT_GT(covered, trials / 2);
    EXPECT_GT(lit, lanes / 5);
    EXPECT_GT(lit_cones, lit / 5);  // spots, cosine emitters and VPLs that light their points
    EXPECT_GT(lit_disney, lit / 4);  // points with the Disney BRDF that a light reaches
    if (cpu::cpu_has_avx2()) {
        EXPECT_GT(pairs, covered / 2);
        EXPECT_GT(pairs_lit, lit / 2);
    }
#endif
}

// Grazing views with the light nearly opposite, where the half vector can
// face away from the viewer: the microfacet lobes count only where the
// facets reflect towards it (lc_facets_reflect), in the quads' lanes as in
// the scalar code (the lanes kept them: a GGX floor at the alpha floor up
// to 1.8e12 times the scalar value, an audit found).
TEST(QuadCut, LightUnitsKeepOnlyFacetsFacingTheViewer) {
#if defined(__SSE2__)
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const gpu::Material materials[2] = {loader::make_disney_material(test::polished_metal()),
                                        test::glossy(glm::vec3(0.2f), glm::vec3(1.0f), gpu::kMinGgxAlpha)};
    Kernel k;
    k.materials = materials;
    int dark = 0;  // lanes where the scalar code drops the lobes and Lambert's light is all
    for (int trial = 0; trial < 20000; ++trial) {
        const gpu::Material& m = materials[trial % 2];
        Kernel::SurfacePoint sp[4];
        const float phi = 6.2831853f * u(rng);
        const glm::vec3 along(std::cos(phi), std::sin(phi), 0.0f);
        for (Kernel::SurfacePoint& p : sp) {
            const glm::vec3 wo = glm::normalize(along + glm::vec3(0.0f, 0.0f, std::pow(10.0f, -3.5f - 1.5f * u(rng))));
            p = k.lc_make_surface(glm::vec3(0.0f), glm::vec3(0.0f, 0.0f, 1.0f), wo, 0, glm::vec2(0.0f),
                                  glm::vec4(0.0f));
            p.mat = m;
        }
        // wi + wo within about 1e-4 of zero: there wo . h, which is
        // positive in exact arithmetic, rounds to either sign.
        const glm::vec3 to = -along + glm::vec3(1e-5f * (u(rng) - 0.5f), 1e-5f * (u(rng) - 0.5f),
                                                std::pow(10.0f, -3.5f - 1.5f * u(rng)));
        const gpu::Light light = test::point_light(to, glm::vec3(1.0f));
        glm::vec3 unit[4], wi[4];
        float t_max[4];
        const cpu::QuadLanes quad = cpu::quad_lanes(k, sp, 0xFu);
        ASSERT_TRUE(cpu::quad_light_units(k, quad, light, 1e-8f, unit, wi, t_max));
        for (unsigned p = 0; p < 4u; ++p) {
            glm::vec3 scalar_wi;
            float scalar_t_max;
            const glm::vec3 scalar = k.lc_light_unit(sp[p], light, 1e-8f, scalar_wi, scalar_t_max);
            ASSERT_EQ(unit[p], scalar) << "trial " << trial << " lane " << p;
            const glm::vec3 h = glm::normalize(scalar_wi + sp[p].wo);
            dark += scalar.x > 0.0f && glm::dot(sp[p].wo, h) <= 0.0f;
        }
    }
    EXPECT_GT(dark, 1000);
#else
    GTEST_SKIP() << "no SSE2: the quads' lanes are not built";
#endif
}

#if defined(__SSE2__)
// An octet's lanes (quad8::join, the two quads' points side by side): one
// cluster given twice to quad_pair_errors, a refinement's two children to
// quad16::octet_pair_errors over the joined lanes widened (the pair's
// lanes spread as a, a, b, b), and a light given twice to
// quad_light_units_pair give the
// scalar bounds and units at all eight points, bit for bit, over random
// clusters with and without emission cones, lights, materials (Lambert,
// GGX, Disney) and active points (a quad with none among them).
TEST(OctetCut, LanesAreTheScalarOnesBitForBit) {
    if (!cpu::cpu_has_avx2()) GTEST_SKIP() << "octets take the quads' lanes without AVX2";
    std::mt19937 rng(808);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const std::vector<gpu::Material> materials = {test::lambert(glm::vec3(0.5f))};
    Kernel k;
    k.materials = materials.data();
    k.vpl_min_distance2 = 0.01f;
    const auto same = [](float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); };
    const auto random_node = [&](glm::vec3 centre) {
        const glm::vec3 half = glm::vec3(u(rng), u(rng), u(rng)) * 0.7f;
        const float pick = u(rng);
        const std::uint32_t type = pick < 0.6f ? gpu::kLightPoint : pick < 0.8f ? gpu::kLightSpot : gpu::kLightOriented;
        gpu::LightNode node = test::node_with_box(centre - half, centre + half, type);
        if (type != gpu::kLightPoint) {
            node.axis_oct = std::uint32_t(rng());
            node.cos_theta_o = 1.0f - 1.9f * u(rng);
            node.cos_theta_e = type == gpu::kLightSpot ? 1.0f - 2.0f * u(rng) * u(rng) : std::cos(1.5707964f);
            node.falloff_width = std::max(1e-3f, u(rng));
        }
        node.intensity_r = 10.0f * u(rng), node.intensity_g = 10.0f * u(rng), node.intensity_b = 10.0f * u(rng);
        return node;
    };
    int lit_bounds = 0, lit_units = 0, checked = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        const glm::vec3 centre = (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f) * 4.0f;
        const gpu::LightNode a = random_node(centre), b = random_node(centre + glm::vec3(0.3f));
        const gpu::Light light = trial % 3 == 0 ? test::point_light(centre, glm::vec3(u(rng), u(rng), u(rng)) * 10.0f)
                                 : trial % 3 == 1
                                     ? test::spot_light(centre, test::random_unit(rng), glm::vec3(5.0f), 20.0f, 40.0f)
                                     : test::oriented_light(centre, test::random_unit(rng), glm::vec3(5.0f));
        Kernel::SurfacePoint sp[8];
        const int disney = trial % 4;
        for (Kernel::SurfacePoint& s : sp)
            s = random_point(k, rng, centre + (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f) * 6.0f,
                             disney == 1 || (disney > 1 && u(rng) < 0.5f));
        const unsigned active = trial % 7 == 0 ? 0x0Fu : trial % 5 == 0 ? unsigned(rng() & 0xFFu) : 0xFFu;
        const cpu::QuadLanes quads[2] = {cpu::quad_lanes(k, sp, active & 0xFu), cpu::quad_lanes(k, sp + 4, active >> 4u)};
        if (!quads[0].covered || !quads[1].covered) continue;
        cpu::quad8::QuadLanes octet;
        cpu::quad8::join(quads[0], quads[1], octet);
        const float md2 = u(rng) < 0.5f ? 1e-8f : 0.05f;
        const auto scalar_error = [&](const gpu::LightNode& node, unsigned p) {
            return (active >> p & 1u) != 0u ? k.lc_cluster_error(sp[p], sp[p].mat, node, md2) : 0.0f;
        };
        float errors[8];
        cpu::quad8::quad_pair_errors(k, octet, a, a, md2, errors, errors + 4);
        for (unsigned p = 0; p < 8u; ++p) {
            ASSERT_TRUE(same(errors[p], scalar_error(a, p))) << "trial " << trial << " point " << p;
            lit_bounds += errors[p] > 0.0f ? 1 : 0;
            ++checked;
        }
        if (cpu::cpu_has_avx512dq()) {
            cpu::quad16::QuadLanes wider;
            cpu::quad16::widen(octet, wider);
            float errors_a[8], errors_b[8];
            cpu::quad16::octet_pair_errors(k, wider, a, b, md2, errors_a, errors_b);
            for (unsigned p = 0; p < 8u; ++p) {
                ASSERT_TRUE(same(errors_a[p], scalar_error(a, p))) << "trial " << trial << " point " << p << " (a)";
                ASSERT_TRUE(same(errors_b[p], scalar_error(b, p))) << "trial " << trial << " point " << p << " (b)";
            }
        }
        glm::vec3 units[2][4], wi[2][4];
        float t_max[2][4];
        ASSERT_TRUE(cpu::quad8::quad_light_units_pair(k, octet, light, light, md2, units, wi, t_max));
        for (unsigned p = 0; p < 8u; ++p) {
            glm::vec3 scalar_wi(0.0f);
            float scalar_t_max = 0.0f;
            const glm::vec3 scalar = (active >> p & 1u) != 0u ? k.lc_light_unit(sp[p], light, md2, scalar_wi, scalar_t_max)
                                                              : glm::vec3(0.0f);
            const glm::vec3 unit = units[p / 4u][p % 4u];
            ASSERT_EQ(unit, scalar) << "trial " << trial << " point " << p;
            if (!(scalar.x + scalar.y + scalar.z > 0.0f)) continue;
            ++lit_units;
            ASSERT_EQ(wi[p / 4u][p % 4u], scalar_wi) << "trial " << trial << " point " << p;
            ASSERT_EQ(t_max[p / 4u][p % 4u], scalar_t_max) << "trial " << trial << " point " << p;
        }
    }
    EXPECT_GT(checked, 8 * 3000);
    EXPECT_GT(lit_bounds, checked / 4);
    EXPECT_GT(lit_units, checked / 10);
}
#endif

// With a heap as large as the tree needs and no cut limit, every cluster
// left in a quad's cut meets Walter's criterion at each of the four points:
// its bound there is at most relative_error times that point's estimate.
// (The estimate the refinement tests is the running sum, which differs
// from the final sum by float rounding: the check allows 1e-5 of it.)
// Nothing is frozen, and every cut refines beyond the roots.
// Point q of the block of N pixels at (x, y): host/cpu_renderer.cpp's
// order, each quad's four points, the left quad's first.
std::uint32_t block_x(std::uint32_t q) { return (q & 1u) + 2u * (q >> 2u); }
std::uint32_t block_y(std::uint32_t q) { return q >> 1u & 1u; }

template <std::uint32_t N>
void expect_every_cluster_meets_the_criterion() {
    Scene s = test::room_scene(test::random_point_lights(500, {-0.9f, 0.2f, -0.9f}, {0.9f, 1.9f, 0.9f}, 10.0f, 17), 16);
    PreparedScene p = prepare_scene(std::move(s), 1);
    RenderOptions o = test::options("lightcuts", 16);
    o.max_cut = 1u << 20;
    const gpu::FrameParams f = make_frame_params(p, o);
    cpu::BlockHeap<N> heap(p.tree.cut_heap_capacity(f.max_cut));
    Kernel k = cpu::make_shade_kernel(p);
    cpu::BlockCut<Kernel, N> block(k, heap, f);
    std::size_t checked = 0;
    for (std::uint32_t y = 0; y < 16; y += 2)
        for (std::uint32_t x = 0; x < 16; x += N / 2u) {
            Kernel::SurfacePoint sp[N];
            unsigned active = 0u;
            for (std::uint32_t q = 0; q < N; ++q)
                if (k.lc_camera_hit(f, x + block_x(q), y + block_y(q), 0, sp[q])) active |= 1u << q;
            ASSERT_EQ(active, (1u << N) - 1u) << "the room is closed";
            glm::vec3 radiance[N];
            Kernel::ShadeStats stats[N];
            block.shade(sp, active, radiance, stats);
            for (std::uint32_t q = 0; q < N; ++q) {
                ASSERT_EQ(stats[q].frozen, 0u);
                ASSERT_EQ(stats[q].hit_max_cut, 0u);
                ASSERT_GT(stats[q].cut_size, 1u);
                ASSERT_EQ(stats[q].cut_size, stats[0].cut_size) << "one cut for the block";
            }
            for (std::uint32_t i = 0; i < block.heap_size(); ++i) {
                const cpu::BlockEntry<N>& e = heap.entries()[heap.slot()[i]];
                for (std::uint32_t q = 0; q < N; ++q) {
                    const float estimate = gpu::lc_luminance(radiance[q]);
                    ASSERT_LE(e.error[q], f.relative_error * estimate * (1.0f + 1e-5f))
                        << "block " << x << "," << y << " point " << q << " node " << e.node;
                    ++checked;
                }
            }
        }
    EXPECT_GT(checked, 1000u);
}

TEST(QuadCut, EveryClusterMeetsTheCriterionAtEveryPoint) { expect_every_cluster_meets_the_criterion<4>(); }
TEST(OctetCut, EveryClusterMeetsTheCriterionAtEveryPoint) { expect_every_cluster_meets_the_criterion<8>(); }

// What the stress tests check of a cut per pixel, for shared cuts: at each point
// the error of the result against brute force is at most the sum of the
// bounds of the cut's clusters there, those left in the heap and those
// frozen out of it (each cluster's true contribution and its estimate both
// lie between 0 and its bound). With heaps of 1 and 3 slots a point, which
// freeze at almost every block, and two trees (point and directional lights), so
// two roots. The sums of floats are allowed 1e-4 of the bound.
template <std::uint32_t N>
void expect_error_within_the_cuts_bounds() {
    std::vector<gpu::Light> lights = test::random_point_lights(300, {-0.9f, 0.2f, -0.9f}, {0.9f, 1.9f, 0.9f}, 10.0f, 6);
    lights.push_back(test::directional_light({0.3f, -1.0f, 0.2f}, glm::vec3(0.5f)));
    lights.push_back(test::directional_light({-0.4f, -1.0f, -0.1f}, glm::vec3(0.3f)));
    PreparedScene p = prepare_scene(test::room_scene(std::move(lights), 12), 1);
    const gpu::FrameParams f = make_frame_params(p, test::options("lightcuts", 12));
    cpu::CutHeap brute_heap(1);
    Kernel k = cpu::make_shade_kernel(p, &brute_heap);
    std::size_t points = 0, froze = 0;
    for (std::uint32_t slots : {N, 3u * N}) {
        cpu::BlockHeap<N> heap(slots);
        cpu::BlockCut<Kernel, N> block(k, heap, f);
        for (std::uint32_t y = 0; y < 12; y += 2)
            for (std::uint32_t x = 0; x < 12; x += N / 2u) {
                Kernel::SurfacePoint sp[N];
                unsigned active = 0u;
                for (std::uint32_t q = 0; q < N; ++q)
                    if (k.lc_camera_hit(f, x + block_x(q), y + block_y(q), 0, sp[q])) active |= 1u << q;
                glm::vec3 radiance[N];
                Kernel::ShadeStats stats[N];
                block.shade(sp, active, radiance, stats);
                for (std::uint32_t q = 0; q < N; ++q) {
                    if ((active >> q & 1u) == 0u) continue;
                    double bounds = stats[q].frozen_error;
                    for (std::uint32_t i = 0; i < block.heap_size(); ++i)
                        bounds += heap.entries()[heap.slot()[i]].error[q];
                    Kernel::ShadeStats ss{};
                    const glm::vec3 exact = k.lc_shade_brute(sp[q], f.light_count, f.min_distance2, ss);
                    const double error = std::abs(double(gpu::lc_luminance(radiance[q])) -
                                                  double(gpu::lc_luminance(exact)));
                    ASSERT_LE(error, bounds * (1.0 + 1e-4) + 1e-12)
                        << slots << " slots, block " << x << "," << y << " point " << q;
                    ++points;
                    froze += stats[q].frozen > 0u ? 1u : 0u;
                }
            }
    }
    EXPECT_EQ(points, 2u * 144u);
    EXPECT_GT(froze, points / 2);
}

TEST(QuadCut, ErrorIsWithinTheCutsBoundsAtEveryPoint) { expect_error_within_the_cuts_bounds<4>(); }
TEST(OctetCut, ErrorIsWithinTheCutsBoundsAtEveryPoint) { expect_error_within_the_cuts_bounds<8>(); }

// A floor seen at an angle, with the sky above the horizon: quads and
// octets whose camera rays partly miss, on an image whose odd sides cut the
// last column and row of blocks (the last octets' right quads lie wholly
// outside). With relative_error 0 and a heap as large as the tree needs
// every cluster is refined to its lights, so each pixel of the blocks is
// brute force's up to the summation order, the missed ones included.
TEST(QuadCut, PartialBlocksAndMissedPixelsAreShaded) {
    Scene s;
    s.materials = {test::lambert(glm::vec3(0.6f))};
    test::add_quad(s, {-4, 0, -8}, {4, 0, -8}, {4, 0, 2}, {-4, 0, 2}, 0);
    s.lights = test::random_point_lights(200, {-2.0f, 0.5f, -4.0f}, {2.0f, 2.0f, 0.0f}, 10.0f, 9);
    s.camera = test::camera({0.0f, 1.0f, 3.0f}, {0.0f, 0.6f, -2.0f}, 60.0f, 13, 7);
    update_bounds(s);
    PreparedScene p = prepare_scene(std::move(s), 1);
    RenderOptions o = test::options("lightcuts", 13);
    o.height = 7;
    o.relative_error = 0.0f;
    o.max_cut = 1u << 20;
    o.cut_heap = o.max_cut;
    o.method = "brute";
    const RenderResult brute = render_cpu(p, o);
    o.method = "lightcuts";
    for (const char* sharing : {"quad", "octet"}) {
        SCOPED_TRACE(sharing);
        o.cut_sharing = sharing;
        const RenderResult lc = render_cpu(p, o);
        EXPECT_EQ(lc.stats.cut_points, o.cut_sharing == "quad" ? 4u : 8u);
        int missed = 0, lit = 0;
        for (std::uint32_t y = 0; y < 7; ++y)
            for (std::uint32_t x = 0; x < 13; ++x) {
                const glm::vec3 want = brute.image.at(x, y), got = lc.image.at(x, y);
                for (int c = 0; c < 3; ++c) ASSERT_NEAR(got[c], want[c], 1e-5f * want[c] + 1e-9f) << x << "," << y;
                const float cut = lc.stats.cut_size[std::size_t(y) * 13 + x];
                if (want == glm::vec3(0.0f) && cut == 0.0f) ++missed;
                if (want.x > 0.0f) ++lit;
            }
        EXPECT_GT(missed, 5) << "some camera rays must leave the scene";
        EXPECT_GT(lit, 30);
    }
}

// Octets where their cuts stay below max_cut, quads after one that reached
// it (host/cpu_renderer.cpp, shade_tile_by_octets): with max_cut 40 every
// cut reaches it, so in each 8x8 tile the first 4x2 block is an octet and
// every later one two quads, whose pixels are then the quad render's bit
// for bit; the octets' are not (their last pass marks what eight points
// need, a quad's what four do).
TEST(OctetCut, BlocksAfterAnOctetAtMaxCutAreCutAsQuads) {
    Scene s = test::room_scene(test::random_point_lights(300, {-0.9f, 0.2f, -0.9f}, {0.9f, 1.9f, 0.9f}, 10.0f, 5), 20);
    PreparedScene p = prepare_scene(std::move(s), 1);
    RenderOptions o = test::options("lightcuts", 20);
    o.height = 12;
    o.max_cut = 40;
    o.cut_sharing = "quad";
    const RenderResult quads = render_cpu(p, o);
    o.cut_sharing = "octet";
    const RenderResult octets = render_cpu(p, o);
    ASSERT_EQ(octets.stats.cut_points, 8u);
    for (float cut : octets.stats.cut_size) ASSERT_EQ(cut, 40.0f) << "every cut must reach max_cut";
    int octet_pixels = 0, octet_pixels_differing = 0, quad_pixels = 0;
    for (std::uint32_t y = 0; y < 12; ++y)
        for (std::uint32_t x = 0; x < 20; ++x) {
            const bool first_block = x % 8u < 4u && y % 8u < 2u;
            const glm::vec3 got = octets.image.at(x, y), quad = quads.image.at(x, y);
            if (first_block) {
                ++octet_pixels;
                octet_pixels_differing += got != quad ? 1 : 0;
                continue;
            }
            ++quad_pixels;
            ASSERT_EQ(got, quad) << "pixel " << x << "," << y << " is not its quad's";
        }
    EXPECT_EQ(octet_pixels, 3 * 2 * 4 * 2);  // 3 x 2 tiles (the last column and row cut short)
    EXPECT_GT(octet_pixels_differing, 0) << "the octets' cuts are their own";  // 4 of the 24 here
    EXPECT_GT(quad_pixels, 150);
}

// Each pixel's cut alone, the quad's or the octet's: a render names the
// one it made, and its heap pools the points' slots.
TEST(QuadCut, CutSharingSettingPicksThePath) {
    // 700 lights: 699 interior nodes, more than an octet's 8 x 64 slots.
    Scene s = test::room_scene(test::random_point_lights(700, {-0.9f, 0.2f, -0.9f}, {0.9f, 1.9f, 0.9f}, 10.0f, 2), 8);
    PreparedScene p = prepare_scene(std::move(s), 1);
    ASSERT_GT(p.tree.cut_heap_capacity(1000), 8 * kDefaultCutHeap);
    RenderOptions o = test::options("lightcuts", 8);
    EXPECT_EQ(o.cut_sharing, "auto");
    const RenderResult automatic = render_cpu(p, o);
    EXPECT_EQ(automatic.stats.cut_points, 8u);
    o.cut_sharing = "pixel";
    const RenderResult pixel = render_cpu(p, o);
    EXPECT_EQ(pixel.stats.cut_points, 1u);
    EXPECT_EQ(pixel.stats.heap_slots, kDefaultCutHeap);
    o.cut_sharing = "quad";
    const RenderResult quad = render_cpu(p, o);
    EXPECT_EQ(quad.stats.cut_points, 4u);
    EXPECT_EQ(quad.stats.heap_slots, 4 * kDefaultCutHeap);
    o.cut_sharing = "octet";
    const RenderResult octet = render_cpu(p, o);
    EXPECT_EQ(octet.stats.cut_points, 8u);
    EXPECT_EQ(octet.stats.heap_slots, 8 * kDefaultCutHeap);
    EXPECT_EQ(octet.image.rgb, automatic.image.rgb) << "auto is octet on the CPU";
    o.method = "stochastic";  // cuts each pixel alone
    EXPECT_EQ(render_cpu(p, o).stats.cut_points, 1u);
    o.method = "lightcuts";
    o.cut_sharing = "tiles";
    EXPECT_THROW(render_cpu(p, o), std::invalid_argument);
    EXPECT_EQ(cut_sharing_problem("tiles"), "must be \"auto\", \"pixel\", \"quad\" or \"octet\", got \"tiles\"");
}

}  // namespace
}  // namespace lc
