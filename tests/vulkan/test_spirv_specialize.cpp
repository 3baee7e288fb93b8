// Kernels specialized on the host (host/vulkan/spirv_specialize.h): the
// module SPIRV-Tools returns is valid, has nothing left to specialize, has
// lost the code the values switch off, and renders the images the driver's
// own specialization renders, bit for bit.
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <spirv-tools/libspirv.hpp>

#include "bindings.glsl"
#include "spirv/lightcuts.h"
#include "spirv_specialize.h"
#include "test_util.h"
#include "vulkan_test_support.h"

namespace lc {
namespace {

using vulkan_test::max_relative_difference;
using vulkan_test::options;
using vulkan_test::random_scene;
using vulkan_test::Vulkan;

constexpr std::size_t kLightcutsWords = sizeof lc_spirv_lightcuts / sizeof(std::uint32_t);

// The values a scene with every feature (or none) would give the Lightcuts kernel.
vk::SpecValues lightcuts_values(bool features) {
    const std::string f = features ? "true" : "false";
    vk::SpecValues v = {
        {gpu::kSpecWorkgroupSize, std::to_string(gpu::kWorkgroupSize)},
        {gpu::kSpecHeapSlots, "64"},
        {gpu::kSpecEnableGgx, f},
        {gpu::kSpecEnableShadows, "true"},
        {gpu::kSpecEnableOriented, f},
        {gpu::kSpecStochastic, "false"},
        {gpu::kSpecEnableTextures, f},
        {gpu::kSpecEnableDisney, f},
        {gpu::kSpecEnableSheen, f},
        {gpu::kSpecEnableClearcoat, f},
        {gpu::kSpecSplitScene, "false"},
        {gpu::kSpecTexelReads, "true"},
    };
    for (std::uint32_t b = 0; b < gpu::kSceneArrayCount; ++b) v[gpu::kSpecChunkShift + b] = "31";
    return v;
}

// Instructions of `words` with opcode `op` (and, for OpDecorate, decoration `decoration`).
std::size_t count_instructions(const std::vector<std::uint32_t>& words, std::uint32_t op,
                               std::uint32_t decoration = ~0u) {
    std::size_t count = 0;
    for (std::size_t i = 5; i < words.size();) {
        const std::uint32_t length = words[i] >> 16;
        if (length == 0) {
            ADD_FAILURE() << "instruction of length 0 at word " << i;
            break;
        }
        if ((words[i] & 0xFFFFu) == op && (decoration == ~0u || (length > 2 && words[i + 2] == decoration))) ++count;
        i += length;
    }
    return count;
}

constexpr std::uint32_t kOpDecorate = 71, kDecorationSpecId = 1;
constexpr std::uint32_t kOpSpecConstantTrue = 48, kOpSpecConstantOp = 52;

TEST(SpirvSpecialize, LeavesAValidModuleWithNothingToSpecialize) {
    const std::vector<std::uint32_t> original(lc_spirv_lightcuts, lc_spirv_lightcuts + kLightcutsWords);
    ASSERT_GT(count_instructions(original, kOpDecorate, kDecorationSpecId), 10u);
    const std::vector<std::uint32_t> s =
        vk::specialize_spirv(lc_spirv_lightcuts, kLightcutsWords, lightcuts_values(false), "lightcuts.comp");
    spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_2);
    std::string messages;
    tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t&, const char* m) {
        messages += std::string(m) + "\n";
    });
    EXPECT_TRUE(tools.Validate(s)) << messages;
    EXPECT_EQ(count_instructions(s, kOpDecorate, kDecorationSpecId), 0u);
    for (std::uint32_t op = kOpSpecConstantTrue; op <= kOpSpecConstantOp; ++op)
        EXPECT_EQ(count_instructions(s, op), 0u) << "opcode " << op;
}

// What host specialization is for: the code of switched-off features leaves
// the module (the Disney BRDF and texture lookups are most of it).
TEST(SpirvSpecialize, DropsTheCodeOfSwitchedOffFeatures) {
    const std::size_t all =
        vk::specialize_spirv(lc_spirv_lightcuts, kLightcutsWords, lightcuts_values(true), "lightcuts.comp").size();
    const std::size_t none =
        vk::specialize_spirv(lc_spirv_lightcuts, kLightcutsWords, lightcuts_values(false), "lightcuts.comp").size();
    std::printf("[ measured ] lightcuts.comp: %zu words, specialized %zu with every feature, %zu with none\n",
                kLightcutsWords, all, none);
    EXPECT_LT(all, kLightcutsWords);
    // Measured (glslang of Debian 12): 17,588 of 25,165 words, 0.70. The
    // limit 0.8 fails if the switches stop removing the features' code,
    // and leaves room for another glslang's code generation.
    EXPECT_LT(double(none), 0.8 * double(all)) << none << " words against " << all;
}

// The cache between runs (specialize_spirv_cached): it gives the module
// specialize_spirv gives; a second call reads the file the first wrote
// (the same file, not written again); a file cut short or with a changed
// word is not used but made afresh; other values get a file of their own;
// and a folder that cannot be written only means no cache.
TEST(SpirvSpecialize, CacheGivesTheSameModuleAndNeverUsesABadFile) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("lc-spirv-cache-test-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const vk::SpecValues values = lightcuts_values(false);
    const std::vector<std::uint32_t> fresh =
        vk::specialize_spirv(lc_spirv_lightcuts, kLightcutsWords, values, "lightcuts.comp");
    auto cached = [&](const vk::SpecValues& v, const fs::path& d) {
        return vk::specialize_spirv_cached(lc_spirv_lightcuts, kLightcutsWords, v, "lightcuts.comp", d);
    };
    auto inode = [](const fs::path& f) {
        struct stat st {};
        return ::stat(f.c_str(), &st) == 0 ? st.st_ino : ino_t(0);
    };

    EXPECT_EQ(cached(values, dir), fresh);
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir)) files.push_back(e.path());
    ASSERT_EQ(files.size(), 1u);
    const fs::path file = files[0];
    const auto size = fs::file_size(file);
    const ino_t first = inode(file);
    EXPECT_EQ(cached(values, dir), fresh);
    EXPECT_EQ(inode(file), first) << "a good file was made again";

    // One changed word of the module: not used, made again.
    {
        std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(std::streamoff(size - 8));
        const char junk[4] = {'\x5a', '\x5a', '\x5a', '\x5a'};
        f.write(junk, sizeof junk);
    }
    EXPECT_EQ(cached(values, dir), fresh);
    EXPECT_NE(inode(file), first);
    EXPECT_EQ(fs::file_size(file), size);
    // Cut short: the same.
    fs::resize_file(file, size / 2);
    EXPECT_EQ(cached(values, dir), fresh);
    EXPECT_EQ(fs::file_size(file), size);

    // Other values: their own file and module.
    const vk::SpecValues others = lightcuts_values(true);
    EXPECT_EQ(cached(others, dir), vk::specialize_spirv(lc_spirv_lightcuts, kLightcutsWords, others, "lightcuts.comp"));
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 2);
    fs::remove_all(dir);

    // A folder that cannot be made (under a file): no cache, the same module.
    const fs::path blocker = dir.string() + "-file";
    std::ofstream(blocker) << "not a folder";
    EXPECT_EQ(cached(values, blocker / "cache"), fresh);
    fs::remove(blocker);
    // No folder: no cache.
    EXPECT_EQ(cached(values, fs::path()), fresh);
}

// The folder keeps the modules used last: a new file removes the least
// recently used beyond keep_files, and old temporaries, never anything else.
TEST(SpirvSpecialize, CacheKeepsTheModulesUsedLast) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("lc-spirv-prune-test-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    auto with_heap = [](const char* slots) {
        vk::SpecValues v = lightcuts_values(false);
        v[gpu::kSpecHeapSlots] = slots;
        return v;
    };
    auto cached = [&](const char* slots) {
        return vk::specialize_spirv_cached(lc_spirv_lightcuts, kLightcutsWords, with_heap(slots), "lightcuts.comp",
                                           dir, 2);
    };
    auto files = [&] {
        std::set<std::string> names;
        for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
        return names;
    };
    cached("8");
    const std::set<std::string> first = files();
    ASSERT_EQ(first.size(), 1u);
    // File times are set explicitly: two files written within one tick of
    // the file system's clock would otherwise tie.
    const auto past = fs::file_time_type::clock::now() - std::chrono::hours(2);
    fs::last_write_time(dir / *first.begin(), past);
    std::ofstream(dir / "spirv-0.bin.tmp-1") << "left by a killed writer";
    fs::last_write_time(dir / "spirv-0.bin.tmp-1", past);
    std::ofstream(dir / "spirv-0.bin.tmp-2") << "being written";
    std::ofstream(dir / "notes.txt") << "not the cache's";
    cached("16");
    std::set<std::string> second = files();
    EXPECT_EQ(second.size(), 4u) << "two modules, the fresh temporary and notes.txt";
    EXPECT_EQ(second.count("spirv-0.bin.tmp-1"), 0u) << "an old temporary was kept";
    EXPECT_EQ(second.count("notes.txt"), 1u);
    std::string module16;
    for (const std::string& f : second)
        if (f != *first.begin() && f.rfind("spirv-", 0) == 0 && f.find(".tmp-") == std::string::npos) module16 = f;
    ASSERT_FALSE(module16.empty());
    // "8" used again (its time brought up to date), then a third module: the
    // module of "16" is the one used longest ago, and goes.
    fs::last_write_time(dir / *first.begin(), past);
    fs::last_write_time(dir / module16, past + std::chrono::minutes(1));
    cached("8");
    cached("32");
    std::set<std::string> third = files();
    EXPECT_EQ(third.size(), 4u);
    EXPECT_EQ(third.count(*first.begin()), 1u) << "the module used last but one was removed";
    EXPECT_EQ(third.count(module16), 0u) << "the module used longest ago was kept";
    fs::remove_all(dir);
}

TEST(SpirvSpecialize, RefusesAModuleItCannotReadNamingTheKernel) {
    const std::vector<std::uint32_t> garbage = {0x07230203u, 0x00010500u, 0u, 100u, 0u, 0xFFFFFFFFu};
    try {
        vk::specialize_spirv(garbage.data(), garbage.size(), {}, "broken.comp");
        FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("broken.comp"), std::string::npos) << e.what();
    }
}

// Lightcuts on a scene with GGX and shadows, every method on one with
// textures, Disney materials and spot lights: the same image and shadow rays whether
// the driver or the host specializes (under the validation layer).
TEST_F(Vulkan, HostSpecializationGivesTheDriversImages) {
    Scene textured = load_scene(LC_SOURCE_DIR "/scenes/gltf/textured.gltf");
    textured.render.area_light_samples = 256;
    const PreparedScene scenes[] = {prepare_scene(random_scene(68, 60, 2, 12, 10), 1),
                                    prepare_scene(std::move(textured), 1)};
    ASSERT_TRUE(scenes[1].has_textures && scenes[1].has_disney && scenes[1].has_oriented);
    vk::Tuning host, driver;
    host.specialize_on_host = vk::Tuning::HostSpecialization::kOn;
    driver.specialize_on_host = vk::Tuning::HostSpecialization::kOff;
    for (const PreparedScene& p : scenes) {
        for (const char* method : {"brute", "lightcuts", "sampled", "stochastic"}) {
            if (&p == &scenes[0] && std::string(method) != "lightcuts") continue;  // the kernels' switches: once
            SCOPED_TRACE(method);
            const RenderOptions o = options(method, 12, 10);
            const RenderResult a = gpu(p, o, host);
            const RenderResult b = gpu(p, o, driver);
            EXPECT_EQ(max_relative_difference(a.image, b.image, std::string("host specialization ") + method, 0.0),
                      0.0);
            EXPECT_EQ(a.stats.shadow_rays, b.stats.shadow_rays);
        }
    }
}

}  // namespace
}  // namespace lc
