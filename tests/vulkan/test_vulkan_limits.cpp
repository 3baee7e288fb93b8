// The Vulkan path at its limits: a max_cut far beyond the tree, a heap too
// large for any buffer, per-pixel counters past 2^32, and the automatic
// re-split of the work when lavapipe cuts the kernels' loops short.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bindings.glsl"
#include "render_setup.h"
#include "test_util.h"
#include "tile_pass.h"
#include "vulkan_test_support.h"

namespace lc {
namespace {

using vulkan_test::expect_brute_matches;
using vulkan_test::expect_lightcuts_matches;
using vulkan_test::max_relative_difference;
using vulkan_test::options;
using vulkan_test::random_scene;
using vulkan_test::Vulkan;

std::uint64_t buffer_bytes(const RenderStats& stats, const std::string& name) {
    for (const auto& [buffer, bytes] : stats.buffer_bytes)
        if (buffer == name) return bytes;
    ADD_FAILURE() << "no buffer '" << name << "'";
    return 0;
}

// Runs `check` on the set-up (buffers, descriptors, kernels) of a 12x10
// lightcuts render of `p` with each tuning, under the validation layer,
// which must stay silent.
template <typename Check>
void check_setups(const PreparedScene& p, std::initializer_list<vk::Tuning> tunings, Check check) {
    VulkanOptions v;
    v.validation = true;
    vk::MessageLog log;
    vk::Context ctx(v, &log);
    const RenderOptions o = options("lightcuts", 12, 10);
    const gpu::FrameParams frame = vk::frame_params(ctx, p, o);
    for (const vk::Tuning& tuning : tunings) {
        const vk::RenderSetup setup(ctx, p, o, frame, tuning);
        check(setup);
    }
    EXPECT_EQ(log.count(), 0u);
}

// The cut heap holds interior nodes of the tree, so it never gets more
// slots than LightTree::cut_heap_capacity(max_cut), whatever max_cut and
// cut_heap say: a max_cut of 4e9 over 8 lights takes 7 slots per pixel (it
// was refused when the heap took max_cut slots).
TEST_F(Vulkan, HugeMaxCutTakesAHeapSizedByTheTree) {
    PreparedScene p = prepare_scene(random_scene(61, 8, 0, 8, 8), 1);
    RenderOptions o = options("lightcuts", 8, 8);
    o.max_cut = 4'000'000'000u;
    o.cut_heap = 4'000'000'000u;
    o.relative_error = 0.0f;  // refine every cluster whose bound is not zero
    const RenderResult g = gpu(p, o);
    expect_lightcuts_matches(p, o, g);
    ASSERT_EQ(p.tree.cut_heap_capacity(o.max_cut), 7u);
    EXPECT_EQ(g.stats.heap_slots, 7u);
    EXPECT_EQ(g.stats.heap_frozen_samples, 0u);
    EXPECT_EQ(buffer_bytes(g.stats, "heap save"), 7u * sizeof(gpu::CutEntry) * 64);  // one workgroup
}

// A cut_heap whose slots for a whole workgroup pass the device's
// maxComputeSharedMemorySize is refused for heaps in shared memory, naming
// the setting, the bytes it needs and the largest cut_heap that fits. Heaps
// in each invocation's private memory (the default on CPU devices) are not
// limited by it: the same cut_heap renders there, as the CPU reference
// renders it.
TEST_F(Vulkan, CutHeapLargerThanSharedMemoryIsRefusedThereOnly) {
    Scene s = random_scene(62, 0, 0, 8, 8);
    s.lights = test::random_point_lights(3000, {-3, 0.5f, -3}, {3, 3, 3}, 20.0f, 62);
    update_bounds(s);
    PreparedScene p = prepare_scene(std::move(s), 1);
    RenderOptions o = options("lightcuts", 8, 8);
    o.cut_heap = 1000;  // 1000 slots x 8 bytes x 64 invocations = 512 000 bytes
    vk::Tuning shared;
    shared.heap_memory = vk::Tuning::HeapMemory::kShared;
    try {
        gpu(p, o, shared);
        FAIL() << "expected an exception";
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("cut_heap 1000 needs 512000 bytes of shared memory"), std::string::npos) << what;
        EXPECT_NE(what.find("so at most cut_heap "), std::string::npos) << what;
    }

    vk::Tuning own;
    own.heap_memory = vk::Tuning::HeapMemory::kPrivate;
    const RenderResult g = gpu(p, o, own);
    EXPECT_TRUE(g.stats.heap_private);
    EXPECT_GT(std::uint64_t(g.stats.heap_slots) * gpu::kWorkgroupSize * sizeof(gpu::CutEntry), 32768u);
    expect_lightcuts_matches(p, o, g);
}

// Private heaps have their own limit (Tuning::kMaxPrivateHeapBytes, 8192
// slots): a heap that max_cut and the tree let grow past it is refused
// before any kernel is compiled, naming both settings and the limit.
TEST_F(Vulkan, CutHeapPastThePrivateLimitIsRefused) {
    Scene s = random_scene(63, 0, 0, 8, 8);
    s.lights = test::random_point_lights(20000, {-3, 0.5f, -3}, {3, 3, 3}, 20.0f, 63);
    update_bounds(s);
    PreparedScene p = prepare_scene(std::move(s), 1);
    RenderOptions o = options("lightcuts", 8, 8);
    o.cut_heap = 100000;
    o.max_cut = 100000;
    try {
        gpu(p, o);
        FAIL() << "expected an exception";
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("cut_heap 100000 with max_cut 100000 needs "), std::string::npos) << what;
        EXPECT_NE(what.find("the Vulkan kernels take at most 8192 slots"), std::string::npos) << what;
    }
}

// Start every pixel's 64-bit counters at `start` (lo/hi words), run one
// real pass of the shading kernel on top, and return the counters.
std::vector<gpu::PixelStats> pass_over(vk::RenderSetup& setup, const gpu::FrameParams& frame,
                                       const std::vector<gpu::PixelStats>* start) {
    const std::uint32_t pixels = frame.width * frame.height;
    VkCommandBuffer cmd = setup.submitter.begin();
    if (start)
        // The pass's first barrier makes this transfer visible to the kernels.
        setup.ctx.fn().vkCmdUpdateBuffer(cmd, setup.resources.pixel_stats().get(), 0,
                                         pixels * sizeof(gpu::PixelStats), start->data());
    gpu::PushConstants tile{};
    tile.tile_width = frame.width;
    tile.tile_height = frame.height;
    setup.pass.record(cmd, tile, /*first=*/start == nullptr, /*last=*/true);
    setup.submitter.submit_and_wait();
    // The pass made the counters host-readable; its fence has signalled.
    const gpu::PixelStats* out = setup.resources.pixel_stats_sums();
    return {out, out + pixels};
}

// A pixel's cut sizes and shadow rays, summed over samples, pass 2^32 with
// 10^6 lights and 4295 samples: too much to render here. So each kernel
// runs one pass from zero, then one pass from counters a few counts below
// 2^32 (a pre-filled stats buffer), and the second must end exactly the
// first's counts above the start, carried into the high word.
TEST_F(Vulkan, PixelCountersCarryPast32Bits) {
    const PreparedScene p = prepare_scene(random_scene(63, 40, 1, 8, 8), 1);
    const std::uint64_t start = (std::uint64_t(5) << 32) | 0xFFFFFFF8u;  // 8 below a carry
    for (const char* method : {"brute", "lightcuts"}) {
        SCOPED_TRACE(method);
        RenderOptions o = options(method, 8, 8);
        o.relative_error = 0.0f;
        VulkanOptions v;
        v.validation = true;
        vk::MessageLog log;
        vk::Context ctx(v, &log);
        const gpu::FrameParams frame = vk::frame_params(ctx, p, o);
        vk::RenderSetup setup(ctx, p, o, frame, {});
        const std::vector<gpu::PixelStats> base = pass_over(setup, frame, nullptr);
        std::vector<gpu::PixelStats> from(base.size(), gpu::PixelStats{});
        for (gpu::PixelStats& ps : from) {
            ps.cut_size_lo = ps.shadow_rays_lo = std::uint32_t(start);
            ps.cut_size_hi = ps.shadow_rays_hi = std::uint32_t(start >> 32);
        }
        const std::vector<gpu::PixelStats> after = pass_over(setup, frame, &from);
        std::size_t carried = 0;
        for (std::size_t i = 0; i < base.size(); ++i) {
            const std::uint64_t rays = gpu::count64(base[i].shadow_rays_lo, base[i].shadow_rays_hi);
            const std::uint64_t cut = gpu::count64(base[i].cut_size_lo, base[i].cut_size_hi);
            EXPECT_EQ(gpu::count64(after[i].shadow_rays_lo, after[i].shadow_rays_hi), start + rays);
            EXPECT_EQ(gpu::count64(after[i].cut_size_lo, after[i].cut_size_hi), start + cut);
            carried += rays >= 8 ? 1 : 0;
        }
        EXPECT_GT(carried, base.size() / 2) << "the pass should carry at most pixels";
        EXPECT_EQ(log.count(), 0u);
    }
}

// lavapipe (llvmpipe) silently ends an invocation's loops after 65535
// iterations; the kernels notice, and the renderer splits the work finer
// and renders the tile again, without any tuning asking for it. Other
// devices have no such limit and render in one dispatch per stage.
void expect_resplit_on_llvmpipe(const RenderStats& stats) {
    std::printf("[ measured ] %s: %u loop-limit retries\n", stats.device.c_str(),
                stats.loop_limit_retries);
    // Only llvmpipe limits a kernel's loops; another device runs each pass
    // whole.
    if (stats.device.find("llvmpipe") != std::string::npos) EXPECT_GT(stats.loop_limit_retries, 0u);
    else EXPECT_EQ(stats.loop_limit_retries, 0u);
}

// 70000 unshadowed lights: 70000 iterations of the brute-force loop alone.
TEST_F(Vulkan, LoopLimitSplitsBruteForceAutomatically) {
    Scene s;
    s.materials = {test::lambert({0.6f, 0.5f, 0.4f})};
    test::add_quad(s, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0);
    s.lights = test::random_point_lights(70000, {-2, 0.5f, -2}, {2, 2, 2}, 10.0f, 64);
    s.camera = test::camera({0.0f, 2.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 50.0f, 4, 4);
    update_bounds(s);
    const PreparedScene p = prepare_scene(std::move(s), 1);
    ASSERT_FALSE(p.has_occluders);
    const RenderOptions o = options("brute", 4, 4);
    const RenderResult g = gpu(p, o);
    expect_brute_matches(p, o, g, vulkan_test::kBruteSplitRelative);
    expect_resplit_on_llvmpipe(g.stats);
}

// Scene arrays larger than a buffer may be are split into chunks, read
// through their device addresses (docs/vulkan.md). Forced here at 256
// bytes, so every array of a small scene has several chunks (lights: 5
// per chunk, light-tree nodes and BVH nodes a few each), both as windows of
// one buffer per array (where the array fits one allocation; storage-buffer
// and texel reads) and as one buffer per chunk (the arrays larger than an
// allocation): the images are those of the CPU reference within the usual
// tolerances, for every method, as without a split.
TEST_F(Vulkan, SceneArraysSplitIntoChunksMatchTheCpu) {
    const PreparedScene p = prepare_scene(random_scene(66, 60, 2, 12, 10), 1);
    vk::Tuning windows, windows_texels, buffers;
    windows.split_bytes = windows_texels.split_bytes = buffers.split_bytes = 256;
    windows.texel_reads = vk::Tuning::TexelReads::kOff;
    windows_texels.texel_reads = vk::Tuning::TexelReads::kOn;
    buffers.chunk_buffers = true;
    std::vector<std::size_t> light_buffers;
    check_setups(p, {windows, windows_texels, buffers}, [&](const vk::RenderSetup& setup) {
        EXPECT_TRUE(setup.resources.chunks().split);
        for (std::uint32_t b : {gpu::kBindingBvhNodes, gpu::kBindingTriangles, gpu::kBindingNormals,
                                gpu::kBindingLights, gpu::kBindingLightNodes}) {
            SCOPED_TRACE(b);
            EXPECT_GT(setup.resources.chunk_count(b), 2u);
            EXPECT_LE(setup.resources.chunks().shift[b], 3u);  // at most 8 elements of >= 32 bytes
        }
        EXPECT_EQ(setup.resources.chunk_count(gpu::kBindingFrame), 1u);  // never split
        light_buffers.push_back(setup.resources.chunk_buffer_count(gpu::kBindingLights));
    });
    ASSERT_EQ(light_buffers.size(), 3u);
    EXPECT_EQ(light_buffers[0], 1u);
    EXPECT_EQ(light_buffers[1], 1u);
    EXPECT_GT(light_buffers[2], 2u);
    for (const char* method : {"brute", "lightcuts", "sampled"}) {
        SCOPED_TRACE(method);
        RenderOptions o = options(method, 12, 10);
        const RenderResult whole = gpu(p, o);
        for (const vk::Tuning* split : {&windows, &windows_texels, &buffers}) {
            const RenderResult chunked = gpu(p, o, *split);
            // The same kernels read the same values: the images are identical.
            EXPECT_EQ(max_relative_difference(chunked.image, whole.image, std::string("split ") + method, 0.0),
                      0.0);
            if (std::string(method) == "brute") expect_brute_matches(p, o, chunked);
            if (std::string(method) == "lightcuts") expect_lightcuts_matches(p, o, chunked);
        }
    }
    // A forced split smaller than an element (48-byte lights, 64-byte tree
    // nodes at 40 bytes) gives each such element a chunk of its own (those
    // arrays were left whole, so the switch tested less than it said).
    vk::Tuning elements;
    elements.split_bytes = 40;
    check_setups(p, {elements}, [&](const vk::RenderSetup& setup) {
        for (std::uint32_t b : {gpu::kBindingLights, gpu::kBindingLightNodes}) {
            SCOPED_TRACE(b);
            EXPECT_EQ(setup.resources.chunks().shift[b], 0u);
            EXPECT_GT(setup.resources.chunk_count(b), 50u);
        }
    });
    const RenderOptions o = options("lightcuts", 12, 10);
    EXPECT_EQ(max_relative_difference(gpu(p, o, elements).image, gpu(p, o).image, "one element a chunk", 0.0), 0.0);
}

// On a CPU device that can import host memory (lavapipe), the large scene
// arrays, the lights and light-tree nodes (1 MiB and more, which own whole
// pages), are read in place instead of copied (Tuning::host_import), also
// when split into chunks; the images are those of the copies exactly.
TEST_F(Vulkan, LargeArraysAreReadInPlaceOnCpuDevices) {
    const PreparedScene p = prepare_scene(random_scene(68, 25000, 0, 8, 8), 1);
    ASSERT_GE(p.tree.lights.size() * sizeof(gpu::Light), std::size_t(1) << 20);
    vk::Tuning in_place, copied, split;
    copied.host_import = false;
    split.split_bytes = 1 << 18;
    std::vector<bool> imported, splits;
    bool can_import = false, llvmpipe = false;
    check_setups(p, {in_place, copied, split}, [&](const vk::RenderSetup& setup) {
        can_import = setup.ctx.host_import_alignment() > 0;
        llvmpipe = setup.ctx.device_name().find("llvmpipe") != std::string::npos;
        for (std::uint32_t b : {gpu::kBindingLights, gpu::kBindingLightNodes})
            imported.push_back(setup.resources.imported(b));
        EXPECT_FALSE(setup.resources.imported(gpu::kBindingFrame));
        splits.push_back(setup.resources.chunk_count(gpu::kBindingLightNodes) > 1);
    });
    EXPECT_EQ(splits, (std::vector<bool>{false, false, true}));
    // lavapipe has VK_EXT_external_memory_host; a GPU copies.
    if (llvmpipe) {
        EXPECT_TRUE(can_import);
    }
    const bool c = can_import;
    EXPECT_EQ(imported, (std::vector<bool>{c, c, false, false, c, c}));
    for (const char* method : {"brute", "lightcuts"}) {
        SCOPED_TRACE(method);
        const RenderOptions o = options(method, 8, 8);
        const RenderResult copy = gpu(p, o, copied);
        for (const vk::Tuning* t : {&in_place, &split}) {
            const RenderResult read_in_place = gpu(p, o, *t);
            EXPECT_EQ(max_relative_difference(read_in_place.image, copy.image, std::string("in place ") + method, 0.0),
                      0.0);
        }
        if (std::string(method) == "lightcuts") expect_lightcuts_matches(p, o, copy);
    }
}

// The BVH nodes, triangles, lights, light-tree nodes and the 4-wide BVH can
// be read through storage texel buffers instead of storage buffers (Tuning::texel_reads;
// the default on CPU devices). The same kernels read the same bits: the
// images are identical for every method. A split scene keeps the texel
// reads while each array's chunks are windows of one buffer, and falls
// back to the storage buffers where they are buffers of their own, which a
// texel view cannot cover.
TEST_F(Vulkan, TexelReadsGiveTheImagesOfStorageBufferReads) {
    const PreparedScene p = prepare_scene(random_scene(67, 60, 2, 12, 10), 1);
    vk::Tuning texels, buffers, split, split_buffers;
    texels.texel_reads = vk::Tuning::TexelReads::kOn;
    buffers.texel_reads = vk::Tuning::TexelReads::kOff;
    split.texel_reads = split_buffers.texel_reads = vk::Tuning::TexelReads::kOn;
    split.split_bytes = split_buffers.split_bytes = 256;
    split_buffers.chunk_buffers = true;
    std::vector<bool> reads;
    check_setups(p, {texels, buffers, split, split_buffers},
                 [&](const vk::RenderSetup& setup) { reads.push_back(setup.resources.texel_reads()); });
    EXPECT_EQ(reads, (std::vector<bool>{true, false, true, false}));
    for (const char* method : {"brute", "lightcuts", "sampled", "stochastic"}) {
        SCOPED_TRACE(method);
        const RenderOptions o = options(method, 12, 10);
        const RenderResult a = gpu(p, o, texels);
        const RenderResult b = gpu(p, o, buffers);
        EXPECT_EQ(max_relative_difference(a.image, b.image, std::string("texel reads ") + method, 0.0), 0.0);
        EXPECT_EQ(a.stats.shadow_rays, b.stats.shadow_rays);
    }
}

// A device is refused, with the limit named, where the kernels' one
// descriptor set does not fit: Vulkan's minimum limits allow four storage
// buffers and four storage images (texel buffers among them) per stage.
TEST(DescriptorRefusal, NamesTheLimitTheKernelsExceed) {
    VkPhysicalDeviceLimits limits{};
    limits.maxPerStageDescriptorStorageBuffers = limits.maxDescriptorSetStorageBuffers = gpu::kBindingCount;
    limits.maxPerStageDescriptorStorageImages = limits.maxDescriptorSetStorageImages = gpu::kTexelBindingCount;
    limits.maxPerStageResources = gpu::kBindingCount + gpu::kTexelBindingCount;
    const VkFormatFeatureFlags texels = VK_FORMAT_FEATURE_STORAGE_TEXEL_BUFFER_BIT;
    EXPECT_EQ(vk::descriptor_refusal(limits, texels), "");
    EXPECT_EQ(vk::descriptor_refusal(limits, VK_FORMAT_FEATURE_UNIFORM_TEXEL_BUFFER_BIT),
              "has no storage texel buffers of format R32G32B32A32_UINT");
    VkPhysicalDeviceLimits minimum = limits;
    minimum.maxPerStageDescriptorStorageImages = 4;
    EXPECT_EQ(vk::descriptor_refusal(minimum, texels),
              "allows 4 storage images (storage texel buffers among them) per shader stage, the kernels bind 5");
    minimum = limits;
    minimum.maxDescriptorSetStorageBuffers = 4;
    EXPECT_EQ(vk::descriptor_refusal(minimum, texels),
              "allows 4 storage buffers per descriptor set, the kernels bind 18");
    minimum = limits;
    minimum.maxPerStageResources = gpu::kBindingCount + gpu::kTexelBindingCount - 1u;
    EXPECT_EQ(vk::descriptor_refusal(minimum, texels), "allows 22 resources per shader stage, the kernels bind 23");
}

// The kernels' order of a tile's pixels (lc_tile_column, lc_tile_row):
// every pixel of the tile exactly once, whatever its size, and eight
// consecutive invocations a 4x2 block wherever two whole rows remain.
TEST(TilePixels, EveryPixelOnceInBlocksOfFourByTwo) {
    for (const std::uint32_t width : {1u, 3u, 8u, 128u, 130u})
        for (const std::uint32_t height : {1u, 2u, 5u, 64u}) {
            SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height));
            std::vector<int> seen(std::size_t(width) * height, 0);
            for (std::uint32_t i = 0; i < width * height; ++i) {
                const std::uint32_t x = gpu::lc_tile_column(i, width, height), y = gpu::lc_tile_row(i, width, height);
                ASSERT_LT(x, width);
                ASSERT_LT(y, height);
                ++seen[std::size_t(y) * width + x];
            }
            EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
            if (width % 4 != 0) continue;
            for (std::uint32_t group = 0; 8 * group + 7 < width * (height - height % 2); ++group) {
                const std::uint32_t i = 8 * group;
                const std::uint32_t x0 = gpu::lc_tile_column(i, width, height), y0 = gpu::lc_tile_row(i, width, height);
                for (std::uint32_t lane = 0; lane < 8; ++lane) {
                    EXPECT_EQ(gpu::lc_tile_column(i + lane, width, height), x0 + lane / 2);
                    EXPECT_EQ(gpu::lc_tile_row(i + lane, width, height), y0 + lane % 2);
                }
            }
        }
}

// workgroup_stride: workgroup j shades block (j * stride) mod groups, which
// must take every block exactly once and stay within 32-bit arithmetic.
// lavapipe hands each of its T threads one contiguous share of the
// workgroups; each share (T = 2, 4, 8) must hold between half and 1.5 times
// its even part of every quarter of the tile (where that part is at least 4
// blocks), not one end of the tile.
TEST(TilePixels, GroupStrideTakesEveryBlockOnceSpreadOverTheTile) {
    std::vector<std::uint32_t> counts;
    for (std::uint32_t g = 1; g <= 600; ++g) counts.push_back(g);
    for (const std::uint32_t g : {1000u, 4096u, 6561u, 30030u, 65536u}) counts.push_back(g);
    for (const std::uint32_t groups : counts) {
        SCOPED_TRACE(std::to_string(groups) + " workgroups");
        const std::uint32_t stride = vk::workgroup_stride(groups);
        ASSERT_LE(std::uint64_t(groups - 1) * stride, std::uint64_t(UINT32_MAX));
        std::vector<int> seen(groups, 0);
        for (std::uint32_t j = 0; j < groups; ++j) ++seen[(j * stride) % groups];
        ASSERT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
        for (const std::uint32_t threads : {2u, 4u, 8u}) {
            for (std::uint32_t t = 0; t < threads; ++t) {
                const std::uint32_t first = groups * t / threads, last = groups * (t + 1) / threads;
                for (std::uint32_t q = 0; q < 4; ++q) {
                    const std::uint32_t lo = groups * q / 4, hi = groups * (q + 1) / 4;
                    const double even = double(last - first) * (hi - lo) / groups;
                    if (even < 4.0) continue;
                    std::uint32_t in = 0;
                    for (std::uint32_t j = first; j < last; ++j) {
                        const std::uint32_t block = (j * stride) % groups;
                        in += block >= lo && block < hi ? 1u : 0u;
                    }
                    EXPECT_NEAR(in / even, 1.0, 0.5) << "thread " << t << " of " << threads << ", quarter " << q;
                }
            }
        }
    }
    EXPECT_EQ(vk::workgroup_stride(65537u), 1u);  // past 32-bit products: tile order
}

// Workgroups spread over the tile (lavapipe's default) shade the same
// pixels as in tile order: the same images and counts for every method, on
// a tile whose last workgroup is partly past it, over several tiles, and
// with cuts continued over several dispatches.
TEST_F(Vulkan, SpreadWorkgroupsGiveTheImagesOfTileOrder) {
    const PreparedScene p = prepare_scene(random_scene(73, 300, 2, 23, 17), 1);
    for (const char* method : {"brute", "lightcuts", "sampled", "stochastic"}) {
        for (const std::uint32_t budget : {0u, 4u}) {
            if (budget > 0 && std::string(method) != "lightcuts") continue;
            SCOPED_TRACE(std::string(method) + ", refinements per dispatch " + std::to_string(budget));
            const RenderOptions o = options(method, 23, 17);
            vk::Tuning spread, ordered;
            spread.spread_groups_on_cpu = true;
            ordered.spread_groups_on_cpu = false;
            spread.refinements_per_dispatch = ordered.refinements_per_dispatch = budget;
            spread.max_tile_pixels = ordered.max_tile_pixels = 23 * 17 - 64;  // two tiles
            const RenderResult a = gpu(p, o, spread);
            const RenderResult b = gpu(p, o, ordered);
            EXPECT_EQ(max_relative_difference(a.image, b.image, std::string("spread workgroups ") + method, 0.0), 0.0);
            EXPECT_EQ(a.stats.shadow_rays, b.stats.shadow_rays);
            EXPECT_EQ(a.stats.cut_size, b.stats.cut_size);
            EXPECT_EQ(a.stats.heap_paused_samples, b.stats.heap_paused_samples);
            if (std::string(method) == "lightcuts") expect_lightcuts_matches(p, o, a);
            if (std::string(method) == "brute") expect_brute_matches(p, o, a);
        }
    }
}

// The cut heaps in each invocation's private memory (Tuning::heap_memory;
// the default) and in workgroup shared memory hold
// the same entries: the images and counts are identical for Lightcuts and
// Stochastic Lightcuts, with each cut in one dispatch and spread over many
// (its heap paused in global memory between them). A heap of 8 slots
// fills, so clusters are frozen too.
TEST_F(Vulkan, PrivateHeapsGiveTheImagesOfSharedHeaps) {
    const PreparedScene p = prepare_scene(random_scene(71, 300, 2, 12, 10), 1);
    for (const char* method : {"lightcuts", "stochastic"}) {
        for (const std::uint32_t budget : {0u, 4u}) {
            SCOPED_TRACE(std::string(method) + ", refinements per dispatch " + std::to_string(budget));
            RenderOptions o = options(method, 12, 10);
            o.cut_heap = 8;
            vk::Tuning shared, own;
            shared.heap_memory = vk::Tuning::HeapMemory::kShared;
            own.heap_memory = vk::Tuning::HeapMemory::kPrivate;
            shared.refinements_per_dispatch = own.refinements_per_dispatch = budget;
            const RenderResult a = gpu(p, o, shared);
            const RenderResult b = gpu(p, o, own);
            EXPECT_FALSE(a.stats.heap_private);
            EXPECT_TRUE(b.stats.heap_private);
            EXPECT_EQ(max_relative_difference(b.image, a.image, std::string("private heaps ") + method, 0.0), 0.0);
            EXPECT_EQ(a.stats.shadow_rays, b.stats.shadow_rays);
            EXPECT_EQ(a.stats.heap_frozen_samples, b.stats.heap_frozen_samples);
            EXPECT_GT(b.stats.heap_frozen_samples, 0u);
            EXPECT_EQ(a.stats.heap_paused_samples, b.stats.heap_paused_samples);
            if (budget > 0) {
                EXPECT_GT(b.stats.heap_paused_samples, 0u);
            }
            if (std::string(method) == "lightcuts") expect_lightcuts_matches(p, o, b);
        }
    }
}

// A grey floor with two boxes on it, seen from above at 4x4 pixels; no
// lights yet.
Scene floor_with_boxes() {
    Scene s;
    s.materials = {test::lambert({0.6f, 0.5f, 0.4f})};
    test::add_quad(s, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, 0);
    test::add_box(s, {-1.0f, 0.0f, -1.0f}, {-0.3f, 0.6f, -0.3f}, 0);
    test::add_box(s, {0.4f, 0.0f, 0.2f}, {0.9f, 0.4f, 0.8f}, 0);
    s.camera = test::camera({0.0f, 2.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 50.0f, 4, 4);
    return s;
}

// At the default max_cut (1000) a cut takes at most 1001 steps, and on
// llvmpipe the renderer runs such cuts whole in one dispatch
// (Tuning::whole_cut_steps), so no heap waits in global memory between
// dispatches: here cuts refined at error 0 over 20000 lights take more
// than the 512 steps a dispatch would otherwise take, with no pass thrown
// away to the loop limit. Other devices run every cut in one dispatch.
TEST_F(Vulkan, CutsAtTheDefaultMaxCutStayInOneDispatch) {
    Scene s = floor_with_boxes();
    s.lights = test::random_point_lights(20000, {-2, 0.5f, -2}, {2, 2, 2}, 10.0f, 66);
    update_bounds(s);
    const PreparedScene p = prepare_scene(std::move(s), 1);
    RenderOptions o = options("lightcuts", 4, 4);
    o.relative_error = 0.0f;
    ASSERT_EQ(o.max_cut, 1000u);
    const RenderResult g = gpu(p, o);
    expect_lightcuts_matches(p, o, g);
    EXPECT_GT(*std::max_element(g.stats.cut_size.begin(), g.stats.cut_size.end()), 512.0f);
    EXPECT_EQ(g.stats.heap_paused_samples, 0u);
    EXPECT_EQ(g.stats.loop_limit_retries, 0u);

    // Split at 512 steps a dispatch (kLlvmpipeRefinements, llvmpipe's split
    // before; forced on any device): the same image, the deeper cuts paused.
    vk::Tuning split;
    split.whole_cut_steps = 0;
    split.refinements_per_dispatch = vk::Tuning::kLlvmpipeRefinements;
    const RenderResult h = gpu(p, o, split);
    EXPECT_EQ(max_relative_difference(h.image, g.image, "split at 512 steps", 0.0), 0.0);
    EXPECT_GT(h.stats.heap_paused_samples, 0u);
}

// Cuts refined at error 0 over 20000 lights: each refinement loops over
// heap levels, the search for the smallest entry of a full heap (64 slots)
// and a shadow ray's BVH nodes and triangles, here about 130 trips a ray
// (the needles below); together past the limit (with 4000 lights and no
// needles, the full heap ends the cuts at about 400 refinements, under it).
// On llvmpipe the renderer splits Lightcuts from the start
// (Tuning::presplit_on_llvmpipe); without that, the failed pass must split
// it.
TEST_F(Vulkan, LoopLimitSplitsLightcutsAutomatically) {
    Scene s = floor_with_boxes();
    test::add_box(s, {-0.5f, 0.8f, 0.5f}, {0.0f, 1.0f, 1.0f}, 0);
    // 300 needles: long thin triangles across the room, which the shadow
    // rays pass without touching but whose boxes they all enter: the BVH
    // cannot separate boxes that each span the room, so every ray tests
    // many of them.
    for (int k = 0; k < 300; ++k) {
        const float f = float(k) / 300.0f;
        const glm::vec3 a(-1.9f, 0.05f + 0.4f * f, -1.9f + 3.8f * f), b(1.9f, 0.45f - 0.4f * f, 1.9f - 3.8f * f);
        test::add_triangle(s, a, b, b + glm::vec3(0.0f, 0.001f, 0.0f), 0);
    }
    s.lights = test::random_point_lights(20000, {-2, 0.5f, -2}, {2, 2, 2}, 10.0f, 65);
    update_bounds(s);
    const PreparedScene p = prepare_scene(std::move(s), 1);
    RenderOptions o = options("lightcuts", 4, 4);
    o.relative_error = 0.0f;
    o.max_cut = 100000;
    vk::Tuning no_presplit;
    no_presplit.presplit_on_llvmpipe = false;
    const RenderResult g = gpu(p, o, no_presplit);
    expect_lightcuts_matches(p, o, g);
    expect_resplit_on_llvmpipe(g.stats);

    // Split from the start, as the renderer does on llvmpipe (512
    // refinements a dispatch): the same image. This scene's rays take so
    // many trips that the split must still be made finer once.
    const RenderResult presplit = gpu(p, o);
    expect_lightcuts_matches(p, o, presplit);
    std::printf("[ measured ] %s, split from the start: %u loop-limit retries\n",
                presplit.stats.device.c_str(), presplit.stats.loop_limit_retries);
    EXPECT_LE(presplit.stats.loop_limit_retries, 1u);

    // Split finely enough from the start: no pass is spoilt.
    vk::Tuning fine;
    fine.refinements_per_dispatch = 128;
    const RenderResult fine_split = gpu(p, o, fine);
    expect_lightcuts_matches(p, o, fine_split);
    EXPECT_EQ(fine_split.stats.loop_limit_retries, 0u);
}

}  // namespace
}  // namespace lc
