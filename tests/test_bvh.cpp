// BVH build and the shared traversal (shaders/lc_shared/trace.h, run on the CPU
// through lc::cpu::TraceKernel), checked against brute force over every
// triangle with the same intersection routine.
#include <algorithm>
#include <array>
#include <bit>
#include <cfloat>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "cpu_kernel.h"
#include "lightcuts/bvh.h"
#include "wide_trace.h"
#include "test_util.h"

namespace {

using glm::vec3;
using lc::gpu::BvhNode;
using lc::gpu::kInvalidIndex;
using lc::gpu::Triangle;
using lc::gpu::TriangleNormals;
constexpr float kRayInfinity = lc::cpu::TraceKernel::kRayInfinity;

Triangle make_triangle(vec3 a, vec3 b, vec3 c) {
    Triangle t{};
    t.v0_x = a.x; t.v0_y = a.y; t.v0_z = a.z;
    t.v1_x = b.x; t.v1_y = b.y; t.v1_z = b.z;
    t.v2_x = c.x; t.v2_y = c.y; t.v2_z = c.z;
    return t;
}
vec3 v0(const Triangle& t) { return {t.v0_x, t.v0_y, t.v0_z}; }
vec3 v1(const Triangle& t) { return {t.v1_x, t.v1_y, t.v1_z}; }
vec3 v2(const Triangle& t) { return {t.v2_x, t.v2_y, t.v2_z}; }
vec3 geometric_normal(const Triangle& t) { return glm::normalize(glm::cross(v1(t) - v0(t), v2(t) - v0(t))); }

// Triangles tagged with their input index (material, normals.pad0) so the
// permutation applied by the build can be checked.
struct Scene {
    std::vector<Triangle> triangles;
    std::vector<TriangleNormals> normals;
    lc::Bvh bvh;

    explicit Scene(std::vector<Triangle> input) : triangles(std::move(input)) {
        normals.resize(triangles.size());
        for (std::size_t i = 0; i < triangles.size(); ++i) {
            triangles[i].material = std::uint32_t(i);
            normals[i] = TriangleNormals{};
            normals[i].pad0 = std::uint32_t(i);
        }
        bvh = lc::build_bvh(triangles, normals);
    }
    lc::cpu::TraceKernel kernel() const { return {bvh.nodes.data(), triangles.data()}; }
};

struct Hit {
    std::uint32_t index = kInvalidIndex;
    float t = 0.0f;
};

Hit brute_closest(const Scene& s, vec3 org, vec3 dir, float t_max) {
    lc::cpu::TraceKernel k = s.kernel();
    Hit hit;
    float best = t_max;
    for (std::uint32_t i = 0; i < s.triangles.size(); ++i) {
        float b1, b2;
        const float t = k.lc_intersect_triangle(org, dir, s.triangles[i], best, b1, b2);
        if (t > 0.0f) {
            best = t;
            hit = {i, t};
        }
    }
    return hit;
}

bool brute_any(const Scene& s, vec3 org, vec3 dir, float t_max) {
    lc::cpu::TraceKernel k = s.kernel();
    for (const Triangle& tri : s.triangles) {
        float b1, b2;
        if (k.lc_intersect_triangle(org, dir, tri, t_max, b1, b2) > 0.0f) return true;
    }
    return false;
}

std::string describe(vec3 org, vec3 dir, float t_max) {
    std::ostringstream os;
    os.precision(9);
    os << "org (" << org.x << ", " << org.y << ", " << org.z << ") dir (" << dir.x << ", " << dir.y << ", " << dir.z
       << ") t_max " << t_max;
    return os.str();
}

// Compares the BVH traversal with brute force for one ray. Returns an empty
// string when they agree. Ties at shared edges may pick either triangle, but
// the distance must agree.
std::string check_ray(const Scene& s, vec3 org, vec3 dir, float t_max) {
    lc::cpu::TraceKernel k = s.kernel();
    float t, b1, b2;
    const std::uint32_t index = k.lc_trace_closest(org, dir, t_max, t, b1, b2);
    const float binary_t = t, binary_b1 = b1, binary_b2 = b2;  // (b1, b2 are reused below)
    const Hit expected = brute_closest(s, org, dir, t_max);
    if (index == kInvalidIndex || expected.index == kInvalidIndex) {
        if (index != expected.index)
            return "closest: bvh " + std::to_string(index) + " vs brute " + std::to_string(expected.index) + " for " +
                   describe(org, dir, t_max);
    } else {
        if (std::abs(t - expected.t) > 1e-6f * expected.t)
            return "closest t " + std::to_string(t) + " vs " + std::to_string(expected.t) + " for " +
                   describe(org, dir, t_max);
        if (index != expected.index) {
            const float t_own = k.lc_intersect_triangle(org, dir, s.triangles[index], kRayInfinity, b1, b2);
            if (!(std::abs(t_own - expected.t) <= 1e-6f * expected.t))
                return "closest picked a triangle that is not a tie for " + describe(org, dir, t_max);
        }
    }
    const bool any = brute_any(s, org, dir, t_max);
    if (k.lc_trace_any(org, dir, t_max) != any)
        return "any-hit disagrees with brute force for " + describe(org, dir, t_max);
    if (lc::cpu::trace_any_wide(k, s.bvh.wide_nodes.data(), s.bvh.wide_leaves.data(), org, dir, t_max) != any)
        return "4-wide any-hit disagrees with brute force for " + describe(org, dir, t_max);
    lc::cpu::Trace4Kernel k4{s.bvh.nodes.data(), s.triangles.data(), s.bvh.kernel_nodes.data()};
    if (k4.lc_trace_any(org, dir, t_max) != any)
        return "the kernels' 4-wide any-hit disagrees with brute force for " + describe(org, dir, t_max);
#if defined(LC_WIDE8_TRACE)
    // The 8-wide closest hit, both builds that this CPU runs: the binary
    // walk's distance, triangle and weights bit for bit, or where it names
    // another triangle, one hit at exactly the same distance.
    const auto closest8 = [&](auto walk, const char* name) -> std::string {
        float t8, b1_8, b2_8;
        const std::uint32_t index8 = walk(k, s.bvh.wide8_nodes.data(), s.bvh.wide8_leaves.data(), org, dir, t_max, t8,
                                          b1_8, b2_8);
        const std::string at = std::string(name) + " for " + describe(org, dir, t_max);
        if ((index8 == kInvalidIndex) != (index == kInvalidIndex)) return "8-wide closest hit or miss differs " + at;
        if (index == kInvalidIndex) return {};
        if (std::bit_cast<std::uint32_t>(t8) != std::bit_cast<std::uint32_t>(binary_t))
            return "8-wide closest t " + std::to_string(t8) + " vs " + std::to_string(binary_t) + " " + at;
        if (index8 == index) {
            if (std::bit_cast<std::uint32_t>(b1_8) != std::bit_cast<std::uint32_t>(binary_b1) ||
                std::bit_cast<std::uint32_t>(b2_8) != std::bit_cast<std::uint32_t>(binary_b2))
                return "8-wide closest weights differ " + at;
            return {};
        }
        float own_b1, own_b2;
        const float own = k.lc_intersect_triangle(org, dir, s.triangles[index8], kRayInfinity, own_b1, own_b2);
        if (std::bit_cast<std::uint32_t>(own) != std::bit_cast<std::uint32_t>(binary_t))
            return "8-wide closest picked a triangle that is not an exact tie " + at;
        return {};
    };
    std::string closest_problem;
    if (lc::cpu::cpu_has_avx2())
        closest_problem = closest8(
            [](auto&&... a) { return lc::cpu::trace_closest_wide8_avx2(std::forward<decltype(a)>(a)...); }, "(AVX2)");
    if (closest_problem.empty() && lc::cpu::cpu_has_avx512vl())
        closest_problem = closest8(
            [](auto&&... a) { return lc::cpu::trace_closest_wide8_avx512(std::forward<decltype(a)>(a)...); },
            "(AVX-512)");
    if (!closest_problem.empty()) return closest_problem;
    // Both builds of the 8-wide walk that this CPU runs.
    if (lc::cpu::cpu_has_avx2() &&
        lc::cpu::trace_any_wide8_avx2(k, s.bvh.wide8_nodes.data(), s.bvh.wide8_leaves.data(), org, dir, t_max) != any)
        return "8-wide any-hit (AVX2) disagrees with brute force for " + describe(org, dir, t_max);
    if (lc::cpu::cpu_has_avx512vl() &&
        lc::cpu::trace_any_wide8_avx512(k, s.bvh.wide8_nodes.data(), s.bvh.wide8_leaves.data(), org, dir, t_max) !=
            any)
        return "8-wide any-hit (AVX-512) disagrees with brute force for " + describe(org, dir, t_max);
#endif
    return {};
}

// The kernels' copy of the 4-wide tree (Bvh4Node) against wide_nodes: the
// same slots, a leaf's entry naming its triangles; each box as the kernels
// decode it (lc_bvh4_node, compiled here as C++) holds the child's box, and
// no plane could move inwards by one step of its grid and still hold it.
void check_kernel_nodes(const Scene& s) {
    ASSERT_EQ(s.bvh.kernel_nodes.size(), s.bvh.wide_nodes.size());
    lc::cpu::Trace4Kernel k4{s.bvh.nodes.data(), s.triangles.data(), s.bvh.kernel_nodes.data()};
    for (std::size_t i = 0; i < s.bvh.wide_nodes.size(); ++i) {
        const lc::WideBvhNode& w = s.bvh.wide_nodes[i];
        const lc::gpu::Bvh4Node& g = s.bvh.kernel_nodes[i];
        const auto n = k4.lc_bvh4_node(std::uint32_t(i));
        const std::array<float, 3> scale = {g.scale_x, g.scale_y, g.scale_z};
        for (float sc : scale) {
            int exponent = 0;
            EXPECT_EQ(std::frexp(sc, &exponent), 0.5f) << "scale " << sc << " is not a power of two";
            EXPECT_GE(sc, std::numeric_limits<float>::min());
        }
        for (int slot = 0; slot < 4; ++slot) {
            if (w.count[slot] < 0) {
                EXPECT_EQ(g.entry[slot], kInvalidIndex);
                continue;
            }
            if (w.count[slot] > 0) {
                EXPECT_EQ(g.entry[slot], lc::gpu::kBvh4LeafEntry | std::uint32_t(w.count[slot] - 1) << 29 |
                                             s.bvh.wide_leaves[w.child[slot]].first);
            } else {
                EXPECT_EQ(g.entry[slot], w.child[slot]);
            }
            const std::array<float, 3> lo = {n.lo_x[slot], n.lo_y[slot], n.lo_z[slot]};
            const std::array<float, 3> hi = {n.hi_x[slot], n.hi_y[slot], n.hi_z[slot]};
            const std::array<float, 3> true_lo = {w.lo_x[slot], w.lo_y[slot], w.lo_z[slot]};
            const std::array<float, 3> true_hi = {w.hi_x[slot], w.hi_y[slot], w.hi_z[slot]};
            for (int a = 0; a < 3; ++a) {
                EXPECT_LE(lo[a], true_lo[a]) << "node " << i << " slot " << slot << " axis " << a;
                EXPECT_GE(hi[a], true_hi[a]) << "node " << i << " slot " << slot << " axis " << a;
                // Tight: within a step of the grid, give or take the
                // rounding of the decoded sums.
                EXPECT_LT(true_lo[a] - lo[a], 1.5f * scale[a]) << "node " << i << " slot " << slot << " axis " << a;
                EXPECT_LT(hi[a] - true_hi[a], 1.5f * scale[a]) << "node " << i << " slot " << slot << " axis " << a;
            }
        }
        // The grid: the finest power of two whose 255 steps span the
        // children (or the smallest normal float), doubled at most once
        // where the rounding of the last plane fell short.
        for (int a = 0; a < 3; ++a) {
            const float(&lo)[4] = a == 0 ? w.lo_x : a == 1 ? w.lo_y : w.lo_z;
            const float(&hi)[4] = a == 0 ? w.hi_x : a == 1 ? w.hi_y : w.hi_z;
            double bottom = INFINITY, top = -INFINITY;
            for (int slot = 0; slot < 4; ++slot) {
                if (w.count[slot] < 0) continue;
                bottom = std::min(bottom, double(lo[slot]));
                top = std::max(top, double(hi[slot]));
            }
            if (top < bottom) continue;
            EXPECT_LE(double(scale[a]), std::max(4.0 * (top - bottom) / 255.0, double(std::numeric_limits<float>::min())))
                << "node " << i << " axis " << a;
        }
    }
}

int max_leaf_depth(const std::vector<BvhNode>& nodes, std::uint32_t index, int depth) {
    const BvhNode& n = nodes[index];
    if (n.tri_count > 0) return depth;
    return std::max(max_leaf_depth(nodes, n.first_or_left, depth + 1),
                    max_leaf_depth(nodes, n.first_or_left + 1, depth + 1));
}

bool contains(const BvhNode& outer, const BvhNode& inner) {
    return outer.min_x <= inner.min_x && outer.min_y <= inner.min_y && outer.min_z <= inner.min_z &&
           outer.max_x >= inner.max_x && outer.max_y >= inner.max_y && outer.max_z >= inner.max_z;
}
bool contains(const BvhNode& box, vec3 p) {
    return box.min_x <= p.x && box.min_y <= p.y && box.min_z <= p.z && box.max_x >= p.x && box.max_y >= p.y &&
           box.max_z >= p.z;
}

// The triangles under each binary node and the first of them.
void count_under(const std::vector<BvhNode>& nodes, std::uint32_t index, std::vector<std::uint32_t>& under,
                 std::vector<std::uint32_t>& first) {
    const BvhNode& n = nodes[index];
    if (n.tri_count > 0 || n.first_or_left == 0) {  // a leaf, or the root of an empty tree
        under[index] = n.tri_count;
        first[index] = n.first_or_left;
        return;
    }
    count_under(nodes, n.first_or_left, under, first);
    count_under(nodes, n.first_or_left + 1, under, first);
    under[index] = under[n.first_or_left] + under[n.first_or_left + 1];
    first[index] = first[n.first_or_left];
}

// A wide tree (4 or 8 wide): every wide node reached once, its slots filled from the
// first, each child's box one of the binary tree's, leaves exactly the
// binary tree's leaves (every triangle once, inside its box), no deeper
// than the binary tree. With `whole_subtrees` (the 8-wide tree) a leaf may
// also be a binary subtree of at most four triangles, with that subtree's
// box: then the tree has at most the binary tree's leaves.
template <class Node>
void check_wide_invariants(const Scene& s, const std::vector<Node>& wide, const std::vector<lc::WideLeaf>& wide_leaves,
                           bool whole_subtrees = false) {
    constexpr int kSlots = int(sizeof(Node::child) / sizeof(Node::child[0]));
    ASSERT_FALSE(wide.empty());
    std::map<std::array<float, 6>, int> binary_boxes;
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> binary_leaves;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::array<float, 6>> allowed_leaves;  // (first, count): box
    std::vector<std::uint32_t> under(s.bvh.nodes.size()), first(s.bvh.nodes.size());
    count_under(s.bvh.nodes, 0, under, first);
    for (std::size_t i = 0; i < s.bvh.nodes.size(); ++i) {
        const BvhNode& n = s.bvh.nodes[i];
        const std::array<float, 6> box = {n.min_x, n.min_y, n.min_z, n.max_x, n.max_y, n.max_z};
        ++binary_boxes[box];
        if (n.tri_count > 0) ++binary_leaves[{n.first_or_left, n.tri_count}];
        if (n.tri_count > 0 || (whole_subtrees && under[i] > 0 && under[i] <= 4u))
            allowed_leaves[{first[i], under[i]}] = box;
    }
    std::vector<int> seen(wide.size(), 0), tri_seen(s.triangles.size(), 0);
    std::size_t leaves = 0;
    std::vector<std::pair<std::uint32_t, int>> stack = {{0u, 0}};
    int max_depth = 0;
    while (!stack.empty()) {
        const auto [index, depth] = stack.back();
        stack.pop_back();
        ASSERT_LT(index, wide.size());
        ++seen[index];
        max_depth = std::max(max_depth, depth);
        const Node& w = wide[index];
        for (int slot = 0; slot < kSlots; ++slot) {
            if (w.count[slot] < 0) {
                for (int later = slot; later < kSlots; ++later) ASSERT_LT(w.count[later], 0) << "slots not filled first";
                break;
            }
            EXPECT_EQ(binary_boxes.count({w.lo_x[slot], w.lo_y[slot], w.lo_z[slot], w.hi_x[slot], w.hi_y[slot],
                                          w.hi_z[slot]}),
                      1u);
            if (w.count[slot] == 0) {
                stack.push_back({w.child[slot], depth + 1});
                continue;
            }
            ++leaves;
            ASSERT_LT(w.child[slot], wide_leaves.size());
            const lc::WideLeaf& leaf = wide_leaves[w.child[slot]];
            const auto count = std::uint32_t(w.count[slot]);
            const auto allowed = allowed_leaves.find({leaf.first, count});
            ASSERT_TRUE(allowed != allowed_leaves.end()) << "a leaf that is not a binary subtree's triangles";
            EXPECT_EQ(allowed->second, (std::array<float, 6>{w.lo_x[slot], w.lo_y[slot], w.lo_z[slot], w.hi_x[slot],
                                                             w.hi_y[slot], w.hi_z[slot]}));
            for (std::uint32_t lane = 0; lane < 4; ++lane) {
                if (lane >= count) {
                    EXPECT_EQ(leaf.v0[0][lane], 0.0f);  // unused lanes stay zero
                    continue;
                }
                ASSERT_LT(leaf.first + lane, s.triangles.size());
                ++tri_seen[leaf.first + lane];
                const Triangle& t = s.triangles[leaf.first + lane];
                EXPECT_EQ(vec3(leaf.v0[0][lane], leaf.v0[1][lane], leaf.v0[2][lane]), v0(t));
                EXPECT_EQ(vec3(leaf.v1[0][lane], leaf.v1[1][lane], leaf.v1[2][lane]), v1(t));
                EXPECT_EQ(vec3(leaf.v2[0][lane], leaf.v2[1][lane], leaf.v2[2][lane]), v2(t));
            }
        }
    }
    if (whole_subtrees) {
        EXPECT_LE(leaves, binary_leaves.size());
    } else {
        EXPECT_EQ(leaves, binary_leaves.size());
    }
    EXPECT_EQ(wide_leaves.size(), leaves);
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
    EXPECT_TRUE(std::all_of(tri_seen.begin(), tri_seen.end(), [](int c) { return c == 1; }));
    EXPECT_LE(max_depth, max_leaf_depth(s.bvh.nodes, 0, 0));
}

// Structural invariants: every node reached once, children inside parents,
// every triangle in exactly one leaf and inside its box, leaf sizes, depth,
// and triangles and normals permuted together.
void check_invariants(const Scene& s) {
    const auto& nodes = s.bvh.nodes;
    const std::size_t n = s.triangles.size();
    ASSERT_FALSE(nodes.empty());
    ASSERT_EQ(s.normals.size(), n);
    std::vector<int> node_seen(nodes.size(), 0), tri_seen(n, 0);
    std::vector<std::pair<std::uint32_t, int>> stack = {{0u, 0}};
    int max_depth = 0;
    while (!stack.empty()) {
        const auto [index, depth] = stack.back();
        stack.pop_back();
        ASSERT_LT(index, nodes.size());
        ++node_seen[index];
        max_depth = std::max(max_depth, depth);
        const BvhNode& node = nodes[index];
        if (node.tri_count > 0) {
            ASSERT_LE(node.tri_count, lc::gpu::kBvhMaxLeafTriangles);
            ASSERT_LE(std::size_t(node.first_or_left) + node.tri_count, n);
            for (std::uint32_t i = node.first_or_left; i < node.first_or_left + node.tri_count; ++i) {
                ++tri_seen[i];
                const Triangle& t = s.triangles[i];
                ASSERT_TRUE(contains(node, v0(t)) && contains(node, v1(t)) && contains(node, v2(t)));
            }
        } else {
            ASSERT_LT(std::size_t(node.first_or_left) + 1, nodes.size());
            EXPECT_TRUE(contains(node, nodes[node.first_or_left]));
            EXPECT_TRUE(contains(node, nodes[node.first_or_left + 1]));
            stack.push_back({node.first_or_left, depth + 1});
            stack.push_back({node.first_or_left + 1, depth + 1});
        }
    }
    EXPECT_LT(max_depth, int(lc::gpu::kBvhStackSize) - 1);
    EXPECT_TRUE(std::all_of(node_seen.begin(), node_seen.end(), [](int c) { return c == 1; }));
    EXPECT_TRUE(std::all_of(tri_seen.begin(), tri_seen.end(), [](int c) { return c == 1; }));
    std::vector<int> input_seen(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
        ASSERT_LT(s.triangles[i].material, n);
        ++input_seen[s.triangles[i].material];
        ASSERT_EQ(s.normals[i].pad0, s.triangles[i].material) << "normals not permuted with triangles";
    }
    EXPECT_TRUE(std::all_of(input_seen.begin(), input_seen.end(), [](int c) { return c == 1; }));
    check_wide_invariants(s, s.bvh.wide_nodes, s.bvh.wide_leaves);
    check_wide_invariants(s, s.bvh.wide8_nodes, s.bvh.wide8_leaves, true);
    check_kernel_nodes(s);
}

using lc::test::random_unit;

// Direction in the hemisphere around n, at least `min_cos` away from grazing.
vec3 random_in_hemisphere(std::mt19937& rng, vec3 n, float min_cos) {
    while (true) {
        const vec3 d = random_unit(rng);
        const float c = glm::dot(d, n);
        if (std::abs(c) >= min_cos) return c > 0.0f ? d : -d;
    }
}

std::vector<Triangle> random_triangles(std::mt19937& rng, std::size_t count, float extent, float size) {
    std::uniform_real_distribution<float> pos(-extent, extent), off(-size, size);
    std::vector<Triangle> tris;
    tris.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
        const vec3 c(pos(rng), pos(rng), pos(rng));
        tris.push_back(make_triangle(c + vec3(off(rng), off(rng), off(rng)), c + vec3(off(rng), off(rng), off(rng)),
                                     c + vec3(off(rng), off(rng), off(rng))));
    }
    return tris;
}

// The surface of a rotated cube as an n x n grid of quads per face. Every
// lattice vertex is computed once, so neighbouring triangles share exactly
// the same corner values and the mesh is closed.
struct GridCube {
    int n;
    vec3 center;
    float size;
    glm::mat3 rotation;
    std::map<std::array<int, 3>, vec3> vertices;

    GridCube(int n_, vec3 center_, float size_, vec3 axis, float angle)
        : n(n_), center(center_), size(size_) {
        const vec3 a = glm::normalize(axis);
        const float c = std::cos(angle), s = std::sin(angle);
        const glm::mat3 k(0, a.z, -a.y, -a.z, 0, a.x, a.y, -a.x, 0);  // cross-product matrix, column major
        rotation = glm::mat3(1.0f) * c + (1.0f - c) * glm::outerProduct(a, a) + s * k;
    }
    vec3 vertex(std::array<int, 3> ijk) {
        auto it = vertices.find(ijk);
        if (it != vertices.end()) return it->second;
        const vec3 lattice_point{static_cast<float>(ijk[0]), static_cast<float>(ijk[1]), static_cast<float>(ijk[2])};
        const vec3 local = (lattice_point / float(n) - 0.5f) * size;
        return vertices[ijk] = center + rotation * local;
    }
    // Corner of face (axis, side) at grid coordinates (u, v).
    static std::array<int, 3> lattice(int axis, int side, int u, int v) {
        std::array<int, 3> ijk{};
        ijk[std::size_t(axis)] = side;
        ijk[std::size_t((axis + 1) % 3)] = u;
        ijk[std::size_t((axis + 2) % 3)] = v;
        return ijk;
    }
    std::vector<Triangle> triangles() {
        std::vector<Triangle> tris;
        for (int axis = 0; axis < 3; ++axis)
            for (int side : {0, n})
                for (int u = 0; u < n; ++u)
                    for (int v = 0; v < n; ++v) {
                        const vec3 p00 = vertex(lattice(axis, side, u, v)), p10 = vertex(lattice(axis, side, u + 1, v));
                        const vec3 p11 = vertex(lattice(axis, side, u + 1, v + 1));
                        const vec3 p01 = vertex(lattice(axis, side, u, v + 1));
                        if ((u + v) % 2 == 0) {  // alternate diagonals
                            tris.push_back(make_triangle(p00, p10, p11));
                            tris.push_back(make_triangle(p00, p11, p01));
                        } else {
                            tris.push_back(make_triangle(p00, p10, p01));
                            tris.push_back(make_triangle(p10, p11, p01));
                        }
                    }
        return tris;
    }
    // A point on a shared vertex or edge of the grid (quad sides and
    // diagonals), and the outward normal of its face.
    std::pair<vec3, vec3> random_edge_point(std::mt19937& rng) {
        std::uniform_int_distribution<int> face(0, 5), cell(0, n - 1), kind(0, 4);
        std::uniform_real_distribution<float> f(0.0f, 1.0f);
        const int f_index = face(rng);
        const int axis = f_index / 2, side = f_index % 2 ? n : 0;
        const int u = cell(rng), v = cell(rng);
        const vec3 a = vertex(lattice(axis, side, u, v));
        const vec3 b = vertex(lattice(axis, side, u + 1, v));
        const vec3 c = vertex(lattice(axis, side, u + 1, v + 1));
        const vec3 d = vertex(lattice(axis, side, u, v + 1));
        vec3 local_normal(0.0f);
        local_normal[axis] = side ? 1.0f : -1.0f;
        const vec3 normal = rotation * local_normal;
        switch (kind(rng)) {
            case 0: return {a, normal};                               // shared vertex
            case 1: return {0.5f * (a + b), normal};                  // quad side midpoint
            case 2: return {0.5f * (a + c), normal};                  // diagonal midpoint
            case 3: return {0.5f * (b + d), normal};                  // other diagonal
            default: return {a + f(rng) * (d - a), normal};           // anywhere on a side
        }
    }
};

// The traversal tests' scene: 2000 random triangles and a closed grid cube
// whose shared edges and vertices rays aim at.
GridCube traversal_cube() { return GridCube(6, vec3(25.0f, 3.0f, -4.0f), 8.0f, vec3(0.3f, 1.0f, 0.2f), 0.7f); }

std::vector<Triangle> traversal_triangles(std::mt19937& rng, GridCube& cube) {
    std::vector<Triangle> tris = random_triangles(rng, 2000, 10.0f, 1.5f);
    const std::vector<Triangle> grid = cube.triangles();
    tris.insert(tris.end(), grid.begin(), grid.end());
    return tris;
}

}  // namespace

TEST(Bvh, TraversalMatchesBruteForceIncludingSharedEdges) {
    std::mt19937 rng(20240611u);
    GridCube cube = traversal_cube();
    const Scene scene(traversal_triangles(rng, cube));
    check_invariants(scene);
    lc::cpu::TraceKernel k = scene.kernel();

    std::uniform_real_distribution<float> u01(0.0f, 1.0f), box(-15.0f, 15.0f), inner(-0.35f, 0.35f);
    int failures = 0, misses_inside = 0, total = 0;
    std::string first_failure;
    auto check = [&](vec3 org, vec3 dir, float t_max) {
        ++total;
        const std::string problem = check_ray(scene, org, dir, t_max);
        if (!problem.empty() && failures++ == 0) first_failure = problem;
    };

    // Random rays, unbounded and short segments.
    for (int i = 0; i < 4000; ++i) {
        const vec3 org(box(rng) + 10.0f, box(rng), box(rng));
        check(org, random_unit(rng), i % 2 ? kRayInfinity : 30.0f * u01(rng));
    }
    // From inside the closed cube at its shared vertices and edges: the
    // watertight test must never let such a ray escape.
    for (int i = 0; i < 3000; ++i) {
        const vec3 org = cube.center + cube.rotation * (vec3(inner(rng), inner(rng), inner(rng)) * cube.size);
        const vec3 target = cube.random_edge_point(rng).first;
        const vec3 dir = target - org;
        check(org, dir, kRayInfinity);
        float t, b1, b2;
        if (k.lc_trace_closest(org, dir, kRayInfinity, t, b1, b2) == kInvalidIndex ||
            !k.lc_trace_any(org, dir, kRayInfinity))
            ++misses_inside;
    }
    // From outside, grazing the faces towards shared vertices and edges.
    for (int i = 0; i < 3000; ++i) {
        const auto [target, normal] = cube.random_edge_point(rng);
        vec3 tangent = glm::cross(normal, random_unit(rng));
        tangent = glm::normalize(tangent);
        const float lift = std::pow(10.0f, -4.0f * u01(rng));  // 1 .. 1e-4 rad above the face
        const vec3 org = target + 20.0f * (tangent + lift * normal);
        check(org, target - org, kRayInfinity);
    }
    EXPECT_EQ(total, 10000);
    EXPECT_EQ(failures, 0) << "first: " << first_failure;
    EXPECT_EQ(misses_inside, 0) << "rays leaked through shared edges or vertices of the closed grid";
}

// Packets of four rays (trace_any_wide4, the CPU's brute force): each ray
// gets brute force's any-hit answer, as on its own; rays left out of the
// packet report nothing. Packets share an origin, as a shaded point's rays
// do, with directions close together or spread out, including rays from
// inside the closed grid to its shared edges and vertices.
TEST(Bvh, PacketsOfFourGiveEachRaysAnswer) {
    std::mt19937 rng(20261201u);
    GridCube cube = traversal_cube();
    const Scene scene(traversal_triangles(rng, cube));
    lc::cpu::TraceKernel k = scene.kernel();
    std::uniform_real_distribution<float> u01(0.0f, 1.0f), box(-15.0f, 15.0f), inner(-0.35f, 0.35f);
    int failures = 0, blocked = 0, rays = 0;
    std::string first_failure;
    for (int packet_index = 0; packet_index < 4000; ++packet_index) {
        const bool in_cube = packet_index % 4 == 3;
        const vec3 org = in_cube ? cube.center + cube.rotation * (vec3(inner(rng), inner(rng), inner(rng)) * cube.size)
                                 : vec3(box(rng) + 10.0f, box(rng), box(rng));
        const vec3 base = random_unit(rng);
        const float spread = std::pow(10.0f, -3.0f * u01(rng));
        lc::cpu::RayPacket4 packet;
        for (int j = 0; j < 4; ++j) {
            packet.org[j] = org;
            packet.dir[j] = in_cube ? cube.random_edge_point(rng).first - org
                                    : (packet_index % 2 ? glm::normalize(base + spread * random_unit(rng))
                                                        : random_unit(rng));
            packet.t_max[j] = in_cube || u01(rng) < 0.5f ? kRayInfinity : 30.0f * u01(rng);
        }
        packet.valid = packet_index % 8 == 5 ? 1u + unsigned(u01(rng) * 14.99f) : 15u;
        const unsigned valid = packet.valid;
        const unsigned got =
            lc::cpu::trace_any_wide4(k, scene.bvh.wide_nodes.data(), scene.bvh.wide_leaves.data(), packet);
        for (int j = 0; j < 4; ++j) {
            const bool expected = (valid >> j & 1u) != 0u && brute_any(scene, org, packet.dir[j], packet.t_max[j]);
            rays += (valid >> j & 1u) != 0u;
            blocked += expected;
            if (((got >> j & 1u) != 0u) != expected && failures++ == 0)
                first_failure = "packet " + std::to_string(packet_index) + " ray " + std::to_string(j) + ": " +
                                describe(org, packet.dir[j], packet.t_max[j]);
        }
    }
    EXPECT_EQ(failures, 0) << "first: " << first_failure;
    EXPECT_GT(blocked, rays / 10);
    EXPECT_LT(blocked, rays - rays / 10);
}

#if defined(LC_WIDE8_TRACE)
// trace_any_wide8_packet: R rays from R points (a quad's
// or an octet's points to one light, or anywhere), some of them not in the
// packet, each answered as its own walk would, in both builds this CPU runs.
template <unsigned R>
void expect_packets_from_points_give_each_rays_answer() {
    if (!lc::cpu::cpu_has_avx2()) GTEST_SKIP() << "this CPU has no AVX2: the 8-wide walk is not used";
    std::mt19937 rng(20261202u);
    GridCube cube = traversal_cube();
    const Scene scene(traversal_triangles(rng, cube));
    lc::cpu::TraceKernel k = scene.kernel();
    std::uniform_real_distribution<float> u01(0.0f, 1.0f), box(-15.0f, 15.0f), inner(-0.35f, 0.35f);
    int failures = 0, blocked = 0, rays = 0, mixed = 0;
    std::string first_failure;
    for (int packet_index = 0; packet_index < 4000; ++packet_index) {
        const bool in_cube = packet_index % 4 == 3;
        const vec3 centre = in_cube
                                ? cube.center + cube.rotation * (vec3(inner(rng), inner(rng), inner(rng)) * cube.size)
                                : vec3(box(rng) + 10.0f, box(rng), box(rng));
        const float spread = std::pow(10.0f, -3.0f * u01(rng));
        const vec3 target = in_cube ? cube.random_edge_point(rng).first : centre + 30.0f * random_unit(rng);
        lc::cpu::RayPacket<R> packet;
        for (unsigned j = 0; j < R; ++j) {
            packet.org[j] = centre + (in_cube ? 0.01f : spread) * random_unit(rng);
            const bool to_target = packet_index % 3 != 0;
            packet.dir[j] = to_target ? target - packet.org[j] : random_unit(rng);
            packet.t_max[j] = to_target ? (u01(rng) < 0.5f ? 0.999f : kRayInfinity)
                                        : (u01(rng) < 0.5f ? kRayInfinity : 30.0f * u01(rng));
        }
        const unsigned all = (1u << R) - 1u;
        packet.valid = packet_index % 8 == 5 ? 1u + unsigned(u01(rng) * (float(all) - 1.01f)) : all;
        const unsigned valid = packet.valid;
        unsigned expected = 0u;
        for (unsigned j = 0; j < R; ++j)
            if ((valid >> j & 1u) != 0u && brute_any(scene, packet.org[j], packet.dir[j], packet.t_max[j]))
                expected |= 1u << j;
        rays += __builtin_popcount(valid);
        blocked += __builtin_popcount(expected);
        mixed += expected != 0u && expected != valid;
        auto check = [&](const char* build, unsigned got) {
            if (got != expected && failures++ == 0)
                first_failure = std::string(build) + ", packet " + std::to_string(packet_index) + ": blocked " +
                                std::to_string(got) + ", brute force " + std::to_string(expected);
        };
        const lc::WideBvhNode8* nodes = scene.bvh.wide8_nodes.data();
        const lc::WideLeaf* leaves = scene.bvh.wide8_leaves.data();
        check("AVX2", lc::cpu::trace_any_wide8_packet_avx2(k, nodes, leaves, packet));
        if (lc::cpu::cpu_has_avx512vl())
            check("AVX-512", lc::cpu::trace_any_wide8_packet_avx512(k, nodes, leaves, packet));
    }
    EXPECT_EQ(failures, 0) << "first: " << first_failure;
    EXPECT_GT(blocked, rays / 10);
    EXPECT_LT(blocked, rays - rays / 10);
    EXPECT_GT(mixed, 100) << "packets whose rays disagree, which a shared answer would get wrong";
}
#endif

TEST(Bvh, EightWidePacketsFromFourPointsGiveEachRaysAnswer) {
#if defined(LC_WIDE8_TRACE)
    expect_packets_from_points_give_each_rays_answer<4>();
#else
    GTEST_SKIP() << "no 8-wide walk on this architecture";
#endif
}

TEST(Bvh, EightWidePacketsFromEightPointsGiveEachRaysAnswer) {
#if defined(LC_WIDE8_TRACE)
    expect_packets_from_points_give_each_rays_answer<8>();
#else
    GTEST_SKIP() << "no 8-wide walk on this architecture";
#endif
}

// lc_bvh4_take (the kernels' walk takes a group's next node and leaf with
// it) against the loop over the slots that defines it, in every case: each
// set of children left, each mix of leaves and inner nodes, a node or a
// leaf already taken or not.
TEST(Bvh, KernelWalkTakesTheFirstInnerChildAndTheFirstLeaf) {
    lc::cpu::Trace4Kernel k4{nullptr, nullptr, nullptr};
    for (std::uint32_t left = 0; left < 16u; ++left)
        for (std::uint32_t leaf_slots = 0; leaf_slots < 16u; ++leaf_slots)
            for (int held = 0; held < 4; ++held) {
                glm::uvec4 entries;
                for (std::uint32_t s = 0; s < 4u; ++s)
                    entries[int(s)] = (leaf_slots >> s & 1u) != 0u ? lc::gpu::kBvh4LeafEntry | (100u + s) : 200u + s;
                const std::uint32_t node_in = (held & 1) != 0 ? 7u : kInvalidIndex;
                const std::uint32_t leaf_in = (held & 2) != 0 ? 9u : kInvalidIndex;
                std::uint32_t node = node_in, leaf = leaf_in, expect_node = node_in, expect_leaf = leaf_in;
                std::uint32_t expect_left = left;
                for (std::uint32_t s = 0; s < 4u; ++s) {
                    const bool live = (expect_left >> s & 1u) != 0u, is_leaf = (leaf_slots >> s & 1u) != 0u;
                    if (live && !is_leaf && expect_node == kInvalidIndex) {
                        expect_node = entries[int(s)];
                        expect_left &= ~(1u << s);
                    } else if (live && is_leaf && expect_leaf == kInvalidIndex) {
                        expect_leaf = entries[int(s)];
                        expect_left &= ~(1u << s);
                    }
                }
                const std::uint32_t got_left = k4.lc_bvh4_take(entries, left, node, leaf);
                EXPECT_EQ(got_left, expect_left) << "left " << left << " leaves " << leaf_slots << " held " << held;
                EXPECT_EQ(node, expect_node) << "left " << left << " leaves " << leaf_slots << " held " << held;
                EXPECT_EQ(leaf, expect_leaf) << "left " << left << " leaves " << leaf_slots << " held " << held;
            }
}

TEST(Bvh, EmptySceneMissesEverything) {
    std::vector<Triangle> tris;
    std::vector<TriangleNormals> normals;
    const lc::Bvh bvh = lc::build_bvh(tris, normals);
    ASSERT_EQ(bvh.nodes.size(), 1u);
    EXPECT_EQ(bvh.nodes[0].tri_count, 0u);
    lc::cpu::TraceKernel k{bvh.nodes.data(), nullptr};
    lc::cpu::Trace4Kernel k4{bvh.nodes.data(), nullptr, bvh.kernel_nodes.data()};
    std::mt19937 rng(7u);
    std::uniform_real_distribution<float> pos(-1e3f, 1e3f);
    std::vector<std::pair<vec3, vec3>> rays = {{vec3(0.0f), vec3(1.0f)},   // towards the sentinel box
                                               {vec3(0.0f), vec3(-1.0f)},
                                               {vec3(0.0f), vec3(0.0f, 0.0f, 1.0f)}};
    for (int i = 0; i < 1000; ++i) rays.push_back({vec3(pos(rng), pos(rng), pos(rng)), random_unit(rng)});
    for (const auto& [org, dir] : rays) {
        float t, b1, b2;
        EXPECT_EQ(k.lc_trace_closest(org, dir, kRayInfinity, t, b1, b2), kInvalidIndex);
        EXPECT_FALSE(k.lc_trace_any(org, dir, kRayInfinity));
        EXPECT_FALSE(k4.lc_trace_any(org, dir, kRayInfinity));
        EXPECT_FALSE(lc::cpu::trace_any_wide(k, bvh.wide_nodes.data(), bvh.wide_leaves.data(), org, dir, kRayInfinity));
#if defined(LC_WIDE8_TRACE)
        if (lc::cpu::cpu_has_avx2()) {
            EXPECT_FALSE(lc::cpu::trace_any_wide8_avx2(k, bvh.wide8_nodes.data(), bvh.wide8_leaves.data(), org, dir,
                                                       kRayInfinity));
            EXPECT_EQ(lc::cpu::trace_closest_wide8(k, bvh.wide8_nodes.data(), bvh.wide8_leaves.data(), org, dir,
                                                   kRayInfinity, t, b1, b2),
                      kInvalidIndex);
        }
        if (lc::cpu::cpu_has_avx512vl()) {
            EXPECT_FALSE(lc::cpu::trace_any_wide8_avx512(k, bvh.wide8_nodes.data(), bvh.wide8_leaves.data(), org, dir,
                                                         kRayInfinity));
        }
#endif
    }
    ASSERT_EQ(bvh.wide_nodes.size(), 1u);
    for (int slot = 0; slot < 4; ++slot) EXPECT_EQ(bvh.wide_nodes[0].count[slot], -1);
    ASSERT_EQ(bvh.kernel_nodes.size(), 1u);
    for (int slot = 0; slot < 4; ++slot) EXPECT_EQ(bvh.kernel_nodes[0].entry[slot], kInvalidIndex);
    ASSERT_EQ(bvh.wide8_nodes.size(), 1u);
    for (int slot = 0; slot < 8; ++slot) EXPECT_EQ(bvh.wide8_nodes[0].count[slot], -1);
}

TEST(Bvh, DegenerateInputsKeepInvariants) {
    // All centroids coincide: split by index.
    std::vector<Triangle> same(37, make_triangle(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0)));
    const Scene stacked(same);
    check_invariants(stacked);
    float t, b1, b2;
    EXPECT_NE(stacked.kernel().lc_trace_closest(vec3(0.2f, 0.2f, 1.0f), vec3(0, 0, -1), kRayInfinity, t, b1, b2),
              kInvalidIndex);
    EXPECT_FLOAT_EQ(t, 1.0f);

    // Geometrically spaced triangles make SAH peel off one at a time; the
    // depth cap must switch to median splits.
    std::vector<Triangle> spread;
    for (int i = 0; i < 400; ++i) {
        const float x = std::pow(1.2f, float(i));
        spread.push_back(make_triangle(vec3(x, 0, 0), vec3(x * 1.01f, 1, 0), vec3(x, 0, 1)));
    }
    const Scene deep(spread);
    check_invariants(deep);
    std::mt19937 rng(99u);
    std::uniform_int_distribution<std::size_t> pick(0, deep.triangles.size() - 1);
    int failures = 0;
    std::string first_failure;
    for (int i = 0; i < 2000; ++i) {
        const Triangle& tri = deep.triangles[pick(rng)];
        const vec3 target = (v0(tri) + v1(tri) + v2(tri)) / 3.0f;
        const vec3 org = target + vec3(0.0f, 2.0f, 3.0f) + random_unit(rng);
        const std::string problem = check_ray(deep, org, target - org, kRayInfinity);
        if (!problem.empty() && failures++ == 0) first_failure = problem;
    }
    EXPECT_EQ(failures, 0) << first_failure;

    // Millimetre triangles 10^5 units from the origin: the kernels'
    // quantized boxes (Bvh4Node) have grids of a few float ulps there.
    std::vector<Triangle> far_small;
    std::uniform_real_distribution<float> jitter(-0.05f, 0.05f);
    const vec3 far_centre(1e5f, -1e5f, 3e4f);
    for (int i = 0; i < 300; ++i) {
        const vec3 c = far_centre + vec3(jitter(rng), jitter(rng), jitter(rng));
        far_small.push_back(make_triangle(c, c + vec3(1e-3f, 0, 0), c + vec3(0, 1e-3f, 1e-3f)));
    }
    const Scene far_away(far_small);
    check_invariants(far_away);
    failures = 0;
    for (int i = 0; i < 2000; ++i) {
        const Triangle& tri = far_away.triangles[pick(rng) % far_away.triangles.size()];
        const vec3 target = (v0(tri) + v1(tri) + v2(tri)) / 3.0f;
        const vec3 org = target + 0.2f * random_unit(rng);
        const std::string problem = check_ray(far_away, org, target - org, kRayInfinity);
        if (!problem.empty() && failures++ == 0) first_failure = problem;
    }
    EXPECT_EQ(failures, 0) << first_failure;

    std::vector<Triangle> one = {make_triangle(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0))};
    const Scene single(one);
    check_invariants(single);
    EXPECT_EQ(single.bvh.nodes.size(), 1u);
    ASSERT_EQ(single.bvh.wide_nodes.size(), 1u);  // the root leaf in slot 0
    EXPECT_EQ(single.bvh.wide_nodes[0].count[0], 1);
    ASSERT_EQ(single.bvh.wide8_nodes.size(), 1u);
    EXPECT_EQ(single.bvh.wide8_nodes[0].count[0], 1);
    EXPECT_TRUE(check_ray(single, vec3(0.2f, 0.2f, 1.0f), vec3(0, 0, -1), kRayInfinity).empty());
    lc::cpu::TraceKernel single_kernel = single.kernel();
    EXPECT_TRUE(lc::cpu::trace_any_wide(single_kernel, single.bvh.wide_nodes.data(), single.bvh.wide_leaves.data(), vec3(0.2f, 0.2f, 1.0f),
                                        vec3(0, 0, -1), kRayInfinity));
}

// The 8-wide tree takes a small binary subtree as one leaf where testing
// it whole is cheaper (collapse_bvh8): the two halves of a square, whose
// boxes are the square's, become one leaf; a floor's triangle and a wall's
// meeting at a corner stay two, since a box around both would be entered by
// the shadow rays leaving either surface that their flat boxes let pass.
TEST(Bvh, EightWideLeavesKeepFlatSubtreesWholeButNotCorners) {
    for (const bool corner : {false, true}) {
        SCOPED_TRACE(corner ? "corner" : "square");
        const std::vector<Triangle> triangles = {
            make_triangle({0, 0, 0}, {1, 0, 0}, {1, 0, 1}),
            corner ? make_triangle({0, 0, 0}, {1, 0, 0}, {1, 1, 0}) : make_triangle({0, 0, 0}, {1, 0, 1}, {0, 0, 1})};
        auto box = [&](std::uint32_t first, std::uint32_t count) {
            BvhNode n{FLT_MAX, FLT_MAX, FLT_MAX, first, -FLT_MAX, -FLT_MAX, -FLT_MAX, count};
            for (std::uint32_t i = first; i < first + count; ++i)
                for (const vec3 p : {v0(triangles[i]), v1(triangles[i]), v2(triangles[i])}) {
                    n.min_x = std::min(n.min_x, p.x), n.min_y = std::min(n.min_y, p.y), n.min_z = std::min(n.min_z, p.z);
                    n.max_x = std::max(n.max_x, p.x), n.max_y = std::max(n.max_y, p.y), n.max_z = std::max(n.max_z, p.z);
                }
            return n;
        };
        std::vector<BvhNode> nodes = {box(0, 2), box(0, 1), box(1, 1)};
        nodes[0].first_or_left = 1;  // the root's children, nodes 1 and 2
        nodes[0].tri_count = 0;
        std::vector<lc::WideBvhNode8> wide;
        std::vector<lc::WideLeaf> leaves;
        lc::collapse_bvh8(nodes, triangles, wide, leaves);
        ASSERT_EQ(wide.size(), 1u);
        EXPECT_EQ(leaves.size(), corner ? 2u : 1u);
        EXPECT_EQ(wide[0].count[0], corner ? 1 : 2);
    }
}

TEST(Bvh, BuildsLargeRandomSceneWithValidTree) {
    std::mt19937 rng(5u);
    const Scene scene(random_triangles(rng, 50000, 100.0f, 1.0f));
    check_invariants(scene);
    EXPECT_GT(scene.bvh.build_seconds, 0.0);
    EXPECT_LE(scene.bvh.nodes.size(), 2 * scene.triangles.size());
}

// lc_offset_hit_point: a shadow ray leaving the surface from the offset
// (barycentric) hit point never hits the surface it starts on.
// The hit point as the renderer computes it (lc_surface_point).
vec3 barycentric_point(const Triangle& t, float b1, float b2) {
    return (1.0f - b1 - b2) * vec3(t.v0_x, t.v0_y, t.v0_z) + b1 * vec3(t.v1_x, t.v1_y, t.v1_z) +
           b2 * vec3(t.v2_x, t.v2_y, t.v2_z);
}

TEST(Bvh, OffsetOriginsAvoidSelfIntersectionFarFromOrigin) {
    const vec3 n = glm::normalize(vec3(1.0f, 2.0f, 3.0f));
    const vec3 p0(1e5f, -1e5f, 1e5f);
    const vec3 t1 = glm::normalize(glm::cross(n, vec3(0, 0, 1))), t2 = glm::cross(n, t1);
    const float half = 100.0f;
    const vec3 a = p0 - half * t1 - half * t2, b = p0 + half * t1 - half * t2;
    const vec3 c = p0 + half * t1 + half * t2, d = p0 - half * t1 + half * t2;
    const Scene plane({make_triangle(a, b, c), make_triangle(a, c, d)});
    lc::cpu::TraceKernel k = plane.kernel();

    std::mt19937 rng(3u);
    std::uniform_real_distribution<float> on(-60.0f, 60.0f), height(0.01f, 100.0f);
    int hits = 0, self_hits = 0, raw_self_hits = 0;
    for (int i = 0; i < 4000; ++i) {
        const float side = i % 2 ? 1.0f : -1.0f;
        const vec3 q = p0 + on(rng) * t1 + on(rng) * t2;
        const vec3 org = q + side * height(rng) * n + on(rng) * t1;
        const vec3 dir = glm::normalize(q - org);
        float t, b1, b2;
        const std::uint32_t tri = k.lc_trace_closest(org, dir, kRayInfinity, t, b1, b2);
        if (tri == kInvalidIndex) continue;
        ++hits;
        const vec3 p = barycentric_point(plane.triangles[tri], b1, b2);
        vec3 ng = geometric_normal(plane.triangles[tri]);
        if (glm::dot(ng, dir) > 0.0f) ng = -ng;  // face the incoming ray
        const vec3 shadow = random_in_hemisphere(rng, ng, 1e-3f);
        self_hits += k.lc_trace_any(k.lc_offset_hit_point(p, ng, plane.triangles[tri]), shadow, kRayInfinity);
        raw_self_hits += k.lc_trace_any(p, shadow, kRayInfinity);
    }
    EXPECT_GT(hits, 3900);
    EXPECT_EQ(self_hits, 0);
    EXPECT_GT(raw_self_hits, 0) << "the test should be sensitive: without the offset some rays self-intersect";
}

TEST(Bvh, OffsetOriginsAvoidSelfIntersectionOnCurvedSurface) {
    // UV sphere away from the origin; a convex mesh, so any ray leaving the
    // outside of a face within that face's hemisphere must escape.
    const vec3 center(1e3f, -2e3f, 5e2f);
    const float radius = 10.0f;
    const int rings = 32, segments = 64;
    auto point = [&](int r, int s) {
        const float theta = std::numbers::pi_v<float> * float(r) / float(rings);
        const float phi = 2.0f * std::numbers::pi_v<float> * float(s % segments) / float(segments);
        return center + radius * vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
    };
    std::vector<Triangle> tris;
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const vec3 p00 = point(r, s), p01 = point(r, s + 1), p10 = point(r + 1, s), p11 = point(r + 1, s + 1);
            if (r > 0) tris.push_back(make_triangle(p00, p10, p01));
            if (r < rings - 1) tris.push_back(make_triangle(p01, p10, p11));
        }
    const Scene sphere(std::move(tris));
    check_invariants(sphere);
    lc::cpu::TraceKernel k = sphere.kernel();

    std::mt19937 rng(11u);
    int hits = 0, self_hits = 0;
    for (int i = 0; i < 4000; ++i) {
        const vec3 org = center + 3.0f * radius * random_unit(rng);
        const vec3 aim = center + 0.8f * radius * random_unit(rng);
        const vec3 dir = glm::normalize(aim - org);
        float t, b1, b2;
        const std::uint32_t tri = k.lc_trace_closest(org, dir, kRayInfinity, t, b1, b2);
        if (tri == kInvalidIndex) continue;
        ++hits;
        const vec3 p = barycentric_point(sphere.triangles[tri], b1, b2);
        vec3 ng = geometric_normal(sphere.triangles[tri]);
        if (glm::dot(ng, dir) > 0.0f) ng = -ng;
        const vec3 shadow = random_in_hemisphere(rng, ng, 0.02f);
        self_hits += k.lc_trace_any(k.lc_offset_hit_point(p, ng, sphere.triangles[tri]), shadow, kRayInfinity);
    }
    EXPECT_GT(hits, 3900);
    EXPECT_EQ(self_hits, 0);
}
