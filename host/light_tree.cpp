// Light tree construction (Walter et al. 2005, section 4.1): bottom-up
// agglomerative clustering under the metric I_C (alpha_C^2 + c^2 (1 - cos
// beta_C)^2), where I_C is the Rec.709 luminance of the cluster's RGB
// intensity sum, alpha_C the diagonal of its box and beta_C the spread of
// the emission axes of its spot or oriented lights (light_bounds.h). One
// tree per light type.
//
// kFast is locally-ordered clustering (Walter et al. 2008; the PLOC variant
// of Meister and Bittner 2018): clusters sorted along a Morton curve, each
// picks its best partner within a window of kWindow neighbours each side,
// mutual best pairs merge, repeat. O(n log n) for the sort plus O(n * window)
// per round; the rounds shrink geometrically.
//
// kExact is exhaustive greedy: always merge the globally cheapest pair.
// Each cluster caches its best partner; a merge rescans only the clusters
// whose partner disappeared. O(n^2) time overall for typical inputs.
#include "lightcuts/light_tree.h"

#include "shared/color.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <thread>

#include <glm/glm.hpp>

#include "light_bounds.h"

namespace lc {
namespace {

constexpr int kWindow = 16;

struct Cluster {
    glm::vec3 lo, hi;
    // Summed in double: sums of many bright lights must neither overflow
    // nor lose the small ones (the loader checks each type's total fits a float).
    glm::dvec3 intensity;
    double weight;         // luminance of intensity, the metric's I_C
    EmissionCone cone;     // as stored: axis quantized, theta_o widened to match
    std::uint32_t axis_packed = 0;
    std::uint32_t rep;     // index into the input light array
    std::uint32_t left = gpu::kInvalidIndex, right = gpu::kInvalidIndex;  // build ids
    bool rep_from_right = false;
};

// One tree in the making: every cluster so far (leaves first) and what the
// merges need.
struct Build {
    std::vector<Cluster> all;
    std::uint32_t seed = 0;
    // c^2 of the metric's cone term: 0 for lights that emit everywhere.
    double cone_weight = 0.0;
};

// Walter 2005 §4.1: I_C * (alpha_C^2 + c^2 (1 - cos beta_C)^2) for the
// cluster a and b would make.
// (Cluster, or the CostKey the fast builder gathers: the same fields.)
template <typename C>
double merge_cost(const Build& b, const C& x, const C& y) {
    glm::dvec3 d = glm::dvec3(glm::max(x.hi, y.hi)) - glm::dvec3(glm::min(x.lo, y.lo));
    double size = glm::dot(d, d);
    if (b.cone_weight > 0.0) {
        const double spread = 1.0 - double(cone_union(x.cone, y.cone).cos_beta());
        size += b.cone_weight * spread * spread;
    }
    return (x.weight + y.weight) * size;
}


// Merges clusters a and b (build ids) into a new cluster appended to `all`.
// The representative is one of the children's, chosen with probability
// proportional to their intensities from a hash of (seed, new id), so the
// choice is the same whatever order or thread made it.
void merge(Build& build, std::uint32_t a, std::uint32_t b) {
    std::vector<Cluster>& all = build.all;
    const std::uint32_t seed = build.seed;
    Cluster c;
    const Cluster& ca = all[a];
    const Cluster& cb = all[b];
    c.lo = glm::min(ca.lo, cb.lo);
    c.hi = glm::max(ca.hi, cb.hi);
    c.intensity = ca.intensity + cb.intensity;
    c.weight = ca.weight + cb.weight;
    c.cone = quantized(cone_union(ca.cone, cb.cone), c.axis_packed);
    c.left = a;
    c.right = b;
    auto id = static_cast<std::uint32_t>(all.size());
    double u = gpu::lc_unit_float(gpu::lc_hash(seed ^ gpu::lc_hash(id)));
    double p_left = c.weight > 0.0 ? ca.weight / c.weight : 0.5;
    c.rep_from_right = u >= p_left;
    c.rep = c.rep_from_right ? cb.rep : ca.rep;
    all.push_back(c);
}

// Runs fn(begin, end) over [0, n) on up to hardware_concurrency threads.
template <typename Fn>
void parallel_for(std::size_t n, Fn fn) {
    unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    if (n < 4096 || threads == 1) {
        fn(std::size_t(0), n);
        return;
    }
    std::vector<std::thread> pool;
    std::size_t chunk = (n + threads - 1) / threads;
    for (unsigned t = 0; t < threads; ++t) {
        std::size_t b = t * chunk, e = std::min(n, b + chunk);
        if (b < e) pool.emplace_back(fn, b, e);
    }
    for (auto& th : pool) th.join();
}

// Interleaves the 10-bit coordinates q[0..dims) into one Morton key.
std::uint64_t morton_key(const std::uint32_t* q, int dims) {
    std::uint64_t key = 0;
    for (int bit = 9; bit >= 0; --bit)
        for (int d = 0; d < dims; ++d) key = (key << 1) | ((q[d] >> bit) & 1u);
    return key;
}

// Sorts cluster ids along a Morton curve of their box centres, in 3D, or
// in 6D with the emission axis too where the metric has a cone term: the
// window of partners then holds lights that are near and face alike.
void sort_morton(const std::vector<Cluster>& all, std::vector<std::uint32_t>& active, bool with_axis) {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (auto id : active) {
        lo = glm::min(lo, all[id].lo);
        hi = glm::max(hi, all[id].hi);
    }
    glm::vec3 extent = glm::max(hi - lo, glm::vec3(1e-30f));
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(active.size());
    for (std::size_t i = 0; i < active.size(); ++i) {
        const Cluster& c = all[active[i]];
        const glm::vec3 t = glm::clamp((0.5f * (c.lo + c.hi) - lo) / extent, 0.0f, 1.0f) * 1023.0f;
        const glm::vec3 a = glm::clamp(0.5f * (c.cone.axis + 1.0f), 0.0f, 1.0f) * 1023.0f;
        const std::uint32_t q[6] = {std::uint32_t(t.x), std::uint32_t(t.y), std::uint32_t(t.z),
                                    std::uint32_t(a.x), std::uint32_t(a.y), std::uint32_t(a.z)};
        keyed[i] = {morton_key(q, with_axis ? 6 : 3), active[i]};
    }
    std::sort(keyed.begin(), keyed.end());
    for (std::size_t i = 0; i < keyed.size(); ++i) active[i] = keyed[i].second;
}

// What merge_cost reads of a cluster. The fast builder gathers these in
// Morton order every round, so a window of partners is contiguous memory,
// not clusters scattered over Build::all (gathering cut the build of 10^6 lights
// from 3.45 s to 2.79 s).
struct CostKey {
    glm::vec3 lo, hi;
    double weight;
    EmissionCone cone;
};

// The cheapest partner of keys[i] within kWindow positions each side.
//
// Ties go to the nearer index; between i - d and i + d to the right when
// i / d is even, else the left. Any choice at equal distance keeps the
// globally cheapest pair at the smallest distance mutual, so rounds
// progress; alternating sides makes a run of equal costs pair up as (0,1),
// (2,3), ... Always taking the lower index merged one pair per round when
// every cost is equal, which they are for coincident lights (cost 0):
// O(n^2) rounds' work and a tree as deep as n (8000 coincident lights took
// 5 s).
std::size_t best_partner(const Build& b, const std::vector<CostKey>& keys, std::size_t i) {
    const std::size_t n = keys.size();
    const std::size_t jb = i >= std::size_t(kWindow) ? i - kWindow : 0;
    const std::size_t je = std::min(n, i + kWindow + 1);
    double best_cost = std::numeric_limits<double>::infinity();
    std::size_t best_j = i == 0 ? 1 : i - 1;
    for (std::size_t j = jb; j < je; ++j) {
        if (j == i) continue;
        const double cost = merge_cost(b, keys[i], keys[j]);
        if (cost > best_cost) continue;
        if (cost == best_cost) {
            // The tie rule, off the common path: its division cost as much
            // as the metric.
            const std::size_t dist = j > i ? j - i : i - j;
            const std::size_t best_dist = best_j > i ? best_j - i : i - best_j;
            if (dist > best_dist) continue;
            if (dist == best_dist && (j > i) != ((i / dist) % 2 == 0)) continue;
        } else if (!(cost < best_cost)) {
            continue;  // NaN: never chosen, as before
        }
        best_cost = cost;
        best_j = j;
    }
    return best_j;
}

// Locally-ordered clustering; returns the root's build id.
std::uint32_t cluster_fast(Build& build, std::vector<std::uint32_t> active) {
    sort_morton(build.all, active, build.cone_weight > 0.0);
    std::vector<std::uint32_t> best(active.size());
    std::vector<CostKey> keys(active.size());
    std::vector<std::uint32_t> next;
    while (active.size() > 1) {
        const std::size_t n = active.size();
        best.resize(n);
        keys.resize(n);
        parallel_for(n, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i) {
                const Cluster& c = build.all[active[i]];
                keys[i] = CostKey{c.lo, c.hi, c.weight, c.cone};
            }
        });
        parallel_for(n, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
                best[i] = static_cast<std::uint32_t>(best_partner(build, keys, i));
        });
        // Mutual best pairs merge (in place of their first member, so the
        // Morton order holds); the others wait for the next round.
        next.clear();
        std::size_t merged = 0;
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t j = best[i];
            if (best[j] != i) {
                next.push_back(active[i]);
            } else if (i < j) {
                merge(build, active[i], active[j]);
                next.push_back(static_cast<std::uint32_t>(build.all.size() - 1));
                ++merged;
            }
        }
        if (merged == 0) {
            // Cannot happen with the tie-breaking above (the cheapest pair in
            // any window is mutual); merge neighbours rather than loop forever.
            merge(build, active[0], active[1]);
            next.erase(next.begin(), next.begin() + 2);
            next.insert(next.begin(), static_cast<std::uint32_t>(build.all.size() - 1));
        }
        active.swap(next);
    }
    return active[0];
}

std::uint32_t cluster_exact(Build& build, std::vector<std::uint32_t> active) {
    std::vector<Cluster>& all = build.all;
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<std::uint32_t> best(active.size());
    std::vector<double> best_cost(active.size(), inf);
    auto rescan = [&](std::size_t i) {
        best_cost[i] = inf;
        for (std::size_t j = 0; j < active.size(); ++j) {
            if (j == i) continue;
            double c = merge_cost(build, all[active[i]], all[active[j]]);
            if (c < best_cost[i]) {
                best_cost[i] = c;
                best[i] = static_cast<std::uint32_t>(j);
            }
        }
    };
    for (std::size_t i = 0; i < active.size(); ++i) rescan(i);
    while (active.size() > 1) {
        std::size_t a = std::size_t(std::min_element(best_cost.begin(), best_cost.end()) - best_cost.begin());
        std::size_t b = best[a];
        if (b < a) std::swap(a, b);
        merge(build, active[a], active[b]);
        // Slot a takes the merged cluster; slot b takes the last one.
        active[a] = static_cast<std::uint32_t>(all.size() - 1);
        std::size_t last = active.size() - 1;
        active[b] = active[last];
        best[b] = best[last];
        best_cost[b] = best_cost[last];
        active.pop_back();
        best.pop_back();
        best_cost.pop_back();
        for (std::size_t i = 0; i < active.size(); ++i) {
            if (best[i] == last) best[i] = static_cast<std::uint32_t>(b);  // moved, not merged
        }
        rescan(a);
        for (std::size_t i = 0; i < active.size(); ++i) {
            if (i == a) continue;
            if (best[i] == a || best[i] == b) {
                rescan(i);
            } else {
                double c = merge_cost(build, all[active[i]], all[active[a]]);
                if (c < best_cost[i]) {
                    best_cost[i] = c;
                    best[i] = static_cast<std::uint32_t>(a);
                }
            }
        }
    }
    return active[0];
}

// Writes the subtree of build id `id` into node slot `slot`: children take
// two adjacent slots, lights are numbered in depth-first leaf order.
void flatten(const std::vector<Cluster>& all, std::span<const gpu::Light> input, std::uint32_t root,
             std::uint32_t type, std::uint32_t base_slot, LightTree& tree) {
    const std::uint32_t type_bits = type << gpu::kNodeTypeShift;
    struct Item { std::uint32_t id, slot; };
    std::vector<Item> stack{{root, base_slot}};
    std::uint32_t next_slot = base_slot + 1;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> leaf_slots;  // (slot, input light)
    // Depth-first, left before right, so leaves come out in light order.
    while (!stack.empty()) {
        Item it = stack.back();
        stack.pop_back();
        const Cluster& c = all[it.id];
        gpu::LightNode& n = tree.nodes[it.slot];
        n.min_x = c.lo.x; n.min_y = c.lo.y; n.min_z = c.lo.z;
        n.max_x = c.hi.x; n.max_y = c.hi.y; n.max_z = c.hi.z;
        n.intensity_r = float(c.intensity.x);
        n.intensity_g = float(c.intensity.y);
        n.intensity_b = float(c.intensity.z);
        n.rep_light = c.rep;  // remapped to leaf order below
        n.axis_oct = c.axis_packed;
        n.cos_theta_o = c.cone.emits_everywhere() ? -1.0f : std::cos(c.cone.theta_o);
        n.cos_theta_e = std::cos(c.cone.theta_e);
        n.falloff_width = c.cone.falloff_width;
        const std::uint32_t node_bits = type_bits | (c.cone.two_sided ? gpu::kNodeTwoSided : 0u);
        if (c.left == gpu::kInvalidIndex) {
            n.left = gpu::kInvalidIndex;
            n.flags = gpu::kNodeLeaf | node_bits;
            leaf_slots.emplace_back(it.slot, c.rep);
        } else {
            n.left = next_slot;
            n.flags = (c.rep_from_right ? gpu::kNodeRepFromRight : 0u) | node_bits;
            next_slot += 2;
            stack.push_back({c.right, n.left + 1});
            stack.push_back({c.left, n.left});
        }
    }
    // Input light index -> leaf-order index.
    std::vector<std::uint32_t> remap(input.size(), gpu::kInvalidIndex);
    for (auto [slot, light] : leaf_slots) {
        remap[light] = static_cast<std::uint32_t>(tree.lights.size());
        tree.lights.push_back(input[light]);
    }
    for (std::uint32_t s = base_slot; s < next_slot; ++s) tree.nodes[s].rep_light = remap[tree.nodes[s].rep_light];
}

}  // namespace

std::uint32_t LightTree::root_count() const {
    std::uint32_t n = 0;
    for (std::uint32_t root : roots) n += root != gpu::kInvalidIndex ? 1u : 0u;
    return n;
}

std::uint32_t LightTree::cut_heap_capacity(std::uint32_t max_cut) const {
    // Each tree of n lights has n - 1 interior nodes: nodes.size() - lights.size() in all.
    const std::uint64_t interior = nodes.size() - lights.size();
    const std::uint64_t cut = std::max<std::uint64_t>(max_cut, root_count());
    return std::uint32_t(std::max<std::uint64_t>(1, std::min(interior, cut)));
}

std::uint32_t LightTree::cut_heap_slots(std::uint32_t max_cut, std::uint32_t cut_heap) const {
    return std::max(1u, std::min(cut_heap, cut_heap_capacity(max_cut)));
}

LightTree build_light_tree(std::span<const gpu::Light> lights, std::uint32_t seed, TreeBuilder builder,
                           double cone_scale) {
    auto start = std::chrono::steady_clock::now();
    LightTree tree;
    tree.lights.reserve(lights.size());
    for (const gpu::Light& l : lights) tree_point(l);  // unknown types fail before any work
    for (std::uint32_t type = 0; type < gpu::kLightTypeCount; ++type) {
        Build build;
        build.seed = seed ^ type;
        std::vector<Cluster>& all = build.all;
        std::vector<std::uint32_t> leaves;
        glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
        for (std::uint32_t i = 0; i < lights.size(); ++i) {
            const gpu::Light& l = lights[i];
            if ((l.type & gpu::kLightTypeMask) != type) continue;
            Cluster c;
            c.lo = c.hi = tree_point(l);
            c.cone = quantized(EmissionCone::of_light(l), c.axis_packed);
            c.intensity = glm::dvec3(l.r, l.g, l.b);
            c.weight = gpu::lc_luminance(glm::vec3(l.r, l.g, l.b));
            if (!(c.weight > 0.0)) {
                tree.black_lights += 1;
                continue;
            }
            c.rep = i;
            lo = glm::min(lo, c.lo);
            hi = glm::max(hi, c.hi);
            leaves.push_back(static_cast<std::uint32_t>(all.size()));
            all.push_back(c);
        }
        if (leaves.empty()) continue;
        // Walter 2005 §4.1 sets c, which weighs directional against spatial
        // similarity, to the scene's diagonal; here the diagonal of this
        // tree's lights. Lights that emit everywhere have no cone term.
        const bool has_cones = std::any_of(leaves.begin(), leaves.end(),
                                           [&](std::uint32_t id) { return !all[id].cone.emits_everywhere(); });
        if (has_cones)
            build.cone_weight = cone_scale * cone_scale * glm::dot(glm::dvec3(hi - lo), glm::dvec3(hi - lo));
        all.reserve(2 * leaves.size());
        std::uint32_t root = builder == TreeBuilder::kExact ? cluster_exact(build, leaves) : cluster_fast(build, leaves);
        auto base = static_cast<std::uint32_t>(tree.nodes.size());
        tree.nodes.resize(tree.nodes.size() + 2 * leaves.size() - 1);
        tree.roots[type] = base;
        // flatten() numbers lights from tree.lights.size() on, so the light
        // indices of each tree follow those of the one before.
        flatten(all, lights, root, type, base, tree);
    }
    tree.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return tree;
}

}  // namespace lc
