// Replays the fuzzers' seed corpora and every kept crash input (scene
// inputs and glTF files) through load_scene: each must load into a scene that keeps the loader's promises
// or be rejected with lc::InputError. Anything else (a crash, a sanitizer
// report in an LC_SANITIZE build, another exception) fails.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "fuzz_input.h"
#include "lightcuts/error.h"

namespace lc {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputs(std::initializer_list<const char*> dirs) {
    std::vector<fs::path> files;
    for (const char* dir : dirs) {
        if (!fs::is_directory(dir)) continue;
        for (const auto& entry : fs::directory_iterator(dir))
            if (entry.is_regular_file() && entry.path().filename().string()[0] != '.') files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

// Loads one input as the fuzz target named by the test suite would.
void replay(const fs::path& input, bool gltf) {
    std::ifstream in(input, std::ios::binary);
    ASSERT_TRUE(in) << input;
    const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    std::replace(name.begin(), name.end(), '/', '_');
    const fs::path dir = fs::temp_directory_path() / ("lc_fuzz_replay_" + std::to_string(::getpid()) + "_" + name);
    const fs::path scene_file = gltf ? fuzz::write_gltf_file(data, dir) : fuzz::write_scene_files(data, dir);
    try {
        const Scene scene = load_scene(scene_file);
        std::printf("loaded: %zu triangles, %zu lights\n", scene.triangles.size(), scene.lights.size());
        EXPECT_EQ(fuzz::check_scene_contract(scene), "");
    } catch (const InputError& e) {
        std::printf("rejected: %.200s\n", e.what());
    } catch (const std::exception& e) {
        ADD_FAILURE() << "load_scene threw something other than lc::InputError: " << e.what();
    }
    std::error_code ec;
    fs::remove_all(dir, ec);
}

std::string name_of(const ::testing::TestParamInfo<fs::path>& info) {
    std::string name = info.param.parent_path().filename().string() + "_" + info.param.filename().string();
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return name;
}

class FuzzInput : public ::testing::TestWithParam<fs::path> {};
TEST_P(FuzzInput, LoadsOrIsRejectedWithInputError) { replay(GetParam(), false); }
INSTANTIATE_TEST_SUITE_P(Fuzz, FuzzInput, ::testing::ValuesIn(inputs({LC_FUZZ_CORPUS_DIR, LC_FUZZ_REGRESSIONS_DIR})),
                         name_of);

class FuzzGltfInput : public ::testing::TestWithParam<fs::path> {};
TEST_P(FuzzGltfInput, LoadsOrIsRejectedWithInputError) { replay(GetParam(), true); }
INSTANTIATE_TEST_SUITE_P(Fuzz, FuzzGltfInput,
                         ::testing::ValuesIn(inputs({LC_FUZZ_GLTF_CORPUS_DIR, LC_FUZZ_GLTF_REGRESSIONS_DIR})),
                         name_of);

// regressions/deeply_nested_*: memory grew with the square of the nesting
// depth (over 2 GB for 400 KB of '['). Replaying them proves no crash; this
// proves the cap that fixed it, which a replay of a small file cannot.
TEST(FuzzRegression, DeepNestingIsRejectedByDepth) {
    const fs::path dir = fs::temp_directory_path() / ("lc_fuzz_replay_deep_nesting_" + std::to_string(::getpid()));
    const fs::path scene_file =
        fuzz::write_scene_files("{\"camera\": " + std::string(100, '[') + std::string(100, ']') + "}", dir);
    try {
        load_scene(scene_file);
        ADD_FAILURE() << "a 100-level scene file loaded";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("nested more than 64 levels deep"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("camera[0][0]"), std::string::npos) << e.what();
    }
    std::error_code ec;
    fs::remove_all(dir, ec);
}

// tinygltf turns `extras` into its own values recursively: a file of nested
// brackets must be refused before it runs the stack out.
TEST(FuzzRegression, DeeplyNestedGltfIsRejectedByDepth) {
    const fs::path dir = fs::temp_directory_path() / ("lc_fuzz_replay_deep_gltf_" + std::to_string(::getpid()));
    const fs::path file = fuzz::write_gltf_file(
        "{\"asset\": {\"version\": \"2.0\"}, \"extras\": " + std::string(100000, '[') + "}", dir);
    try {
        load_scene(file);
        ADD_FAILURE() << "a 100000-level glTF loaded";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("JSON nested more than 64 levels deep"), std::string::npos) << e.what();
    }
    std::error_code ec;
    fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace lc
