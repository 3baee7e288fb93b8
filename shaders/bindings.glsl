// The Vulkan kernels' interface: descriptor bindings, specialization
// constant ids, workgroup size and the per-pixel statistics record.
//
// Compiles as GLSL (included by the kernels) and as C++ (included by
// host/vulkan), in the same way as lc_shared/types.h, so the host sizes its
// dispatches and buffers from these constants.
#ifndef LC_BINDINGS_GLSL
#define LC_BINDINGS_GLSL

#include "lc_shared/types.h"

#ifdef __cplusplus
namespace lc::gpu {
#endif

// Invocations per workgroup (1D; one invocation per pixel of the tile).
LC_CONST uint kWorkgroupSize = 64u;

// Descriptor set 0, one storage buffer per binding.
LC_CONST uint kBindingBvhNodes = 0u;
LC_CONST uint kBindingTriangles = 1u;
LC_CONST uint kBindingNormals = 2u;
LC_CONST uint kBindingUvs = 3u;           // TriangleUvs, parallel to the triangles
LC_CONST uint kBindingMaterials = 4u;
LC_CONST uint kBindingTextures = 5u;      // TextureInfo per texture (one zeroed record if none)
LC_CONST uint kBindingTexels = 6u;        // RGBA8 texels of every texture, one uint each
LC_CONST uint kBindingLights = 7u;        // leaf order of the light tree
LC_CONST uint kBindingLightNodes = 8u;
LC_CONST uint kBindingEnvironment = 9u;   // RGB floats of the environment map (one black texel if none)
LC_CONST uint kBindingWideBvhNodes = 10u; // the BVH 4 wide for shadow rays (Bvh4Node, kBvh4NodeWords uvec4 each)
LC_CONST uint kBindingFrame = 11u;        // one FrameParams
LC_CONST uint kBindingGBuffer = 12u;      // GBufferTexel per tile pixel
LC_CONST uint kBindingRadiance = 13u;     // 3 floats per tile pixel, summed over samples
LC_CONST uint kBindingPixelStats = 14u;   // PixelStats per tile pixel, summed over samples
LC_CONST uint kBindingHeapSave = 15u;     // cut heaps paused between dispatches (see heap.glsl)
LC_CONST uint kBindingCutState = 16u;     // CutState per tile pixel, between Lightcuts dispatches
LC_CONST uint kBindingChunkTable = 17u;   // ChunkTable: where the chunks of a split scene array are
LC_CONST uint kBindingCount = 18u;        // storage-buffer bindings: 0 .. kBindingCount - 1
// Storage texel buffers (RGBA32UI views, read only) over five of the scene arrays
// above: the arrays the shadow rays and cut selection read most, read
// through these instead where kSpecTexelReads is set (docs/vulkan.md).
LC_CONST uint kBindingBvhNodeTexels = 18u;
LC_CONST uint kBindingTriangleTexels = 19u;
LC_CONST uint kBindingLightTexels = 20u;
LC_CONST uint kBindingLightNodeTexels = 21u;
LC_CONST uint kBindingWideBvhNodeTexels = 22u;
LC_CONST uint kTexelBindingCount = 5u;

// Scene arrays (bindings 0 .. kSceneArrayCount - 1) larger than one buffer
// may be are split into chunks of 2^shift elements each. Chunk 0 stays at
// the array's binding; every chunk's buffer device address is in the
// ChunkTable, whose std430 layout is:
//   uint first[kChunkTableFirstWords];  // index in addr of each array's chunk 0
//   uvec2 addr[];                       // device addresses, low word first
// (shaders/kernel.glsl reads it; GpuResources writes it.) The header has an
// even number of words, so the addresses follow it unpadded.
LC_CONST uint kSceneArrayCount = 11u;
LC_CONST uint kChunkTableFirstWords = (kSceneArrayCount + 1u) & ~1u;
LC_CONST uint kChunkTableHeaderBytes = 4u * kChunkTableFirstWords;

// Specialization constant ids.
LC_CONST uint kSpecWorkgroupSize = 0u;    // local_size_x
LC_CONST uint kSpecEnableGgx = 1u;        // any material has a GGX lobe
LC_CONST uint kSpecEnableShadows = 2u;    // any triangle can block a light
LC_CONST uint kSpecHeapSlots = 3u;        // K: cut-heap slots per invocation (shared memory, or private: 4)
LC_CONST uint kSpecHeapPrivate = 4u;      // the K slots in each invocation's private memory instead
LC_CONST uint kSpecTexelReads = 5u;       // read the four texel-buffer arrays through their views
LC_CONST uint kSpecEnableOriented = 6u;   // any spot or oriented light (emission cones)
LC_CONST uint kSpecStochastic = 7u;       // lightcuts.comp: Stochastic Lightcuts' fresh representatives
LC_CONST uint kSpecEnableTextures = 8u;   // any material has a texture
LC_CONST uint kSpecEnableDisney = 9u;     // any Disney material
LC_CONST uint kSpecEnableSheen = 10u;     // any Disney material with sheen > 0
LC_CONST uint kSpecEnableClearcoat = 11u; // any Disney material with clearcoat > 0
LC_CONST uint kSpecSplitScene = 12u;      // some scene array is split into chunks
LC_CONST uint kSpecChunkShift = 13u;      // 13 + b: log2 of the elements per chunk of the scene
                                          // array at binding b (b < kSceneArrayCount)

// PixelStats.flags
LC_CONST uint kPixelLoopLimit = 2u;     // the driver cut the invocation's loops short
LC_CONST uint kPixelCutUnfinished = 4u; // refinement went on past the pass's last dispatch (a bug)

// Per tile pixel, summed over the samples of the pixel (40 bytes). The three
// sums that can pass 2^32 (10^6 lights times 4295 samples do) are 64-bit
// counts kept as lo/hi word pairs, added to with lc_count_add, so no device
// needs shaderInt64; the host joins them with count64. Sample counts stay
// below kMaxSpp and fit one word.
struct PixelStats {
    uint cut_size_lo, cut_size_hi;        // lightcuts: clusters in the final cuts
    uint shadow_rays_lo, shadow_rays_hi;
    uint max_cut_samples;   // samples whose refinement stopped at max_cut
    uint frozen_samples;    // samples whose cut froze clusters out of a full heap
    uint flags;             // kPixel* bits, or-ed over samples
    uint paused_samples;    // samples whose heap waited in global memory between dispatches
    uint cut_indirect_lo, cut_indirect_hi;  // ... of which virtual point lights
};

// Where tile pixel i (of a tile `width` x `height`) lies in its tile. The
// rows are taken in pairs and a pair's pixels column by column, so eight
// consecutive invocations (one SIMD group on lavapipe) shade a 4x2 block
// of neighbours instead of eight pixels of one row; an odd last row is
// taken in order.
#ifdef __cplusplus
inline
#endif
uint lc_tile_column(uint i, uint width, uint height) {
    uint pair = i / (2u * width);
    return 2u * pair + 1u < height ? (i % (2u * width)) / 2u : i % (2u * width);
}
#ifdef __cplusplus
inline
#endif
uint lc_tile_row(uint i, uint width, uint height) {
    uint pair = i / (2u * width);
    return 2u * pair + (2u * pair + 1u < height ? (i & 1u) : 0u);
}

// The inverse: the index of the tile pixel at (x, y) of the tile.
#ifdef __cplusplus
inline
#endif
uint lc_tile_index(uint x, uint y, uint width, uint height) {
    uint pair = y / 2u;
    return 2u * pair + 1u < height ? pair * 2u * width + 2u * x + (y & 1u) : pair * 2u * width + x;
}

#ifdef __cplusplus
inline std::uint64_t count64(uint lo, uint hi) { return std::uint64_t(hi) << 32 | lo; }
#else
// (lo, hi) += v, carrying into the high word.
void lc_count_add(inout uint lo, inout uint hi, uint v) {
    uint carry;
    lo = uaddCarry(lo, v, carry);
    hi += carry;
}
#endif

// A Lightcuts cut in the making, kept in global memory between the
// dispatches of one sample when the refinement is spread over several
// (52 bytes). The heap slots go to the heap-save buffer.
LC_CONST uint kCutDone = 1u;       // result added to the pixel; later dispatches skip it
LC_CONST uint kCutFroze = 2u;      // the cut froze clusters out of a full heap
LC_CONST uint kCutSelected = 4u;   // stochastic: the cut is final; its clusters are being shaded
LC_CONST uint kCutFreshKeys = 8u;  // quadcuts.comp: the heap's keys are from the current estimates
LC_CONST uint kCutHeapMode = 16u;     // quadcuts.comp: the cut's list is a heap, refined largest first
LC_CONST uint kCutPassUnderWay = 32u; // quadcuts.comp: a pass is under way (its marks in the keys' sign bits)
LC_CONST uint kCutHitMaxCut = 64u;    // lightcuts.comp: refinement stopped at max_cut (a stochastic cut then
                                      // goes on to shade its clusters, maybe in later dispatches)
// quadcuts.comp keeps a quad's cut in the same record, one per lane: `shaded`
// holds the bits of the quad's summed root bounds, `draw` those of the
// lane's weight (host/quad_cut.h, update_weights).
struct CutState {
    uint heap_size;
    uint cut_size;
    uint shadow_rays;
    uint flags;                    // kCut* bits
    // Single lights and frozen clusters; stochastic, once kCutSelected: the
    // sum of the draws [0, draw) of heap slot `shaded`.
    float fixed_r, fixed_g, fixed_b;
    // While the cut is refined: the running sum of the heap's estimates.
    // Stochastic, once kCutSelected: the selection's fixed_sum plus the
    // fresh estimates of heap slots [0, shaded).
    float heap_r, heap_g, heap_b;
    uint shaded;
    uint draw;
    uint cut_indirect;             // VPL clusters of cut_size
};

// PushConstants.cut_flags
LC_CONST uint kCutFirstDispatch = 1u;  // start the cut from the roots
LC_CONST uint kCutLastDispatch = 2u;   // every cut must be final by the end of this one
LC_CONST uint kUnlimitedRefinements = 0xFFFFFFFFu;

// Push constants of every kernel: what changes from dispatch to dispatch
// (44 bytes; the frame's constants are in the kBindingFrame buffer).
struct PushConstants {
    uint tile_x, tile_y;    // first pixel of the dispatched tile
    uint tile_width, tile_height;
    uint sample_index;      // which of the spp samples this pass renders
    uint light_first;       // brute force: this dispatch's range of lights
    uint light_count;
    uint cut_flags;         // lightcuts: kCut*Dispatch bits
    uint refine_budget;     // lightcuts: refinements per pixel in this dispatch
    // lightcuts: invocations the heap-save buffer is laid out for. A push
    // constant, not a specialization constant: it follows the image size,
    // and a new pipeline per size costs seconds of compilation on lavapipe.
    uint heap_save_stride;
    // Workgroup j of a dispatch shades the tile's block of invocations
    // (j * group_stride) mod (workgroups); group_stride is coprime to the
    // count, so every block once. 1 on GPUs. llvmpipe (lavapipe) hands each
    // of its threads one contiguous range of a dispatch's workgroups, so in
    // tile order one thread would get the top of the tile and another the
    // bottom; a stride near the count over the golden ratio gives every
    // range blocks from all over the tile (workgroup_stride, tile_pass.cpp).
    uint group_stride;
};

#ifdef __cplusplus
}  // namespace lc::gpu
#endif
#endif
