// The shared kernel headers (shaders/lc_shared/*.h) compiled as C++ for the CPU
// reference: the same intersection, traversal, shading, bound and cut code
// the Vulkan kernels run, here as member functions reading host arrays.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string_view>
#include <type_traits>
#include <vector>

#include <glm/glm.hpp>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "lightcuts/render.h"
#include "pair_bound.h"
#include "wide_trace.h"
#include "lc_shared/types.h"
#include "lc_shared/color.h"
#include "lc_shared/octahedral.h"
#include "lc_shared/glsl_compat.h"

namespace lc::cpu {

using namespace glm;
using namespace lc::gpu;

// Whether the environment variable `name` is "1" (the benchmarks' switches).
inline bool environment_flag(const char* name) {
    const char* value = std::getenv(name);
    return value != nullptr && std::string_view(value) == "1";
}

// GLSL's abs for the kernels, as GPUs do it: the sign bit cleared, one
// instruction. glm's abs is x >= 0 ? x : -x, which keeps -0 and so compiles
// to a compare and a branch per component; in the cluster bound those
// branches follow the box's side of the point and were mispredicted.
// Found before glm's by unqualified lookup in the kernel structs below (and
// preferred to its template for vectors).
inline float abs(float x) { return std::fabs(x); }
inline vec2 abs(vec2 v) { return vec2(std::fabs(v.x), std::fabs(v.y)); }
inline vec3 abs(vec3 v) { return vec3(std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)); }

// Ray tracing only: BVH traversal and triangle intersection.
struct TraceKernel {
    const BvhNode* bvh_nodes = nullptr;
    const Triangle* triangles = nullptr;

#define LC_BVH_NODE(i) bvh_nodes[i]
#define LC_TRIANGLE(i) triangles[i]
#include "lc_shared/trace.h"
#undef LC_BVH_NODE
#undef LC_TRIANGLE
};

// The Vulkan kernels' shadow-ray traversal, through the 4-wide tree they
// read (Bvh::kernel_nodes), run on the CPU: the tests compare it with brute
// force. The renderer's own shadow rays use host/wide_trace.h.
struct Trace4Kernel {
    const BvhNode* bvh_nodes = nullptr;
    const Triangle* triangles = nullptr;
    const Bvh4Node* bvh4_nodes = nullptr;
    std::uint64_t* trips = nullptr;  // where given, counts the trips round the walk's loop (bench/embree_rays)

    uvec4 bvh4_word(uint i, uint k) const {
        uvec4 w;
        std::memcpy(&w, reinterpret_cast<const char*>(bvh4_nodes + i) + sizeof(uvec4) * k, sizeof w);
        return w;
    }

#define LC_BVH_NODE(i) bvh_nodes[i]
#define LC_TRIANGLE(i) triangles[i]
#define LC_BVH4_WORD(i, k) bvh4_word(i, k)
#define LC_ON_TRIP() (trips != nullptr ? void(++*trips) : void())
#include "lc_shared/trace.h"
#undef LC_BVH_NODE
#undef LC_TRIANGLE
#undef LC_BVH4_WORD
#undef LC_ON_TRIP
};

// Texture lookups and materials at a point only (lc_shared/textures.h): what
// the host needs to sample textured emitters.
struct TextureKernel {
    const Material* materials = nullptr;
    const TriangleUvs* uvs = nullptr;
    const TextureInfo* textures = nullptr;
    const uint* texels = nullptr;
    static constexpr bool kEnableTextures = true;

#define LC_MATERIAL(i) materials[i]
#define LC_UVS(i) uvs[i]
#define LC_TEXTURE(i) textures[i]
#define LC_TEXEL(i) texels[i]
#include "lc_shared/textures.h"
#undef LC_MATERIAL
#undef LC_UVS
#undef LC_TEXTURE
#undef LC_TEXEL
};

// The CPU's cut-heap entry: the GPU's CutEntry (node and visibility bit,
// error bound) and the representative's unit contribution, which the GPU
// evaluates again instead of storing (lc_shared/lightcuts.h, lc_entry_unit).
struct HeapEntry {
    uint node;
    float error;
    vec3 unit;
};

// The CPU's cut heap, stored as two arrays: the entries' errors, which the
// heap's compares and the search for the smallest read, side by side, and
// the rest of each entry (16 bytes). A child pair's errors are then one
// 8-byte load and the search reads whole vectors, where 20-byte entries
// made it gather one float at a time.
//
// Each thread has its own heap, and no cache line of it is shared with
// anything else: both arrays keep a cache line of padding before and after
// the slots. The threads' heaps were once allocated back to back, the top
// of one in the line that held the other's last slots, and rendering on two
// threads ran at 1.4 to 1.7 times one thread's speed; padded, at 1.9 to 2.2
// times (docs/results/speed.md).
//
// The arrays are not zeroed (as BlockHeap's, host/quad_cut.h): the cut
// writes each slot before it reads it, so a heap far larger than its cuts
// (--cut-heap as large as the tree) takes only the pages its cuts touch.
struct HeapPayload {
    uint node;
    vec3 unit;
};
static_assert(std::is_trivially_default_constructible_v<HeapPayload>, "new HeapPayload[n] leaves the slots unwritten");

class CutHeap {
public:
    explicit CutHeap(std::size_t slots = 0)
        : slots_(uint(slots)),
          error_(new float[slots + 2 * kErrorPad]),
          payload_(new HeapPayload[slots + 2 * kPayloadPad]) {}
    uint slots() const { return slots_; }
    float* error() { return error_.get() + kErrorPad; }
    HeapPayload* payload() { return payload_.get() + kPayloadPad; }

private:
    static constexpr std::size_t kCacheLine = 64;
    static constexpr std::size_t kErrorPad = kCacheLine / sizeof(float);
    static constexpr std::size_t kPayloadPad = kCacheLine / sizeof(HeapPayload);
    uint slots_;
    std::unique_ptr<float[]> error_;
    std::unique_ptr<HeapPayload[]> payload_;
};

// lc_heap_smallest's answer on the CPU's heap (lc_shared/lightcuts.h): the
// first slot of [from, to) whose error is the smallest, if that error is
// below `bound`; kInvalidIndex if none is. A full heap is searched at most
// refinements once cuts outgrow it (K = 64 against cuts of 150 to 250 on
// the shipped room), and the scalar loop's compares form one chain, about
// four cycles a slot; here the minimum is taken eight slots at a time in
// two chains of SSE lanes, then its first slot is looked up.
inline uint heap_smallest(const float* errors, uint from, uint to, float bound) {
    float best = bound;
    uint i = from;
#if defined(__SSE2__)
    // _mm_min_ps(x, m) is x < m ? x : m, the scalar test's choice lane by
    // lane (a NaN error is passed over, as there).
    __m128 lo = _mm_set1_ps(bound), hi = lo;
    for (; i + 8u <= to; i += 8u) {
        lo = _mm_min_ps(_mm_loadu_ps(errors + i), lo);
        hi = _mm_min_ps(_mm_loadu_ps(errors + i + 4u), hi);
    }
    __m128 m = _mm_min_ps(lo, hi);
    m = _mm_min_ps(m, _mm_movehl_ps(m, m));
    m = _mm_min_ss(m, _mm_shuffle_ps(m, m, 1));
    best = _mm_cvtss_f32(m);
#endif
    for (; i < to; ++i) best = errors[i] < best ? errors[i] : best;
    if (!(best < bound)) return kInvalidIndex;
    for (uint j = from;; ++j)
        if (errors[j] == best) return j;
}

// A shadow ray as the kernels cast it (origin, unit direction, length).
struct ShadowRayRecord {
    vec3 org;
    vec3 dir;
    float t_max;
};

// A packet of shadow rays in a ray log: its first ray and how many.
struct RayPacketRecord {
    std::size_t first;
    uint count;
};

// Everything a pixel needs. `heap_error` and `heap_payload` hold the cut
// heap's `heap_slots` entries (a CutHeap of LightTree::cut_heap_slots
// slots, bind_heap); one kernel object per thread (make_shade_kernel binds
// one to a scene). kRecordRays: every shadow ray is also appended to `*ray_log`
// (bench/embree_rays traces lightcuts' rays again with other tracers); the
// renderer's kernel, ShadeKernel, has no such code.
template <bool kRecordRays>
struct BasicShadeKernel {
    const BvhNode* bvh_nodes = nullptr;
    const WideBvhNode* wide_nodes = nullptr;  // the same tree 4 wide, for shadow rays (none: bvh_nodes)
    const WideLeaf* wide_leaves = nullptr;    // its leaves' triangles
    const WideBvhNode8* wide8_nodes = nullptr;  // the same tree 8 wide, where the CPU has AVX2
    const WideLeaf* wide8_leaves = nullptr;     // ... and its leaves
    const Triangle* triangles = nullptr;
    const TriangleNormals* normals = nullptr;
    const TriangleUvs* uvs = nullptr;
    const Material* materials = nullptr;
    const TextureInfo* textures = nullptr;
    const uint* texels = nullptr;
    const Light* lights = nullptr;
    const LightNode* light_nodes = nullptr;
    const float* environment = nullptr;  // RGB texels of the environment map
    float vpl_min_distance2 = 0.0f;      // FrameParams.vpl_min_distance2
    float* heap_error = nullptr;          // the cut heap (CutHeap), heap_slots entries
    HeapPayload* heap_payload = nullptr;
    uint heap_slots = 1u;
    std::vector<ShadowRayRecord>* ray_log = nullptr;  // kRecordRays only
    // kRecordRays only, where set: each packet of lc_visible4 or
    // lc_visible8 (the rays a quad's or an octet's points cast to one light
    // together) as its first ray in ray_log and its count, so that the
    // packets can be traced again as the renderer traces them.
    std::vector<RayPacketRecord>* packet_log = nullptr;

    // The CPU reference always runs the full kernel; the GPU switches parts
    // off only where the scene cannot use them.
    static constexpr bool kEnableGgx = true;
    static constexpr bool kEnableShadows = true;
    static constexpr bool kEnableOriented = true;
    static constexpr bool kEnableTextures = true;
    static constexpr bool kEnableDisney = true;
    static constexpr bool kEnableSheen = true;
    static constexpr bool kEnableClearcoat = true;
    // Benchmarks only: replace the Disney BRDF's non-diffuse lobe bounds by
    // the seed report's constant 1 (lc_disney_bound), to measure the cut
    // size the lobe bounds save (docs/results/disney.md). Not conservative;
    // LC_CPU_SEED_LOBE_BOUND=1, read once when the program starts, so that
    // renders on several threads never write it (a data race, ThreadSanitizer
    // found, while it was set by every render).
    static inline const bool seed_lobe_bound = environment_flag("LC_CPU_SEED_LOBE_BOUND");
    // Benchmarks only: bound a refinement's children by the tightest bound
    // of Walter's form instead (tightest_error below), to measure how much
    // smaller the cuts could get with better bounds (docs/results/speed.md).
    // It visits every light of the cluster, so it is far too slow to render
    // with; LC_CPU_TIGHTEST_BOUND=1, read as the one above.
    static inline const bool tightest_bound = environment_flag("LC_CPU_TIGHTEST_BOUND");

#define LC_BVH_NODE(i) bvh_nodes[i]
#define LC_TRIANGLE(i) triangles[i]
#define LC_NORMALS(i) normals[i]
#define LC_MATERIAL(i) materials[i]
#define LC_UVS(i) uvs[i]
#define LC_TEXTURE(i) textures[i]
#define LC_TEXEL(i) texels[i]
#define LC_LIGHT(i) lights[i]
#define LC_LIGHT_NODE(i) light_nodes[i]
#define LC_ENVIRONMENT_TEXEL(i) vec3(environment[3u * (i)], environment[3u * (i) + 1u], environment[3u * (i) + 2u])
#define LC_VPL_MIN_DISTANCE2 vpl_min_distance2
#define LC_HEAP_LOAD(i) heap_load(i)
#define LC_HEAP_STORE(i, e) heap_store(i, e)
#define LC_HEAP_CAPACITY heap_slots
#define LC_HEAP_KEEPS_UNITS
#define LC_HEAP_SMALLEST(from, to, bound) heap_smallest(heap_error, from, to, bound)
// Both children of a node pushed on the heap, 128 bytes: the profile
// showed the node reads in lc_add_cluster stalling on cache misses.
#define LC_PREFETCH_LIGHT_NODES(i) \
    (__builtin_prefetch(light_nodes + (i)), __builtin_prefetch(light_nodes + (i) + 1u))
#define LC_ON_SHADOW_RAY(o, d, t) \
    if constexpr (kRecordRays) ray_log->push_back({o, d, t})
#define LC_SEED_LOBE_BOUND seed_lobe_bound
#define LC_TRACE_ANY(o, d, t) lc_trace_shadow(o, d, t)
#define LC_TRACE_CLOSEST(o, d, t_max, t, b1, b2) lc_trace_first_hit(o, d, t_max, t, b1, b2)
#define LC_CHILD_ERRORS(sp, m, left, right, d2) lc_child_errors(sp, m, left, right, d2)
#include "lc_shared/trace.h"
#include "lc_shared/textures.h"
#include "lc_shared/shading.h"
#include "lc_shared/brute.h"
#include "lc_shared/sampling.h"
#include "lc_shared/lightcuts.h"
#undef LC_BVH_NODE
#undef LC_TRIANGLE
#undef LC_NORMALS
#undef LC_MATERIAL
#undef LC_UVS
#undef LC_TEXTURE
#undef LC_TEXEL
#undef LC_LIGHT
#undef LC_LIGHT_NODE
#undef LC_ENVIRONMENT_TEXEL
#undef LC_VPL_MIN_DISTANCE2
#undef LC_HEAP_LOAD
#undef LC_HEAP_STORE
#undef LC_HEAP_CAPACITY
#undef LC_HEAP_KEEPS_UNITS
#undef LC_HEAP_SMALLEST
#undef LC_PREFETCH_LIGHT_NODES
#undef LC_ON_SHADOW_RAY
#undef LC_SEED_LOBE_BOUND
#undef LC_TRACE_ANY
#undef LC_TRACE_CLOSEST
#undef LC_CHILD_ERRORS

    HeapEntry heap_load(uint i) const { return HeapEntry{heap_payload[i].node, heap_error[i], heap_payload[i].unit}; }
    void heap_store(uint i, const HeapEntry& e) {
        heap_error[i] = e.error;
        heap_payload[i] = HeapPayload{e.node, e.unit};
    }
    void bind_heap(CutHeap& heap) {
        heap_error = heap.error();
        heap_payload = heap.payload();
        heap_slots = heap.slots();
    }

    // A refinement's two children's lc_cluster_error: both at once in SSE
    // lanes where pair_errors covers them (host/pair_bound.h); else, where
    // the CPU has AVX2 and the quads' evaluation covers them (emission
    // cones, the Disney BRDF), in its eight lanes with the point in the
    // first of each half (the others idle): the point's lanes are made
    // again only when the point or its material changes. The same values
    // bit for bit.
    vec2 lc_child_errors(const SurfacePoint& sp, const Material& m, const LightNode& left, const LightNode& right,
                         float min_distance2) {
        vec2 errors;
        if (tightest_bound)
            return vec2(tightest_error(sp, left, min_distance2), tightest_error(sp, right, min_distance2));
        if (pair_errors(*this, sp, m, left, right, min_distance2, errors)) return errors;
#if defined(__SSE2__)
        if (quad_bound_covers(left) && quad_bound_covers(right) && cpu_has_avx2()) {
            if (!lanes_made || std::memcmp(&sp, &lanes_point, offsetof(SurfacePoint, mat)) != 0 ||
                std::memcmp(&m, &lanes_point.mat, sizeof m) != 0) {
                SurfacePoint point = sp;
                point.mat = m;
                const SurfacePoint four[4] = {point, point, point, point};
                const QuadLanes q = quad_lanes(*this, four, 1u);
                lanes_covered = q.covered;
                if (lanes_covered) quad8::widen(q, point_lanes);
                lanes_point = point;
                lanes_made = true;
            }
            if (lanes_covered) {
                float a[4], b[4];
                quad8::quad_pair_errors(*this, point_lanes, left, right, min_distance2, a, b);
                return vec2(a[0], b[0]);
            }
        }
#endif
        return vec2(lc_cluster_error(sp, m, left, min_distance2), lc_cluster_error(sp, m, right, min_distance2));
    }
#if defined(__SSE2__)
    // lc_child_errors' lanes, of lanes_point (its material the one it was
    // given), compared byte for byte: SurfacePoint has no padding.
    static_assert(offsetof(SurfacePoint, mat) == 5 * sizeof(vec3) + sizeof(uint) + sizeof(vec2) + sizeof(vec4));
    quad8::QuadLanes point_lanes;
    SurfacePoint lanes_point;
    bool lanes_made = false, lanes_covered = false;
#endif

    // The smallest error bound of Walter's form, material * geometry *
    // emission bounded over the cluster and visibility by 1: the largest
    // unshadowed unit contribution among the cluster's own lights, channel
    // by channel, times the cluster's intensity. Every conservative bound
    // of lc_cluster_error's kind is at least this. Zero for a leaf.
    float tightest_error(const SurfacePoint& sp, const LightNode& node, float min_distance2) {
        if ((node.flags & kNodeLeaf) != 0u) return 0.0f;
        std::vector<uint> stack = {node.left, node.left + 1u};
        vec3 largest(0.0f);
        while (!stack.empty()) {
            const LightNode& n = light_nodes[stack.back()];
            stack.pop_back();
            if ((n.flags & kNodeLeaf) == 0u) {
                stack.push_back(n.left);
                stack.push_back(n.left + 1u);
                continue;
            }
            vec3 wi;
            float t_max;
            largest = max(largest, lc_light_unit(sp, lights[n.rep_light], min_distance2, wi, t_max));
        }
        return lc_luminance(largest * lc_node_intensity(node));
    }

    // lc_shade_brute's result, bit for bit, with the shadow rays traced
    // eight at a time: a point's rays to consecutive lights, which the
    // tree's leaf order keeps close together, go down the tree as one packet
    // (lc_visible8; the room at 10^4 lights 4% faster than in packets of
    // four, the gallery 1% slower, docs/results/speed.md). The
    // contributions are summed in light order, as there, in double
    // (lc_brute_add).
    vec3 lc_shade_brute_packets(const SurfacePoint& sp, uint light_count, float min_distance2, ShadeStats& stats) {
        if (kRecordRays || wide_nodes == nullptr) return lc_shade_brute(sp, light_count, min_distance2, stats);
        constexpr uint R = 8u;
        BruteSum acc;
        RayPacket8 packet;
        vec3 contribution[R];
        uint pending = 0u;
        auto trace = [&] {
            packet.valid = (1u << pending) - 1u;
            const unsigned visible = lc_visible8(packet);
            for (uint j = 0; j < pending; ++j)
                if ((visible >> j & 1u) != 0u) lc_brute_add(acc, contribution[j]);
            pending = 0u;
        };
        for (uint i = 0u; i < light_count; ++i) {
            const Light& light = lights[i];
            vec3 wi;
            float t_max;
            const vec3 unit = lc_light_unit(sp, light, min_distance2, wi, t_max);
            if (!(unit.x + unit.y + unit.z > 0.0f)) continue;
            stats.shadow_rays += 1u;
            packet.org[pending] = sp.p;
            packet.dir[pending] = wi;
            packet.t_max[pending] = t_max;
            contribution[pending] = unit * lc_light_intensity(light);
            if (++pending == R) trace();
        }
        if (pending > 0u) trace();
        return lc_brute_total(acc);
    }

    // The shadow rays' any-hit query: lc_trace_any's answer, from the 8-wide
    // tree where one is bound (AVX2), else from the 4-wide one (1.4 to 2.4
    // times the binary tree's rays per second on the shipped room, and the
    // 8-wide 1.1 to 1.3 times the 4-wide's on lightcuts' rays; bench/embree_rays).
    bool lc_trace_shadow(vec3 org, vec3 dir, float t_max) {
#if defined(LC_WIDE8_TRACE)
        if (wide8_nodes != nullptr) return trace_any_wide8(*this, wide8_nodes, wide8_leaves, org, dir, t_max);
#endif
        return wide_nodes != nullptr ? trace_any_wide(*this, wide_nodes, wide_leaves, org, dir, t_max)
                                     : lc_trace_any(org, dir, t_max);
    }

    // lc_trace_closest's hit (its triangle, distance and barycentric
    // weights), from the 8-wide tree where one is bound (AVX2:
    // trace_closest_wide8; where two triangles tie at exactly the same
    // distance it may name the other one), else from the binary tree.
    // The camera rays, the path tracer's and the VPLs' paths take it.
    uint lc_trace_first_hit(vec3 org, vec3 dir, float t_max, float& t, float& b1, float& b2) {
#if defined(LC_WIDE8_TRACE)
        if (wide8_nodes != nullptr)
            return trace_closest_wide8(*this, wide8_nodes, wide8_leaves, org, dir, t_max, t, b1, b2);
#endif
        return lc_trace_closest(org, dir, t_max, t, b1, b2);
    }

    // lc_visible for up to four rays (bit r of packet.valid): bit r of the
    // result is set where ray r is visible. Each answer is lc_visible's;
    // the rays go down the 8-wide tree together where it is bound
    // (trace_any_wide8_packet: a quad's points' rays to one light), else through
    // the 4-wide one as a packet (trace_any_wide4), else one at a time (the
    // ray recorder).
    unsigned lc_visible4(const RayPacket4& packet) {
        if constexpr (kRecordRays)
            if (packet_log != nullptr && (packet.valid & 0xFu) != 0u)
                packet_log->push_back({ray_log->size(), uint(__builtin_popcount(packet.valid & 0xFu))});
        return visible4(packet);
    }

    // lc_visible4 for up to eight rays (an octet's points' rays to one
    // light, brute force's rays from one point to eight lights): down the
    // 8-wide tree together (trace_any_wide8_packet), else as two packets of
    // four.
    unsigned lc_visible8(const RayPacket8& packet) {
        const unsigned valid = packet.valid & 0xFFu;
        if (!kEnableShadows) return valid;
#if defined(LC_WIDE8_TRACE)
        if (!kRecordRays && wide8_nodes != nullptr)
            return valid & ~trace_any_wide8_packet(*this, wide8_nodes, wide8_leaves, packet);
#endif
        if constexpr (kRecordRays)
            if (packet_log != nullptr && valid != 0u) packet_log->push_back({ray_log->size(), uint(__builtin_popcount(valid))});
        unsigned visible = 0u;
        for (unsigned h = 0; h < 2u; ++h) {
            RayPacket4 half;
            for (unsigned r = 0; r < 4u; ++r) {
                half.org[r] = packet.org[4u * h + r];
                half.dir[r] = packet.dir[4u * h + r];
                half.t_max[r] = packet.t_max[4u * h + r];
            }
            half.valid = valid >> 4u * h & 0xFu;
            if (half.valid != 0u) visible |= visible4(half) << 4u * h;
        }
        return visible;
    }

private:
    // lc_visible4 without the packet's entry in packet_log.
    unsigned visible4(const RayPacket4& packet) {
        const unsigned valid = packet.valid & 0xFu;
        if (!kEnableShadows) return valid;
#if defined(LC_WIDE8_TRACE)
        if (!kRecordRays && wide8_nodes != nullptr)
            return valid & ~trace_any_wide8_packet(*this, wide8_nodes, wide8_leaves, packet);
#endif
        if (!kRecordRays && wide_nodes != nullptr) return valid & ~trace_any_wide4(*this, wide_nodes, wide_leaves, packet);
        unsigned visible = 0u;
        for (unsigned r = 0; r < 4u; ++r) {
            if ((valid >> r & 1u) == 0u) continue;
            SurfacePoint at;
            at.p = packet.org[r];
            if (lc_visible(at, packet.dir[r], packet.t_max[r])) visible |= 1u << r;
        }
        return visible;
    }
};

using ShadeKernel = BasicShadeKernel<false>;

// A kernel reading the prepared scene's arrays, with `heap` (if any) as its
// cut heap.
template <bool kRecordRays = false>
BasicShadeKernel<kRecordRays> make_shade_kernel(const PreparedScene& p, CutHeap* heap = nullptr) {
    BasicShadeKernel<kRecordRays> k;
    k.bvh_nodes = p.bvh.nodes.data();
    k.wide_nodes = p.bvh.wide_nodes.empty() ? nullptr : p.bvh.wide_nodes.data();
    k.wide_leaves = p.bvh.wide_leaves.data();
    if (cpu_has_avx2() && !p.bvh.wide8_nodes.empty()) {
        k.wide8_nodes = p.bvh.wide8_nodes.data();
        k.wide8_leaves = p.bvh.wide8_leaves.data();
    }
    k.triangles = p.scene.triangles.data();
    k.normals = p.scene.normals.data();
    k.uvs = p.scene.uvs.data();
    k.materials = p.scene.materials.data();
    k.textures = p.scene.textures.data();
    k.texels = p.scene.texels.data();
    k.lights = p.tree.lights.data();
    k.light_nodes = p.tree.nodes.data();
    k.environment = p.scene.environment.rgb.data();
    k.vpl_min_distance2 = p.vpl_min_distance2;
    if (heap != nullptr) k.bind_heap(*heap);
    return k;
}

}  // namespace lc::cpu
