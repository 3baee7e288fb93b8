#include "stress_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>

#include "vulkan/require_vulkan.h"

namespace lc::stress {
namespace {

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

glm::vec3 node_min(const gpu::LightNode& n) { return {n.min_x, n.min_y, n.min_z}; }
glm::vec3 node_max(const gpu::LightNode& n) { return {n.max_x, n.max_y, n.max_z}; }
glm::vec3 node_intensity(const gpu::LightNode& n) { return {n.intensity_r, n.intensity_g, n.intensity_b}; }

// Reports at most this many offenders per check, then only counts them.
constexpr int kMaxReports = 5;

std::string current_test_name() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "stress";
    std::replace(name.begin(), name.end(), '/', '_');
    return name;
}

}  // namespace

std::vector<NodeRange> check_tree(const PreparedScene& p) {
    const LightTree& tree = p.tree;
    // Black lights stay out of the tree.
    std::size_t n_point = 0, n_dir = 0, n_black = 0;
    for (const auto& l : p.scene.lights) {
        if (l.r == 0.0f && l.g == 0.0f && l.b == 0.0f) n_black += 1;
        else (l.type == gpu::kLightPoint ? n_point : n_dir) += 1;
    }
    EXPECT_EQ(tree.nodes.size(), (n_point ? 2 * n_point - 1 : 0) + (n_dir ? 2 * n_dir - 1 : 0));
    EXPECT_EQ(tree.lights.size(), n_point + n_dir);
    EXPECT_EQ(tree.black_lights, n_black);
    EXPECT_TRUE(std::isfinite(p.min_distance2) && p.min_distance2 > 0.0f) << p.min_distance2;
    for (const auto& b : p.bvh.nodes)
        EXPECT_TRUE(finite({b.min_x, b.min_y, b.min_z}) && finite({b.max_x, b.max_y, b.max_z}));

    int reports = 0;
    auto fail = [&](std::size_t i, const char* what) {
        if (reports++ < kMaxReports) ADD_FAILURE() << "light node " << i << ": " << what;
    };
    for (std::size_t i = 0; i < tree.lights.size(); ++i) {
        const gpu::Light& l = tree.lights[i];
        if (!finite({l.x, l.y, l.z}) || !finite({l.r, l.g, l.b})) fail(i, "light not finite");
    }
    // Children always sit in higher slots than their parent (flatten() hands
    // out slots top-down), so one pass from the last slot down sees every
    // child before its parent.
    std::vector<NodeRange> ranges(tree.nodes.size());
    for (std::size_t i = tree.nodes.size(); i-- > 0;) {
        const gpu::LightNode& n = tree.nodes[i];
        const glm::vec3 lo = node_min(n), hi = node_max(n), intensity = node_intensity(n);
        if (!finite(lo) || !finite(hi) || !finite(intensity)) fail(i, "not finite");
        if (!(glm::all(glm::lessThanEqual(lo, hi)))) fail(i, "box min > max");
        if (n.rep_light >= tree.lights.size()) {
            fail(i, "representative out of range");
            continue;
        }
        if (n.flags & gpu::kNodeLeaf) {
            const gpu::Light& l = tree.lights[n.rep_light];
            if (lo != glm::vec3(l.x, l.y, l.z) || hi != lo) fail(i, "leaf box is not its light");
            if (intensity != glm::vec3(l.r, l.g, l.b)) fail(i, "leaf intensity is not its light's");
            ranges[i] = {n.rep_light, 1};
            continue;
        }
        if (n.left <= i || n.left + 1 >= tree.nodes.size()) {
            fail(i, "children out of range");
            continue;
        }
        const gpu::LightNode& a = tree.nodes[n.left];
        const gpu::LightNode& b = tree.nodes[n.left + 1];
        // The node and both children are each the exact sum of their
        // lights rounded once to float (light_tree.cpp sums in double), so
        // the node is within 3 * 2^-24 of the exact sum of the children's
        // floats (intensities are >= 0).
        const glm::dvec3 sum = glm::dvec3(node_intensity(a)) + glm::dvec3(node_intensity(b));
        for (int c = 0; c < 3; ++c)
            if (std::abs(double(intensity[c]) - sum[c]) > 3.0 * 0x1p-24 * double(intensity[c]) + 1e-45)
                fail(i, "intensity is not the children's sum");
        for (const auto* child : {&a, &b})
            if (!glm::all(glm::lessThanEqual(lo, node_min(*child))) ||
                !glm::all(glm::greaterThanEqual(hi, node_max(*child))))
                fail(i, "box does not contain a child's box");
        const gpu::LightNode& rep_child = (n.flags & gpu::kNodeRepFromRight) ? b : a;
        if (n.rep_light != rep_child.rep_light) fail(i, "representative is not the flagged child's");
        const NodeRange ra = ranges[n.left], rb = ranges[n.left + 1];
        if (ra.first + ra.count != rb.first) fail(i, "children's light ranges are not adjacent");
        ranges[i] = {ra.first, ra.count + rb.count, 1 + std::max(ra.height, rb.height)};
        if (n.rep_light < ranges[i].first || n.rep_light >= ranges[i].first + ranges[i].count)
            fail(i, "representative outside the cluster");
    }
    for (std::uint32_t root : tree.roots) {
        if (root == gpu::kInvalidIndex) continue;
        const std::size_t expected = root == tree.roots[gpu::kLightPoint] ? n_point : n_dir;
        EXPECT_EQ(ranges[root].count, expected) << "root " << root;
    }
    if (reports > kMaxReports) ADD_FAILURE() << reports << " tree invariant failures in all";
    return ranges;
}

std::vector<ShadingPoint> shading_points(const PreparedScene& p, const RenderOptions& o) {
    const gpu::FrameParams f = make_frame_params(p, o);
    Kernel k = cpu::make_shade_kernel(p, nullptr);
    std::vector<ShadingPoint> points;
    for (std::uint32_t y = 0; y < f.height; ++y)
        for (std::uint32_t x = 0; x < f.width; ++x) {
            Kernel::SurfacePoint sp;
            if (k.lc_camera_hit(f, x, y, 0, sp)) points.push_back({x, y, sp});
        }
    return points;
}

BoundStats check_bounds(const PreparedScene& p, const std::vector<NodeRange>& ranges,
                        const std::vector<ShadingPoint>& points, const BoundCheck& how) {
    const LightTree& tree = p.tree;
    Kernel k = cpu::make_shade_kernel(p, nullptr);
    BoundStats stats;
    int reports = 0;
    std::uint64_t failures = 0;
    const std::size_t node_count =
        how.max_nodes ? std::min(how.max_nodes, tree.nodes.size()) : tree.nodes.size();
    // With a node cap, check the top of both trees: the first slots of each.
    std::vector<std::uint32_t> nodes;
    for (std::uint32_t type = 0; type < gpu::kLightTypeCount; ++type) {
        const std::uint32_t root = tree.roots[type];
        if (root == gpu::kInvalidIndex) continue;
        std::uint32_t end = std::uint32_t(tree.nodes.size());
        for (std::uint32_t other : tree.roots)
            if (other != gpu::kInvalidIndex && other > root) end = std::min(end, other);
        for (std::uint32_t i = root; i < end && (how.max_nodes == 0 || i - root < node_count); ++i)
            nodes.push_back(i);
    }
    for (std::size_t pi = 0; pi < points.size(); pi += std::max<std::size_t>(how.pixel_stride, 1)) {
        const ShadingPoint& s = points[pi];
        const gpu::Material& m = s.sp.mat;
        for (std::uint32_t ni : nodes) {
            const gpu::LightNode& n = tree.nodes[ni];
            const std::uint32_t type = (n.flags >> gpu::kNodeTypeShift) & gpu::kNodeTypeMask;
            const glm::vec3 lo = node_min(n), hi = node_max(n);
            const glm::vec3 bound = k.lc_cluster_bound(s.sp, m, n, p.min_distance2);
            if (!finite(bound) || glm::any(glm::lessThan(bound, glm::vec3(0.0f)))) {
                ++failures;
                if (reports++ < kMaxReports)
                    ADD_FAILURE() << "bound not finite or negative at pixel " << s.x << "," << s.y << " node "
                                  << ni << ": " << bound.x << "," << bound.y << "," << bound.z;
                continue;
            }
            if (type == gpu::kLightPoint && glm::all(glm::lessThanEqual(lo, s.sp.p)) &&
                glm::all(glm::lessThanEqual(s.sp.p, hi)))
                ++stats.point_inside_box;
            if (!(n.flags & gpu::kNodeLeaf) && bound == glm::vec3(0.0f)) ++stats.zero_bounds;
            const NodeRange r = ranges[ni];
            const std::size_t samples =
                how.max_lights_per_node ? std::min<std::size_t>(how.max_lights_per_node, r.count) : r.count;
            for (std::size_t j = 0; j < samples; ++j) {
                // Evenly spaced, always including the first and the last light.
                const std::size_t offset = samples > 1 ? j * (r.count - 1) / (samples - 1) : 0;
                const std::uint32_t li = r.first + std::uint32_t(offset);
                glm::vec3 wi;
                float t_max;
                const glm::vec3 exact = k.lc_light_unit(s.sp, tree.lights[li], p.min_distance2, wi, t_max);
                ++stats.light_checks;
                if (!finite(exact) || glm::any(glm::lessThan(bound, exact))) {
                    ++failures;
                    if (reports++ < kMaxReports) {
                        const gpu::Light& l = tree.lights[li];
                        ADD_FAILURE() << "bound below the exact value at pixel " << s.x << "," << s.y << " node "
                                      << ni << " light " << li << " (" << l.x << "," << l.y << "," << l.z
                                      << ") bound " << bound.x << "," << bound.y << "," << bound.z << " exact "
                                      << exact.x << "," << exact.y << "," << exact.z << " p " << s.sp.p.x << ","
                                      << s.sp.p.y << "," << s.sp.p.z << " n " << s.sp.n.x << "," << s.sp.n.y
                                      << "," << s.sp.n.z;
                    }
                }
            }
        }
    }
    EXPECT_EQ(failures, 0u) << "bound failures in " << stats.light_checks << " checks";
    return stats;
}

void expect_finite_image(const Image& image, const std::string& what) {
    std::size_t bad = 0;
    for (float v : image.rgb) bad += !(std::isfinite(v) && v >= 0.0f);
    EXPECT_EQ(bad, 0u) << what << ": channels that are NaN, Inf or negative";
}

// Per-point guarantee of the cut (Walter 2005 §4, with this renderer's
// bounds): a cluster's true contribution T and its estimate R both lie in
// [0, bound * I_C] per channel, so |Y(T) - Y(R)| <= Y(bound * I_C), the
// error bound its heap entry carries; leaves are exact. So at every shaded
// point, whether or not refinement stopped at max_cut,
//   |Y(lightcuts) - Y(brute force)| <= sum of the final cut's error bounds,
// the bounds of the clusters frozen out of a full heap included.
// The slack covers float rounding of the sums: 1e-5 of the magnitudes
// summed (the estimate, the exact value and the bounds themselves).
void expect_cut_guarantee(const PreparedScene& p, const RenderOptions& o,
                          const std::vector<ShadingPoint>& points, const std::string& what) {
    const gpu::FrameParams f = make_frame_params(p, o);
    cpu::CutHeap heap(p.tree.cut_heap_slots(o.max_cut, o.cut_heap));
    Kernel k = cpu::make_shade_kernel(p, &heap);
    int reports = 0;
    std::size_t violations = 0;
    double largest_share = 0.0;  // |difference| / sum of bounds, the tightest point
    for (const ShadingPoint& s : points) {
        const gpu::Material m = s.sp.mat;
        Kernel::ShadeStats stats{};
        std::uint32_t heap_size = 0;
        glm::vec3 fixed_sum, heap_sum;
        k.lc_cut_start(s.sp, m, f, heap_size, fixed_sum, heap_sum, stats, 0u, 0u);
        while (k.lc_cut_refine(s.sp, m, f, heap_size, fixed_sum, heap_sum, stats, 0u, 0u)) {
        }
        const double a = luminance(k.lc_cut_result(s.sp, f.min_distance2, heap_size, fixed_sum));
        double bounds = double(stats.frozen_error);
        for (std::uint32_t i = 0; i < heap_size; ++i) bounds += double(heap.error()[i]);
        const double r = luminance(k.lc_shade_brute(s.sp, f.light_count, f.min_distance2, stats));
        const double allowed = bounds + 1e-5 * (a + r + bounds);
        if (bounds > 0.0) largest_share = std::max(largest_share, std::abs(a - r) / bounds);
        if (!(std::abs(a - r) <= allowed)) {
            ++violations;
            if (reports++ < kMaxReports)
                ADD_FAILURE() << what << ": pixel " << s.x << "," << s.y << " lightcuts Y " << a << " brute Y " << r
                              << " cut " << stats.cut_size << " sum of the cut's error bounds " << bounds;
        }
    }
    std::printf("[ stress   ] %s: largest |error| / sum of the cut's bounds %.3f over %zu points\n", what.c_str(),
                largest_share, points.size());
    EXPECT_EQ(violations, 0u) << what << ": points whose error exceeds the sum of their cut's bounds";
}

// Lightcuts against brute force over the whole image: relative RMSE and
// the fraction of pixels above 5%, within the scene's stated limits.
void expect_lightcuts_within_limits(const RenderResult& lightcuts, const RenderResult& brute,
                                    const LightcutsLimits& limits, const std::string& what) {
    expect_finite_image(lightcuts.image, what + " lightcuts");
    expect_finite_image(brute.image, what + " brute force");
    const CompareResult cmp = compare_images(lightcuts.image, brute.image);
    std::printf("[ stress   ] %s: lightcuts vs brute relative RMSE %.5f, above 5%% %.4f, max cut hits %llu\n",
                what.c_str(), cmp.relative_rmse, cmp.fraction_above_5pct,
                static_cast<unsigned long long>(lightcuts.stats.max_cut_pixels));
    EXPECT_LE(cmp.relative_rmse, limits.max_rmse) << what;
    EXPECT_LE(cmp.fraction_above_5pct, limits.max_above_5pct) << what;
    if (!(cmp.relative_rmse <= limits.max_rmse && cmp.fraction_above_5pct <= limits.max_above_5pct))
        write_failure_images(what + "_lightcuts", lightcuts.image, brute.image);
}

void expect_images_agree(const Image& image, const Image& reference, double max_rmse,
                         double max_fraction_above_1pct, const std::string& what) {
    expect_finite_image(image, what);
    const CompareResult cmp = compare_images(image, reference);
    std::printf("[ stress   ] %s: relative RMSE %.3g, above 1%% %.4f, max %.3g\n", what.c_str(),
                cmp.relative_rmse, cmp.fraction_above_1pct, cmp.max_relative_error);
    EXPECT_LE(cmp.relative_rmse, max_rmse) << what;
    EXPECT_LE(cmp.fraction_above_1pct, max_fraction_above_1pct) << what;
    if (!(cmp.relative_rmse <= max_rmse && cmp.fraction_above_1pct <= max_fraction_above_1pct)) {
        std::vector<std::size_t> order(cmp.per_pixel.size());
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
        const std::size_t shown = std::min<std::size_t>(5, order.size());
        std::partial_sort(order.begin(), order.begin() + std::ptrdiff_t(shown), order.end(),
                          [&](std::size_t a, std::size_t b) { return cmp.per_pixel[a] > cmp.per_pixel[b]; });
        for (std::size_t k = 0; k < shown; ++k) {
            const auto x = std::uint32_t(order[k] % image.width), y = std::uint32_t(order[k] / image.width);
            std::printf("  pixel %u,%u: Y %.6g, reference Y %.6g\n", x, y, double(luminance(image.at(x, y))),
                        double(luminance(reference.at(x, y))));
        }
        write_failure_images(what, image, reference);
    }
}

CpuRenders run_cpu_checks(const PreparedScene& p, const RenderOptions& lightcuts_options,
                          const LightcutsLimits& limits, const BoundCheck& how, const std::string& what) {
    CpuRenders out;
    const std::vector<NodeRange> ranges = check_tree(p);
    const std::vector<ShadingPoint> points = shading_points(p, lightcuts_options);
    EXPECT_GT(points.size(), 0u) << what << ": no camera ray hits the scene";
    out.shading_points = points.size();
    out.bounds = check_bounds(p, ranges, points, how);
    for (std::uint32_t root : p.tree.roots)
        if (root != gpu::kInvalidIndex) out.tree_height = std::max(out.tree_height, ranges[root].height);
    std::printf("[ stress   ] %s: tree height %u, %zu shading points, %llu bound checks, %llu inside a box, "
                "%llu zero bounds\n",
                what.c_str(), out.tree_height, points.size(), static_cast<unsigned long long>(out.bounds.light_checks),
                static_cast<unsigned long long>(out.bounds.point_inside_box),
                static_cast<unsigned long long>(out.bounds.zero_bounds));
    out.lightcuts = render_cpu(p, lightcuts_options);
    RenderOptions brute_options = lightcuts_options;
    brute_options.method = "brute";
    out.brute = render_cpu(p, brute_options);
    expect_lightcuts_within_limits(out.lightcuts, out.brute, limits, what);
    expect_cut_guarantee(p, lightcuts_options, points, what);
    // Again with a heap of 3 slots, which freezes clusters at most points.
    RenderOptions small_heap = lightcuts_options;
    small_heap.cut_heap = 3;
    expect_cut_guarantee(p, small_heap, points, what + " (cut_heap 3)");
    return out;
}

std::optional<RenderResult> render_vulkan_if_available(const PreparedScene& p, const RenderOptions& o) {
#if LC_STRESS_HAVE_VULKAN
    VulkanOptions v;
    v.validation = true;  // any validation message makes render_vulkan throw
    try {
        return render_vulkan(p, o, v);
    } catch (const NoVulkanDevice& e) {
        if (test::vulkan_required()) ADD_FAILURE() << test::kNoVulkanButRequired << ": " << e.what();
        return std::nullopt;
    }
#else
    (void)p;
    (void)o;
    if (test::vulkan_required())
        ADD_FAILURE() << "LC_REQUIRE_VULKAN=1, but this build has no Vulkan path (lc_vulkan)";
    return std::nullopt;
#endif
}

RenderResult render_cpu_as_vulkan(const PreparedScene& p, RenderOptions o) {
    o.cut_sharing = "pixel";
    return render_cpu(p, o);
}

void write_failure_images(const std::string& label, const Image& image, const Image& reference) {
    const std::filesystem::path dir = std::filesystem::path(LC_BINARY_DIR) / "test-output" / "stress";
    std::filesystem::create_directories(dir);
    std::string stem = (dir / (current_test_name() + "_" + label)).string();
    std::replace(stem.begin() + std::ptrdiff_t(dir.string().size()), stem.end(), ' ', '_');
    write_exr(stem + "_image.exr", image);
    write_exr(stem + "_reference.exr", reference);
    const CompareResult cmp = compare_images(image, reference);
    write_heatmap_png(stem + "_error.png", image.width, image.height, cmp.per_pixel, 0.05f);
    std::printf("comparison images written to %s_{image,reference}.exr and %s_error.png\n", stem.c_str(),
                stem.c_str());
}

}  // namespace lc::stress
