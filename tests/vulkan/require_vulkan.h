// LC_REQUIRE_VULKAN=1 makes a missing Vulkan device fail the GPU tests (and
// the Vulkan half of the stress tests) instead of skipping them, so that a
// CI whose Vulkan driver went missing is not green (docs/testing.md).
#pragma once

#include <cstdlib>
#include <cstring>

namespace lc::test {

// Set to anything but empty or "0" (tests/cli_test.sh reads it the same way:
// a CI that sets it to "true" must not skip the GPU tests).
inline bool vulkan_required() {
    const char* value = std::getenv("LC_REQUIRE_VULKAN");
    return value != nullptr && *value != '\0' && std::strcmp(value, "0") != 0;
}

// The failure's text; tests/vulkan/CMakeLists.txt's check of the switch looks for it.
inline constexpr const char* kNoVulkanButRequired =
    "no Vulkan device, and LC_REQUIRE_VULKAN=1 makes that a failure";

}  // namespace lc::test
