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
// mutual best pairs merge, repeat. A radix sort of the Morton keys, then
// O(n * window) per round; the rounds shrink geometrically.
//
// kExact is exhaustive greedy: always merge the globally cheapest pair.
// Each cluster caches its best partner; a merge rescans only the clusters
// whose partner disappeared. O(n^2) time overall for typical inputs.
#include "lightcuts/light_tree.h"

#include "lc_shared/color.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <thread>
#include <type_traits>

#include <glm/glm.hpp>

#include "light_bounds.h"
#include "run_on_threads.h"
#include "scene/huge_pages.h"

namespace lc {
namespace {

constexpr int kWindow = 16;

// Left unwritten where made (Build::all does not zero its elements): the
// leaves and merges write every field.
struct Cluster {
    glm::vec3 lo, hi;
    // Summed in double: sums of many bright lights must neither overflow
    // nor lose the small ones (the loader checks each type's total fits a float).
    glm::dvec3 intensity;
    double weight;         // luminance of intensity, the metric's I_C
    std::uint32_t rep;     // index into the input light array
    std::uint32_t left, right;  // build ids; kInvalidIndex for leaves
    std::uint32_t leaves : 31;  // the lights below (flatten() numbers the nodes by them)
    std::uint32_t rep_from_right : 1;
};
static_assert(std::is_trivially_default_constructible_v<Cluster>);
static_assert(sizeof(Cluster) == 72, "2n clusters of 10^7 lights take 1.4 GB: keep the record small");

// A cluster's emission cone, as stored: axis quantized (axis_packed, as the
// nodes hold it), theta_o widened to match.
struct ClusterCone {
    EmissionCone cone;
    std::uint32_t axis_packed;
};

ClusterCone cone_record(const EmissionCone& cone) {
    ClusterCone c;
    c.cone = quantized(cone, c.axis_packed);
    return c;
}

// One tree in the making: every cluster so far (leaves first) and what the
// merges need.
struct Build {
    UninitializedVector<Cluster> all;
    // The clusters' cones by build id, kept only where some light of the
    // tree has a cone (spots, oriented lights, VPLs); without, every
    // cluster's is `everywhere` (the union of cones that emit everywhere
    // emits everywhere), and the clusters are 30% smaller.
    UninitializedVector<ClusterCone> cones;
    ClusterCone everywhere = cone_record(EmissionCone::everywhere());
    std::uint32_t seed = 0;
    // c^2 of the metric's cone term: 0 for lights that emit everywhere.
    double cone_weight = 0.0;
    // Powers of two that the metric's positions and weights are scaled by
    // (MetricKeys), 1 but where its float could overflow (metric_scales).
    float position_scale = 1.0f, weight_scale = 1.0f;

    const ClusterCone& cone(std::uint32_t id) const { return cones.empty() ? everywhere : cones[id]; }
};

// Merges clusters a and b (build ids) into the cluster of build id `id`.
// The representative is one of the children's, chosen with probability
// proportional to their intensities from a hash of (seed, new id), so the
// choice is the same whatever order or thread made it.
void merge_into(Build& build, std::uint32_t a, std::uint32_t b, std::uint32_t id) {
    UninitializedVector<Cluster>& all = build.all;
    const std::uint32_t seed = build.seed;
    Cluster& c = all[id];
    const Cluster& ca = all[a];
    const Cluster& cb = all[b];
    c.lo = glm::min(ca.lo, cb.lo);
    c.hi = glm::max(ca.hi, cb.hi);
    c.intensity = ca.intensity + cb.intensity;
    c.weight = ca.weight + cb.weight;
    if (!build.cones.empty()) build.cones[id] = cone_record(cone_union(build.cones[a].cone, build.cones[b].cone));
    c.left = a;
    c.right = b;
    double u = gpu::lc_unit_float(gpu::lc_hash(seed ^ gpu::lc_hash(id)));
    double p_left = c.weight > 0.0 ? ca.weight / c.weight : 0.5;
    c.rep_from_right = u >= p_left;
    c.rep = c.rep_from_right ? cb.rep : ca.rep;
    c.leaves = (ca.leaves + cb.leaves) & 0x7FFFFFFFu;  // at most 2^31 - 1 lights (build_light_tree)
}

// Merges clusters a and b into a new cluster appended to `all`.
void merge(Build& build, std::uint32_t a, std::uint32_t b) {
    const auto id = static_cast<std::uint32_t>(build.all.size());
    build.all.emplace_back();
    if (!build.cones.empty()) build.cones.emplace_back();
    merge_into(build, a, b, id);
}

// The metric's I_C of a single light: its luminance.
double leaf_weight(const gpu::Light& l) { return gpu::lc_luminance(glm::vec3(l.r, l.g, l.b)); }

// The leaf of light `index`.
Cluster leaf_of(const gpu::Light& l, std::size_t index) {
    Cluster c;
    c.lo = c.hi = tree_point(l);
    c.intensity = glm::dvec3(l.r, l.g, l.b);
    c.weight = leaf_weight(l);
    c.rep = std::uint32_t(index);
    c.left = c.right = gpu::kInvalidIndex;
    c.leaves = 1;
    c.rep_from_right = false;
    return c;
}

// The threads of the build running on this thread: build_light_tree's
// `threads`, or 0 for one per hardware thread.
thread_local unsigned build_threads = 0;

// The threads parallel_for uses for n items, and the range of thread t.
unsigned thread_count(std::size_t n) {
    if (n < 4096) return 1u;
    return build_threads > 0 ? build_threads : std::max(1u, std::thread::hardware_concurrency());
}
std::pair<std::size_t, std::size_t> thread_range(std::size_t n, unsigned threads, unsigned t) {
    const std::size_t chunk = (n + threads - 1) / threads;
    return {std::min(n, t * chunk), std::min(n, (t + 1) * chunk)};
}

// Runs fn(begin, end, t) over [0, n) on up to hardware_concurrency threads,
// t the thread's number: the same ranges as thread_range(). Range 0 runs on
// the calling thread, so a loop starts one thread fewer (a build runs 50 to
// 140 of these loops, and starting and joining a thread took 70 µs on the
// development machine).
template <typename Fn>
void parallel_for_ranges(std::size_t n, Fn fn) {
    const unsigned threads = thread_count(n);
    if (threads == 1) {
        fn(std::size_t(0), n, 0u);
        return;
    }
    run_on_threads(threads, [&](unsigned t) {
        const auto [b, e] = thread_range(n, threads, t);
        if (b < e || t == 0u) fn(b, e, t);
    });
}

// Runs fn(begin, end) over [0, n) on up to hardware_concurrency threads.
template <typename Fn>
void parallel_for(std::size_t n, Fn fn) {
    parallel_for_ranges(n, [&fn](std::size_t b, std::size_t e, unsigned) { fn(b, e); });
}

// Interleaves the 10-bit coordinates q[0..dims) into one Morton key.
std::uint64_t morton_key(const std::uint32_t* q, int dims) {
    std::uint64_t key = 0;
    for (int bit = 9; bit >= 0; --bit)
        for (int d = 0; d < dims; ++d) key = (key << 1) | ((q[d] >> bit) & 1u);
    return key;
}

// The Morton key of a leaf: its point in the tree's box [lo, lo + extent],
// in 3D, or in 6D with the emission axis too where the metric has a cone
// term: the window of partners then holds lights that are near and face
// alike.
// (`point` is the leaf's box's, lo = hi; `axis` its stored cone axis, read
// only with the axis. 0.5 * (point + point) is the box's centre as it was
// computed from lo + hi: not `point` where |point| > FLT_MAX / 2.)
std::uint64_t leaf_key(glm::vec3 point, glm::vec3 axis, glm::vec3 lo, glm::vec3 extent, bool with_axis) {
    const glm::vec3 t = glm::clamp((0.5f * (point + point) - lo) / extent, 0.0f, 1.0f) * 1023.0f;
    const glm::vec3 a = glm::clamp(0.5f * (axis + 1.0f), 0.0f, 1.0f) * 1023.0f;
    const std::uint32_t q[6] = {std::uint32_t(t.x), std::uint32_t(t.y), std::uint32_t(t.z),
                                std::uint32_t(a.x), std::uint32_t(a.y), std::uint32_t(a.z)};
    return morton_key(q, with_axis ? 6 : 3);
}

// Sorts (key, light) pairs by their keys, which have `key_bits` bits:
// least-significant-digit radix sort, 10 bits a pass, each pass counting
// and then scattering on every thread. Stable, so pairs made in light order
// come out in the order of one std::sort of the pairs (equal keys by light
// index), whatever the thread count. (std::sort on each thread and a merge
// of the sorted ranges took 0.5 to 1.5 s of the build for 10^7 lights.)
void radix_sort(std::vector<std::pair<std::uint64_t, std::uint32_t>>& keyed, int key_bits) {
    using Pair = std::pair<std::uint64_t, std::uint32_t>;
    constexpr int kDigitBits = 10;
    constexpr std::size_t kBuckets = std::size_t(1) << kDigitBits;
    const std::size_t n = keyed.size();
    const unsigned threads = thread_count(n);
    UninitializedVector<Pair> scratch;
    reserve_huge(scratch, n);
    scratch.resize(n);
    Pair* from = keyed.data();
    Pair* to = scratch.data();
    std::vector<std::size_t> next(std::size_t(threads) * kBuckets);  // thread t's next place for digit d
    for (int shift = 0; shift < key_bits; shift += kDigitBits) {
        auto digit = [shift](const Pair& p) { return std::size_t(p.first >> shift) & (kBuckets - 1); };
        // Zeroed here, not by each thread: a thread whose range is empty
        // never runs, and its row must still count nothing.
        std::fill(next.begin(), next.end(), std::size_t(0));
        parallel_for_ranges(n, [&](std::size_t begin, std::size_t end, unsigned t) {
            std::size_t* count = &next[std::size_t(t) * kBuckets];
            for (std::size_t i = begin; i < end; ++i) ++count[digit(from[i])];
        });
        // Digit-major, thread-minor: thread t's pairs of a digit follow
        // those of the threads before it.
        std::size_t place = 0;
        for (std::size_t d = 0; d < kBuckets; ++d)
            for (unsigned t = 0; t < threads; ++t) {
                const std::size_t count = next[std::size_t(t) * kBuckets + d];
                next[std::size_t(t) * kBuckets + d] = place;
                place += count;
            }
        parallel_for_ranges(n, [&](std::size_t begin, std::size_t end, unsigned t) {
            std::size_t* place_of = &next[std::size_t(t) * kBuckets];
            for (std::size_t i = begin; i < end; ++i) to[place_of[digit(from[i])]++] = from[i];
        });
        std::swap(from, to);
    }
    if (from != keyed.data()) std::copy(from, from + n, keyed.data());
}

// What the metric reads of the clusters, one array per value: the boxes
// and weights and, for trees with a cone term, the cones' axes and
// spreads (ConeSpread). The fast builder keeps the clusters of a round in
// Morton order here, so that best_partners reads the partners of a block
// of clusters as contiguous floats, in vector instructions.
struct MetricKeys {
    std::vector<float> lo_x, lo_y, lo_z, hi_x, hi_y, hi_z, weight;
    std::vector<float> axis_x, axis_y, axis_z, cos_half, sin_half, cos_beta;  // with cones only
    bool cones = false;
    float cone_weight = 0.0f;  // Build::cone_weight, in the scaled positions' units
    float position_scale = 1.0f, weight_scale = 1.0f;  // Build's

    explicit MetricKeys(const Build& b)
        : cones(b.cone_weight > 0.0),
          cone_weight(float(b.cone_weight * double(b.position_scale) * double(b.position_scale))),
          position_scale(b.position_scale),
          weight_scale(b.weight_scale) {}
    std::size_t size() const { return weight.size(); }
    void resize(std::size_t n) {
        auto fit = [n](std::vector<float>& v) {
            if (v.capacity() < n) reserve_huge(v, n);
            v.resize(n);
        };
        for (auto* v : {&lo_x, &lo_y, &lo_z, &hi_x, &hi_y, &hi_z, &weight}) fit(*v);
        if (cones)
            for (auto* v : {&axis_x, &axis_y, &axis_z, &cos_half, &sin_half, &cos_beta}) fit(*v);
    }
    // Slot i takes build id `id`.
    void set(std::size_t i, const Build& b, std::uint32_t id) {
        const Cluster& c = b.all[id];
        const glm::vec3 lo = c.lo * position_scale, hi = c.hi * position_scale;  // exact: powers of two
        lo_x[i] = lo.x; lo_y[i] = lo.y; lo_z[i] = lo.z;
        hi_x[i] = hi.x; hi_y[i] = hi.y; hi_z[i] = hi.z;
        weight[i] = float(c.weight * double(weight_scale));
        if (!cones) return;
        const EmissionCone& cone = b.cone(id).cone;
        const ConeSpread spread = ConeSpread::of(cone);
        axis_x[i] = cone.axis.x; axis_y[i] = cone.axis.y; axis_z[i] = cone.axis.z;
        cos_half[i] = spread.cos_half; sin_half[i] = spread.sin_half; cos_beta[i] = spread.cos_beta;
    }
    void copy(std::size_t i, const MetricKeys& from, std::size_t j) {
        lo_x[i] = from.lo_x[j]; lo_y[i] = from.lo_y[j]; lo_z[i] = from.lo_z[j];
        hi_x[i] = from.hi_x[j]; hi_y[i] = from.hi_y[j]; hi_z[i] = from.hi_z[j];
        weight[i] = from.weight[j];
        if (!cones) return;
        axis_x[i] = from.axis_x[j]; axis_y[i] = from.axis_y[j]; axis_z[i] = from.axis_z[j];
        cos_half[i] = from.cos_half[j]; sin_half[i] = from.sin_half[j]; cos_beta[i] = from.cos_beta[j];
    }
};

// Walter 2005 §4.1, I_C * (alpha_C^2 + c^2 (1 - cos beta_C)^2) for the
// cluster two clusters would make, in float, for the clusters [i, i +
// count) and each one's d-th successor: out[t] for cluster i + t. With
// the cone term where Cones (union_cos_beta). (The restrict-qualified
// copies of the arrays let the compiler vectorize; the box term written
// out in each loop, as a lambda over them it did not.)
template <bool Cones>
void successor_costs(const MetricKeys& k, std::size_t i, std::size_t count, std::size_t d, float* __restrict out) {
    const float* __restrict lx = k.lo_x.data() + i;
    const float* __restrict ly = k.lo_y.data() + i;
    const float* __restrict lz = k.lo_z.data() + i;
    const float* __restrict hx = k.hi_x.data() + i;
    const float* __restrict hy = k.hi_y.data() + i;
    const float* __restrict hz = k.hi_z.data() + i;
    const float* __restrict wt = k.weight.data() + i;
    if constexpr (!Cones) {
        for (std::size_t t = 0; t < count; ++t) {
            const float dx = std::max(hx[t], hx[t + d]) - std::min(lx[t], lx[t + d]);
            const float dy = std::max(hy[t], hy[t + d]) - std::min(ly[t], ly[t + d]);
            const float dz = std::max(hz[t], hz[t + d]) - std::min(lz[t], lz[t + d]);
            out[t] = (wt[t] + wt[t + d]) * (dx * dx + dy * dy + dz * dz);
        }
    } else {
        const float* __restrict ax = k.axis_x.data() + i;
        const float* __restrict ay = k.axis_y.data() + i;
        const float* __restrict az = k.axis_z.data() + i;
        const float* __restrict ch = k.cos_half.data() + i;
        const float* __restrict sh = k.sin_half.data() + i;
        const float* __restrict cb = k.cos_beta.data() + i;
        const float cone_weight = k.cone_weight;
        std::size_t t = 0;
#if defined(__SSE2__)
        // Four pairs at a time: the scalar loop's floats (union_cos_beta4).
        const __m128 weight4 = _mm_set1_ps(cone_weight), one = _mm_set1_ps(1.0f);
        const auto extent = [](const float* lo, const float* hi, std::size_t t, std::size_t d) {
            return _mm_sub_ps(_mm_max_ps(_mm_loadu_ps(hi + t), _mm_loadu_ps(hi + t + d)),
                              _mm_min_ps(_mm_loadu_ps(lo + t), _mm_loadu_ps(lo + t + d)));
        };
        const auto lanes = [&](std::size_t at) {
            return ConeLanes{_mm_loadu_ps(ax + at), _mm_loadu_ps(ay + at), _mm_loadu_ps(az + at),
                             _mm_loadu_ps(ch + at), _mm_loadu_ps(sh + at), _mm_loadu_ps(cb + at)};
        };
        for (; t + 4 <= count; t += 4) {
            const __m128 dx = extent(lx, hx, t, d), dy = extent(ly, hy, t, d), dz = extent(lz, hz, t, d);
            const __m128 size = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
            const __m128 spread = _mm_sub_ps(one, union_cos_beta4(lanes(t), lanes(t + d)));
            const __m128 weights = _mm_add_ps(_mm_loadu_ps(wt + t), _mm_loadu_ps(wt + t + d));
            _mm_storeu_ps(out + t, _mm_mul_ps(weights, _mm_add_ps(size, _mm_mul_ps(weight4, _mm_mul_ps(spread, spread)))));
        }
#endif
        for (; t < count; ++t) {
            const float dx = std::max(hx[t], hx[t + d]) - std::min(lx[t], lx[t + d]);
            const float dy = std::max(hy[t], hy[t + d]) - std::min(ly[t], ly[t + d]);
            const float dz = std::max(hz[t], hz[t + d]) - std::min(lz[t], lz[t + d]);
            const float cos_beta =
                union_cos_beta(glm::vec3(ax[t], ay[t], az[t]), ConeSpread{ch[t], sh[t], cb[t]},
                               glm::vec3(ax[t + d], ay[t + d], az[t + d]), ConeSpread{ch[t + d], sh[t + d], cb[t + d]});
            const float spread = 1.0f - cos_beta;
            out[t] = (wt[t] + wt[t + d]) * ((dx * dx + dy * dy + dz * dz) + cone_weight * (spread * spread));
        }
    }
}

// The metric of slots i and j of `k`.
float pair_cost(const MetricKeys& k, std::size_t i, std::size_t j) {
    float cost;
    const std::size_t first = std::min(i, j), d = std::max(i, j) - first;
    if (k.cones)
        successor_costs<true>(k, first, 1, d, &cost);
    else
        successor_costs<false>(k, first, 1, d, &cost);
    return cost;
}

// The cheapest partner of cluster i within kWindow positions each side,
// for a cluster within kWindow of either end of the keys, and for interior
// clusters whose window holds no finite cost.
//
// Ties go to the nearer index; between i - d and i + d to the right when
// i / d is even, else the left. Any choice at equal distance keeps the
// globally cheapest pair at the smallest distance mutual, so rounds
// progress; alternating sides makes a run of equal costs pair up as (0,1),
// (2,3), ... Always taking the lower index merged one pair per round when
// every cost is equal, which they are for coincident lights (cost 0):
// O(n^2) rounds' work and a tree as deep as n (8000 coincident lights took
// 5 s).
std::size_t best_partner_edge(const MetricKeys& k, std::size_t i) {
    const std::size_t n = k.size();
    constexpr float inf = std::numeric_limits<float>::infinity();
    float cost[2 * kWindow + 1];
    const std::size_t jb = i >= std::size_t(kWindow) ? i - kWindow : 0;
    const std::size_t je = std::min(n, i + kWindow + 1);
    for (std::size_t j = jb; j < je; ++j)
        if (j != i) cost[j - jb] = pair_cost(k, i, j);
    cost[i - jb] = inf;
    float smallest = inf;
    for (std::size_t t = 0; t < je - jb; ++t) smallest = cost[t] < smallest ? cost[t] : smallest;
    float best_cost = inf;
    std::size_t best_j = i == 0 ? 1 : i - 1;
    for (std::size_t j = jb; j < je; ++j) {
        const float c = cost[j - jb];
        if (j == i || !(c == smallest)) continue;  // NaN: never chosen
        if (c == best_cost) {
            const std::size_t dist = j > i ? j - i : i - j;
            const std::size_t best_dist = best_j > i ? best_j - i : i - best_j;
            if (dist > best_dist) continue;
            if (dist == best_dist && (j > i) != ((i / dist) % 2 == 0)) continue;
        }
        best_cost = c;
        best_j = j;
    }
    return best_j;
}

// The cheapest partner of each of the clusters [begin, end) within
// kWindow positions each side: best_partner_edge's choices, tie rule
// included. The metric is symmetric to the last bit for finite
// coordinates (max, min and the weights' sum do not depend on the order of
// their operands, except for the sign of a zero difference, which squaring
// drops; the loader refuses NaN positions; union_cos_beta is symmetric
// too), so each pair's cost is computed once. The work runs over blocks of
// clusters, and each step over a block's clusters at once, in vector
// instructions: row d of `ahead` holds the costs of the clusters from r0
// on to their d-th successors; a cluster's smallest cost is the smallest
// of its row entries and of its predecessors' entries that name it; then
// bit d - 1 of its masks says which of the partners at distance d have
// that cost.
template <bool Cones>
void best_partners(const MetricKeys& k, std::uint32_t* best, std::size_t begin, std::size_t end) {
    constexpr float inf = std::numeric_limits<float>::infinity();
    constexpr std::size_t w = kWindow;
    constexpr std::size_t kBlock = 256;         // a block's rows stay in the L1 cache
    constexpr std::size_t kRow = kBlock + w;    // clusters b0 - w .. b1 - 1
    static_assert(kWindow <= 32, "a 32-bit mask per side");
    const std::size_t n = k.size();
    alignas(64) static thread_local float ahead[w][kRow];
    alignas(64) float smallest[kBlock];
    alignas(64) std::uint32_t left_mask[kBlock], right_mask[kBlock];
    for (std::size_t b0 = begin; b0 < end; b0 += kBlock) {
        const std::size_t b1 = std::min(end, b0 + kBlock);
        // The interior clusters of the block, whose windows are whole.
        const std::size_t i0 = std::max(b0, w), i1 = std::max(i0, std::min(b1, n - std::min(n, w)));
        if (i0 < i1) {
            const std::size_t r0 = i0 - w;  // cluster of each row's first entry
            for (std::size_t d = 1; d <= w; ++d) successor_costs<Cones>(k, r0, i1 - r0, d, ahead[d - 1]);
            const std::size_t m = i1 - i0;
            for (std::size_t t = 0; t < m; ++t) smallest[t] = inf;
            // NaN never wins a comparison, so it is never the smallest.
            for (std::size_t d = 1; d <= w; ++d) {
                const float* right = ahead[d - 1] + w;    // cost of i0 + t to i0 + t + d
                const float* left = ahead[d - 1] + w - d;  // cost of i0 + t - d to i0 + t
                for (std::size_t t = 0; t < m; ++t) {
                    smallest[t] = left[t] < smallest[t] ? left[t] : smallest[t];
                    smallest[t] = right[t] < smallest[t] ? right[t] : smallest[t];
                }
            }
            for (std::size_t t = 0; t < m; ++t) left_mask[t] = right_mask[t] = 0u;
            for (std::size_t d = 1; d <= w; ++d) {
                const float* right = ahead[d - 1] + w;
                const float* left = ahead[d - 1] + w - d;
                const std::uint32_t bit = 1u << (d - 1);
                for (std::size_t t = 0; t < m; ++t) {
                    left_mask[t] |= left[t] == smallest[t] ? bit : 0u;
                    right_mask[t] |= right[t] == smallest[t] ? bit : 0u;
                }
            }
            // The nearest partner of that cost; both sides at the same
            // distance: the tie rule of best_partner_edge.
            for (std::size_t t = 0; t < m; ++t) {
                const std::size_t i = i0 + t;
                const std::uint32_t either = left_mask[t] | right_mask[t];
                if (!(smallest[t] < inf)) {  // no finite cost: the general rule
                    best[i] = static_cast<std::uint32_t>(best_partner_edge(k, i));
                    continue;
                }
                const std::size_t d = std::size_t(__builtin_ctz(either)) + 1;
                const bool left = (left_mask[t] >> (d - 1) & 1u) != 0u;
                const bool right = (right_mask[t] >> (d - 1) & 1u) != 0u;
                const bool go_right = left && right ? (i / d) % 2 == 0 : right;
                best[i] = static_cast<std::uint32_t>(go_right ? i + d : i - d);
            }
        }
        for (std::size_t i = b0; i < std::min(b1, i0); ++i)
            best[i] = static_cast<std::uint32_t>(best_partner_edge(k, i));
        for (std::size_t i = std::max(b0, i1); i < b1; ++i)
            best[i] = static_cast<std::uint32_t>(best_partner_edge(k, i));
    }
}

// The metric is computed in float, and its largest value, about the
// tree's total weight times (12 r^2 + 4 c^2) for lights within r of the
// origin, passes float's range inside the scenes the loader accepts (an
// extent of 10^18, or 10^33 per light over 10^4 lights): costs became
// infinite, ties broken by the Morton order alone, or NaN (infinity times
// a zero cone term), and the tree a chain. So the positions are scaled by
// the smallest power of two that brings the geometric part (12 r^2 + 4 c^2)
// to 2^100 or less, then the weights by the smallest that brings the whole
// to 2^120 or less: exact, and no more than overflow needs, since what it
// scales down may meet float's lower end (the costs of lights a centimetre
// apart beside a sun 1.5e11 away). Where nothing would overflow the scales
// are 1, and the trees bit for bit what they were.
void metric_scales(Build& build, glm::vec3 lo, glm::vec3 hi, double total_weight) {
    const glm::dvec3 reach = glm::max(glm::abs(glm::dvec3(lo)), glm::abs(glm::dvec3(hi)));
    const double r = std::max({reach.x, reach.y, reach.z});
    double geometric = 12.0 * r * r + 4.0 * build.cone_weight;
    if (geometric > 0x1p100) {
        const int j = (std::ilogb(geometric) - 100) / 2 + 1;  // 2^-2j brings it to 2^100 or less
        build.position_scale = float(std::ldexp(1.0, -j));
        geometric = std::ldexp(geometric, -2 * j);
    }
    const double largest = total_weight * geometric;
    if (largest > 0x1p120) build.weight_scale = float(std::ldexp(1.0, -(std::ilogb(largest) - 120 + 1)));
}

// Locally-ordered clustering of leaves given in Morton order (leaf_key);
// returns the root's build id.
std::uint32_t cluster_fast(Build& build, std::vector<std::uint32_t> active) {
    std::vector<std::uint32_t> best(active.size());
    MetricKeys keys(build), next_keys(build);
    keys.resize(active.size());
    parallel_for(active.size(), [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) keys.set(i, build, active[i]);
    });
    std::vector<std::uint32_t> next;
    std::vector<std::size_t> kept_before, merged_before;  // per thread: prefix counts
    while (active.size() > 1) {
        const std::size_t n = active.size();
        best.resize(n);
        parallel_for(n, [&](std::size_t begin, std::size_t end) {
            if (keys.cones)
                best_partners<true>(keys, best.data(), begin, end);
            else
                best_partners<false>(keys, best.data(), begin, end);
        });
        // Mutual best pairs merge (in place of their first member, so the
        // Morton order holds); the others wait for the next round. Each
        // thread counts its range's survivors and merges first, so that the
        // new clusters get the build ids, and the survivors the places, of
        // one pass in order.
        const unsigned threads = thread_count(n);
        kept_before.assign(threads + 1, 0);
        merged_before.assign(threads + 1, 0);
        parallel_for_ranges(n, [&](std::size_t begin, std::size_t end, unsigned t) {
            std::size_t kept = 0, merged = 0;
            for (std::size_t i = begin; i < end; ++i) {
                const std::size_t j = best[i];
                const bool mutual = best[j] == i;
                kept += !mutual || i < j ? 1 : 0;
                merged += mutual && i < j ? 1 : 0;
            }
            kept_before[t + 1] = kept;
            merged_before[t + 1] = merged;
        });
        for (unsigned t = 0; t < threads; ++t) {
            kept_before[t + 1] += kept_before[t];
            merged_before[t + 1] += merged_before[t];
        }
        const std::size_t merged = merged_before[threads];
        const auto first_id = static_cast<std::uint32_t>(build.all.size());
        build.all.resize(build.all.size() + merged);
        if (!build.cones.empty()) build.cones.resize(build.all.size());
        next.resize(kept_before[threads]);
        next_keys.resize(next.size());
        parallel_for_ranges(n, [&](std::size_t begin, std::size_t end, unsigned t) {
            std::size_t out = kept_before[t];
            auto id = static_cast<std::uint32_t>(first_id + merged_before[t]);
            for (std::size_t i = begin; i < end; ++i) {
                // A round's clusters come from all the rounds before it, so
                // from all over `all`: ask for the records well ahead.
                if (i + 8 < end) {
                    const char* ahead = reinterpret_cast<const char*>(&build.all[active[i + 8]]);
                    __builtin_prefetch(ahead);
                    __builtin_prefetch(ahead + sizeof(Cluster) - 1);
                }
                const std::size_t j = best[i];
                if (best[j] != i) {
                    next[out] = active[i];
                    next_keys.copy(out, keys, i);
                    ++out;
                } else if (i < j) {
                    merge_into(build, active[i], active[j], id);
                    next[out] = id;
                    next_keys.set(out, build, id);
                    ++out;
                    ++id;
                }
            }
        });
        std::swap(keys, next_keys);
        if (merged == 0) {
            // Cannot happen with the tie-breaking above (the cheapest pair in
            // any window is mutual); merge neighbours rather than loop forever.
            merge(build, active[0], active[1]);
            next.erase(next.begin(), next.begin() + 2);
            next.insert(next.begin(), static_cast<std::uint32_t>(build.all.size() - 1));
            keys.resize(next.size());
            for (std::size_t i = 0; i < next.size(); ++i) keys.set(i, build, next[i]);
        }
        active.swap(next);
    }
    return active[0];
}

std::uint32_t cluster_exact(Build& build, std::vector<std::uint32_t> active) {
    UninitializedVector<Cluster>& all = build.all;
    const float inf = std::numeric_limits<float>::infinity();
    // The metric's keys by build id: the leaves', then each merge's.
    MetricKeys keys(build);
    keys.resize(2 * active.size());
    for (const std::uint32_t id : active) keys.set(id, build, id);
    std::vector<std::uint32_t> best(active.size());
    std::vector<float> best_cost(active.size(), inf);
    auto rescan = [&](std::size_t i) {
        // A partner other than itself even where every cost is infinite or
        // NaN (merging a cluster with itself wrote past the node array).
        best_cost[i] = inf;
        best[i] = i == 0 ? 1u : 0u;
        for (std::size_t j = 0; j < active.size(); ++j) {
            if (j == i) continue;
            const float c = pair_cost(keys, active[i], active[j]);
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
        keys.set(all.size() - 1, build, static_cast<std::uint32_t>(all.size() - 1));
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
                const float c = pair_cost(keys, active[i], active[a]);
                if (c < best_cost[i]) {
                    best_cost[i] = c;
                    best[i] = static_cast<std::uint32_t>(a);
                }
            }
        }
    }
    return active[0];
}

// A cluster's cone as a LightNode stores it.
struct NodeCone {
    std::uint32_t axis_oct;
    float cos_theta_o, cos_theta_e, falloff_width;
    std::uint32_t flags;  // kNodeTwoSided or 0
};

NodeCone node_cone(const ClusterCone& c) {
    return NodeCone{c.axis_packed, c.cone.emits_everywhere() ? -1.0f : std::cos(c.cone.theta_o),
                    std::cos(c.cone.theta_e), c.cone.falloff_width, c.cone.two_sided ? gpu::kNodeTwoSided : 0u};
}

// Writes the tree of build id `root` into nodes [base_slot, base_slot + 2n - 1)
// and its lights into [base_light, base_light + n) (both already sized). The root
// takes base_slot; the two children of each interior node take the next
// two free slots when a depth-first walk, left before right, reaches it;
// lights are numbered in the walk's leaf order, so each node's lights are
// a contiguous range. The build's clusters are released once written.
//
// The walk's numbering follows from subtree sizes: a subtree of L leaves
// takes 2(L - 1) slots below its root and L lights, so its right child's
// subtree starts 2 L_left slots and L_left lights after its left child's.
// The top of the tree is cut into subtrees that way, and threads walk them.
void flatten(Build& build, std::size_t leaf_count, std::span<const gpu::Light> input, std::uint32_t root,
             std::uint32_t type, std::uint32_t base_slot, std::uint32_t base_light, LightTree& tree) {
    const UninitializedVector<Cluster>& all = build.all;
    const std::uint32_t type_bits = type << gpu::kNodeTypeShift;
    // Every node's, in a tree without cones: worked out once.
    const NodeCone everywhere = node_cone(build.everywhere);
    // Input light index -> leaf-order index, for the representatives.
    std::vector<std::uint32_t> remap(input.size(), gpu::kInvalidIndex);
    // Leaf-order light index - base_light -> input light index: the walk
    // notes each leaf's light, a pass after it copies them (reading a light
    // where the walk finds its leaf stalled it on a cache miss every leaf,
    // two thirds of its time for 10^7 lights; the pass reads ahead).
    UninitializedVector<std::uint32_t> leaf_input;
    leaf_input.resize(leaf_count);

    // A subtree to write: its root's build id and slot, the first slot of
    // the pairs below it and its first light.
    struct Item { std::uint32_t id, slot, pairs, light; };
    // Writes cluster it.id into its slot; returns whether it has children.
    auto write = [&](const Item& it) {
        const Cluster& c = all[it.id];
        gpu::LightNode& n = tree.nodes[it.slot];
        n.min_x = c.lo.x; n.min_y = c.lo.y; n.min_z = c.lo.z;
        n.max_x = c.hi.x; n.max_y = c.hi.y; n.max_z = c.hi.z;
        n.intensity_r = float(c.intensity.x);
        n.intensity_g = float(c.intensity.y);
        n.intensity_b = float(c.intensity.z);
        n.rep_light = c.rep;  // remapped to leaf order below
        const NodeCone cone = build.cones.empty() ? everywhere : node_cone(build.cones[it.id]);
        n.axis_oct = cone.axis_oct;
        n.cos_theta_o = cone.cos_theta_o;
        n.cos_theta_e = cone.cos_theta_e;
        n.falloff_width = cone.falloff_width;
        const std::uint32_t node_bits = type_bits | cone.flags;
        if (c.left == gpu::kInvalidIndex) {
            n.left = gpu::kInvalidIndex;
            n.flags = gpu::kNodeLeaf | node_bits;
            leaf_input[it.light - base_light] = c.rep;
            remap[c.rep] = it.light;
            return false;
        }
        n.left = it.pairs;
        n.flags = (c.rep_from_right ? gpu::kNodeRepFromRight : 0u) | node_bits;
        return true;
    };
    auto children = [&](const Item& it) {
        const Cluster& c = all[it.id];
        const std::uint32_t l = all[c.left].leaves;
        return std::pair<Item, Item>{{c.left, it.pairs, it.pairs + 2, it.light},
                                     {c.right, it.pairs + 1, it.pairs + 2 * l, it.light + l}};
    };

    // The top: split the largest subtree until there are enough for the
    // threads to share evenly.
    const unsigned threads = thread_count(leaf_count);
    std::vector<Item> tasks{{root, base_slot, base_slot + 1, base_light}};
    const std::size_t wanted = threads == 1 ? 1 : 16 * std::size_t(threads);
    while (tasks.size() < wanted) {
        auto largest = std::max_element(tasks.begin(), tasks.end(), [&](const Item& x, const Item& y) {
            return all[x.id].leaves < all[y.id].leaves;
        });
        if (all[largest->id].leaves < 2) break;
        const Item it = *largest;
        write(it);
        auto [left, right] = children(it);
        *largest = left;
        tasks.push_back(right);
    }
    std::atomic<std::size_t> next{0};
    auto walk = [&] {
        std::vector<Item> stack;
        for (std::size_t t; (t = next.fetch_add(1)) < tasks.size();) {
            stack.assign(1, tasks[t]);
            while (!stack.empty()) {
                const Item it = stack.back();
                stack.pop_back();
                if (!write(it)) continue;
                auto [left, right] = children(it);
                stack.push_back(right);
                stack.push_back(left);
            }
        }
    };
    run_on_threads(threads, [&](unsigned) { walk(); });
    // The clusters are written: their memory (144 bytes a light without
    // cones) goes back before the leaf-order lights' pages (48 bytes a light)
    // are first touched, so that the build's peak holds one or the other.
    release(build.all);
    release(build.cones);
    parallel_for(leaf_count, [&](std::size_t begin, std::size_t end) {
        for (std::size_t l = begin; l < end; ++l) {
            if (l + 16 < end) __builtin_prefetch(&input[leaf_input[l + 16]]);
            tree.lights[base_light + l] = input[leaf_input[l]];
        }
    });
    const std::size_t slots = 2 * leaf_count - 1;
    parallel_for(slots, [&](std::size_t begin, std::size_t end) {
        for (std::size_t s = begin; s < end; ++s) {
            if (s + 16 < end) __builtin_prefetch(&remap[tree.nodes[base_slot + s + 16].rep_light]);
            gpu::LightNode& n = tree.nodes[base_slot + s];
            n.rep_light = remap[n.rep_light];
        }
    });
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
                           double cone_scale, unsigned threads) {
    auto start = std::chrono::steady_clock::now();
    struct ThreadsOfThisBuild {
        unsigned before = build_threads;
        explicit ThreadsOfThisBuild(unsigned t) { build_threads = t; }
        ~ThreadsOfThisBuild() { build_threads = before; }
    } threads_of_this_build(threads);
    // Node indices are 32-bit: 2n - 1 nodes, and Cluster::leaves has 31 bits.
    if (lights.size() >= (std::size_t(1) << 31))
        throw std::invalid_argument("light tree: " + std::to_string(lights.size()) +
                                    " lights; at most 2^31 - 1 fit its 32-bit node indices");
    LightTree tree;
    reserve_huge(tree.lights, lights.size());
    reserve_huge(tree.nodes, 2 * lights.size());
    // Unknown types fail before any work (tree_point names the first).
    std::array<bool, gpu::kLightTypeCount> present{};
    {
        const unsigned threads = thread_count(lights.size());
        std::vector<std::array<bool, gpu::kLightTypeCount>> range_present(threads);
        std::vector<std::size_t> range_unknown(threads, lights.size());
        parallel_for_ranges(lights.size(), [&](std::size_t begin, std::size_t end, unsigned t) {
            std::array<bool, gpu::kLightTypeCount> seen{};
            for (std::size_t i = begin; i < end; ++i) {
                const std::uint32_t type = lights[i].type & gpu::kLightTypeMask;
                if (type >= gpu::kLightTypeCount) {
                    range_unknown[t] = i;
                    break;
                }
                seen[type] = true;
            }
            range_present[t] = seen;
        });
        for (unsigned t = 0; t < threads; ++t) {
            if (range_unknown[t] < lights.size()) tree_point(lights[range_unknown[t]]);
            for (std::uint32_t type = 0; type < gpu::kLightTypeCount; ++type)
                present[type] = present[type] || range_present[t][type];
        }
    }
    for (std::uint32_t type = 0; type < gpu::kLightTypeCount; ++type) {
        if (!present[type]) continue;
        Build build;
        build.seed = seed ^ type;
        UninitializedVector<Cluster>& all = build.all;
        const auto of_type = [type](const gpu::Light& l) { return (l.type & gpu::kLightTypeMask) == type; };
        // Pass 1, each thread over its range of lights: how many leaves
        // the range makes (black lights make none), and their box.
        const unsigned threads = thread_count(lights.size());
        std::vector<std::size_t> made(threads + 1, 0);  // leaves before each thread's range
        // A thread whose range is empty never runs: its box stays empty.
        std::vector<glm::vec3> range_lo(threads, glm::vec3(std::numeric_limits<float>::max()));
        std::vector<glm::vec3> range_hi(threads, glm::vec3(-std::numeric_limits<float>::max()));
        std::vector<std::size_t> range_black(threads, 0);
        std::vector<double> range_weight(threads, 0.0);
        std::vector<char> range_cones(threads, 0);
        parallel_for_ranges(lights.size(), [&](std::size_t begin, std::size_t end, unsigned t) {
            glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
            std::size_t count = 0, black = 0;
            double weight = 0.0;
            bool cones = false;
            for (std::size_t i = begin; i < end; ++i) {
                if (!of_type(lights[i])) continue;
                if (!(leaf_weight(lights[i]) > 0.0)) {
                    ++black;
                    continue;
                }
                ++count;
                weight += leaf_weight(lights[i]);
                const glm::vec3 p = tree_point(lights[i]);
                lo = glm::min(lo, p);
                hi = glm::max(hi, p);
                cones = cones || !EmissionCone::of_light(lights[i]).emits_everywhere();
            }
            made[t + 1] = count;
            range_black[t] = black;
            range_weight[t] = weight;
            range_lo[t] = lo;
            range_hi[t] = hi;
            range_cones[t] = cones ? 1 : 0;
        });
        glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
        bool has_cones = false;
        double total_weight = 0.0;
        for (unsigned t = 0; t < threads; ++t) {
            made[t + 1] += made[t];
            tree.black_lights += range_black[t];
            total_weight += range_weight[t];
            lo = glm::min(lo, range_lo[t]);
            hi = glm::max(hi, range_hi[t]);
            has_cones = has_cones || range_cones[t] != 0;
        }
        const std::size_t leaf_count = made[threads];
        if (leaf_count == 0) continue;
        // Walter 2005 §4.1 sets c, which weighs directional against spatial
        // similarity, to the scene's diagonal; here the diagonal of this
        // tree's lights. Lights that emit everywhere have no cone term.
        if (has_cones) {
            // The float difference, as always; in double where it overflows.
            const glm::vec3 diagonal = hi - lo;
            const glm::dvec3 d = glm::all(glm::lessThanEqual(glm::abs(diagonal), glm::vec3(std::numeric_limits<float>::max())))
                                     ? glm::dvec3(diagonal)
                                     : glm::dvec3(hi) - glm::dvec3(lo);
            build.cone_weight = cone_scale * cone_scale * glm::dot(d, d);
        }
        metric_scales(build, lo, hi, total_weight);
        // Pass 2: the leaves' lights in light order, each with its Morton
        // key where the fast builder will sort them.
        const bool sorted = builder == TreeBuilder::kFast;
        const bool with_axis = build.cone_weight > 0.0;
        // Finite where the box spans more than a float holds (a NaN key's
        // conversion to an integer is undefined).
        const glm::vec3 extent = glm::min(glm::max(hi - lo, glm::vec3(1e-30f)), glm::vec3(std::numeric_limits<float>::max()));
        std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
        reserve_huge(keyed, leaf_count);
        keyed.resize(leaf_count);
        parallel_for_ranges(lights.size(), [&](std::size_t begin, std::size_t end, unsigned t) {
            std::size_t out = made[t];
            for (std::size_t i = begin; i < end; ++i) {
                if (!of_type(lights[i]) || !(leaf_weight(lights[i]) > 0.0)) continue;
                std::uint64_t key = 0;
                if (sorted && with_axis) {
                    key = leaf_key(tree_point(lights[i]), cone_record(EmissionCone::of_light(lights[i])).cone.axis,
                                   lo, extent, true);
                } else if (sorted) {
                    key = leaf_key(tree_point(lights[i]), glm::vec3(0.0f), lo, extent, false);
                }
                keyed[out++] = {key, std::uint32_t(i)};
            }
        });
        // Pass 3: the leaves, build ids 0, 1, ... in that order. Sorted, the
        // windows of the first round, the merges and flatten() read
        // neighbouring clusters from neighbouring memory (the input order of
        // a light file is arbitrary).
        if (sorted) radix_sort(keyed, with_axis ? 60 : 30);  // leaf_key: 10 bits a coordinate
        reserve_huge(all, 2 * leaf_count);
        all.resize(leaf_count);
        if (has_cones) {
            reserve_huge(build.cones, 2 * leaf_count);
            build.cones.resize(leaf_count);
        }
        parallel_for(leaf_count, [&](std::size_t begin, std::size_t end) {
            for (std::size_t k = begin; k < end; ++k) {
                // The lights are read in Morton order, so from all over
                // memory: ask for one well ahead.
                if (k + 16 < end) __builtin_prefetch(&lights[keyed[k + 16].second]);
                const gpu::Light& light = lights[keyed[k].second];
                all[k] = leaf_of(light, keyed[k].second);
                if (has_cones) build.cones[k] = cone_record(EmissionCone::of_light(light));
            }
        });
        release(keyed);
        std::vector<std::uint32_t> leaves(leaf_count);
        std::iota(leaves.begin(), leaves.end(), 0u);
        std::uint32_t root = builder == TreeBuilder::kExact ? cluster_exact(build, std::move(leaves))
                                                                : cluster_fast(build, std::move(leaves));
        const auto base = static_cast<std::uint32_t>(tree.nodes.size());
        const auto base_light = static_cast<std::uint32_t>(tree.lights.size());
        tree.nodes.resize(tree.nodes.size() + 2 * leaf_count - 1);
        tree.lights.resize(tree.lights.size() + leaf_count);
        tree.roots[type] = base;
        // The light indices of each tree follow those of the one before.
        flatten(build, leaf_count, lights, root, type, base, base_light, tree);
    }
    tree.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return tree;
}

}  // namespace lc
