// Light tree invariants on random and degenerate light sets.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "lightcuts/light_tree.h"
#include "test_util.h"

namespace lc {
namespace {

// Checks every structural promise of the flattened tree; returns nothing,
// fails the test on the first broken invariant.
void check_tree(const LightTree& tree, std::span<const gpu::Light> input) {
    // Black lights stay out of the tree (and are counted).
    std::size_t n_point = 0, n_dir = 0, n_black = 0;
    for (const auto& l : input) {
        if (l.r == 0.0f && l.g == 0.0f && l.b == 0.0f) n_black += 1;
        else (l.type == gpu::kLightPoint ? n_point : n_dir) += 1;
    }
    std::size_t expected = (n_point ? 2 * n_point - 1 : 0) + (n_dir ? 2 * n_dir - 1 : 0);
    ASSERT_EQ(tree.nodes.size(), expected);
    ASSERT_EQ(tree.lights.size(), n_point + n_dir);
    ASSERT_EQ(tree.black_lights, n_black);
    ASSERT_EQ(tree.roots[gpu::kLightPoint], n_point ? 0u : gpu::kInvalidIndex);
    ASSERT_EQ(tree.roots[gpu::kLightDirectional],
              n_dir ? std::uint32_t(n_point ? 2 * n_point - 1 : 0) : gpu::kInvalidIndex);
    // Every node of a type's tree carries that type.
    for (std::uint32_t type = 0; type < gpu::kLightTypeCount; ++type) {
        const std::uint32_t root = tree.roots[type];
        if (root == gpu::kInvalidIndex) continue;
        const std::size_t count = 2 * (type == gpu::kLightPoint ? n_point : n_dir) - 1;
        for (std::size_t i = root; i < root + count; ++i) ASSERT_EQ(test::node_type(tree.nodes[i]), type) << i;
    }

    std::vector<int> light_seen(tree.lights.size(), 0);
    for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
        const gpu::LightNode& n = tree.nodes[i];
        ASSERT_LT(n.rep_light, tree.lights.size());
        for (float v : {n.min_x, n.min_y, n.min_z, n.max_x, n.max_y, n.max_z, n.intensity_r, n.intensity_g,
                        n.intensity_b})
            ASSERT_TRUE(std::isfinite(v));
        if (n.flags & gpu::kNodeLeaf) {
            const gpu::Light& l = tree.lights[n.rep_light];
            EXPECT_EQ(n.min_x, l.x);
            EXPECT_EQ(n.max_y, l.y);
            EXPECT_EQ(n.intensity_r, l.r);
            light_seen[n.rep_light] += 1;
            continue;
        }
        ASSERT_LT(n.left + 1, tree.nodes.size());
        ASSERT_GT(n.left, i);
        const gpu::LightNode& a = tree.nodes[n.left];
        const gpu::LightNode& b = tree.nodes[n.left + 1];
        // Intensity is the sum of the children's: each of the three is the
        // exact sum of its lights rounded once to float (relative error
        // 2^-24 at most, intensities >= 0), so the node and the exact sum of
        // its children's floats are at most 3 * 2^-24 of the node apart.
        auto near = [](float sum, float x, float y) {
            return std::abs(double(sum) - (double(x) + double(y))) <= 3.0 * 0x1p-24 * double(sum) + 1e-45;
        };
        EXPECT_TRUE(near(n.intensity_r, a.intensity_r, b.intensity_r)) << i;
        EXPECT_TRUE(near(n.intensity_g, a.intensity_g, b.intensity_g)) << i;
        EXPECT_TRUE(near(n.intensity_b, a.intensity_b, b.intensity_b)) << i;
        // The box contains the children's boxes.
        for (const auto* c : {&a, &b}) {
            EXPECT_LE(n.min_x, c->min_x); EXPECT_LE(n.min_y, c->min_y); EXPECT_LE(n.min_z, c->min_z);
            EXPECT_GE(n.max_x, c->max_x); EXPECT_GE(n.max_y, c->max_y); EXPECT_GE(n.max_z, c->max_z);
        }
        // The representative is the flagged child's.
        const gpu::LightNode& rep_child = (n.flags & gpu::kNodeRepFromRight) ? b : a;
        EXPECT_EQ(n.rep_light, rep_child.rep_light) << i;
    }
    for (std::size_t i = 0; i < light_seen.size(); ++i) ASSERT_EQ(light_seen[i], 1) << "light " << i;

    // Leaves appear in light order in a depth-first walk: subtrees are ranges.
    for (std::uint32_t root : tree.roots) {
        if (root == gpu::kInvalidIndex) continue;
        std::vector<std::uint32_t> stack{root};
        std::uint32_t expected_light = tree.nodes[root].flags & gpu::kNodeLeaf ? tree.nodes[root].rep_light : 0;
        bool first = true;
        while (!stack.empty()) {
            std::uint32_t i = stack.back();
            stack.pop_back();
            const auto& n = tree.nodes[i];
            if (n.flags & gpu::kNodeLeaf) {
                if (first) expected_light = n.rep_light, first = false;
                ASSERT_EQ(n.rep_light, expected_light);
                ++expected_light;
            } else {
                stack.push_back(n.left + 1);
                stack.push_back(n.left);
            }
        }
    }
}

std::vector<gpu::Light> random_mixed(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-5.0f, 5.0f), w(0.0f, 2.0f);
    std::vector<gpu::Light> lights;
    for (std::size_t i = 0; i < n; ++i) {
        if (i % 7 == 3)
            lights.push_back(test::directional_light({u(rng), u(rng) - 6.0f, u(rng)}, {w(rng), w(rng), w(rng)}));
        else
            lights.push_back(test::point_light({u(rng), u(rng), u(rng)}, {w(rng), w(rng), w(rng)}));
    }
    return lights;
}

TEST(LightTree, InvariantsOnRandomSets) {
    for (std::size_t n : {1u, 2u, 3u, 10u, 1000u, 100000u}) {
        SCOPED_TRACE(n);
        auto lights = random_mixed(n, std::uint32_t(n));
        check_tree(build_light_tree(lights, 5), lights);
        if (n <= 1000) check_tree(build_light_tree(lights, 5, TreeBuilder::kExact), lights);
    }
}

TEST(LightTree, InvariantsOnDegenerateSets) {
    std::vector<std::vector<gpu::Light>> cases;
    cases.emplace_back(1000, test::point_light({1, 2, 3}, {1, 1, 1}));  // coincident
    std::vector<gpu::Light> line, plane, zeros;
    for (int i = 0; i < 1000; ++i) line.push_back(test::point_light({float(i) * 0.01f, 0, 0}, {1, 0.5f, 0.25f}));
    for (int i = 0; i < 1024; ++i)
        plane.push_back(test::point_light({float(i % 32), 0, float(i / 32)}, {0.1f, 0.1f, 0.1f}));
    for (int i = 0; i < 1000; ++i)
        zeros.push_back(test::point_light({float(i % 10), float(i / 100), float((i / 10) % 10)},
                                          i % 3 ? glm::vec3(0.0f) : glm::vec3(1.0f)));
    cases.push_back(line);
    cases.push_back(plane);
    cases.push_back(zeros);
    cases.emplace_back(10, test::point_light({0, 0, 0}, {0, 0, 0}));  // all zero
    for (std::size_t c = 0; c < cases.size(); ++c) {
        SCOPED_TRACE(c);
        check_tree(build_light_tree(cases[c], 1), cases[c]);
        check_tree(build_light_tree(cases[c], 1, TreeBuilder::kExact), cases[c]);
    }
}

// The same cases at a size where the leaves are made and the merges done on
// several threads (4096 lights and more): black lights scattered over every
// thread's range of lights, coincident lights (every merge cost equal).
// The deepest leaf of the tree whose root is node 0.
std::uint32_t tree_depth(const LightTree& tree) {
    std::vector<std::uint32_t> depth(tree.nodes.size(), 0);
    std::uint32_t deepest = 0;
    for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
        const gpu::LightNode& node = tree.nodes[i];
        if (node.flags & gpu::kNodeLeaf) continue;
        depth[node.left] = depth[node.left + 1] = depth[i] + 1;
        deepest = std::max(deepest, depth[i] + 1);
    }
    return deepest;
}

TEST(LightTree, InvariantsOnLargeDegenerateSets) {
    std::vector<gpu::Light> zeros, coincident(50000, test::point_light({1, 2, 3}, {1, 1, 1}));
    for (int i = 0; i < 50000; ++i)
        zeros.push_back(test::point_light({float(i % 50), float(i / 2500), float((i / 50) % 50)},
                                          i % 3 ? glm::vec3(0.0f) : glm::vec3(1.0f)));
    for (const auto* lights : {&zeros, &coincident}) {
        const LightTree tree = build_light_tree(*lights, 1);
        check_tree(tree, *lights);
        // Coincident lights pair up round by round: a balanced tree.
        if (lights == &coincident) {
            EXPECT_LE(tree_depth(tree), 20u);  // log2(50000) = 15.6
        }
    }
}

// Scaling every position or every intensity by a power of two scales the
// build's metric exactly, so the tree is the same, also where the metric's
// floats would overflow inside what the loader accepts (positions at 2^60,
// 1.2e18: 38,644 of 39,999 nodes differed, the tree 27% worse by its own
// measure; intensities of 2^110 each, 20% worse); and oriented lights of
// one axis spread over 1e20 no longer make a chain (infinity times a zero
// cone term was NaN: depth 3999 for 4000 lights).
TEST(LightTree, SameTreeWhereTheMetricsFloatsWouldOverflow) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f), w(0.5f, 1.0f);
    std::vector<gpu::Light> lights;
    for (int i = 0; i < 20000; ++i) lights.push_back(test::point_light({u(rng), u(rng), u(rng)}, {w(rng), w(rng), w(rng)}));
    const LightTree reference = build_light_tree(lights, 1);
    const auto same_shape = [&](const LightTree& t) {
        ASSERT_EQ(t.nodes.size(), reference.nodes.size());
        std::size_t differ = 0;
        for (std::size_t i = 0; i < t.nodes.size(); ++i)
            differ += t.nodes[i].left != reference.nodes[i].left || t.nodes[i].rep_light != reference.nodes[i].rep_light ||
                      t.nodes[i].flags != reference.nodes[i].flags;
        EXPECT_EQ(differ, 0u);
    };
    std::vector<gpu::Light> far = lights, bright = lights;
    for (gpu::Light& l : far) l.x *= 0x1p60f, l.y *= 0x1p60f, l.z *= 0x1p60f;
    for (gpu::Light& l : bright) l.r *= 0x1p110f, l.g *= 0x1p110f, l.b *= 0x1p110f;
    {
        SCOPED_TRACE("positions times 2^60");
        same_shape(build_light_tree(far, 1));
    }
    {
        SCOPED_TRACE("intensities times 2^110");
        same_shape(build_light_tree(bright, 1));
    }
    std::vector<gpu::Light> spread;
    for (int i = 0; i < 4000; ++i)
        spread.push_back(test::oriented_light({u(rng) * 1e20f, u(rng) * 1e20f, u(rng) * 1e20f}, {0, 1, 0}, {1, 1, 1}));
    const LightTree oriented = build_light_tree(spread, 1);
    ASSERT_EQ(oriented.nodes.size(), 2u * spread.size() - 1u);
    EXPECT_LE(tree_depth(oriented), 40u);  // log2(4000) = 12
}

// Scaled no further than overflow needs: beside a sun-like light (3e25 at
// 1.5e11), lights a centimetre apart keep their costs (scaled to keep
// every coordinate below 1 and the total weight below 1, theirs became 0
// and their tree was the ties' order). The exact builder, which pairs by
// the costs alone, gives them the tree it gives them without the sun.
TEST(LightTree, ScalingKeepsSmallCostsBesideHugeOnes) {
    std::vector<gpu::Light> room;
    for (int i = 0; i < 200; ++i)
        room.push_back(test::point_light({0.01f * float(i % 10), 0.013f * float(i / 10 % 5), 0.017f * float(i / 50)},
                                         {1.0f + 0.01f * float(i % 7), 1.0f, 1.0f}));
    std::vector<gpu::Light> with_sun = room;
    with_sun.push_back(test::point_light({1.5e11f, 0.0f, 0.0f}, {3e25f, 3e25f, 3e25f}));
    const auto interior_boxes = [](const LightTree& t, float skip_above) {
        std::vector<std::array<float, 6>> boxes;
        for (const gpu::LightNode& n : t.nodes)
            if (!(n.flags & gpu::kNodeLeaf) && n.max_x < skip_above)
                boxes.push_back({n.min_x, n.min_y, n.min_z, n.max_x, n.max_y, n.max_z});
        std::sort(boxes.begin(), boxes.end());
        return boxes;
    };
    const LightTree alone = build_light_tree(room, 1, TreeBuilder::kExact);
    const LightTree both = build_light_tree(with_sun, 1, TreeBuilder::kExact);
    EXPECT_EQ(interior_boxes(both, 1e10f), interior_boxes(alone, 1e10f));
}

// The exact builder's costs all infinite (six lights 9e18 apart, each of
// 1e30): it merged a cluster with itself and wrote past the node array.
TEST(LightTree, ExactBuilderWithInfiniteCosts) {
    std::vector<gpu::Light> lights;
    for (int i = 0; i < 6; ++i)
        lights.push_back(test::point_light({float(i % 2) * 9e18f, float(i / 2 % 2) * 9e18f, float(i / 4) * 9e18f},
                                           {1e30f, 1e30f, 1e30f}));
    check_tree(build_light_tree(lights, 1, TreeBuilder::kExact), lights);
}

// Black lights stay out of the tree; lights 10^40 times dimmer than their
// neighbours (denormal floats) stay in, and are picked as a cluster's
// representative in proportion to intensity: never, where a bright light
// shares the cluster (a choice blind to the weights, or one whose
// probability underflowed to a uniform draw, would pick them about half
// the time).
TEST(LightTree, RepresentativesFollowIntensityToTheSmallestFloats) {
    std::vector<gpu::Light> lights;
    for (int i = 0; i < 300; ++i) {
        const glm::vec3 intensity = i % 3 == 0 ? glm::vec3(1.0f) : i % 3 == 1 ? glm::vec3(1e-40f) : glm::vec3(0.0f);
        lights.push_back(test::point_light({float(i), 0, 0}, intensity));
    }
    LightTree tree = build_light_tree(lights, 9);
    EXPECT_EQ(tree.black_lights, 100u);
    ASSERT_EQ(tree.lights.size(), 200u);
    std::size_t dim_reps = 0, bright_subtrees = 0;
    for (const auto& n : tree.nodes) {
        if (n.flags & gpu::kNodeLeaf) continue;
        if (n.intensity_r < 0.5f) continue;  // only dim lights below
        ++bright_subtrees;
        if (tree.lights[n.rep_light].r < 0.5f) ++dim_reps;
    }
    EXPECT_GT(bright_subtrees, 90u);
    EXPECT_EQ(dim_reps, 0u);
}

TEST(LightTree, SameSeedSameTree) {
    auto lights = random_mixed(20000, 3);
    LightTree a = build_light_tree(lights, 11), b = build_light_tree(lights, 11);
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    EXPECT_EQ(0, std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(gpu::LightNode)));
    EXPECT_EQ(0, std::memcmp(a.lights.data(), b.lights.data(), a.lights.size() * sizeof(gpu::Light)));
    // A different seed changes some representatives.
    LightTree c = build_light_tree(lights, 12);
    int differ = 0;
    for (std::size_t i = 0; i < a.nodes.size(); ++i) differ += a.nodes[i].rep_light != c.nodes[i].rep_light;
    EXPECT_GT(differ, 0);
}

// The same tree whatever the thread count: each thread of the build writes
// where one pass in order would. 4100 lights on 128 threads leave the last
// threads' ranges empty (a thread with no lights once put the origin into
// the tree's box); a third of the lights are black, a seventh directional.
TEST(LightTree, SameTreeWhateverTheThreadCount) {
    for (std::size_t n : {4100u, 30000u}) {
        SCOPED_TRACE(n);
        std::vector<gpu::Light> lights = random_mixed(n, std::uint32_t(n) + 1);
        for (std::size_t i = 0; i < n; i += 3) lights[i].r = lights[i].g = lights[i].b = 0.0f;
        const LightTree one = build_light_tree(lights, 3, TreeBuilder::kFast, 1.0, 1);
        check_tree(one, lights);
        for (unsigned threads : {2u, 3u, 7u, 128u}) {
            SCOPED_TRACE(threads);
            const LightTree t = build_light_tree(lights, 3, TreeBuilder::kFast, 1.0, threads);
            ASSERT_EQ(t.nodes.size(), one.nodes.size());
            ASSERT_EQ(t.lights.size(), one.lights.size());
            EXPECT_EQ(t.roots, one.roots);
            EXPECT_EQ(t.black_lights, one.black_lights);
            EXPECT_EQ(std::memcmp(t.nodes.data(), one.nodes.data(), one.nodes.size() * sizeof(gpu::LightNode)), 0);
            EXPECT_EQ(std::memcmp(t.lights.data(), one.lights.data(), one.lights.size() * sizeof(gpu::Light)), 0);
        }
    }
}

// The same over the leaves' own passes (the Morton keys' radix sort, the
// merges): 4097 lit point lights make one tree of 4097 leaves, which 128
// threads split into ranges of 33, leaving the last three threads none (the
// sort once read those threads' counts from its previous pass, past the end
// of its arrays).
TEST(LightTree, SameTreeWhenSomeThreadsGetNoLeaves) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-5.0f, 5.0f), w(0.1f, 2.0f);
    std::vector<gpu::Light> lights;
    for (int i = 0; i < 4097; ++i) lights.push_back(test::point_light({u(rng), u(rng), u(rng)}, {w(rng), w(rng), w(rng)}));
    const LightTree one = build_light_tree(lights, 5, TreeBuilder::kFast, 1.0, 1);
    check_tree(one, lights);
    for (unsigned threads : {2u, 100u, 128u}) {
        SCOPED_TRACE(threads);
        const LightTree t = build_light_tree(lights, 5, TreeBuilder::kFast, 1.0, threads);
        ASSERT_EQ(t.nodes.size(), one.nodes.size());
        EXPECT_EQ(std::memcmp(t.nodes.data(), one.nodes.data(), one.nodes.size() * sizeof(gpu::LightNode)), 0);
        EXPECT_EQ(std::memcmp(t.lights.data(), one.lights.data(), one.lights.size() * sizeof(gpu::Light)), 0);
    }
}

// Spots and oriented lights (one-sided, two-sided) keep each cluster's
// cone beside its record, written by the merges on every thread: the same
// trees on any thread count, with more leaves per tree than one thread
// takes alone (4096).
TEST(LightTree, SameConeTreesWhateverTheThreadCount) {
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> u(-5.0f, 5.0f), w(0.1f, 2.0f), a(5.0f, 40.0f);
    std::vector<gpu::Light> lights;
    for (int i = 0; i < 15000; ++i) {
        const glm::vec3 p(u(rng), u(rng), u(rng)), axis(u(rng), u(rng), u(rng) + 0.01f), c(w(rng), w(rng), w(rng));
        if (i % 3 == 0) {
            const float inner = a(rng);
            lights.push_back(test::spot_light(p, axis, c, inner, inner + a(rng)));
        } else {
            lights.push_back(test::oriented_light(p, axis, c, i % 3 == 2));
        }
    }
    const LightTree one = build_light_tree(lights, 9, TreeBuilder::kFast, 1.0, 1);
    ASSERT_EQ(one.nodes.size(), std::size_t(2 * 5000 - 1 + 2 * 10000 - 1));  // a spot tree, an oriented tree
    for (unsigned threads : {2u, 7u, 128u}) {
        SCOPED_TRACE(threads);
        const LightTree t = build_light_tree(lights, 9, TreeBuilder::kFast, 1.0, threads);
        ASSERT_EQ(t.nodes.size(), one.nodes.size());
        EXPECT_EQ(t.roots, one.roots);
        EXPECT_EQ(std::memcmp(t.nodes.data(), one.nodes.data(), one.nodes.size() * sizeof(gpu::LightNode)), 0);
        EXPECT_EQ(std::memcmp(t.lights.data(), one.lights.data(), one.lights.size() * sizeof(gpu::Light)), 0);
    }
}

TEST(LightTree, EmptyInputGivesNoTree) {
    LightTree t = build_light_tree({}, 1);
    EXPECT_TRUE(t.nodes.empty());
    for (std::uint32_t root : t.roots) EXPECT_EQ(root, gpu::kInvalidIndex);
}

// Walter 2005 §4.1: a cluster's representative is one of its lights chosen
// with probability proportional to its intensity. The builder picks a
// child's representative in proportion to the child's luminance at every
// merge, so the root's representative is light i with probability
// Y_i / sum Y, the product of the branch probabilities on its path. Over
// 4000 seeds each light's frequency must lie within 5 standard deviations
// of Y_i / sum Y: a correct builder fails this for a given seed set with
// probability below 1e-5 (normal approximation of the binomial).
TEST(LightTree, RepresentativesFollowLuminance) {
    const std::vector<glm::vec3> colours = {{1, 1, 1}, {2, 0, 0}, {0, 3, 0}, {0, 0, 4}, {0.5f, 0.5f, 0.5f}};
    std::vector<gpu::Light> lights;
    double total = 0.0;
    for (std::size_t i = 0; i < colours.size(); ++i) {
        lights.push_back(test::point_light({float(i) * 1.5f, float(i % 2), 0.0f}, colours[i]));
        total += double(luminance(colours[i]));
    }
    const int seeds = 4000;
    std::vector<int> count(lights.size(), 0);
    for (int seed = 0; seed < seeds; ++seed) {
        LightTree tree = build_light_tree(lights, std::uint32_t(seed));
        const gpu::Light& rep = tree.lights[tree.nodes[0].rep_light];
        for (std::size_t i = 0; i < lights.size(); ++i)
            if (rep.x == lights[i].x && rep.y == lights[i].y) count[i] += 1;
    }
    for (std::size_t i = 0; i < lights.size(); ++i) {
        const double p = double(luminance(colours[i])) / total;
        const double sd = std::sqrt(seeds * p * (1.0 - p));
        EXPECT_NEAR(double(count[i]), seeds * p, 5.0 * sd) << "light " << i << " with probability " << p;
    }
}

// Cluster sums are taken in double: the root's intensity is the exact sum
// of the lights rounded once to float, even over intensities from 1e-8 to
// 1e8 (float sums lose the small ones and round at every merge).
TEST(LightTree, ClusterSumsAreExactlyRounded) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<gpu::Light> lights;
    glm::dvec3 exact(0.0);
    for (int i = 0; i < 20000; ++i) {
        const float magnitude = std::pow(10.0f, -8.0f + 16.0f * u(rng));
        const glm::vec3 c = glm::vec3(u(rng), u(rng), u(rng)) * magnitude;
        lights.push_back(test::point_light({u(rng), u(rng), u(rng)}, c));
        exact += glm::dvec3(c);
    }
    LightTree tree = build_light_tree(lights, 1);
    const gpu::LightNode& root = tree.nodes[0];
    EXPECT_EQ(root.intensity_r, float(exact.x));
    EXPECT_EQ(root.intensity_g, float(exact.y));
    EXPECT_EQ(root.intensity_b, float(exact.z));
}

}  // namespace
}  // namespace lc
