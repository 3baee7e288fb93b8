// What keeping a Vulkan device open saves a render: ROUNDS renders of a
// scene at its own render settings, each through render_vulkan (which
// opens the device and closes it after: MODE "once") or all through one
// VulkanRenderer (opened once, before the first: MODE "kept"), and each
// render's time (RenderStats::seconds_total; for VulkanRenderer::render
// without opening the device) and its kernels' (seconds_primary +
// seconds_shading). One mode a process: a device kept open also keeps
// its driver's libraries loaded, which spares render_vulkan's later
// renders in the same process their loading (lavapipe's LLVM). The device is the one render_vulkan picks (VK_DRIVER_FILES, say).
//
//   vulkan_renders once|kept SCENE [SIZE] [ROUNDS]   (SIZE x SIZE pixels, default 256; ROUNDS default 5)
#include <chrono>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>

#include "lightcuts/render.h"
#include "lightcuts/scene.h"

int main(int argc, char** argv) {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (argc < 3 || (mode != "once" && mode != "kept")) {
        std::fprintf(stderr, "usage: vulkan_renders once|kept SCENE [SIZE] [ROUNDS]\n");
        return 2;
    }
    try {
        const std::uint32_t size = argc > 3 ? std::uint32_t(std::stoul(argv[3])) : 256u;
        const int rounds = argc > 4 ? std::stoi(argv[4]) : 5;
        const lc::PreparedScene prepared = lc::prepare_scene(lc::load_scene(argv[2]), 0);
        lc::RenderOptions options = lc::scene_render_options(prepared.scene);
        options.width = size;
        options.height = size;
        std::unique_ptr<lc::VulkanRenderer> renderer;
        if (mode == "kept") {
            const auto start = std::chrono::steady_clock::now();
            renderer = std::make_unique<lc::VulkanRenderer>();
            std::printf("VulkanRenderer opened in %.3f s\n",
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        }
        for (int round = 1; round <= rounds; ++round) {
            const lc::RenderStats s =
                renderer ? renderer->render(prepared, options).stats : lc::render_vulkan(prepared, options).stats;
            std::printf("%s %s %ux%u %s on %s, render %d: %.3f s, kernels %.3f s\n", mode.c_str(), argv[2], size,
                        size, options.method.c_str(), s.device.c_str(), round, s.seconds_total,
                        s.seconds_primary + s.seconds_shading);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "vulkan_renders: %s\n", e.what());
        return 1;
    }
    return 0;
}
