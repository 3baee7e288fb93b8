// Compares the fast light-tree builder with exact greedy clustering: build
// time and the mean cut size lightcuts selects with each tree on the same
// scene, image and settings (the cut size is what a worse tree costs).
//
//   tree_quality SCENE [--lights N] [--size S]
#include <chrono>
#include <cstdio>
#include <numeric>
#include <string>

#include "lightcuts/render.h"
#include "lightcuts/scene.h"

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: tree_quality SCENE [SIZE]\n");
        return 2;
    }
    try {
        lc::Scene scene = lc::load_scene(argv[1]);
        std::uint32_t size = argc > 2 ? std::uint32_t(std::stoul(argv[2])) : 64;
        lc::PreparedScene prepared = lc::prepare_scene(scene, 1);
        lc::RenderOptions o;
        o.method = "lightcuts";
        o.width = o.height = size;
        std::printf("%s: %zu lights, %ux%u\n", argv[1], scene.lights.size(), size, size);
        std::printf("%-8s %12s %14s %10s\n", "builder", "build [s]", "mean cut", "rays/px");
        for (auto builder : {lc::TreeBuilder::kFast, lc::TreeBuilder::kExact}) {
            prepared.tree = lc::build_light_tree(scene.lights, 1, builder);
            lc::RenderResult r = lc::render_cpu(prepared, o);
            double mean = std::accumulate(r.stats.cut_size.begin(), r.stats.cut_size.end(), 0.0) /
                          double(r.stats.cut_size.size());
            std::printf("%-8s %12.3f %14.2f %10.1f\n", builder == lc::TreeBuilder::kFast ? "fast" : "exact",
                        prepared.tree.build_seconds, mean, double(r.stats.shadow_rays) / double(size * size));
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    return 0;
}
