// Checks every stress case runs: a finite, well-formed light tree; bounds
// that hold for every light of every cluster at the case's real shading
// points; finite images; Lightcuts within its limits of brute force; and the
// Vulkan path against the CPU reference.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cpu_kernel.h"
#include "lightcuts/image.h"
#include "lightcuts/render.h"

namespace lc::stress {

using Kernel = cpu::ShadeKernel;

// The light range [first, first + count) of every node (lights are in leaf
// order, so each subtree is a contiguous range).
struct NodeRange {
    std::uint32_t first = 0, count = 0;
    std::uint32_t height = 1;  // of the subtree: 1 for a leaf
};

// Structural promises of the flattened tree: 2n-1 nodes per type, every float
// finite, sums and boxes of the children contained in the parent, leaves
// holding their light, subtrees contiguous. Fails the test (non-fatally,
// reporting the first few offenders) and returns the node ranges.
std::vector<NodeRange> check_tree(const PreparedScene& p);

// Primary hits of the pixel centres (spp = 1), computed exactly as the
// renderer does; pixels whose ray leaves the scene have no entry.
struct ShadingPoint {
    std::uint32_t x, y;
    Kernel::SurfacePoint sp;
};
std::vector<ShadingPoint> shading_points(const PreparedScene& p, const RenderOptions& o);

struct BoundCheck {
    std::size_t pixel_stride = 1;       // check every k-th shading point
    std::size_t max_lights_per_node = 0; // 0: every light; else this many, evenly spaced
    std::size_t max_nodes = 0;           // 0: every node; else the first k (top of the tree)
};
struct BoundStats {
    std::uint64_t light_checks = 0;      // (point, node, light) triples compared
    std::uint64_t point_inside_box = 0;  // (point, point-light node) with the point in the box
    std::uint64_t zero_bounds = 0;       // (point, interior node) with a zero bound
};
// Walter 2005 §4.1: bound(M*G) >= M_i*G_i per channel for every light i of
// every cluster, at the case's shading points; bounds finite and >= 0.
BoundStats check_bounds(const PreparedScene& p, const std::vector<NodeRange>& ranges,
                        const std::vector<ShadingPoint>& points, const BoundCheck& how);

// Every channel of every pixel finite and >= 0.
void expect_finite_image(const Image& image, const std::string& what);

struct LightcutsLimits {
    double max_rmse = 0.0;        // relative RMSE of lightcuts against brute force
    double max_above_5pct = 0.0;  // fraction of pixels whose luminance error exceeds 5%
};
// Lightcuts against brute force over the image: the aggregate limits above.
void expect_lightcuts_within_limits(const RenderResult& lightcuts, const RenderResult& brute,
                                    const LightcutsLimits& limits, const std::string& what);

// At every shading point: |Y(lightcuts) - Y(brute force)| is at most the sum
// of the final cut's error bounds (see stress_checks.cpp).
void expect_cut_guarantee(const PreparedScene& p, const RenderOptions& o,
                          const std::vector<ShadingPoint>& points, const std::string& what);

// Same image up to `rel` relative RMSE with at most `max_fraction_above_1pct`
// of pixels above 1% error (used for transformed scenes and CPU vs Vulkan).
void expect_images_agree(const Image& image, const Image& reference, double max_rmse,
                         double max_fraction_above_1pct, const std::string& what);

// All of the above for one prepared scene on the CPU: tree, bounds at the
// shading points of `o`'s image, both renders, finite images, Lightcuts
// within `limits` of brute force. Returns the two renders.
struct CpuRenders {
    RenderResult lightcuts, brute;
    BoundStats bounds;
    std::size_t shading_points = 0;
    std::uint32_t tree_height = 0;  // tallest of the two trees
};
CpuRenders run_cpu_checks(const PreparedScene& p, const RenderOptions& lightcuts_options,
                          const LightcutsLimits& limits, const BoundCheck& how, const std::string& what);

// The Vulkan half: renders on the Vulkan device with validation on. Empty
// when this build has no Vulkan path or no Vulkan device exists (the caller
// skips; under LC_REQUIRE_VULKAN=1 the test has failed already); any other
// failure (a validation message included) throws.
std::optional<RenderResult> render_vulkan_if_available(const PreparedScene& p, const RenderOptions& o);

// The CPU render the Vulkan kernels must match: each pixel's cut alone
// (cut_sharing "pixel"), as the kernels cut, whatever `o` says.
RenderResult render_cpu_as_vulkan(const PreparedScene& p, RenderOptions o);

// Writes image, reference and error map under <build>/test-output/stress/.
void write_failure_images(const std::string& label, const Image& image, const Image& reference);

}  // namespace lc::stress
