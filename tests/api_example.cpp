// The library without the command line: load a scene, build its BVH and
// light tree once, render it with lightcuts on the CPU and through Vulkan
// where there is a device, compare the two, and render it again on a
// Vulkan device kept open. docs/api.md walks through
// it; ctest runs it (api_example) on the room of 1000 lights.
//   api_example SCENE.json OUT.exr
#include <cstdint>
#include <cstdio>
#include <exception>

#include "lightcuts/error.h"
#include "lightcuts/image.h"
#include "lightcuts/render.h"
#include "lightcuts/scene.h"

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: api_example SCENE.json OUT.exr\n");
        return 2;
    }
    try {
        // The scene file's own settings (its `render` block and camera)
        // are in scene.render and scene.camera.
        lc::Scene scene = lc::load_scene(argv[1]);
        for (const std::string& note : scene.load_notes) std::fprintf(stderr, "note: %s\n", note.c_str());

        // What the scene's render block asks for, then lightcuts at a small size.
        lc::RenderOptions options = lc::scene_render_options(scene);
        options.method = "lightcuts";
        options.width = 64;
        options.height = 48;

        // Built once; either device renders it, as often as needed.
        const lc::PreparedScene prepared = lc::prepare_scene(std::move(scene), options.seed);
        const lc::RenderResult cpu = lc::render_cpu(prepared, options);
        std::printf("cpu: %.4f s, %.1f shadow rays a pixel\n", cpu.stats.seconds_total,
                    double(cpu.stats.shadow_rays) / (double(options.width) * options.height));
        lc::write_exr(argv[2], cpu.image);

        // The Vulkan kernels cut each pixel alone; the CPU's default shares
        // a cut among eight pixels, so the reference for them cuts per pixel.
        options.cut_sharing = "pixel";
        try {
            const lc::RenderResult gpu = lc::render_vulkan(prepared, options);
            const lc::CompareResult c = lc::compare_images(gpu.image, lc::render_cpu(prepared, options).image);
            std::printf("vulkan (%s): relative RMSE against the CPU %.2g\n", gpu.stats.device.c_str(),
                        c.relative_rmse);
            if (!(c.relative_rmse < 1e-4)) {  // the two devices differ by rounding
                std::fprintf(stderr, "error: the devices disagree\n");
                return 1;
            }

            // Several renders on one device: a VulkanRenderer opens it once.
            // Each render is render_vulkan's for the same options.
            lc::VulkanRenderer renderer;
            for (const std::uint32_t spp : {1u, 4u}) {
                options.spp = spp;
                const lc::RenderResult kept = renderer.render(prepared, options);
                std::printf("vulkan, device kept open, %u spp: %.4f s\n", spp, kept.stats.seconds_total);
                if (spp == 1u && kept.image.rgb != gpu.image.rgb) {
                    std::fprintf(stderr, "error: the kept device's render differs from render_vulkan's\n");
                    return 1;
                }
            }
        } catch (const lc::NoVulkanDevice& e) {
            std::printf("no Vulkan device: %s\n", e.what());
        }
        return 0;
    } catch (const lc::InputError& e) {  // names the file and the field
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
}
