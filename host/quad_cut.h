// Lightcuts for a block of pixels that share one cut: the four of a 2x2
// quad (the CPU path's cut_sharing "quad") or the eight of a 4x2 octet, two
// quads side by side ("octet", and "auto" on the CPU). The block's shaded
// points refine one cut together: a cluster is split when its error bound
// exceeds relative_error times the estimate of any of them, so when
// refinement stops every cluster of the cut meets Walter's criterion at
// every one of the points, except where the cut reached max_cut, clusters
// frozen out of a full heap, and points held to the floor of
// update_weights. Each point still has its own estimate: its own
// representative contributions, shadow rays and sums. What the points
// share is the cut's bookkeeping (one list of clusters, one pass over the
// tree, one read of each node) instead of doing it for each. The cut is
// refined in passes while its list has room, and largest bound first
// through a heap, Walter's order, once the list is full (refine_all).
//
// The shared cut is the union of the points' own refinements, so it is at
// least as fine as each point's own cut, and costs more shadow rays (on the
// room at 128x128, a quad's 1.08 times a cut per pixel with a heap the tree
// cannot fill, 1.19 times one with the per-pixel heap of 64, which freezes
// more; an octet's 1.08 times a quad's); the bookkeeping it saves costs
// more than those rays (docs/results/speed.md). An octet's bounds and
// units are a quad's vector evaluations with the two quads' points in the
// lanes (quad8::join): the eight lanes of AVX2 take one cluster at eight
// points, the sixteen of AVX-512 a refinement's two children there.
#pragma once

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "cpu_kernel.h"

namespace lc::cpu {

inline constexpr uint kQuadLanes = 4u;

// A colour at each of a block's N points (four for a quad, eight for two
// quads side by side), a row per channel (r, g, b), so that the points'
// sums are one vector operation a channel.
template <uint N>
struct BlockColor {
    float c[3][N];
    vec3 at(uint p) const { return vec3(c[0][p], c[1][p], c[2][p]); }
    void set(uint p, vec3 v) { c[0][p] = v.x, c[1][p] = v.y, c[2][p] = v.z; }
    void clear() {
        for (auto& row : c)
            for (float& x : row) x = 0.0f;
    }
    // this += unit * intensity, channel by channel.
    void add_scaled(const BlockColor& unit, vec3 intensity) {
        for (uint k = 0; k < 3u; ++k)
            for (uint p = 0; p < N; ++p) c[k][p] += unit.c[k][p] * intensity[int(k)];
    }
};
using QuadColor = BlockColor<kQuadLanes>;

// One cluster of a block's cut: its node, and at each of the points its
// error bound and its representative's unit contribution (zero where the
// light is hidden or the bound is zero).
template <uint N>
struct BlockEntry {
    uint node;
    float error[N];
    BlockColor<N> unit;
};
using QuadEntry = BlockEntry<kQuadLanes>;

// The block's cut heap: `slot` lists the refinable clusters, `entries` the
// clusters the list refers to, which stay where they are while the list
// moves their 8-byte handles, and `marks` a bit per place: the clusters
// the current pass refines. Once the list has been full it is a heap, a
// max-heap on `key` (the largest ratio of a cluster's bound to a point's
// estimate; BlockCut::add).
//
// The arrays are not zeroed: each place and slot is written before it is
// read, so the pages of a heap far larger than its cuts (--cut-heap and
// --max-cut as large as the tree) are never touched, and take no memory
// (zeroed, 10^6 lights took 224 MB a thread, and 7 s of the render).
template <uint N>
class BlockHeap {
public:
    explicit BlockHeap(std::size_t slots = 0)
        : slots_(uint(slots)),
          key_(new float[slots + 2 * kPad]),
          slot_(new uint[slots + 2 * kPad]),
          entries_(new BlockEntry<N>[slots + 1]),
          free_(new uint[slots + 1]),
          marks_((slots + 31) / 32 + 1) {}
    uint slots() const { return slots_; }
    float* key() { return key_.get() + kPad; }
    uint* slot() { return slot_.get() + kPad; }
    BlockEntry<N>* entries() { return entries_.get(); }
    uint* free_slots() { return free_.get(); }
    uint* marks() { return marks_.data(); }
    // Words of marks() that a cut may have left set: BlockCut clears them
    // before its cut, and says how many its cut may have set.
    uint& dirty_words() { return dirty_words_; }

private:
    static constexpr std::size_t kPad = 64 / sizeof(float);
    uint dirty_words_ = 0;
    uint slots_;
    std::unique_ptr<float[]> key_;
    std::unique_ptr<uint[]> slot_;
    std::unique_ptr<BlockEntry<N>[]> entries_;
    std::unique_ptr<uint[]> free_;
    std::vector<uint> marks_;  // zeroed: BlockCut clears only the words its last cut used
};
using QuadHeap = BlockHeap<kQuadLanes>;
using OctetHeap = BlockHeap<2u * kQuadLanes>;

// One sample of a block: its N points (`active` bit p where point p is a
// surface to shade; points 4g to 4g + 3 are quad g's) refine one cut;
// radiance[p] is point p's estimate.
template <class Kernel, uint N>
class BlockCut {
public:
    using SurfacePoint = typename Kernel::SurfacePoint;
    using ShadeStats = typename Kernel::ShadeStats;
    using Entry = BlockEntry<N>;
    using Color = BlockColor<N>;
    static constexpr uint kGroups = N / kQuadLanes;  // quads in the block
    static_assert(N == 4u || N == 8u);

    BlockCut(Kernel& kernel, BlockHeap<N>& heap, const FrameParams& frame)
        : k_(kernel), f_(frame), key_(heap.key()), slot_(heap.slot()), entries_(heap.entries()),
          free_(heap.free_slots()), marks_(heap.marks()), capacity_(heap.slots()), dirty_words_(heap.dirty_words()) {}
    ~BlockCut() { note_marked_words(); }
    BlockCut(const BlockCut&) = delete;
    BlockCut& operator=(const BlockCut&) = delete;

    // Shades the active points of `sp`; their results in radiance[p], the
    // stats in stats[p] (cut_size, hit_max_cut and frozen are the block's).
    void shade(const SurfacePoint* sp, unsigned active, vec3* radiance, ShadeStats* stats) {
        sp_ = sp;
        active_ = active;
#if defined(__SSE2__)
        bool covered = true;
        for (uint g = 0; g < kGroups; ++g) {
            lanes_[g] = quad_lanes(k_, sp + 4u * g, active >> 4u * g & 0xFu);
            covered = covered && lanes_[g].covered;
        }
        wide_ = covered && cpu_has_avx2();
        if (wide_) {
            if constexpr (N == 4u) quad8::widen(lanes_[0], lanes8_);
            else quad8::join(lanes_[0], lanes_[1], lanes8_);
        }
        wide16_ = wide_ && cpu_has_avx512dq();
        if (wide16_) quad16::widen(lanes8_, lanes16_);
        if constexpr (N == 8u)
            for (uint p = 0; p < N; ++p)
                if (lane(p)) octet_packet_.org[p] = sp[p].p;
#endif
        for (Ahead& c : ahead_) c.parent = kInvalidIndex;
        stats_ = stats;
        size_ = 0u;
        // Slots come from the freed ones, else the next never used: the
        // order a list of every slot, 0 first, gave, without writing one
        // per slot of the capacity for every block (with --max-cut and
        // --cut-heap as large as the tree, that was the render's time).
        // No mark left by a cut that stopped early: a cut marks only
        // places in its list, below the slots it took.
        note_marked_words();
        for (uint w = 0; w < dirty_words_; ++w) marks_[w] = 0u;
        dirty_words_ = 0u;
        free_count_ = 0u;
        next_fresh_ = 0u;
        heap_mode_ = false;
        fixed_.clear();
        heap_sum_.clear();
        for (uint p = 0; p < N; ++p) {
            frozen_error_[p] = 0.0f;
            stats[p] = ShadeStats{};
        }
        cut_size_ = 0u;
        cut_indirect_ = f_.roots[kLightVpl] != kInvalidIndex ? 1u : 0u;
        frozen_ = 0u;
        hit_max_cut_ = 0u;
        root_bounds_ = 0.0f;
        float root_quarters[N] = {};  // each point's finite root bounds, its share (kShare) of each, summed
        for (uint type = 0u; type < kLightTypeCount; ++type) {
            if (f_.roots[type] == kInvalidIndex) continue;
            const LightNode& root = k_.light_nodes[f_.roots[type]];
            const uint slot = take_slot();
            Entry& e = entries_[slot];
            e.node = f_.roots[type];
            errors(root, e.error);
            e.unit.clear();
            for (uint p = 0; p < N; ++p) {
                if (lane(p) && k_.lc_cluster_needs_unit(root, e.error[p])) {
                    bool visible;
                    e.unit.set(p, k_.lc_rep_unit(sp_[p], root.rep_light, f_.min_distance2, visible, stats_[p]));
                }
            }
            for (uint p = 0; p < N; ++p)
                if (e.error[p] > 0.0f && !std::isinf(e.error[p])) root_quarters[p] += e.error[p] * kShare;
            root_bounds_ = lane_sum(root_quarters);
            if (enter(root, e)) {
                update_weights();
                add(slot);
            } else {
                free_[free_count_++] = slot;
            }
            cut_size_ += 1u;
        }
        refine_all();
        // Each point's sum over the list's clusters in list order, each
        // cluster's node read once for them all.
        Color sum = fixed_;
        for (uint i = 0; i < size_; ++i) {
            const Entry& e = entries_[slot_[i]];
            sum.add_scaled(e.unit, k_.lc_node_intensity(k_.light_nodes[e.node]));
        }
        for (uint p = 0; p < N; ++p) {
            radiance[p] = sum.at(p);
            stats[p].cut_size = cut_size_;
            stats[p].cut_indirect = cut_indirect_;
            stats[p].hit_max_cut = hit_max_cut_;
            stats[p].frozen = frozen_;
            stats[p].frozen_error = frozen_error_[p];
        }
    }

    // After shade(): the clusters the heap still holds (the cut's others
    // are leaves and frozen clusters), at the first heap_size() handles of
    // the QuadHeap's slot().
    uint heap_size() const { return size_; }

private:
    bool lane(uint p) const { return (active_ >> p & 1u) != 0u; }

    uint take_slot() { return free_count_ > 0u ? free_[--free_count_] : next_fresh_++; }
    void note_marked_words() { dirty_words_ = std::max(dirty_words_, next_fresh_ / 32u + 1u); }

    // A cluster entering the cut with its errors and units: a leaf goes to
    // the fixed sums; an interior cluster with a nonzero bound at some
    // point is refinable (true), its units counted in the heap's sums; one
    // whose bound is zero at a point contributes nothing there.
    bool enter(const LightNode& node, Entry& e) {
        const vec3 intensity = k_.lc_node_intensity(node);
        if ((node.flags & kNodeLeaf) != 0u) {
            fixed_.add_scaled(e.unit, intensity);
            return false;
        }
        bool any = false;
        for (uint p = 0; p < N; ++p) {
            if (!(e.error[p] > 0.0f)) {
                e.unit.set(p, vec3(0.0f));
                continue;
            }
            any = true;
        }
        if (!any) return false;
        heap_sum_.add_scaled(e.unit, intensity);
        __builtin_prefetch(k_.light_nodes + node.left);
        __builtin_prefetch(k_.light_nodes + node.left + 1u);
        return true;
    }

    // Each point's 1 / estimate (as luminance), which turns a bound into
    // the ratio the criterion tests. An estimate is taken as at least
    // 2^-18 of the points' mean estimate (of their roots' mean bound
    // while that mean is zero): a point whose estimate is zero would
    // otherwise weigh every bound there infinitely, and the keys could not
    // order them. Such a point is held to relative_error times that floor
    // instead of to Walter's bound > 0. The floor scales with the lights,
    // so scaling every light by a power of two leaves the keys, and so the
    // cuts, unchanged.
    // A quad's mean is the Vulkan kernel's (shaders/quadcuts.comp), bit
    // for bit: in float, each term a quarter of its estimate (four of them
    // cannot pass the float range), added (0 + 1) + (2 + 3) as its quad
    // swaps add them, and the floor kept within the normal floats; an
    // octet's adds its quads' sums of eighths. A point whose estimate is
    // not finite adds nothing to the mean.
    void update_weights() {
        // Loops over the points, one vector operation each.
        float estimate[N], quarter[N];
        for (uint p = 0; p < N; ++p)
            estimate[p] = 0.2126f * (fixed_.c[0][p] + heap_sum_.c[0][p]) +
                          0.7152f * (fixed_.c[1][p] + heap_sum_.c[1][p]) +
                          0.0722f * (fixed_.c[2][p] + heap_sum_.c[2][p]);  // lc_luminance
        unsigned counts = 0u;
        for (uint p = 0; p < N; ++p) {
            const bool finite_positive = estimate[p] > 0.0f && estimate[p] < INFINITY;
            quarter[p] = finite_positive ? estimate[p] * kShare : 0.0f;
            counts |= unsigned(finite_positive);
        }
        const float total = counts != 0u ? lane_sum(quarter) : root_bounds_;
        const float floor = std::clamp(total * 0x1p-18f, FLT_MIN, FLT_MAX);
        for (uint p = 0; p < N; ++p) weight_[p] = 1.0f / (estimate[p] < floor ? floor : estimate[p]);
    }
    static constexpr float kShare = 1.0f / float(N);  // each point's share of the block's mean
    static float quad_sum(const float* v) { return (v[0] + v[1]) + (v[2] + v[3]); }
    static float lane_sum(const float* v) {
        if constexpr (N == 4u) return quad_sum(v);
        else return quad_sum(v) + quad_sum(v + 4);
    }
    // A cluster's key: its largest ratio of bound to estimate
    // over the points, at most FLT_MAX. A NaN bound is passed over, as
    // Walter's test never refines it.
    float key_of(const Entry& e) const {
#if defined(__SSE2__)
        __m128 m = key_terms(e, 0u);
        if constexpr (N == 8u) m = _mm_max_ps(m, key_terms(e, 4u));
        m = _mm_max_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(2, 3, 0, 1)));
        m = _mm_max_ps(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
        return std::min(_mm_cvtss_f32(m), FLT_MAX);
#else
        float key = 0.0f;
        for (uint p = 0; p < N; ++p)
            if (e.error[p] > 0.0f) key = std::max(key, e.error[p] * weight_[p]);
        return std::min(key, FLT_MAX);
#endif
    }
    // key_of(e) > relative_error: whether some point's ratio is above it.
    bool above(const Entry& e) const {
#if defined(__SSE2__)
        const __m128 limit = _mm_set1_ps(f_.relative_error);
        if constexpr (N == 8u)
            return (_mm_movemask_ps(_mm_cmpgt_ps(key_terms(e, 0u), limit)) |
                    _mm_movemask_ps(_mm_cmpgt_ps(key_terms(e, 4u), limit))) != 0;
        return _mm_movemask_ps(_mm_cmpgt_ps(key_terms(e, 0u), limit)) != 0;
#else
        return key_of(e) > f_.relative_error;
#endif
    }
#if defined(__SSE2__)
    // key_of's ratios at four points from `first`: each bound times its point's
    // weight, zero where the bound is not above zero (NaN included). The
    // products are the scalar ones, and a maximum or a comparison of them
    // is exact, so key_of and above are bit for bit the loop's.
    __m128 key_terms(const Entry& e, uint first) const {
        const __m128 error = _mm_loadu_ps(e.error + first);
        return _mm_and_ps(_mm_mul_ps(error, _mm_loadu_ps(weight_ + first)), _mm_cmpgt_ps(error, _mm_setzero_ps()));
    }
#endif

    void remove_estimate(const Entry& e, Color* into) {
        const vec3 intensity = k_.lc_node_intensity(k_.light_nodes[e.node]);
        for (uint k = 0; k < 3u; ++k)
            for (uint p = 0; p < N; ++p) {
                const float estimate = e.unit.c[k][p] * intensity[int(k)];
                heap_sum_.c[k][p] -= estimate;
                if (into != nullptr) into->c[k][p] += estimate;
            }
    }

    bool marked(uint i) const { return (marks_[i >> 5] >> (i & 31u) & 1u) != 0u; }
    void set_mark(uint i, bool on) {
        marks_[i >> 5] = (marks_[i >> 5] & ~(1u << (i & 31u))) | (uint(on) << (i & 31u));
    }

    // Adds the entry in `slot` (its estimates already in heap_sum_) to the
    // cut's refinable clusters: appended, unmarked, while the list has room
    // (a list's keys are not kept: a pass computes them); the first entry
    // to find it full turns it into a heap (rekey: every key from the
    // current estimates) and is pushed with its key, as is every later one
    // (push: a full heap freezes its smallest entry).
    void add(uint slot) {
        if (!heap_mode_ && size_ < capacity_) {
            slot_[size_] = slot;
            size_ += 1u;
            return;
        }
        if (!heap_mode_) {
            heap_mode_ = true;
            rekey();
        }
        push(key_of(entries_[slot]), slot);
    }

    // Refines in passes while the list has room, then largest first. A pass
    // takes the weights (the estimates) once, marks every cluster whose key
    // is above relative_error, and refines the marked clusters lowest place
    // first; their children wait for the next pass, so when a pass marks
    // none every cluster meets the criterion at the final estimates. Once a
    // child finds the list full (add), Walter's order takes over
    // (refine_heap): a full list then spends its slots where the bounds are
    // largest. (Passes alone lost accuracy where the list fills: the stress
    // tests' million lights, relative RMSE 0.0140 -> 0.0179; with a heap
    // alone the room renders 10% slower, for its sifts and the estimates
    // taken again after every refinement: docs/results/speed.md.)
    void refine_all() {
        while (!heap_mode_) {
            update_weights();
            const uint words = (size_ + 31u) / 32u;
            bool any = false;
            for (uint w = 0; w < words; ++w) marks_[w] = 0u;
            for (uint i = 0; i < size_; ++i) {
                const bool mark = above(entries_[slot_[i]]);
                marks_[i >> 5] |= uint(mark) << (i & 31u);
                any |= mark;
            }
            if (!any) return;
            for (uint w = 0; w < words && !heap_mode_; ++w)
                while (marks_[w] != 0u && !heap_mode_) {
                    const uint i = 32u * w + uint(__builtin_ctz(marks_[w]));
                    marks_[w] &= marks_[w] - 1u;
                    if (cut_size_ >= f_.max_cut) {
                        hit_max_cut_ = 1u;
                        return;
                    }
#if defined(__SSE2__)
                    // (An octet's refinement fills the sixteen lanes alone.)
                    if constexpr (N == 4u)
                        if (wide16_) look_ahead(i, w, words);
#endif
                    refine_at(i);
                }
        }
        refine_heap();
    }

    void sift_up(uint i, float key, uint slot) {
        while (i > 0u) {
            const uint parent = (i - 1u) / 2u;
            if (key_[parent] >= key) break;
            key_[i] = key_[parent];
            slot_[i] = slot_[parent];
            i = parent;
        }
        key_[i] = key;
        slot_[i] = slot;
    }
    // The larger child's key is kept as read, not read again, and the
    // heap's size and arrays are locals: through the stores into the
    // arrays the compiler would otherwise read size_ again every level.
    void sift_down(uint i, float key, uint slot) {
        float* const keys = key_;
        uint* const slots = slot_;
        const uint size = size_;
        while (true) {
            uint child = 2u * i + 1u;
            if (child >= size) break;
            float child_key = keys[child];
            if (child + 1u < size) {
                const float right = keys[child + 1u];
                const bool right_larger = right > child_key;
                child += uint(right_larger);
                child_key = right_larger ? right : child_key;
            }
            if (child_key <= key) break;
            keys[i] = child_key;
            slots[i] = slots[child];
            i = child;
        }
        keys[i] = key;
        slots[i] = slot;
    }
    // Pushes the entry in `slot` (its estimates already in heap_sum_) with
    // `key`; into a full heap it freezes the entry with the smallest key,
    // this one included, and frees its slot.
    void push(float key, uint slot) {
        if (size_ < capacity_) {
            size_ += 1u;
            sift_up(size_ - 1u, key, slot);
            return;
        }
        frozen_ += 1u;
        const uint smallest = heap_smallest(key_, size_ / 2u, size_, key);
        const uint leaving = smallest == kInvalidIndex ? slot : slot_[smallest];
        for (uint p = 0; p < N; ++p) frozen_error_[p] += entries_[leaving].error[p];
        remove_estimate(entries_[leaving], &fixed_);
        if (smallest == kInvalidIndex) {
            free_[free_count_++] = slot;
            return;
        }
        free_[free_count_++] = leaving;
        sift_up(smallest, key, slot);
    }

    // Every key again from the current estimates, and the heap rebuilt.
    void rekey() {
        update_weights();
        for (uint i = 0; i < size_; ++i) key_[i] = key_of(entries_[slot_[i]]);
        for (uint i = size_ / 2u; i-- > 0u;) sift_down(i, key_[i], slot_[i]);
    }

    void refine_heap() {
        bool fresh_keys = false;
        update_weights();
        while (size_ > 0u) {
            const float top_key = key_of(entries_[slot_[0]]);
            if (!(top_key > f_.relative_error)) {
                // The keys were computed from the estimates of their time;
                // the cut is final only if no cluster exceeds the criterion
                // at today's.
                if (fresh_keys) return;
                rekey();
                fresh_keys = true;
                continue;
            }
            if (cut_size_ >= f_.max_cut) {
                hit_max_cut_ = 1u;
                return;
            }
            fresh_keys = false;
            refine_top();
        }
    }

    // lc_cluster_error of `node` at the block's points (zero at inactive
    // ones): for an octet in the eight lanes of AVX2 (both quads' points,
    // the cluster twice), else a quad's four lanes at a time.
    void errors(const LightNode& node, float* out) {
        if (Kernel::tightest_bound) {  // benchmarks only (host/cpu_kernel.h)
            for (uint p = 0; p < N; ++p)
                out[p] = lane(p) ? k_.tightest_error(sp_[p], node, f_.min_distance2) : 0.0f;
            return;
        }
#if defined(__SSE2__)
        if constexpr (N == 8u) {
            if (wide_ && quad_bound_covers(node)) {
                quad8::quad_pair_errors(k_, lanes8_, node, node, f_.min_distance2, out, out + 4);
                return;
            }
        }
        for (uint g = 0; g < kGroups; ++g)
            if (!quad_errors(k_, lanes_[g], sp_ + 4u * g, node, f_.min_distance2, out + 4u * g))
                for (uint p = 4u * g; p < 4u * g + 4u; ++p)
                    out[p] = lane(p) ? k_.lc_cluster_error(sp_[p], sp_[p].mat, node, f_.min_distance2) : 0.0f;
        return;
#endif
        for (uint p = 0; p < N; ++p)
            out[p] = lane(p) ? k_.lc_cluster_error(sp_[p], sp_[p].mat, node, f_.min_distance2) : 0.0f;
    }

    // errors() of both children of a refinement: in one evaluation where
    // quad_errors covers both, a quad's in the eight lanes of AVX2, an
    // octet's in the sixteen of AVX-512.
    void child_errors(const LightNode& a, const LightNode& b, float* errors_a, float* errors_b) {
#if defined(__SSE2__)
        if (!Kernel::tightest_bound && wide_ && quad_bound_covers(a) && quad_bound_covers(b)) {
            if constexpr (N == 4u) {
                quad8::quad_pair_errors(k_, lanes8_, a, b, f_.min_distance2, errors_a, errors_b);
                return;
            } else if (wide16_) {
                // Both children at both quads: (a, a, b, b) over lanes16_'s
                // (quad 0, quad 1, quad 0, quad 1).
                quad16::octet_pair_errors(k_, lanes16_, a, b, f_.min_distance2, errors_a, errors_b);
                return;
            }
        }
#endif
        errors(a, errors_a);
        errors(b, errors_b);
    }

    // What split needs of a refinement, found ahead of it (look_ahead): the
    // children's errors and, where has_units, the new representative's
    // units, directions and ray lengths as quad_light_units gives them.
    struct Ahead {
        uint parent;  // the refined node, kInvalidIndex where none
        float kept[N], fresh[N];
        bool has_units;
        vec3 units[N], wi[N];
        float t_max[N];
    };

    // The children's errors of `parent`'s refinement into errors_kept and
    // errors_fresh, and the rest of what look_ahead found for it; nullptr
    // (nothing written) where it found nothing.
    const Ahead* take_ahead(uint parent, float* errors_kept, float* errors_fresh) {
        for (Ahead& c : ahead_) {
            if (c.parent != parent) continue;
            for (uint p = 0; p < N; ++p) errors_kept[p] = c.kept[p], errors_fresh[p] = c.fresh[p];
            c.parent = kInvalidIndex;
            return &c;
        }
        return nullptr;
    }

#if defined(__SSE2__)
    // Before a pass refines place `at` (its mark in word `w` already
    // taken): the children's errors of that refinement and of the pass's
    // next one, in one evaluation of sixteen lanes (quad16), and their new
    // representatives' units in one of eight (quad8), kept in ahead_ for
    // split. Their values do not depend on when they are computed (the
    // points, nodes and lights do not change during a cut), so the cut is
    // the one refined pair by pair; this halves the evaluations of a pass's
    // bounds and units where AVX-512 has the lanes. A quad's only.
    void look_ahead(uint at, uint w, uint words) {
        const uint parent = entries_[slot_[at]].node;
        if (ahead_[0].parent == parent || ahead_[1].parent == parent) return;
        uint next = kInvalidIndex;
        for (uint v = w; v < words; ++v)
            if (marks_[v] != 0u) {
                next = 32u * v + uint(__builtin_ctz(marks_[v]));
                break;
            }
        if (next == kInvalidIndex || Kernel::tightest_bound) return;
        const uint parents[2] = {parent, entries_[slot_[next]].node};
        const LightNode* nodes[4];
        for (uint k = 0; k < 2u; ++k) {
            const LightNode& node = k_.light_nodes[parents[k]];
            const bool right_shares = (node.flags & kNodeRepFromRight) != 0u;
            nodes[2u * k] = &k_.light_nodes[right_shares ? node.left + 1u : node.left];
            nodes[2u * k + 1u] = &k_.light_nodes[right_shares ? node.left : node.left + 1u];
        }
        for (const LightNode* node : nodes)
            if (!quad_bound_covers(*node)) return;
        float errors[4][N];
        quad16::quad_four_errors(k_, lanes16_, nodes, f_.min_distance2, errors);
        // And both new representatives' units, in the eight lanes of AVX2.
        vec3 units[2][N], wi[2][N];
        float t_max[2][N];
        const bool has_units = quad8::quad_light_units_pair(k_, lanes8_, k_.lights[nodes[1]->rep_light],
                                                            k_.lights[nodes[3]->rep_light], f_.min_distance2,
                                                            units, wi, t_max);
        for (uint k = 0; k < 2u; ++k) {
            Ahead& c = ahead_[k];
            c.parent = parents[k];
            c.has_units = has_units;
            for (uint p = 0; p < N; ++p) {
                c.kept[p] = errors[2u * k][p], c.fresh[p] = errors[2u * k + 1u][p];
                if (!has_units) continue;
                c.units[p] = units[k][p];
                if (units[k][p] == vec3(0.0f)) continue;  // wi and t_max not written
                c.wi[p] = wi[k][p], c.t_max[p] = t_max[k][p];
            }
        }
    }
#endif

    // What refine_top and refine_at share: the cluster in `kept_slot` is
    // replaced by its children. The child that keeps the parent's
    // representative keeps its units and the slot; the other one, in the
    // returned slot, gets its units from one new shadow ray per point. Each
    // child enters the cut (enter); a slot whose child does not is freed.
    struct Children {
        uint fresh_slot;
        bool has_kept, has_fresh;
    };
    Children split(uint kept_slot) {
        Entry& kept = entries_[kept_slot];
        const uint parent = kept.node;
        const LightNode& node = k_.light_nodes[parent];
        remove_estimate(kept, nullptr);
        const bool right_shares = (node.flags & kNodeRepFromRight) != 0u;
        const uint kept_index = right_shares ? node.left + 1u : node.left;
        const uint fresh_index = right_shares ? node.left : node.left + 1u;
        const LightNode& kept_node = k_.light_nodes[kept_index];
        const LightNode& fresh_node = k_.light_nodes[fresh_index];
        const uint fresh_slot = take_slot();
        Entry& fresh = entries_[fresh_slot];
        kept.node = kept_index;
        fresh.node = fresh_index;
        const Ahead* ahead = N == 4u ? take_ahead(parent, kept.error, fresh.error) : nullptr;  // look_ahead is a quad's
        if (ahead == nullptr) child_errors(kept_node, fresh_node, kept.error, fresh.error);
        const bool fresh_leaf = (fresh_node.flags & kNodeLeaf) != 0u;
        // The new representative's shadow ray from each point, all traced
        // together (lc_visible4 or lc_visible8: each ray tested on its own
        // at every node it enters, the nodes read and the branches taken
        // once; a packet bounding the four rays with one box test ran
        // slower, as the points' spread widens its bounds).
        const Light& rep = k_.lights[fresh_node.rep_light];
        std::conditional_t<N == 4u, RayPacket4, RayPacket8> rays;
        bool traced = false;
#if defined(__SSE2__)
        if constexpr (N == 8u) traced = wide_ && octet_rays(rep, fresh_leaf, fresh);
#endif
        if (!traced) {
            vec3 units[N], wi[N];
            float t_max[N];
            bool lanes_done = false;
            if (ahead != nullptr && ahead->has_units) {
                for (uint p = 0; p < N; ++p) {
                    units[p] = ahead->units[p];
                    if (units[p] != vec3(0.0f)) wi[p] = ahead->wi[p], t_max[p] = ahead->t_max[p];
                }
                lanes_done = true;
            }
#if defined(__SSE2__)
            if constexpr (N == 4u) {
                if (!lanes_done) lanes_done = quad_light_units(k_, lanes_[0], rep, f_.min_distance2, units, wi, t_max);
            } else {
                lanes_done = quad_light_units(k_, lanes_[0], rep, f_.min_distance2, units, wi, t_max) &&
                             quad_light_units(k_, lanes_[1], rep, f_.min_distance2, units + 4, wi + 4, t_max + 4);
            }
#endif
            // The new representative's rays, a point's in its lane: a
            // quad's four in a packet of four, an octet's eight in one of
            // eight.
            for (uint p = 0; p < N; ++p) {
                fresh.unit.set(p, vec3(0.0f));
                if (!lane(p) || !(fresh_leaf || fresh.error[p] > 0.0f)) continue;
                // lc_rep_unit, on the unit found for the points at once
                // where quad_light_units covers the light.
                if (!lanes_done) units[p] = k_.lc_light_unit(sp_[p], rep, f_.min_distance2, wi[p], t_max[p]);
                if (!(units[p].x + units[p].y + units[p].z > 0.0f)) continue;
                stats_[p].shadow_rays += 1u;
                rays.org[p] = sp_[p].p;
                rays.dir[p] = wi[p];
                rays.t_max[p] = t_max[p];
                rays.valid |= 1u << p;
            }
            unsigned visible = 0u;
            if (rays.valid != 0u) {
                if constexpr (N == 4u) visible = k_.lc_visible4(rays);
                else visible = k_.lc_visible8(rays);
            }
            for (uint p = 0; p < N; ++p)
                if ((visible >> p & 1u) != 0u) fresh.unit.set(p, units[p]);
        }
        const bool has_kept = enter(kept_node, kept);
        const bool has_fresh = enter(fresh_node, fresh);
        if (!has_kept) free_[free_count_++] = kept_slot;
        if (!has_fresh) free_[free_count_++] = fresh_slot;
        cut_size_ += 1u;
        if (k_.lc_node_type(node) == kLightVpl) cut_indirect_ += 1u;
        return {fresh_slot, has_kept, has_fresh};
    }

#if defined(__SSE2__)
    // split's new representative at an octet's points where quad8 covers
    // it (false, nothing done, where not): the units at the eight points in
    // the lanes of AVX2 (the light twice, over both quads' points), the
    // rays traced as one packet of eight, and the visible units into
    // fresh.unit, straight from the lanes.
    bool octet_rays(const Light& rep, bool fresh_leaf, Entry& fresh) {
        alignas(32) float v[7][8];
        unsigned lit;
        if (!quad8::quad_light_unit_lanes(k_, lanes8_, rep, rep, f_.min_distance2, v, lit)) return false;
        // A ray where the point is active, the child's bound there is above
        // zero (or the child is a leaf) and the unit is (lc_rep_unit's
        // sum test).
        const __m128 zero = _mm_setzero_ps();
        const __m128 leaf = fresh_leaf ? _mm_castsi128_ps(_mm_set1_epi32(-1)) : zero;
        unsigned want = 0u;
        for (uint h = 0; h < 2u; ++h) {
            const __m128 sum = _mm_add_ps(_mm_add_ps(_mm_loadu_ps(v[0] + 4u * h), _mm_loadu_ps(v[1] + 4u * h)),
                                          _mm_loadu_ps(v[2] + 4u * h));
            const __m128 bound = _mm_or_ps(leaf, _mm_cmpgt_ps(_mm_loadu_ps(fresh.error + 4u * h), zero));
            want |= unsigned(_mm_movemask_ps(_mm_and_ps(bound, _mm_cmpgt_ps(sum, zero)))) << 4u * h;
        }
        want &= active_ & lit;
        RayPacket8& rays = octet_packet_;  // its origins set by shade()
        for (unsigned todo = want; todo != 0u; todo &= todo - 1u) {
            const uint p = uint(__builtin_ctz(todo));
            stats_[p].shadow_rays += 1u;
            rays.dir[p] = vec3(v[3][p], v[4][p], v[5][p]);
            rays.t_max[p] = v[6][p];
        }
        rays.valid = want;
        const unsigned visible = want != 0u ? k_.lc_visible8(rays) : 0u;
        const __m128i bits = _mm_setr_epi32(1, 2, 4, 8);
        for (uint h = 0; h < 2u; ++h) {
            const __m128 shown = _mm_castsi128_ps(
                _mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(int(visible >> 4u * h)), bits), bits));
            for (uint k = 0; k < 3u; ++k)
                _mm_storeu_ps(fresh.unit.c[k] + 4u * h, _mm_and_ps(_mm_loadu_ps(v[k] + 4u * h), shown));
        }
        return true;
    }
#endif

    // Replaces the cluster at place `at` of the list by its children
    // (split): the kept child keeps the place (unmarked), the other one is
    // added. Where the kept child leaves the cut (a leaf, or zero bounds),
    // the list's last entry takes its place, mark and all.
    void refine_at(uint at) {
        const uint kept_slot = slot_[at];
        const auto [fresh_slot, has_kept, has_fresh] = split(kept_slot);
        if (!has_kept) {
            size_ -= 1u;
            if (at != size_) {
                slot_[at] = slot_[size_];
                set_mark(at, marked(size_));
                set_mark(size_, false);
            }
        }
        if (has_fresh) add(fresh_slot);
    }

    // Replaces the cluster at the top of the heap by its children (split).
    void refine_top() {
        const uint kept_slot = slot_[0];
        const auto [fresh_slot, has_kept, has_fresh] = split(kept_slot);
        const Entry &kept = entries_[kept_slot], &fresh = entries_[fresh_slot];
        update_weights();
        float key_a = has_kept ? key_of(kept) : 0.0f, key_b = has_fresh ? key_of(fresh) : 0.0f;
        uint slot_a = kept_slot, slot_b = fresh_slot;
        bool has_a = has_kept, has_b = has_fresh;
        if (has_b && (!has_a || key_b > key_a)) {
            std::swap(key_a, key_b);
            std::swap(slot_a, slot_b);
            std::swap(has_a, has_b);
        }
        // The larger child takes the parent's place in the heap and sinks;
        // the smaller one is pushed.
        if (has_a) {
            sift_down(0u, key_a, slot_a);
        } else {
            size_ -= 1u;
            if (size_ > 0u) sift_down(0u, key_[size_], slot_[size_]);
        }
        if (has_b) push(key_b, slot_b);
    }

    Kernel& k_;
    const FrameParams& f_;
    float* key_;
    uint* slot_;
    Entry* entries_;
    uint* free_;
    uint* marks_;  // refine_all's marks, a bit per place in the list
    bool heap_mode_ = false;  // the list is a heap (add), refined largest first
    uint capacity_;
    uint size_ = 0u;
    uint free_count_ = 0u;
    uint next_fresh_ = 0u;  // slots below it have been taken in this cut
    uint& dirty_words_;     // the heap's
    const SurfacePoint* sp_ = nullptr;
    unsigned active_ = 0u;
#if defined(__SSE2__)
    QuadLanes lanes_[kGroups];  // each quad's points
    quad8::QuadLanes lanes8_;  // a quad's lanes_ in both halves (child_errors); an octet's quads' side by side
    bool wide_ = false;        // lanes8_ is set and used
    quad16::QuadLanes lanes16_;  // lanes_ in all four quarters (look_ahead)
    bool wide16_ = false;        // lanes16_ is set and used
#endif
    Ahead ahead_[2];  // look_ahead
    RayPacket8 octet_packet_;  // octet_rays' rays, from the points (set by shade)
    ShadeStats* stats_ = nullptr;
    Color fixed_;     // each point's final estimates: leaves and frozen clusters
    Color heap_sum_;  // ... and the running sum of the heap's
    float weight_[N];   // update_weights
    float frozen_error_[N];
    float root_bounds_ = 0.0f;  // a quarter of the roots' finite bounds, summed over the points (update_weights)
    uint cut_size_ = 0u, cut_indirect_ = 0u, frozen_ = 0u, hit_max_cut_ = 0u;
};

template <class Kernel>
using QuadCut = BlockCut<Kernel, kQuadLanes>;
template <class Kernel>
using OctetCut = BlockCut<Kernel, 2u * kQuadLanes>;

}  // namespace lc::cpu
