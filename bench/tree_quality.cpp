// Compares light trees: the fast builder with and without the metric's cone
// term, and exact greedy clustering: build time and the mean cut size
// lightcuts selects with each tree on the same scene, image and settings
// (the cut size is what a worse tree costs).
//
//   tree_quality SCENE [SIZE]     (SIZE x SIZE pixels, default 64; the CPU's defaults)
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "lightcuts/render.h"
#include "lightcuts/scene.h"

namespace {

struct Variant {
    const char* name;
    lc::TreeBuilder builder;
    double cone_scale;
};

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: tree_quality SCENE [SIZE]\n");
        return 2;
    }
    try {
        lc::Scene scene = lc::load_scene(argv[1]);
        std::uint32_t size = argc > 2 ? std::uint32_t(std::stoul(argv[2])) : 64;
        lc::PreparedScene prepared = lc::prepare_scene(scene, 1);
        // Every light the tree holds: the scene's, area samples, environment directions.
        const std::vector<lc::gpu::Light> lights(prepared.tree.lights.begin(), prepared.tree.lights.end());
        lc::RenderOptions o;
        o.method = "lightcuts";
        o.width = o.height = size;
        std::printf("%s: %zu lights, %ux%u\n", argv[1], lights.size(), size, size);
        std::printf("%-14s %12s %14s %10s\n", "builder", "build [s]", "mean cut", "rays/px");
        // The exact builder is O(n^2): only for small sets. The cone term
        // only acts on spot and oriented lights.
        const Variant variants[] = {{"fast", lc::TreeBuilder::kFast, 1.0},
                                    {"fast, no cone", lc::TreeBuilder::kFast, 0.0},
                                    {"exact", lc::TreeBuilder::kExact, 1.0}};
        for (const Variant& v : variants) {
            if (v.builder == lc::TreeBuilder::kExact && lights.size() > 20000) continue;
            prepared.tree = lc::build_light_tree(lights, 1, v.builder, v.cone_scale);
            lc::RenderResult r = lc::render_cpu(prepared, o);
            // Over the pixels that shade a surface, as the report counts it
            // (a pixel of background has no cut: counted as 0, the sky's
            // mean was a pixel-count average).
            double sum = 0.0;
            std::size_t shaded = 0;
            for (const float c : r.stats.cut_size)
                if (c > 0.0f) sum += c, ++shaded;
            const double mean = shaded > 0 ? sum / double(shaded) : 0.0;
            std::printf("%-14s %12.3f %14.2f %10.1f\n", v.name, prepared.tree.build_seconds, mean,
                        double(r.stats.shadow_rays) / double(size * size));
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    return 0;
}
