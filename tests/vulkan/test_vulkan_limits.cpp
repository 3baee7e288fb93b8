// The Vulkan path at its limits: a max_cut far beyond the tree and a heap
// too large for any buffer.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bindings.glsl"
#include "test_util.h"
#include "vulkan_test_support.h"

namespace lc {
namespace {

using vulkan_test::expect_lightcuts_matches;
using vulkan_test::options;
using vulkan_test::random_scene;
using vulkan_test::Vulkan;

std::uint64_t buffer_bytes(const RenderStats& stats, const std::string& name) {
    for (const auto& [buffer, bytes] : stats.buffer_bytes)
        if (buffer == name) return bytes;
    ADD_FAILURE() << "no buffer '" << name << "'";
    return 0;
}

// The cut heap holds interior nodes of the tree, so its capacity is
// LightTree::cut_heap_capacity(max_cut), not max_cut: a max_cut of 4e9 over
// 8 lights takes 7 slots per pixel (it was refused when the heap took
// max_cut slots).
TEST_F(Vulkan, HugeMaxCutTakesAHeapSizedByTheTree) {
    PreparedScene p = prepare_scene(random_scene(61, 8, 0, 8, 8), 1);
    RenderOptions o = options("lightcuts", 8, 8);
    o.max_cut = 4'000'000'000u;
    o.relative_error = 0.0f;  // refine every cluster whose bound is not zero
    const RenderResult g = gpu(p, o);
    expect_lightcuts_matches(p, o, g);
    ASSERT_EQ(p.tree.cut_heap_capacity(o.max_cut), 7u);
    EXPECT_EQ(buffer_bytes(g.stats, "heap spill"), 7u * sizeof(gpu::CutEntry) * 64);  // one workgroup
}

// A tree whose cut heap cannot fit one workgroup's spill region in a single
// buffer (220000 lights: 219999 slots x 20 bytes x 64 invocations, past the
// 256 MiB a buffer may use) is refused with the buffer, its size and the
// limit named.
TEST_F(Vulkan, HeapLargerThanABufferIsRefusedClearly) {
    Scene s = random_scene(62, 0, 0, 8, 8);
    s.lights = test::random_point_lights(220000, {-3, 0.5f, -3}, {3, 3, 3}, 20.0f, 62);
    update_bounds(s);
    PreparedScene p = prepare_scene(std::move(s), 1);
    RenderOptions o = options("lightcuts", 8, 8);
    o.max_cut = 4'000'000'000u;
    try {
        gpu(p, o);
        FAIL() << "expected an exception";
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("buffer 'heap spill' needs 281598720 bytes"), std::string::npos) << what;
        EXPECT_NE(what.find("219999 heap slots per pixel"), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace lc
