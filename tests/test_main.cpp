#include <cstdlib>

#include <gtest/gtest.h>

int main(int argc, char** argv) {
#ifdef LC_BINARY_DIR
    // The host-specialized SPIR-V the Vulkan kernels cache between runs
    // (docs/vulkan.md) goes into the build tree, not the user's ~/.cache,
    // unless the caller chose a place.
    ::setenv("LC_SPIRV_CACHE", LC_BINARY_DIR "/test-spirv-cache", /*overwrite=*/0);
#endif
    ::testing::InitGoogleTest(&argc, argv);
    return RUN_ALL_TESTS();
}
