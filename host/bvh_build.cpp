// Binned SAH BVH builder (Wald, "On fast Construction of SAH-based Bounding
// Volume Hierarchies", 2007): top-down, depth first, children adjacent.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/glm.hpp>

#include "lightcuts/bvh.h"

namespace lc {

namespace {

using gpu::BvhNode;

// 32 bins rather than 16: on the room with 10^4 lights brute force's shadow
// rays then run 4.8% fewer instructions and lightcuts' 0.7% fewer (callgrind,
// docs/results/cpu-speed.md); 64 bins were worse than 16 there.
constexpr int kBins = 32;
constexpr std::uint32_t kMaxLeaf = gpu::kBvhMaxLeafTriangles;
// Deepest leaf, root = depth 0. The any-hit traversal holds up to depth + 2
// entries when it expands an interior node at `depth`, so leaves at depth
// kBvhStackSize - 2 keep it within its stack (the closest-hit one needs less).
constexpr std::uint32_t kMaxDepth = gpu::kBvhStackSize - 2;
// SAH costs relative to one ray/triangle test. A box test pair costs about
// one triangle test in the kernels, so a split pays off once it saves one.
constexpr double kTraversalCost = 1.0;
constexpr double kIntersectCost = 1.0;

struct Aabb {
    glm::vec3 lo{std::numeric_limits<float>::infinity()};
    glm::vec3 hi{-std::numeric_limits<float>::infinity()};
    void grow(const Aabb& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }
    void grow(glm::vec3 p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    // Half the surface area, in double so huge scenes do not overflow.
    double half_area() const {
        const glm::dvec3 d = glm::dvec3(hi) - glm::dvec3(lo);
        return d.x * d.y + d.y * d.z + d.z * d.x;
    }
};

// Number of levels below a node of n triangles that a balanced (median)
// split needs to reach leaves of at most kMaxLeaf.
std::uint32_t levels_needed(std::size_t n) {
    std::uint32_t levels = 0;
    for (std::size_t capacity = kMaxLeaf; capacity < n; capacity *= 2) ++levels;
    return levels;
}

class Builder {
public:
    Builder(const std::vector<Aabb>& bounds, const std::vector<glm::vec3>& centroids,
            std::vector<std::uint32_t>& order, std::vector<BvhNode>& nodes)
        : bounds_(bounds), centroids_(centroids), order_(order), nodes_(nodes) {}

    void build(std::uint32_t node_index, std::uint32_t begin, std::uint32_t end, std::uint32_t depth) {
        Aabb box, centroid_box;
        for (std::uint32_t i = begin; i < end; ++i) {
            box.grow(bounds_[order_[i]]);
            centroid_box.grow(centroids_[order_[i]]);
        }
        BvhNode& node = nodes_[node_index];
        node.min_x = box.lo.x; node.min_y = box.lo.y; node.min_z = box.lo.z;
        node.max_x = box.hi.x; node.max_y = box.hi.y; node.max_z = box.hi.z;

        const std::uint32_t n = end - begin;
        // SAH only while there is depth to spare; once the remaining depth is
        // just enough for a balanced tree, median splits take over for good.
        Split split;
        const bool sah = kMaxDepth - depth > levels_needed(n) + 1;
        const double area = box.half_area();
        const bool found = sah && find_sah_split(begin, end, centroid_box, area, split);
        if (n <= kMaxLeaf) {
            const double leaf_cost = kIntersectCost * n * area;
            if (!found || !(split.cost < leaf_cost)) {
                node.first_or_left = begin;
                node.tri_count = n;
                return;
            }
        }

        std::uint32_t mid = found ? partition(begin, end, centroid_box, split) : begin;
        if (mid == begin || mid == end) mid = median_split(begin, end, centroid_box);

        const auto left = std::uint32_t(nodes_.size());
        node.first_or_left = left;  // `node` is dead after the resize below
        node.tri_count = 0;
        nodes_.resize(nodes_.size() + 2);
        build(left, begin, mid, depth + 1);
        build(left + 1, mid, end, depth + 1);
    }

private:
    struct Split {
        int axis = 0;
        int bin = 0;  // left side = bins [0, bin)
        double cost = std::numeric_limits<double>::infinity();
    };

    static float bin_scale(const Aabb& centroid_box, int axis) {
        const float extent = centroid_box.hi[axis] - centroid_box.lo[axis];
        const float scale = float(kBins) / extent;
        return extent > 0.0f && std::isfinite(scale) ? scale : 0.0f;
    }
    // NaN-safe: a non-finite offset lands in bin 0 instead of UB in the cast.
    static int bin_of(float c, float lo, float scale) {
        const float f = (c - lo) * scale;
        return f > 0.0f ? std::min(int(std::min(f, float(kBins))), kBins - 1) : 0;
    }

    // Wald 2007 §3: bin centroids on all three axes in one pass, then sweep
    // the kBins - 1 planes per axis. Costs are scaled by the parent's area
    // (never divided by it, which may be zero for degenerate input).
    bool find_sah_split(std::uint32_t begin, std::uint32_t end, const Aabb& centroid_box, double parent_area,
                        Split& best) const {
        struct Bin {
            Aabb box;
            std::uint32_t count = 0;
        };
        std::array<std::array<Bin, kBins>, 3> bins{};
        float scale[3];
        bool any_axis = false;
        for (int a = 0; a < 3; ++a) {
            scale[a] = bin_scale(centroid_box, a);
            any_axis |= scale[a] > 0.0f;
        }
        if (!any_axis) return false;

        for (std::uint32_t i = begin; i < end; ++i) {
            const std::uint32_t tri = order_[i];
            const glm::vec3 c = centroids_[tri];
            for (int a = 0; a < 3; ++a) {
                if (scale[a] == 0.0f) continue;
                Bin& bin = bins[std::size_t(a)][std::size_t(bin_of(c[a], centroid_box.lo[a], scale[a]))];
                bin.box.grow(bounds_[tri]);
                ++bin.count;
            }
        }

        for (int a = 0; a < 3; ++a) {
            if (scale[a] == 0.0f) continue;
            const auto& axis_bins = bins[std::size_t(a)];
            // Right-to-left sweep: area and count of bins [k, kBins).
            std::array<double, kBins> right_area{};
            std::array<std::uint32_t, kBins> right_count{};
            Aabb acc;
            std::uint32_t count = 0;
            for (int k = kBins - 1; k > 0; --k) {
                acc.grow(axis_bins[std::size_t(k)].box);
                count += axis_bins[std::size_t(k)].count;
                right_area[std::size_t(k)] = count ? acc.half_area() : 0.0;
                right_count[std::size_t(k)] = count;
            }
            acc = Aabb{};
            count = 0;
            for (int k = 1; k < kBins; ++k) {
                acc.grow(axis_bins[std::size_t(k - 1)].box);
                count += axis_bins[std::size_t(k - 1)].count;
                if (count == 0 || right_count[std::size_t(k)] == 0) continue;
                const double cost = kIntersectCost * (count * acc.half_area() +
                                                      right_count[std::size_t(k)] * right_area[std::size_t(k)]);
                if (cost < best.cost) best = {a, k, cost};
            }
        }
        if (!std::isfinite(best.cost)) return false;
        best.cost += kTraversalCost * parent_area;
        return true;
    }

    std::uint32_t partition(std::uint32_t begin, std::uint32_t end, const Aabb& centroid_box, const Split& split) {
        const int a = split.axis;
        const float lo = centroid_box.lo[a], scale = bin_scale(centroid_box, a);
        auto* first = order_.data() + begin;
        auto* mid = std::partition(first, order_.data() + end, [&](std::uint32_t tri) {
            return bin_of(centroids_[tri][a], lo, scale) < split.bin;
        });
        return begin + std::uint32_t(mid - first);
    }

    // Object median along the widest centroid axis; if all centroids
    // coincide, the middle by index as they are.
    std::uint32_t median_split(std::uint32_t begin, std::uint32_t end, const Aabb& centroid_box) {
        const std::uint32_t mid = begin + (end - begin) / 2;
        const glm::vec3 extent = centroid_box.hi - centroid_box.lo;
        const int a = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
        if (extent[a] > 0.0f) {
            std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                             [&](std::uint32_t x, std::uint32_t y) { return centroids_[x][a] < centroids_[y][a]; });
        }
        return mid;
    }

    const std::vector<Aabb>& bounds_;
    const std::vector<glm::vec3>& centroids_;
    std::vector<std::uint32_t>& order_;
    std::vector<BvhNode>& nodes_;
};

// Half the surface area of a binary node's box.
float half_area(const BvhNode& n) {
    const float dx = n.max_x - n.min_x, dy = n.max_y - n.min_y, dz = n.max_z - n.min_z;
    return dx * dy + dy * dz + dz * dx;
}

// The wide leaf of the `count` (at most four) triangles from `first` on.
WideLeaf wide_leaf(std::uint32_t first, std::uint32_t count, const std::vector<gpu::Triangle>& triangles) {
    WideLeaf w{};
    w.first = first;
    for (std::uint32_t lane = 0; lane < count; ++lane) {
        const gpu::Triangle& t = triangles[first + lane];
        const float v0[3] = {t.v0_x, t.v0_y, t.v0_z}, v1[3] = {t.v1_x, t.v1_y, t.v1_z},
                    v2[3] = {t.v2_x, t.v2_y, t.v2_z};
        for (int axis = 0; axis < 3; ++axis) {
            w.v0[axis][lane] = v0[axis];
            w.v1[axis][lane] = v1[axis];
            w.v2[axis][lane] = v2[axis];
        }
    }
    return w;
}

// The slots of a wide node type (4 or 8).
template <class Node>
constexpr std::uint32_t kSlots = std::uint32_t(sizeof(Node::child) / sizeof(Node::child[0]));

// An empty wide node: every slot masked out (count -1); an empty slot's box
// is never tested.
template <class Node>
Node empty_wide_node() {
    Node w{};
    for (std::uint32_t s = 0; s < kSlots<Node>; ++s) w.count[s] = -1;
    return w;
}

// Which binary nodes a wide tree takes as leaves: leaf_size[i] triangles
// from first[i] on where node i is one (nonzero), 0 where it is inner.
struct LeafView {
    std::vector<std::uint32_t> leaf_size, first;
};

// The binary tree's own leaves (the 4-wide tree, which the kernels read).
LeafView binary_leaves(const std::vector<BvhNode>& nodes) {
    LeafView v;
    v.leaf_size.resize(nodes.size());
    v.first.resize(nodes.size());
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        v.leaf_size[i] = nodes[i].tri_count;
        v.first[i] = nodes[i].first_or_left;
    }
    return v;
}

// The 8-wide tree's leaves: the binary leaves, and the subtrees of at most
// kMaxLeaf triangles that are cheaper to test whole on the CPU's walk. The
// binary tree is built for the kernels, which test a leaf one triangle per
// trip of their loop, so that a node's boxes cost about one triangle
// (kTraversalCost); the 8-wide walk tests a leaf's up to four triangles in
// one SSE test, so there a split must save more to pay. A subtree is kept
// whole where the builder's own leaf test prefers that at twice the
// traversal cost (kWide8TraversalCost), and where its box is at most three
// times as thick (its smallest extent) as the thickest of its leaves'
// boxes (kWide8Thickening). Shadow rays leave surfaces: a box around two
// surfaces that meet at a corner is entered by the rays leaving either one,
// which their two flat boxes let pass. Without that second test the walk on
// the gallery (a hall of 152 triangles) tested 14 times as many leaves and
// its render took 6 to 8% longer; with it Lightcuts renders the room 4%
// faster, the bunny 10%, the other shipped scenes 0 to 6%, and brute force
// the room 7% (docs/results/speed.md, twenty-fourth session). A subtree's
// triangles are contiguous (the build is depth first), so it is one leaf.
constexpr double kWide8TraversalCost = 2.0;
constexpr double kWide8Thickening = 3.0;

LeafView wide8_leaves(const std::vector<BvhNode>& nodes) {
    auto extents = [](const BvhNode& b) {
        return glm::dvec3(double(b.max_x) - b.min_x, double(b.max_y) - b.min_y, double(b.max_z) - b.min_z);
    };
    auto area = [](glm::dvec3 d) { return d.x * d.y + d.y * d.z + d.z * d.x; };
    auto thickness = [](glm::dvec3 d) { return std::min(d.x, std::min(d.y, d.z)); };
    LeafView v = binary_leaves(nodes);
    std::vector<std::uint32_t> under(nodes.size());  // the triangles under each node
    std::vector<double> thickest(nodes.size());      // the thickest leaf box under each node
    // Children come after their parent, so a reverse sweep sees them first.
    for (std::size_t i = nodes.size(); i-- > 0;) {
        const BvhNode& n = nodes[i];
        if (n.tri_count > 0 || n.first_or_left == 0) {  // a leaf, or the root of an empty tree
            under[i] = n.tri_count;
            thickest[i] = thickness(extents(n));
            continue;
        }
        const std::uint32_t l = n.first_or_left, r = l + 1u;
        under[i] = under[l] + under[r];
        v.first[i] = v.first[l];
        thickest[i] = std::max(thickest[l], thickest[r]);
        if (under[i] > kMaxLeaf) continue;
        // As in build: a split that is not cheaper than the leaf is not made.
        const glm::dvec3 d = extents(n);
        const double children = under[l] * area(extents(nodes[l])) + under[r] * area(extents(nodes[r]));
        const double split_cost = kIntersectCost * children + kWide8TraversalCost * area(d);
        const bool cheaper_whole = !(split_cost < kIntersectCost * under[i] * area(d));
        if (cheaper_whole && thickness(d) <= kWide8Thickening * thickest[i]) v.leaf_size[i] = under[i];
    }
    return v;
}

// Puts binary node `c` (index i) in slot s of w: its box and, where `view`
// takes it as a leaf, its count and the index of its wide leaf, which
// `leaf_index(i)` gives (an inner child's index comes later).
template <class Node, class LeafIndex>
void fill_slot(Node& w, std::uint32_t s, const BvhNode& c, std::uint32_t i, const LeafView& view,
               LeafIndex& leaf_index) {
    w.lo_x[s] = c.min_x, w.lo_y[s] = c.min_y, w.lo_z[s] = c.min_z;
    w.hi_x[s] = c.max_x, w.hi_y[s] = c.max_y, w.hi_z[s] = c.max_z;
    w.count[s] = std::int32_t(view.leaf_size[i]);
    if (view.leaf_size[i] > 0) w.child[s] = leaf_index(i);
}

// Writes the wide node for the children of binary node `inner` at
// wide[index], and its inner children's wide nodes after it (depth first).
template <class Node, class LeafIndex>
void collapse(const std::vector<BvhNode>& nodes, const LeafView& view, std::uint32_t inner, std::uint32_t index,
              std::vector<Node>& wide, LeafIndex& leaf_index) {
    std::array<std::uint32_t, kSlots<Node>> slots{nodes[inner].first_or_left, nodes[inner].first_or_left + 1u};
    std::uint32_t used = 2;
    while (used < kSlots<Node>) {
        int widest = -1;
        for (std::uint32_t s = 0; s < used; ++s)
            if (view.leaf_size[slots[s]] == 0 &&
                (widest < 0 || half_area(nodes[slots[s]]) > half_area(nodes[slots[std::size_t(widest)]])))
                widest = int(s);
        if (widest < 0) break;
        const std::uint32_t left = nodes[slots[std::size_t(widest)]].first_or_left;
        slots[std::size_t(widest)] = left;
        slots[used++] = left + 1u;
    }
    Node w = empty_wide_node<Node>();
    for (std::uint32_t s = 0; s < used; ++s) fill_slot(w, s, nodes[slots[s]], slots[s], view, leaf_index);
    wide[index] = w;
    for (std::uint32_t s = 0; s < used; ++s) {
        if (w.count[s] != 0) continue;
        const auto child = std::uint32_t(wide.size());
        wide.emplace_back();
        wide[index].child[s] = child;
        collapse(nodes, view, slots[s], child, wide, leaf_index);
    }
}

// The wide tree of `nodes` with `view`'s leaves, each made a WideLeaf of
// `triangles` into `leaves`.
template <class Node>
void collapse_tree(const std::vector<BvhNode>& nodes, const LeafView& view,
                   const std::vector<gpu::Triangle>& triangles, std::vector<Node>& wide_nodes,
                   std::vector<WideLeaf>& leaves) {
    leaves.clear();
    auto leaf_index = [&](std::uint32_t i) {
        leaves.push_back(wide_leaf(view.first[i], view.leaf_size[i], triangles));
        return std::uint32_t(leaves.size() - 1);
    };
    wide_nodes.assign(1, empty_wide_node<Node>());
    if (nodes.empty()) return;
    // A full binary tree of n nodes has (n + 1) / 2 leaves; a wide node
    // takes the place of at least (arity - 1) / 2 inner ones on average
    // (a guess that leaves a little growth at worst). Reserved, the 4- and
    // 8-wide trees of 4e6 triangles were built in half the time: growth
    // copied the arrays over and over (an audit of large meshes).
    constexpr std::size_t kArity = std::size(Node{}.count);
    leaves.reserve((nodes.size() + 1) / 2);
    wide_nodes.reserve(nodes.size() / (kArity - 1) + 1);
    const BvhNode& r = nodes[0];
    if (r.tri_count == 0 && r.first_or_left == 0) return;  // no triangles (build_bvh's far root)
    if (view.leaf_size[0] > 0) {
        fill_slot(wide_nodes[0], 0, r, 0, view, leaf_index);  // a root leaf: one slot holding it
        return;
    }
    collapse(nodes, view, 0, 0, wide_nodes, leaf_index);
}

}  // namespace

void collapse_bvh(const std::vector<BvhNode>& nodes, const std::vector<gpu::Triangle>& triangles,
                  std::vector<WideBvhNode>& wide_nodes, std::vector<WideLeaf>& wide_leaves) {
    collapse_tree(nodes, binary_leaves(nodes), triangles, wide_nodes, wide_leaves);
}

namespace {

// A plane of a Bvh4Node as the kernels decode it (lc_shared/trace.h,
// lc_bvh4_node): plane * scale is exact, so this is their sum bit for bit.
float bvh4_plane(float origin, float scale, std::uint32_t plane) { return origin + float(plane) * scale; }

// One axis of a Bvh4Node: the grid (origin and power-of-two scale) and each
// used slot's lower and upper plane, rounded outwards so that the decoded
// interval holds [lo, hi], and as tight as the grid allows.
void quantize_axis(const float (&lo)[4], const float (&hi)[4], const std::int32_t (&count)[4], float& origin,
                   float& scale, std::uint32_t& lo_planes, std::uint32_t& hi_planes) {
    origin = std::numeric_limits<float>::max();
    float top = -std::numeric_limits<float>::max();
    for (int s = 0; s < 4; ++s) {
        if (count[s] < 0) continue;
        origin = std::min(origin, lo[s]);
        top = std::max(top, hi[s]);
    }
    lo_planes = hi_planes = 0;
    if (top < origin) {  // no child: any grid
        origin = 0.0f;
        scale = 1.0f;
        return;
    }
    // The smallest power of two (a normal float, so that plane * scale stays
    // exact) whose 255th plane reaches the top.
    const double extent = double(top) - double(origin);
    int exponent = std::numeric_limits<float>::min_exponent - 1;  // 2^-126
    if (extent > 0.0) exponent = std::max(exponent, int(std::ceil(std::log2(extent / 255.0))));
    scale = std::ldexp(1.0f, exponent);
    while (bvh4_plane(origin, scale, 255u) < top) scale *= 2.0f;
    for (int s = 0; s < 4; ++s) {
        if (count[s] < 0) continue;
        const double offset_lo = (double(lo[s]) - double(origin)) / double(scale);
        const double offset_hi = (double(hi[s]) - double(origin)) / double(scale);
        auto q_lo = std::uint32_t(std::clamp(std::floor(offset_lo), 0.0, 255.0));
        auto q_hi = std::uint32_t(std::clamp(std::ceil(offset_hi), 0.0, 255.0));
        // The sum rounds: step outwards until the decoded plane holds the box.
        while (q_lo > 0 && bvh4_plane(origin, scale, q_lo) > lo[s]) --q_lo;
        while (bvh4_plane(origin, scale, q_hi) < hi[s]) ++q_hi;
        lo_planes |= q_lo << (8 * s);
        hi_planes |= q_hi << (8 * s);
    }
}

}  // namespace

std::vector<gpu::Bvh4Node> bvh4_nodes(const std::vector<WideBvhNode>& wide_nodes,
                                      const std::vector<WideLeaf>& wide_leaves) {
    // lc_trace_any keeps a node's index and four bits in one stack word
    // (shaders/lc_shared/trace.h). A tree has about one wide node per three
    // to four triangles (1,004 for the room's 3,492), so below build_bvh's
    // 2^29 triangles this is not reached in practice.
    if (wide_nodes.size() >= std::size_t(1) << 28)
        throw std::invalid_argument("build_bvh: " + std::to_string(wide_nodes.size()) +
                                    " 4-wide nodes; at most 2^28 - 1 are supported");
    std::vector<gpu::Bvh4Node> out(wide_nodes.size());
    for (std::size_t i = 0; i < wide_nodes.size(); ++i) {
        const WideBvhNode& w = wide_nodes[i];
        gpu::Bvh4Node& n = out[i];
        quantize_axis(w.lo_x, w.hi_x, w.count, n.origin_x, n.scale_x, n.lo_x, n.hi_x);
        quantize_axis(w.lo_y, w.hi_y, w.count, n.origin_y, n.scale_y, n.lo_y, n.hi_y);
        quantize_axis(w.lo_z, w.hi_z, w.count, n.origin_z, n.scale_z, n.lo_z, n.hi_z);
        for (int s = 0; s < 4; ++s) {
            if (w.count[s] < 0) {
                n.entry[s] = gpu::kInvalidIndex;
            } else if (w.count[s] == 0) {
                n.entry[s] = w.child[s];
            } else {
                n.entry[s] = gpu::kBvh4LeafEntry | (std::uint32_t(w.count[s] - 1) << 29) | wide_leaves[w.child[s]].first;
            }
        }
    }
    return out;
}

void collapse_bvh8(const std::vector<BvhNode>& nodes, const std::vector<gpu::Triangle>& triangles,
                   std::vector<WideBvhNode8>& wide_nodes, std::vector<WideLeaf>& wide_leaves) {
    collapse_tree(nodes, wide8_leaves(nodes), triangles, wide_nodes, wide_leaves);
}

Bvh build_bvh(std::vector<gpu::Triangle>& triangles, std::vector<gpu::TriangleNormals>& normals,
              std::vector<gpu::TriangleUvs>* uvs) {
    const auto start = std::chrono::steady_clock::now();
    if (normals.size() != triangles.size())
        throw std::invalid_argument("build_bvh: triangles and normals differ in count");
    if (uvs && uvs->size() != triangles.size())
        throw std::invalid_argument("build_bvh: triangles and uvs differ in count");
    // Node indices are 32-bit and a tree holds up to 2n - 1 nodes.
    if (triangles.size() >= std::size_t(gpu::kBvh4MaxTriangles))
        throw std::invalid_argument("build_bvh: " + std::to_string(triangles.size()) +
                                    " triangles; at most 2^29 - 1 are supported");

    Bvh bvh;
    const auto n = std::uint32_t(triangles.size());
    if (n == 0) {
        // No triangle: the root is an interior-looking node (tri_count 0), so
        // traversal must never enter it. Its box is the single point at
        // (FLT_MAX, FLT_MAX, FLT_MAX): a ray can only reach it at t around
        // 3e38 / |dir|, beyond any t_max <= kRayInfinity (1e30). An inverted
        // box (min > max) would not do: the slab test swaps the planes per
        // axis and sees a box around the origin.
        constexpr float far = std::numeric_limits<float>::max();
        bvh.nodes.push_back(BvhNode{far, far, far, 0u, far, far, far, 0u});
        collapse_bvh(bvh.nodes, triangles, bvh.wide_nodes, bvh.wide_leaves);
        collapse_bvh8(bvh.nodes, triangles, bvh.wide8_nodes, bvh.wide8_leaves);
        bvh.kernel_nodes = bvh4_nodes(bvh.wide_nodes, bvh.wide_leaves);
        bvh.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return bvh;
    }

    std::vector<Aabb> bounds(n);
    std::vector<glm::vec3> centroids(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        const gpu::Triangle& t = triangles[i];
        Aabb b;
        b.grow(glm::vec3(t.v0_x, t.v0_y, t.v0_z));
        b.grow(glm::vec3(t.v1_x, t.v1_y, t.v1_z));
        b.grow(glm::vec3(t.v2_x, t.v2_y, t.v2_z));
        bounds[i] = b;
        centroids[i] = 0.5f * (b.lo + b.hi);  // box centre: binning only needs a stable point
    }
    std::vector<std::uint32_t> order(n);
    for (std::uint32_t i = 0; i < n; ++i) order[i] = i;

    bvh.nodes.reserve(2 * std::size_t(n));
    bvh.nodes.resize(1);
    Builder(bounds, centroids, order, bvh.nodes).build(0, 0, n, 0);
    bvh.nodes.shrink_to_fit();

    // Leaves reference contiguous ranges of the reordered arrays.
    std::vector<gpu::Triangle> sorted_triangles(n);
    std::vector<gpu::TriangleNormals> sorted_normals(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        sorted_triangles[i] = triangles[order[i]];
        sorted_normals[i] = normals[order[i]];
    }
    triangles.swap(sorted_triangles);
    normals.swap(sorted_normals);
    if (uvs) {
        std::vector<gpu::TriangleUvs> sorted_uvs(n);
        for (std::uint32_t i = 0; i < n; ++i) sorted_uvs[i] = (*uvs)[order[i]];
        uvs->swap(sorted_uvs);
    }

    collapse_bvh(bvh.nodes, triangles, bvh.wide_nodes, bvh.wide_leaves);
    collapse_bvh8(bvh.nodes, triangles, bvh.wide8_nodes, bvh.wide8_leaves);
    bvh.kernel_nodes = bvh4_nodes(bvh.wide_nodes, bvh.wide_leaves);
    bvh.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return bvh;
}

}  // namespace lc
