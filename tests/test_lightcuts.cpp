// Lightcuts on the CPU: conservative bounds, cut selection, accuracy, cost.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "cpu_kernel.h"
#include "test_util.h"

namespace lc {
namespace {

using Kernel = cpu::ShadeKernel;

using test::random_unit;

// Over 2 x 10^5 random cases (cluster box with lights inside, shaded point
// outside, inside or on the box, normals random or grazing, Lambert or GGX
// of random roughness down to the loader's floor, random view direction),
// the bound of material * geometry is at least the exact value for every
// light of the cluster.
TEST(LightcutsBounds, EveryBoundIsConservative) {
    std::mt19937 rng(12345);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<gpu::Material> materials(1);
    Kernel k;
    k.materials = materials.data();
    const float min_distance2 = 1e-8f;
    int checked = 0, zero_bounds = 0;
    for (int trial = 0; trial < 200000; ++trial) {
        const bool directional = trial % 5 == 0;
        gpu::Material& m = materials[0];
        glm::vec3 kd(u(rng), u(rng), u(rng));
        // GGX alpha log-uniform from 1e-3 (the loader's floor) to 1.
        m = trial % 2 ? test::lambert(kd)
                      : test::glossy(kd, glm::vec3(u(rng), u(rng), u(rng)), std::pow(10.0f, -3.0f * u(rng)));

        // Cluster box and its lights.
        std::vector<glm::vec3> pts(1 + trial % 6);
        glm::vec3 lo(1e30f), hi(-1e30f);
        glm::vec3 centre = directional ? glm::vec3(0.0f) : (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f) * 4.0f;
        glm::vec3 spread = glm::vec3(u(rng), u(rng), u(rng)) * (u(rng) < 0.2f ? 0.0f : 1.0f);
        for (auto& p : pts) {
            p = directional ? random_unit(rng) * (u(rng) < 0.5f ? 1.0f : 0.0f) + random_unit(rng) * 0.3f
                            : centre + (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f) * spread;
            if (directional) p = glm::normalize(p);
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        // Shaded point: far, near, inside or on the box.
        glm::vec3 x;
        float where = u(rng);
        if (where < 0.2f) x = lo + (hi - lo) * glm::vec3(u(rng), u(rng), u(rng));
        else if (where < 0.3f) x = glm::vec3(lo.x, lo.y + (hi.y - lo.y) * u(rng), hi.z);
        else x = (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f) * 6.0f;
        // Normal: random, or grazing (perpendicular to the direction to a light).
        glm::vec3 n = random_unit(rng);
        if (u(rng) < 0.3f) {
            glm::vec3 to = directional ? pts[0] : pts[0] - x;
            if (glm::dot(to, to) > 1e-12f) {
                to = glm::normalize(to);
                glm::vec3 t = glm::cross(to, random_unit(rng));
                if (glm::dot(t, t) > 1e-6f) n = glm::normalize(t);
            }
        }
        glm::vec3 wo = random_unit(rng);
        if (glm::dot(wo, n) < 0.0f) wo = -wo;

        Kernel::SurfacePoint sp;
        sp.p = x;
        sp.n = n;
        sp.wo = wo;
        sp = k.lc_make_surface(sp.p, sp.n, sp.wo, 0, glm::vec2(0.0f), glm::vec4(0.0f));
        glm::vec3 bound = k.lc_cluster_bound(
            sp, m, test::node_with_box(lo, hi, directional ? gpu::kLightDirectional : gpu::kLightPoint),
            min_distance2);
        ASSERT_TRUE(std::isfinite(bound.x) && std::isfinite(bound.y) && std::isfinite(bound.z)) << trial;
        if (bound.x + bound.y + bound.z == 0.0f) ++zero_bounds;
        for (const auto& p : pts) {
            gpu::Light light = directional ? test::directional_light(-p, glm::vec3(1.0f))
                                           : test::point_light(p, glm::vec3(1.0f));
            glm::vec3 wi;
            float t_max;
            glm::vec3 exact = k.lc_light_unit(sp, light, min_distance2, wi, t_max);
            for (int c = 0; c < 3; ++c) {
                ASSERT_GE(bound[c], exact[c]) << "trial " << trial << " channel " << c << " directional "
                                              << directional << " alpha " << m.alpha << " x " << x.x << "," << x.y << "," << x.z
                                              << " n " << n.x << "," << n.y << "," << n.z << " box " << lo.x << ","
                                              << lo.y << "," << lo.z << " - " << hi.x << "," << hi.y << "," << hi.z
                                              << " light " << p.x << "," << p.y << "," << p.z;
            }
            ++checked;
        }
    }
    EXPECT_GT(checked, 500000);
    EXPECT_GT(zero_bounds, 1000);  // clusters fully below the surface do occur
}

// The CPU evaluates a refinement's two children's bounds together in SSE
// lanes (host/pair_bound.h), or where those do not cover them (emission
// cones, the Disney BRDF) in the quads' AVX2 lanes with the point in the
// first of each half (lc_child_errors): over random pairs of clusters
// (points, VPLs, oriented lights, spots and directional ones, leaves),
// points (far, near, inside a box, on its face) and materials (Lambert,
// GGX, Disney), its errors are the scalar lc_cluster_error's bit for bit,
// and the pair path is taken for most of them, the quads' for many of the
// rest. Trials change the point, the material or both, so lanes kept from
// the last trial's point or material would fail it.
TEST(LightcutsBounds, PairOfChildErrorsIsTheScalarOneBitForBit) {
    std::mt19937 rng(777);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<gpu::Material> materials(1);
    Kernel k;
    k.materials = materials.data();
    k.vpl_min_distance2 = 0.01f;
    int paired = 0, laned = 0, trials = 0, nonzero = 0;
    glm::vec3 x(0.0f), n(0.0f, 1.0f, 0.0f), wo(0.0f, 1.0f, 0.0f);
    for (int trial = 0; trial < 100000; ++trial) {
        // A new material and a new point, or one of them new and the other
        // the last trial's.
        const bool new_material = trial % 3 != 1, new_point = trial % 3 != 2;
        gpu::Material& m = materials[0];
        if (new_material) {
            const glm::vec3 kd(u(rng), u(rng), u(rng));
            const int kind = trial % 7;
            m = kind < 3 ? test::lambert(kd)
                         : test::glossy(kd, glm::vec3(u(rng), u(rng), u(rng)), std::pow(10.0f, -3.0f * u(rng)));
            if (kind == 6) {
                loader::DisneyParams p = test::random_disney_params(rng);
                p.base_color = kd;
                m = loader::make_disney_material(p);
            }
        }
        gpu::LightNode nodes[2];
        for (gpu::LightNode& node : nodes) {
            const glm::vec3 centre = (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f) * 4.0f;
            const glm::vec3 half = glm::vec3(u(rng), u(rng), u(rng)) * (u(rng) < 0.2f ? 0.0f : 0.7f);
            const float pick = u(rng);
            const std::uint32_t type = pick < 0.6f   ? gpu::kLightPoint
                                       : pick < 0.7f ? gpu::kLightVpl
                                       : pick < 0.8f ? gpu::kLightOriented
                                       : pick < 0.9f ? gpu::kLightSpot
                                                     : gpu::kLightDirectional;
            node = test::node_with_box(centre - half, centre + half, type);
            if (type == gpu::kLightOriented) node.cos_theta_o = 0.5f;
            if (type == gpu::kLightSpot) {
                node.axis_oct = std::uint32_t(rng());
                node.cos_theta_o = 1.0f - 1.5f * u(rng);
                node.cos_theta_e = 1.0f - u(rng);
                node.falloff_width = std::max(1e-3f, u(rng));
            }
            if (u(rng) < 0.05f) node.flags |= gpu::kNodeLeaf;
            node.intensity_r = 10.0f * u(rng), node.intensity_g = 10.0f * u(rng), node.intensity_b = 10.0f * u(rng);
        }
        if (new_point) {
            x = (glm::vec3(u(rng), u(rng), u(rng)) - 0.5f) * 6.0f;
            if (u(rng) < 0.2f)
                x = glm::vec3(nodes[0].min_x, nodes[0].min_y + 0.5f * (nodes[0].max_y - nodes[0].min_y),
                              nodes[0].max_z);  // on a face
            n = random_unit(rng);
            wo = random_unit(rng);
            if (glm::dot(wo, n) < 0.0f) wo = -wo;
        }
        const Kernel::SurfacePoint sp = k.lc_make_surface(x, n, wo, 0, glm::vec2(0.0f), glm::vec4(0.0f));
        const float min_distance2 = u(rng) < 0.5f ? 1e-8f : 0.05f;
        glm::vec2 pair(-1.0f);
        const bool took = cpu::pair_errors(k, sp, m, nodes[0], nodes[1], min_distance2, pair);
        const glm::vec2 scalar(k.lc_cluster_error(sp, m, nodes[0], min_distance2),
                               k.lc_cluster_error(sp, m, nodes[1], min_distance2));
        const glm::vec2 used = k.lc_child_errors(sp, m, nodes[0], nodes[1], min_distance2);
        ++trials;
        paired += took ? 1 : 0;
        laned += !took && cpu::quad_bound_covers(nodes[0]) && cpu::quad_bound_covers(nodes[1]) ? 1 : 0;
        nonzero += scalar.x > 0.0f ? 1 : 0;
        // Bit for bit: the same float, not merely close.
        ASSERT_EQ(used.x, scalar.x) << "trial " << trial;
        ASSERT_EQ(used.y, scalar.y) << "trial " << trial;
        if (took) {
            ASSERT_EQ(pair.x, scalar.x) << "trial " << trial;
            ASSERT_EQ(pair.y, scalar.y) << "trial " << trial;
        }
    }
#if defined(__SSE2__)
    EXPECT_GT(paired, trials / 4);
    EXPECT_GT(laned, trials / 10);
#endif
    EXPECT_GT(nonzero, trials / 4);
}

// The benchmarks' tightest bound of Walter's form (Kernel::tightest_bound,
// docs/results/speed.md): at every camera hit of a room with 500 lights
// and a glossy box, for every interior node of the tree, it lies between
// the largest single light's share (its own unshadowed contribution) and
// lc_cluster_error, which bounds the same lights less tightly.
TEST(LightcutsBounds, TightestBoundLiesBetweenEveryLightAndTheBound) {
    Scene s = test::room_scene(test::random_point_lights(500, {-0.9f, 0.1f, -0.9f}, {0.9f, 1.9f, 0.9f}, 10.0f, 5), 16);
    PreparedScene p = prepare_scene(std::move(s), 1);
    const gpu::FrameParams f = make_frame_params(p, test::options("lightcuts", 16));
    Kernel k = cpu::make_shade_kernel(p);
    int tighter = 0, nodes = 0;
    for (std::uint32_t y = 0; y < 16; ++y)
        for (std::uint32_t x = 0; x < 16; ++x) {
            Kernel::SurfacePoint sp;
            if (!k.lc_camera_hit(f, x, y, 0, sp)) continue;
            // The largest single light's luminance below each node, leaves up
            // (children follow their parent in the node array).
            std::vector<float> largest(p.tree.nodes.size(), 0.0f);
            for (std::size_t i = p.tree.nodes.size(); i-- > 0;) {
                const gpu::LightNode& node = p.tree.nodes[i];
                if ((node.flags & gpu::kNodeLeaf) != 0u) {
                    glm::vec3 wi;
                    float t_max;
                    const gpu::Light& light = p.tree.lights[node.rep_light];
                    largest[i] = gpu::lc_luminance(k.lc_light_unit(sp, light, f.min_distance2, wi, t_max) *
                                                   k.lc_light_intensity(light));
                } else {
                    largest[i] = std::max(largest[node.left], largest[node.left + 1u]);
                }
            }
            for (std::size_t i = 0; i < p.tree.nodes.size(); ++i) {
                const gpu::LightNode& node = p.tree.nodes[i];
                if ((node.flags & gpu::kNodeLeaf) != 0u) continue;
                const float tightest = k.tightest_error(sp, node, f.min_distance2);
                const float bound = k.lc_cluster_error(sp, sp.mat, node, f.min_distance2);
                // The three are the same quantity's bounds by different float
                // formulas: 1e-5 (about 80 ulps) covers their rounding.
                ASSERT_GE(tightest, largest[i] * (1.0f - 1e-5f)) << "node " << i;
                ASSERT_LE(tightest, bound * (1.0f + 1e-5f)) << "node " << i;
                ++nodes;
                tighter += tightest < 0.5f * bound;
            }
        }
    // Not everywhere equal: the bound is loose somewhere (else the
    // comparison would show nothing).
    EXPECT_GT(nodes, 10000);
    EXPECT_GT(tighter, nodes / 100);
}

// The GGX bound is tighter than a constant: for a small cluster far from the
// mirror direction it is far below the lobe's peak D(1) * G1(wo) / (4 cos_o).
TEST(LightcutsBounds, GgxBoundIsTighterThanThePeak) {
    Kernel k;
    gpu::Material m = test::glossy(glm::vec3(0.0f), glm::vec3(1.0f), 0.1f);
    glm::vec3 n(0, 0, 1), wo = glm::normalize(glm::vec3(1, 0, 1));
    glm::vec3 lo(2.9f, -0.1f, 2.9f), hi(3.1f, 0.1f, 3.1f);  // along wo, far from the mirror (-1, 0, 1)
    float bound = k.lc_ggx_bound(m, lo, hi, glm::vec3(0.0f), n, wo);
    float peak = k.lc_ggx_d(1.0f, 0.0f, m.alpha) * k.lc_smith_g1(wo.z, m.alpha) / (4.0f * wo.z);
    EXPECT_LT(bound, 1e-3f * peak);
    // And a cluster around the mirror direction gets the peak.
    glm::vec3 lo2(-3.1f, -0.1f, 2.9f), hi2(-2.9f, 0.1f, 3.1f);
    EXPECT_GE(k.lc_ggx_bound(m, lo2, hi2, glm::vec3(0.0f), n, wo), peak);
}

// Pushes an entry of bound `error` for node `node` into k's heap, with the
// visibility bit clear (a frozen entry's estimate is then zero).
void push_entry(Kernel& k, std::uint32_t& size, std::uint32_t node, float error, Kernel::ShadeStats& ss) {
    glm::vec3 fixed_sum(0.0f), heap_sum(0.0f);
    k.lc_heap_push(Kernel::SurfacePoint{}, 0.0f, size, cpu::HeapEntry{node, error, glm::vec3(0.0f)}, glm::vec3(0.0f), fixed_sum,
                   heap_sum, ss, 0u, 0u);
}

// lc_cos_h_max works with the cone's sine and cosines (no acos or cos): for
// every direction towards the box, the half vector's cosine with n is at
// most the bound. Small, far boxes around the mirror direction are the
// case where sqrt(1 - cos^2) would lose the angle; a third of the cases
// put the box there.
TEST(LightcutsBounds, HalfVectorBoundHoldsForEveryDirectionInTheCone) {
    std::mt19937 rng(777);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    Kernel k;
    int checked = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        glm::vec3 n = random_unit(rng);
        glm::vec3 wo = random_unit(rng);
        if (glm::dot(n, wo) < 0.0f) wo = -wo;
        const float cos_o = glm::dot(n, wo);
        if (!(cos_o > 1e-3f)) continue;
        const glm::vec3 mirror = glm::normalize(2.0f * cos_o * n - wo);
        const float dist = std::pow(10.0f, 3.0f * u(rng) - 1.0f);     // 0.1 to 100
        const float size = dist * std::pow(10.0f, -5.0f * u(rng));     // down to 1e-5 of it
        const glm::vec3 dir = trial % 3 == 0 ? glm::normalize(mirror + 1e-4f * random_unit(rng)) : random_unit(rng);
        const glm::vec3 centre = dist * dir;
        const glm::vec3 half(size * u(rng), size * u(rng), size * u(rng));
        const glm::vec3 lo = centre - half, hi = centre + half;
        const float bound = k.lc_cos_h_max(k.lc_box_cone(lo, hi, glm::vec3(0.0f)), n, wo, cos_o);
        ASSERT_LE(bound, 1.0f);
        for (int s = 0; s < 16; ++s) {
            const glm::vec3 p = lo + glm::vec3(u(rng), u(rng), u(rng)) * (hi - lo);
            // The exact half vector, in double so that its own rounding
            // does not count against the bound.
            const glm::dvec3 wi = glm::normalize(glm::dvec3(p));
            const glm::dvec3 sum = wi + glm::normalize(glm::dvec3(wo));
            if (glm::length(sum) < 1e-3) continue;  // wi opposite wo: no half vector
            const double cos_h = glm::dot(glm::normalize(sum), glm::normalize(glm::dvec3(n)));
            ASSERT_GE(double(bound), cos_h) << "trial " << trial << " dist " << dist << " size " << size;
            ++checked;
        }
    }
    EXPECT_GT(checked, 200000);
}

TEST(LightcutsHeap, PopsInDecreasingOrder) {
    cpu::CutHeap storage(1000);
    Kernel k;
    k.bind_heap(storage);
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::uint32_t size = 0;
    std::vector<float> pushed;
    Kernel::ShadeStats ss{};
    for (int i = 0; i < 1000; ++i) {
        const float error = u(rng);
        pushed.push_back(error);
        push_entry(k, size, std::uint32_t(i), error, ss);
        if (i % 3 == 2) {  // interleave pops
            float top = storage.error()[0];
            auto it = std::max_element(pushed.begin(), pushed.end());
            ASSERT_EQ(top, *it);
            pushed.erase(it);
            k.lc_heap_pop(size);
        }
        if (i % 7 == 5) {  // and replacements of the top (a refinement's larger child)
            auto it = std::max_element(pushed.begin(), pushed.end());
            ASSERT_EQ(storage.error()[0], *it);
            *it = u(rng);
            k.lc_heap_replace_top(size, cpu::HeapEntry{std::uint32_t(i), *it, glm::vec3(0.0f)});
        }
    }
    ASSERT_EQ(size, pushed.size());
    std::sort(pushed.rbegin(), pushed.rend());
    for (float expected : pushed) {
        ASSERT_EQ(storage.error()[0], expected);
        k.lc_heap_pop(size);
    }
    EXPECT_EQ(size, 0u);
    EXPECT_EQ(ss.frozen, 0u);
}

// The CPU's search of a full heap's leaves for the entry to freeze
// (cpu::heap_smallest, eight slots at a time in SSE lanes) gives the shared
// scalar loop's answer: the first slot of the smallest error below the
// bound, none if no error is below it; on ranges of every length and
// offset, with ties.
TEST(LightcutsHeap, SmallestSearchIsTheScalarLoop) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> heap(80);
    int found = 0, none = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        for (float& e : heap) e = float(int(u(rng) * 16.0f) + 1) / 16.0f;  // ties in every range
        const auto from = std::uint32_t(u(rng) * 40.0f);
        const auto to = from + std::uint32_t(u(rng) * 40.0f);
        const float bound = float(int(u(rng) * 20.0f)) / 16.0f;
        std::uint32_t expected = gpu::kInvalidIndex;
        float smallest = bound;
        for (std::uint32_t i = from; i < to; ++i)
            if (heap[i] < smallest) {
                smallest = heap[i];
                expected = i;
            }
        ASSERT_EQ(cpu::heap_smallest(heap.data(), from, to, bound), expected)
            << "trial " << trial << " slots [" << from << ", " << to << ") bound " << bound;
        (expected == gpu::kInvalidIndex ? none : found) += 1;
    }
    EXPECT_GT(found, 5000);
    EXPECT_GT(none, 2000);
}

// A full heap of K entries freezes the smallest bound of the K + 1 it would
// hold: after any sequence of pushes and pops it holds the K largest of the
// entries not popped, every other one is frozen, and the frozen bounds add
// up in the stats.
TEST(LightcutsHeap, BoundedHeapKeepsTheLargestAndFreezesTheRest) {
    for (std::uint32_t capacity : {1u, 2u, 7u, 16u}) {
        cpu::CutHeap storage(capacity);
        std::vector<gpu::LightNode> nodes(600, gpu::LightNode{});
        Kernel k;
        k.bind_heap(storage);
        k.light_nodes = nodes.data();
        std::mt19937 rng(capacity);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        std::uint32_t size = 0;
        std::vector<float> live;  // entries pushed, not popped and not frozen (a multiset)
        Kernel::ShadeStats ss{};
        double frozen_error = 0.0;
        std::uint32_t frozen = 0;
        for (int i = 0; i < 600; ++i) {
            const float error = float(int(u(rng) * 64.0f)) / 64.0f;  // ties happen
            push_entry(k, size, std::uint32_t(i), error, ss);
            live.push_back(error);
            std::sort(live.rbegin(), live.rend());
            if (live.size() > capacity) {  // the smallest goes
                frozen_error += live.back();
                frozen += 1;
                live.pop_back();
            }
            ASSERT_EQ(size, live.size());
            std::vector<float> held;
            for (std::uint32_t j = 0; j < size; ++j) held.push_back(storage.error()[j]);
            std::sort(held.rbegin(), held.rend());
            ASSERT_EQ(held, live) << "capacity " << capacity << " after push " << i;
            ASSERT_EQ(storage.error()[0], live.front());
            if (i % 5 == 4) {
                k.lc_heap_pop(size);
                live.erase(live.begin());
            }
        }
        EXPECT_EQ(ss.frozen, frozen);
        // The kernel sums the frozen bounds in float, this test in double:
        // each float addition is off by at most 2^-24 relative.
        EXPECT_NEAR(double(ss.frozen_error), frozen_error, 1e-4 * frozen_error);
    }
}

Scene mixed_room(std::size_t n_point, std::uint32_t size, std::uint32_t seed) {
    auto lights = test::random_point_lights(n_point, {-0.95f, 0.05f, -0.95f}, {0.95f, 1.95f, 0.95f}, 30.0f, seed);
    lights.push_back(test::directional_light({0.2f, -1.0f, 0.1f}, {0.5f, 0.5f, 0.5f}));
    lights.push_back(test::directional_light({-0.3f, 1.0f, 0.4f}, {0.3f, 0.2f, 0.1f}));
    return test::room_scene(std::move(lights), size);
}

// With relative_error 0 and no cut limit every cluster with a non-zero bound
// is refined to its lights: the image is the brute-force sum, up to float
// round-off of a different summation order.
TEST(Lightcuts, ZeroErrorReproducesBruteForce) {
    PreparedScene p = prepare_scene(mixed_room(300, 32, 1), 1);
    RenderResult brute = render_cpu(p, test::options("brute", 32));
    for (const char* sharing : {"pixel", "quad", "octet"}) {
        RenderOptions o = test::options("lightcuts", 32);
        o.cut_sharing = sharing;
        o.relative_error = 0.0f;
        o.max_cut = 1u << 20;
        o.cut_heap = o.max_cut;  // nothing frozen
        RenderResult lc = render_cpu(p, o);
        EXPECT_EQ(lc.stats.max_cut_pixels, 0u) << sharing;
        // The same contributions summed in another order (a cut's clusters,
        // not the lights one by one): float rounding, about 2^-24 per
        // addition of similar terms; 1e-5 relative, 1e-9 absolute for black.
        for (std::size_t i = 0; i < brute.image.rgb.size(); ++i)
            ASSERT_NEAR(lc.image.rgb[i], brute.image.rgb[i], 1e-5f * brute.image.rgb[i] + 1e-9f) << sharing << " " << i;
        // It also never needs more shadow rays than brute force.
        EXPECT_LE(lc.stats.shadow_rays, brute.stats.shadow_rays) << sharing;
    }
}

// max_cut = 1 shades each point with the root's representative only, scaled
// by the root's total intensity.
TEST(Lightcuts, MaxCutOneUsesTheRootRepresentative) {
    Scene s = test::room_scene(test::random_point_lights(200, {-0.9f, 1.0f, -0.9f}, {0.9f, 1.9f, 0.9f}, 10.0f, 2), 24);
    PreparedScene p = prepare_scene(std::move(s), 1);
    for (const char* sharing : {"pixel", "quad", "octet"}) {
        SCOPED_TRACE(sharing);
        RenderOptions o = test::options("lightcuts", 24);
        o.cut_sharing = sharing;
        o.max_cut = 1;
        RenderResult r = render_cpu(p, o);
        gpu::FrameParams f = make_frame_params(p, o);
        cpu::CutHeap heap(2);
        Kernel k = cpu::make_shade_kernel(p, &heap);
        const gpu::LightNode& root = p.tree.nodes[p.tree.roots[gpu::kLightPoint]];
        glm::vec3 root_intensity(root.intensity_r, root.intensity_g, root.intensity_b);
        int lit = 0;
        for (std::uint32_t y = 0; y < 24; ++y)
            for (std::uint32_t x = 0; x < 24; ++x) {
                Kernel::SurfacePoint sp;
                ASSERT_TRUE(k.lc_camera_hit(f, x, y, 0, sp));
                Kernel::ShadeStats ss{};
                bool visible = false;
                glm::vec3 expected = k.lc_rep_unit(sp, root.rep_light, f.min_distance2, visible, ss) * root_intensity;
                glm::vec3 got = r.image.at(x, y);
                ASSERT_EQ(got, expected) << x << "," << y;
                ASSERT_EQ(r.stats.cut_size[y * 24 + x], 1.0f);
                lit += expected.x > 0.0f;
            }
        EXPECT_GT(lit, 100);
    }
}

// The CPU's brute force traces its shadow rays four at a time
// (lc_shade_brute_packets, trace_any_wide4) and must give the shared
// per-light loop's result bit for bit, with the same ray count, at every
// point: the contributions of the unblocked lights are summed in the same
// order.
TEST(BruteForce, PacketsGiveTheSharedLoopsResultBitForBit) {
    Scene s = test::room_scene(test::random_point_lights(2000, {-0.9f, 0.1f, -0.9f}, {0.9f, 1.9f, 0.9f}, 10.0f, 3), 32);
    PreparedScene p = prepare_scene(std::move(s), 1);
    RenderOptions o = test::options("brute", 32);
    gpu::FrameParams f = make_frame_params(p, o);
    Kernel k = cpu::make_shade_kernel(p);
    ASSERT_NE(k.wide_nodes, nullptr);
    int shadowed = 0;
    for (std::uint32_t y = 0; y < 32; ++y)
        for (std::uint32_t x = 0; x < 32; ++x) {
            Kernel::SurfacePoint sp;
            ASSERT_TRUE(k.lc_camera_hit(f, x, y, 0, sp));
            Kernel::ShadeStats loop_stats{}, packet_stats{};
            const glm::vec3 loop = k.lc_shade_brute(sp, f.light_count, f.min_distance2, loop_stats);
            const glm::vec3 packets = k.lc_shade_brute_packets(sp, f.light_count, f.min_distance2, packet_stats);
            ASSERT_EQ(packets, loop) << x << "," << y;
            ASSERT_EQ(packet_stats.shadow_rays, loop_stats.shadow_rays) << x << "," << y;
            // Where shadows matter: the unshadowed sum is larger.
            glm::vec3 unshadowed(0.0f);
            for (std::uint32_t i = 0; i < f.light_count; ++i) {
                glm::vec3 wi;
                float t_max;
                unshadowed += k.lc_light_unit(sp, p.tree.lights[i], f.min_distance2, wi, t_max) *
                              k.lc_light_intensity(p.tree.lights[i]);
            }
            shadowed += gpu::lc_luminance(unshadowed) > 1.01f * gpu::lc_luminance(loop);
        }
    EXPECT_GT(shadowed, 100);
}

// Brute force is the reference, so its sum must not drop light: 65,536
// lights each about 2^-27 of the sum of eight bright ones among them (at
// the corners of their box, so that some come early in any light order),
// below half a float step of the running sum, which a plain float sum
// rounds away, give the double-precision sum of the same contributions, in
// the shared loop and in the packets.
TEST(BruteForce, ManyDimLightsBesideBrightOnesAllCount) {
    PreparedScene p = prepare_scene(test::room_scene(test::many_dim_lights(), 8), 1);
    RenderOptions o = test::options("brute", 8);
    const gpu::FrameParams f = make_frame_params(p, o);
    Kernel k = cpu::make_shade_kernel(p);
    const Kernel::SurfacePoint sp =
        k.lc_make_surface({-0.5f, 0.0f, 0.7f}, {0.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 0, glm::vec2(0.0f), glm::vec4(0.0f));
    glm::dvec3 exact(0.0);
    for (std::uint32_t i = 0; i < f.light_count; ++i) {
        glm::vec3 wi;
        float t_max;
        exact += glm::dvec3(k.lc_light_unit(sp, p.tree.lights[i], f.min_distance2, wi, t_max) *
                            k.lc_light_intensity(p.tree.lights[i]));
    }
    Kernel::ShadeStats loop_stats{}, packet_stats{};
    const glm::vec3 loop = k.lc_shade_brute(sp, f.light_count, f.min_distance2, loop_stats);
    const glm::vec3 packets = k.lc_shade_brute_packets(sp, f.light_count, f.min_distance2, packet_stats);
    ASSERT_EQ(loop_stats.shadow_rays, 65544u);  // nothing between the lights and the point
    EXPECT_EQ(packets, loop);
    std::printf("[ measured ] brute force of 8 + 65536 lights: relative error %.2e against double\n",
                std::abs(double(loop.x) / exact.x - 1.0));
    // The sum is in double and rounded to float once at the end (2^-24 =
    // 6e-8); 1e-6 allows the contributions' own float rounding besides.
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(loop[c], exact[c], 1e-6 * exact[c]);
}

// A scene far from the origin renders as the same scene at the origin:
// prepare_scene moves it there. Every coordinate here is a multiple of
// 1/8 and the translation 16384, so both scenes hold exactly the same
// shapes in float. (Rendered where it lay, hit points were shaded 2^-20 of
// 16384 off their surfaces, 0.016, and lights 0.25 above the floor lit it
// up to 14% more.)
TEST(PrepareScene, AFarSceneRendersAsAtTheOrigin) {
    auto scene_at = [](glm::vec3 t) {
        Scene s;
        s.materials = {test::lambert({0.7f, 0.7f, 0.7f})};
        test::add_quad(s, glm::vec3(-1, 0, -1) + t, glm::vec3(-1, 0, 1) + t, glm::vec3(1, 0, 1) + t,
                       glm::vec3(1, 0, -1) + t, 0);
        test::add_box(s, glm::vec3(-0.25f, 0.0f, -0.25f) + t, glm::vec3(0.25f, 0.5f, 0.25f) + t, 0);
        for (const glm::vec3 p : {glm::vec3(0.5f, 0.25f, 0.375f), glm::vec3(-0.625f, 0.25f, -0.5f),
                                  glm::vec3(0.125f, 1.5f, -0.75f)})
            s.lights.push_back(test::point_light(p + t, glm::vec3(1.0f)));
        s.camera = test::camera(glm::vec3(0.0f, 1.5f, 2.0f) + t, t, 60.0f, 16, 16);
        update_bounds(s);
        return s;
    };
    const glm::vec3 far(16384.0f, 16384.0f, -16384.0f);
    const PreparedScene here = prepare_scene(scene_at(glm::vec3(0.0f)), 1);
    const PreparedScene there = prepare_scene(scene_at(far), 1);
    EXPECT_LT(glm::length(there.scene.camera.position), 4.0f);  // moved
    EXPECT_EQ(here.scene.camera.position, glm::vec3(0.0f, 1.5f, 2.0f));  // near the origin: left as it is
    // A camera far from the scene keeps its forward vector: its look_at is
    // not moved on its own (which rounded (-1, 2e-4, 0) to (-2, 2e-4, 0)
    // 1e7 out, where floats are 1 apart).
    Scene distant = scene_at(glm::vec3(100000.5f, 0.0f, 0.0f));
    distant.camera.position = glm::vec3(1e7f, 0.0f, 0.0f);
    distant.camera.look_at = glm::vec3(9999999.0f, 0.0002f, 0.0f);
    const Camera moved = prepare_scene(distant, 1).scene.camera;
    const glm::vec3 forward = moved.look_at - moved.position;  // rounded once, near the scene
    EXPECT_EQ(forward.x, -1.0f);
    EXPECT_NEAR(forward.y, 0.0002f, 1e-7f);
    EXPECT_EQ(forward.z, 0.0f);
    for (const char* method : {"brute", "lightcuts"}) {
        const RenderOptions o = test::options(method, 16);
        const CompareResult c = compare_images(render_cpu(there, o).image, render_cpu(here, o).image);
        std::printf("[ measured ] %s, the scene at 16384 against at the origin: relative RMSE %.2e\n", method,
                    c.relative_rmse);
        EXPECT_LT(c.relative_rmse, 1e-5) << method;
    }
}

// The seed report compared the bound with the estimate in absolute terms;
// the threshold here is relative. Scaling every intensity by an exact power
// of two scales every bound, estimate and cluster sum exactly (no rounding,
// far from overflow and denormals), so every cut must stay the same and the
// image must scale exactly.
TEST(Lightcuts, ThresholdIsRelativeToTheEstimate) {
    auto base = test::random_point_lights(500, {-0.9f, 0.2f, -0.9f}, {0.9f, 1.9f, 0.9f}, 10.0f, 8);
    PreparedScene p0 = prepare_scene(test::room_scene(base, 24), 1);
    for (const char* sharing : {"pixel", "quad", "octet"}) {
        RenderOptions o = test::options("lightcuts", 24);
        o.cut_sharing = sharing;
        const RenderResult reference = render_cpu(p0, o);
        for (float scale : {std::ldexp(1.0f, 20), std::ldexp(1.0f, -20)}) {
            auto lights = base;
            for (auto& l : lights) { l.r *= scale; l.g *= scale; l.b *= scale; }
            PreparedScene p = prepare_scene(test::room_scene(lights, 24), 1);
            RenderResult r = render_cpu(p, o);
            ASSERT_EQ(r.stats.cut_size, reference.stats.cut_size) << sharing << " scale " << scale;
            for (std::size_t i = 0; i < r.image.rgb.size(); ++i)
                ASSERT_EQ(r.image.rgb[i], reference.image.rgb[i] * scale)
                    << sharing << " scale " << scale << " value " << i;
        }
    }
}

// The heap holds only interior nodes, and never more than the cut: its
// capacity follows the tree, whatever max_cut says.
TEST(Lightcuts, HeapCapacityFollowsTheTree) {
    std::vector<gpu::Light> lights;
    for (int i = 0; i < 8; ++i) lights.push_back(test::point_light({float(i), 1, 0}, {1, 1, 1}));
    LightTree points_only = build_light_tree(lights, 1);
    EXPECT_EQ(points_only.cut_heap_capacity(4000000000u), 7u);  // 8 lights: 7 interior nodes
    EXPECT_EQ(points_only.cut_heap_capacity(3u), 3u);
    EXPECT_EQ(points_only.cut_heap_capacity(1u), 1u);
    lights.push_back(test::directional_light({0, -1, 0}, {1, 1, 1}));
    lights.push_back(test::directional_light({1, -1, 0}, {1, 1, 1}));
    LightTree both = build_light_tree(lights, 1);
    EXPECT_EQ(both.cut_heap_capacity(4000000000u), 8u);  // 7 + 1 interior nodes
    EXPECT_EQ(both.cut_heap_capacity(1u), 2u);           // the two roots start the cut
    LightTree single = build_light_tree(std::vector<gpu::Light>{lights[0]}, 1);
    EXPECT_EQ(single.cut_heap_capacity(1000u), 1u);      // no interior node; never zero
}

// max_cut = 4e9 once sized the heap by max_cut: 80 GB per thread, and
// bad_alloc in a worker thread ended the process. Now it renders, and as
// the cut never reaches the limit it equals a render with max_cut = n.
TEST(Lightcuts, HugeMaxCutRendersLikeAnUnreachableLimit) {
    auto lights = test::random_point_lights(64, {-0.9f, 0.2f, -0.9f}, {0.9f, 1.9f, 0.9f}, 10.0f, 3);
    PreparedScene p = prepare_scene(test::room_scene(lights, 16), 1);
    RenderOptions o = test::options("lightcuts", 16);
    o.relative_error = 0.0f;
    o.max_cut = 64;
    const RenderResult limited = render_cpu(p, o);
    o.max_cut = 4000000000u;
    const RenderResult huge = render_cpu(p, o);
    EXPECT_EQ(huge.image.rgb, limited.image.rgb);
    EXPECT_EQ(huge.stats.max_cut_pixels, 0u);
}

// Cost grows sublinearly: 100x more lights, less than 3x the mean cut.
TEST(Lightcuts, MeanCutSizeGrowsSublinearly) {
    auto mean_cut = [](std::size_t n) {
        auto lights = test::random_point_lights(n, {-0.95f, 1.2f, -0.95f}, {0.95f, 1.95f, 0.95f}, 30.0f, 21);
        PreparedScene p = prepare_scene(test::room_scene(lights, 32), 1);
        RenderResult r = render_cpu(p, test::options("lightcuts", 32));
        return std::accumulate(r.stats.cut_size.begin(), r.stats.cut_size.end(), 0.0) / double(r.stats.cut_size.size());
    };
    double small = mean_cut(1000), large = mean_cut(100000);
    RecordProperty("mean_cut_1e3", std::to_string(small));
    RecordProperty("mean_cut_1e5", std::to_string(large));
    EXPECT_LT(large, 3.0 * small) << "mean cut " << small << " at 10^3 lights, " << large << " at 10^5";
    EXPECT_GT(small, 2.0);  // the cut does refine
}

}  // namespace
}  // namespace lc

namespace lc {
namespace {

struct ShippedCase {
    const char* scene;
    double max_rmse;           // relative RMSE limit
    double max_above_2pct;     // limit on the fraction of pixels above 2% error
    double max_above_5pct;
    // The default cut heap (kDefaultCutHeap slots, clusters frozen out of a
    // full heap): relative RMSE limit against brute force. The limits above
    // hold for a heap as large as the tree needs (nothing frozen).
    double bounded_max_rmse;
};

// Lightcuts at the defaults (relative_error 0.02, max_cut 1000) against brute
// force on the shipped scenes at 64x64. Measured when this test was written
// (commit history has the numbers; re-measure before changing a limit):
//   room:  relative RMSE 0.0080, 6.3% of pixels above 2%, 0.15% above 5%;
//   bunny: relative RMSE 0.0076, 3.8% of pixels above 2%, 0.20% above 5%.
// The 2% threshold bounds each cluster's error, not the pixel's, so a pixel
// can exceed 2%; the limits sit about 1.5x above the measurement.
// With the default heap of 64 slots, measured relative RMSE: room 0.0082,
// bunny 0.0077, panels 0.0013, gallery 0.114 (its loose spot cones make cuts
// of 700 clusters, which a heap of 64 cannot refine: docs/results/speed.md,
// section 2),
// sky 0.0121, materials 0.0113; the limit is the last field.
// Those are a cut per pixel's (cut_sharing "pixel", the Vulkan kernels'
// cuts). Cuts shared by 2x2 quads and by 4x2 octets (the CPU's default),
// their pixels' slots pooled, are held to the same limits; measured at the
// unbounded and bounded heap, quads: room 0.0070 and 0.0070, bunny 0.0070
// and 0.0070, panels 0.0013 and 0.0013, gallery 0.0380 and 0.0382, sky
// 0.0103 and 0.0103, materials 0.0095 and 0.0095 (the shared cut is the
// union of its points' refinements, so at least as fine as each point's
// own); octets: room 0.0065 and 0.0065, bunny 0.0067 and 0.0067, panels
// 0.0012 and 0.0012, gallery 0.0459 and 0.0414 (24.0% and 20.3% of its
// pixels above 5%: where the union of eight refinements reaches max_cut,
// each point gets less of it, which is why a tile's blocks after such an
// octet are cut as quads, host/cpu_renderer.cpp), sky 0.0099 and 0.0099,
// materials 0.0088 and 0.0088.
class ShippedScenes : public ::testing::TestWithParam<ShippedCase> {};

TEST_P(ShippedScenes, LightcutsMatchesBruteForceAtDefaults) {
    const ShippedCase& c = GetParam();
    // The bunny comes from the npm package (install-deps.sh), the sky and the
    // gallery's spots from the scripts `make scenes` runs.
    const bool uses_bunny = std::string(c.scene).find("bunny") != std::string::npos ||
                            std::string(c.scene).find("sky") != std::string::npos;
    if (uses_bunny && !std::filesystem::exists(std::string(LC_SOURCE_DIR) + "/scenes/bunny/bunny.obj"))
        GTEST_SKIP() << "scenes/bunny/bunny.obj is missing: run scripts/fetch-bunny.sh";
    Scene scene = load_scene(std::string(LC_SOURCE_DIR) + "/" + c.scene);
    // Brute force over the panels' 65536 samples takes half a minute here:
    // the test samples them 4096 times.
    scene.render.area_light_samples = std::min(scene.render.area_light_samples, 4096u);
    PreparedScene p = prepare_scene(std::move(scene), 1);
    RenderResult brute = render_cpu(p, test::options("brute", 64));
    for (const char* sharing : {"pixel", "quad", "octet"}) {
        SCOPED_TRACE(sharing);
        RenderOptions o = test::options("lightcuts", 64);
        o.cut_sharing = sharing;
        o.cut_heap = o.max_cut;
        RenderResult lc = render_cpu(p, o);
        ASSERT_EQ(lc.stats.heap_frozen_samples, 0u);
        o.cut_heap = kDefaultCutHeap;
        const RenderResult bounded = render_cpu(p, o);
        CompareResult cmp = compare_images(lc.image, brute.image);
        std::printf("[ measured ] %s, %s: relative RMSE %.4f, above 2%% %.4f, above 5%% %.4f; rays %llu vs %llu\n",
                    c.scene, sharing, cmp.relative_rmse, cmp.fraction_above_2pct, cmp.fraction_above_5pct,
                    static_cast<unsigned long long>(lc.stats.shadow_rays),
                    static_cast<unsigned long long>(brute.stats.shadow_rays));
        RecordProperty("relative_rmse", std::to_string(cmp.relative_rmse));
        RecordProperty("above_2pct", std::to_string(cmp.fraction_above_2pct));
        EXPECT_LT(cmp.relative_rmse, c.max_rmse);
        EXPECT_LT(cmp.fraction_above_2pct, c.max_above_2pct);
        EXPECT_LT(cmp.fraction_above_5pct, c.max_above_5pct);
        EXPECT_LT(lc.stats.shadow_rays, brute.stats.shadow_rays / 4);
        const CompareResult bounded_cmp = compare_images(bounded.image, brute.image);
        std::printf("[ measured ] %s, %s, cut_heap %u: relative RMSE %.4f, above 2%% %.4f, above 5%% %.4f; %.1f%% of "
                    "the samples froze clusters\n",
                    c.scene, sharing, kDefaultCutHeap, bounded_cmp.relative_rmse, bounded_cmp.fraction_above_2pct,
                    bounded_cmp.fraction_above_5pct, 100.0 * double(bounded.stats.heap_frozen_samples) / (64.0 * 64.0));
        EXPECT_LT(bounded_cmp.relative_rmse, c.bounded_max_rmse);
    }
}

INSTANTIATE_TEST_SUITE_P(Lightcuts, ShippedScenes,
                         ::testing::Values(ShippedCase{"scenes/room/room.json", 0.012, 0.09, 0.01, 0.012},
                                           ShippedCase{"scenes/bunny/bunny.json", 0.012, 0.06, 0.01, 0.012},
                                           // Measured 0.0013, 5.7%, 0.12% (4096 samples).
                                           ShippedCase{"scenes/panels/panels.json", 0.002, 0.086, 0.002, 0.002},
                                           // Measured 0.040, 53%, 17%: sharp spots whose
                                           // representative misses the point (docs/lightcuts.md);
                                           // above 5% the octets measure 24.1% (quads 23.2%), so
                                           // that limit is 1.5 times the octets'.
                                           ShippedCase{"scenes/gallery/gallery.json", 0.06, 0.8, 0.36, 0.16},
                                           // Measured 0.012, 9.1%, 0.24%.
                                           ShippedCase{"scenes/sky/sky.json", 0.018, 0.14, 0.004, 0.018},
                                           // Disney spheres: measured 0.0106, 8.2%, 0.17%.
                                           ShippedCase{"scenes/materials/materials.json", 0.016, 0.12, 0.003, 0.016}),
                         [](const auto& info) {
                             std::string name = info.param.scene;
                             name = name.substr(name.rfind('/') + 1);
                             return name.substr(0, name.find('.'));
                         });

}  // namespace
}  // namespace lc
