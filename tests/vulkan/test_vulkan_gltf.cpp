// glTF scenes on the Vulkan path: the shipped room as glTF renders like the
// room as JSON + OBJ on the device too, and the textured glTF scene
// (textures, Disney materials, point and spot lights) matches the CPU.
#include <gtest/gtest.h>

#include "gltf_room.h"
#include "test_util.h"
#include "vulkan_test_support.h"

namespace lc {
namespace {

using vulkan_test::expect_brute_matches;
using vulkan_test::max_relative_difference;
using vulkan_test::options;
using vulkan_test::Vulkan;

// As tests/test_gltf.cpp's kRoomPixelRelative: the two files' cameras and
// light values differ in the last float bits (measured 2.2e-5 on the CPU,
// 2.8e-5 on lavapipe).
constexpr double kRoomPixelRelative = 1e-4;

TEST_F(Vulkan, GltfRoomRendersLikeTheJsonRoom) {
    test::RoomTwins t = test::room_twins();
    const RenderOptions o = options("brute", 32, 32);
    const RenderResult a = gpu(prepare_scene(std::move(t.gltf), 1), o);
    const RenderResult b = gpu(prepare_scene(std::move(t.json), 1), o);
    EXPECT_LE(max_relative_difference(a.image, b.image, "gltf_room", kRoomPixelRelative), kRoomPixelRelative);
}

// Textured materials differ more between the devices than kBruteRelative
// allows. Measured on lavapipe: at most 1.65e-4 with the scene's textures,
// 1.3e-4 without the emissive texture, 4.5e-6 with every texture left out.
// The likely cause: the kernels decode sRGB texels with pow(), which the
// device approximates in its own way. The bound is about 3x the measured.
constexpr double kTexturedRelative = 5e-4;

TEST_F(Vulkan, TexturedGltfSceneMatchesTheCpu) {
    Scene s = load_scene(LC_SOURCE_DIR "/scenes/gltf/textured.gltf");
    s.render.area_light_samples = 1024;  // the glowing box; brute force sums every sample
    const PreparedScene p = prepare_scene(std::move(s), 1);
    ASSERT_EQ(p.scene.textures.size(), 4u);
    const RenderOptions o = options("brute", 32, 24);
    expect_brute_matches(p, o, gpu(p, o), kTexturedRelative);
}

}  // namespace
}  // namespace lc
