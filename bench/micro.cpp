// Google Benchmark micro-benchmarks of single kernels on the CPU:
// light-tree build (point and oriented lights), one bound evaluation, one cut selection, shadow rays.
//
//   build/bench/lc_micro [--benchmark_filter=...]
#include <random>

#include <benchmark/benchmark.h>

#include "cpu_kernel.h"
#include "lightcuts/render.h"
#include "../tests/test_util.h"

namespace {

using lc::cpu::ShadeKernel;

std::vector<lc::gpu::Light> lights_in_room(std::size_t n) {
    return lc::test::random_point_lights(n, {-0.95f, 0.05f, -0.95f}, {0.95f, 1.95f, 0.95f}, 30.0f, 1);
}

void BM_TreeBuild(benchmark::State& state) {
    auto lights = lights_in_room(std::size_t(state.range(0)));
    for (auto _ : state) benchmark::DoNotOptimize(lc::build_light_tree(lights, 1).nodes.data());
    state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_TreeBuild)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMillisecond);

// The same lights as oriented ones (cosine emitters, as emissive surfaces'
// samples are) facing random directions: the builder's metric then has
// its cone term.
void BM_TreeBuildOriented(benchmark::State& state) {
    auto lights = lights_in_room(std::size_t(state.range(0)));
    std::mt19937 rng(2);
    std::normal_distribution<float> g;
    for (lc::gpu::Light& l : lights) {
        glm::vec3 axis(g(rng), g(rng), g(rng));
        axis = glm::normalize(axis + glm::vec3(0.0f, 0.0f, 1e-3f));
        l.type = lc::gpu::kLightOriented;
        l.axis_x = axis.x, l.axis_y = axis.y, l.axis_z = axis.z;
    }
    for (auto _ : state) benchmark::DoNotOptimize(lc::build_light_tree(lights, 1).nodes.data());
    state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_TreeBuildOriented)->RangeMultiplier(10)->Range(1000, 1000000)->Unit(benchmark::kMillisecond);

// BVH build over random triangles; reports bytes per triangle (every
// array of the Bvh, the triangles and their normals) as a counter.
void BM_BvhBuild(benchmark::State& state) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-100.0f, 100.0f), e(-0.5f, 0.5f);
    std::vector<lc::gpu::Triangle> tris;
    std::vector<lc::gpu::TriangleNormals> normals(std::size_t(state.range(0)));
    for (std::int64_t i = 0; i < state.range(0); ++i) {
        glm::vec3 c(u(rng), u(rng), u(rng));
        tris.push_back({c.x + e(rng), c.y + e(rng), c.z + e(rng), c.x + e(rng), c.y + e(rng), c.z + e(rng),
                        c.x + e(rng), c.y + e(rng), c.z + e(rng), 0u, 0u, 0u});
    }
    std::size_t bytes = 0;
    for (auto _ : state) {
        auto t = tris;
        auto n = normals;
        const lc::Bvh bvh = lc::build_bvh(t, n);
        // Every array the build makes (the binary tree, the CPU's 4- and
        // 8-wide trees with their leaves' copies of the triangles, the
        // Vulkan kernels' nodes), with the triangles and their normals.
        bytes = bvh.nodes.size() * sizeof(lc::gpu::BvhNode) + bvh.wide_nodes.size() * sizeof(lc::WideBvhNode) +
                bvh.wide_leaves.size() * sizeof(lc::WideLeaf) + bvh.wide8_nodes.size() * sizeof(lc::WideBvhNode8) +
                bvh.wide8_leaves.size() * sizeof(lc::WideLeaf) +
                bvh.kernel_nodes.size() * sizeof(lc::gpu::Bvh4Node) +
                t.size() * (sizeof(lc::gpu::Triangle) + sizeof(lc::gpu::TriangleNormals));
    }
    state.SetItemsProcessed(state.iterations() * state.range(0));
    state.counters["bytes_per_triangle"] = double(bytes) / double(state.range(0));
}
BENCHMARK(BM_BvhBuild)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);

// A prepared room scene with a kernel bound to it, and shading points taken
// from camera rays.
struct Fixture {
    lc::PreparedScene prepared;
    lc::gpu::FrameParams frame;
    lc::cpu::CutHeap heap;
    ShadeKernel k;
    std::vector<ShadeKernel::SurfacePoint> points;

    explicit Fixture(std::size_t n_lights) {
        prepared = lc::prepare_scene(lc::test::room_scene(lights_in_room(n_lights), 64), 1);
        lc::RenderOptions o = lc::test::options("lightcuts", 64);
        frame = lc::make_frame_params(prepared, o);
        heap = lc::cpu::CutHeap(prepared.tree.cut_heap_slots(o.max_cut, o.cut_heap));
        k = lc::cpu::make_shade_kernel(prepared, &heap);
        for (std::uint32_t y = 0; y < 64; y += 4)
            for (std::uint32_t x = 0; x < 64; x += 4) {
                ShadeKernel::SurfacePoint sp;
                if (k.lc_camera_hit(frame, x, y, 0, sp)) points.push_back(sp);
            }
    }
};

void BM_ClusterBound(benchmark::State& state) {
    Fixture f(1000);
    std::size_t i = 0;
    const auto& nodes = f.prepared.tree.nodes;
    for (auto _ : state) {
        const auto& sp = f.points[i % f.points.size()];
        const auto& n = nodes[i % nodes.size()];
        benchmark::DoNotOptimize(
            f.k.lc_cluster_bound(sp, f.prepared.scene.materials[sp.material], n, f.frame.min_distance2));
        ++i;
    }
}
BENCHMARK(BM_ClusterBound);

void BM_CutSelection(benchmark::State& state) {
    Fixture f(std::size_t(state.range(0)));
    std::size_t i = 0;
    std::uint64_t rays = 0, cut = 0, frozen = 0;
    for (auto _ : state) {
        ShadeKernel::ShadeStats ss{};
        benchmark::DoNotOptimize(f.k.lc_shade_lightcuts(f.points[i++ % f.points.size()], f.frame, ss));
        rays += ss.shadow_rays;
        cut += ss.cut_size;
        frozen += ss.frozen;
    }
    state.counters["cut_size"] = benchmark::Counter(double(cut), benchmark::Counter::kAvgIterations);
    state.counters["shadow_rays"] = benchmark::Counter(double(rays), benchmark::Counter::kAvgIterations);
    state.counters["frozen"] = benchmark::Counter(double(frozen), benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_CutSelection)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMicrosecond);

void BM_ShadowRays(benchmark::State& state) {
    Fixture f(1000);
    std::size_t i = 0;
    std::uint64_t blocked = 0;
    for (auto _ : state) {
        const auto& sp = f.points[i % f.points.size()];
        const auto& l = f.prepared.tree.lights[i % f.prepared.tree.lights.size()];
        glm::vec3 d = glm::vec3(l.x, l.y, l.z) - sp.p;
        float len = glm::length(d);
        blocked += f.k.lc_trace_shadow(sp.p, d / len, len * 0.9999f);  // the CPU path's: the 4-wide BVH
        ++i;
    }
    state.SetItemsProcessed(state.iterations());
    state.counters["blocked_fraction"] = benchmark::Counter(double(blocked), benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_ShadowRays);

}  // namespace

BENCHMARK_MAIN();
