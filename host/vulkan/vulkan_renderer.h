// Knobs of the Vulkan renderer that the public VulkanOptions do not expose:
// used by the tests and benchmarks, and settable from the environment.
#pragma once

#include <cstdint>

#include "lightcuts/render.h"

namespace lc::vk {

struct Tuning {
    // Compile a kernel feature in whatever the scene needs, to measure what
    // its specialization constant saves.
    bool force_ggx = false;
    bool force_shadows = false;
    bool force_oriented = false;
    bool force_textures = false;
    bool force_disney = false;
    bool force_sheen = false;
    bool force_clearcoat = false;
    // Largest tile, in pixels (0: limited only by the buffer limits).
    std::uint32_t max_tile_pixels = 0;
    // Tiles are resized so one dispatch takes about this long (0: the
    // device's default, kGpuTargetMs or, on a CPU device, kCpuTargetMs).
    double target_dispatch_ms = 0.0;
    // Split the work of each pixel from the start, as is otherwise done only
    // where the driver cuts long loops short (0: no split): brute force over
    // at most this many lights per dispatch (sampled: light samples),
    // Lightcuts with at most this many steps per dispatch (a refinement, or a
    // stochastic cluster shaded).
    std::uint32_t lights_per_dispatch = 0;
    std::uint32_t refinements_per_dispatch = 0;
    // With refinements_per_dispatch set: a render whose cuts take at most
    // this many steps (the refinements max_cut and the tree allow, one more
    // to find the cut final, and stochastic's fresh draws) runs each cut
    // whole in one dispatch instead (0: never). The llvmpipe presplit sets
    // it.
    std::uint32_t whole_cut_steps = 0;
    // On llvmpipe (lavapipe), whose loop limit cuts deep cuts short,
    // Lightcuts is split from the start when refinements_per_dispatch is 0
    // (kLlvmpipeRefinements steps per dispatch, or whole cuts up to
    // kLlvmpipeWholeCutSteps steps), instead of finding the split by a
    // failed pass over a tile. False: only a failed pass splits the work.
    bool presplit_on_llvmpipe = true;
    // On CPU devices, workgroups take a tile's blocks spread over the tile
    // (workgroup_stride, host/vulkan/tile_pass.h) rather than in tile order:
    // lavapipe gives each thread one contiguous range of a dispatch's
    // workgroups. GPUs keep tile order.
    bool spread_groups_on_cpu = true;

    // The smallest tile (0: the device's, min_tile_pixels in render_setup.h).
    std::uint32_t min_tile_pixels = 0;
    // Where a tile no larger than the smallest has a shading dispatch over
    // 4x target_dispatch_ms, split each pixel's work over more dispatches
    // (ShadingMethod::split_finer) for the tiles after it; the first tile
    // is then a 256-pixel probe. kAuto: on GPUs, whose watchdogs the target
    // is for; a CPU device has none.
    enum class SplitSlowTiles { kAuto, kOn, kOff };
    SplitSlowTiles split_slow_tiles = SplitSlowTiles::kAuto;
    // Tests only: the split rule above reads this many milliseconds as
    // every shading dispatch's time instead of the measured one (0: the
    // measured time), so that what it decides does not hang on a clock.
    double shading_ms_for_split = 0.0;

    // The most private memory a Lightcuts invocation's heap may take: 8192
    // slots of 8 bytes, more than a cut at the default max_cut (1000) can
    // fill. An array of 8192 slots took lavapipe 6.9 s and 630 MB to compile
    // and run at 8x8; one of 2^32 ran LLVM out of memory after 90 s.
    static constexpr std::uint64_t kMaxPrivateHeapBytes = 64 * 1024;

    // One dispatch on a GPU stays well under any display watchdog.
    static constexpr double kGpuTargetMs = 30.0;
    // A GPU's smallest tile: 1024 workgroups, about a quarter of the 132 x
    // 2048 invocations an H200's multiprocessors hold. With tiles of a few
    // hundred pixels, brute force over 10^4 lights on an H200, whose
    // dispatches took one pixel's time whatever the tile's size, shrank its
    // tiles towards single pixels and did not finish 240x135 in 40 s
    // (docs/results/gpu.md).
    static constexpr std::uint32_t kGpuMinTilePixels = 1024 * 64;
    // A CPU device (lavapipe) has no watchdog, and runs each workgroup on
    // one of its threads: long dispatches of many workgroups keep them all
    // busy (docs/results/lavapipe.md).
    static constexpr double kCpuTargetMs = 1000.0;
    // The refinement budget Lightcuts starts with on llvmpipe. Each
    // refinement's loop trips (the heap's levels, the search of a full heap,
    // a shadow ray's walk) count against the 65535-trip limit; 512 stay
    // under it on the shipped scenes and on ones whose rays take many more
    // trips (a retry makes it finer where not: shading_method.cpp, a
    // quarter of the budget each time). But a cut at the default max_cut
    // (1000) takes at most 1001 steps, and every shipped scene at its own
    // size renders such cuts whole in one dispatch with no failed pass:
    // up to kLlvmpipeWholeCutSteps steps, no cut is split, and no heap
    // leaves its invocation (with 512, 0.3% of the room's cuts and 10 to
    // 17% of the panels' and the gallery's waited in global memory between
    // dispatches; docs/results/lavapipe.md, §12).
    static constexpr std::uint32_t kLlvmpipeRefinements = 512;
    static constexpr std::uint32_t kLlvmpipeWholeCutSteps = 1024;

    // Split every scene array into chunks of at most this many bytes, as is
    // otherwise done only for arrays larger than one buffer may be (0: no
    // forced split), so that small scenes test the split.
    std::uint64_t split_bytes = 0;
    // Keep each chunk of a split array in a buffer of its own even where
    // the whole array fits one allocation (whose windows the chunks are
    // otherwise, so that texel views can still cover it): the path of
    // arrays larger than an allocation, for tests.
    bool chunk_buffers = false;

    // On a CPU device with VK_EXT_external_memory_host, let the kernels read
    // the large scene arrays (the lights and light-tree nodes, which own
    // whole pages) in host memory, without copying them.
    bool host_import = true;

    // Read the BVH nodes, triangles, lights, light-tree nodes and the 4-wide
    // BVH through storage texel buffers instead of storage buffers. kAuto: on CPU
    // devices (lavapipe), where it measured faster (docs/results/lavapipe.md);
    // GPUs keep storage buffers until it is measured there. Either way only
    // where each of the five arrays is in one buffer (split or not) and
    // fits maxTexelBufferElements.
    enum class TexelReads { kAuto, kOn, kOff };
    TexelReads texel_reads = TexelReads::kAuto;

    // Specialize the kernels' SPIR-V on the host (host/vulkan/spirv_specialize.h)
    // instead of in the driver. kAuto: on CPU devices, where lavapipe's
    // set-up then took about 0.3 s instead of 0.45 (docs/results/lavapipe.md);
    // GPUs specialize in the driver until it is measured there.
    enum class HostSpecialization { kAuto, kOn, kOff };
    HostSpecialization specialize_on_host = HostSpecialization::kAuto;

    // Where the kernels keep each invocation's cut heap (shaders/heap.glsl):
    // in workgroup shared memory (K slots for each of the workgroup's
    // invocations, which limits K) or in each invocation's private array.
    // kAuto: private, on every device measured. On lavapipe shading took
    // 0.78-0.82 s against 0.93-1.42 s in shared memory on the room
    // (docs/results/lavapipe.md, §10). On an H200 the room with 10^5 lights
    // at 1080p took 17.7/29.7/50.7/79.8 ms of GPU time with K = 8/16/32/64
    // private slots against 18.2/33.1/72.4/246.4 ms in shared memory, whose
    // 4 to 32 KiB a workgroup leave room for fewer workgroups at a time
    // (docs/results/gpu.md).
    enum class HeapMemory { kAuto, kShared, kPrivate };
    HeapMemory heap_memory = HeapMemory::kAuto;

    // LC_VK_FORCE_FEATURES=ggx,shadows,oriented,textures,disney,sheen,clearcoat (or all), LC_VK_MAX_TILE_PIXELS=N, LC_VK_TARGET_MS=X,
    // LC_VK_LIGHTS_PER_DISPATCH=N, LC_VK_REFINEMENTS_PER_DISPATCH=N, LC_VK_SPLIT_BYTES=N,
    // LC_VK_CHUNK_BUFFERS=1, LC_VK_HOST_IMPORT=0, LC_VK_TEXEL_READS=on|off,
    // LC_VK_SPECIALIZE_ON_HOST=on|off, LC_VK_HEAP_MEMORY=shared|private,
    // LC_VK_MIN_TILE_PIXELS=N, LC_VK_SPLIT_SLOW_TILES=on|off.
    static Tuning from_environment();
};

// render_vulkan(prepared, options, vulkan) is this with Tuning::from_environment().
RenderResult render_vulkan(const PreparedScene& prepared, const RenderOptions& options,
                           const VulkanOptions& vulkan, const Tuning& tuning);

// Warning/error messages the validation layer (or loader) has reported to
// any render of this process so far; tests check it stays unchanged.
std::uint64_t validation_message_total();

}  // namespace lc::vk
