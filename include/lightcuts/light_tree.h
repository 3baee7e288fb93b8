// The light tree (Walter et al. 2005, section 4): one binary tree per light
// type, flattened into one array of 2n-1 nodes per tree, read as-is by the
// CPU reference and the Vulkan kernels.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "lc_shared/types.h"

namespace lc {

// std::allocator, except that an element made without a value is
// default-initialized: resize() of a vector of plain structs leaves the new
// elements unwritten. The tree builder's threads then write them, and fault
// their pages in, side by side, instead of one thread zeroing gigabytes first.
template <typename T>
struct DefaultInitAllocator : std::allocator<T> {
    template <typename U>
    struct rebind {
        using other = DefaultInitAllocator<U>;
    };
    DefaultInitAllocator() noexcept = default;
    template <typename U>
    DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}

    // Arrays of 1 MiB and more start on a page and own whole pages, so that
    // a CPU Vulkan device can read them where they are
    // (VK_EXT_external_memory_host) instead of a copy.
    static constexpr std::size_t kPage = 4096;
    static constexpr std::size_t kPagedFrom = std::size_t(1) << 20;
    // The bytes an allocation of n elements owns from its start.
    static constexpr std::size_t allocation_bytes(std::size_t n) {
        return n * sizeof(T) < kPagedFrom ? n * sizeof(T) : (n * sizeof(T) + kPage - 1) / kPage * kPage;
    }
    T* allocate(std::size_t n) {
        if (n * sizeof(T) < kPagedFrom) return std::allocator<T>::allocate(n);
        return static_cast<T*>(::operator new(allocation_bytes(n), std::align_val_t(kPage)));
    }
    void deallocate(T* p, std::size_t n) noexcept {
        if (n * sizeof(T) < kPagedFrom) return std::allocator<T>::deallocate(p, n);
        ::operator delete(p, std::align_val_t(kPage));
    }

    template <typename U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void*>(p)) U;
    }
    template <typename U, typename... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

// A vector whose resize() does not zero plain structs (DefaultInitAllocator).
template <typename T>
using UninitializedVector = std::vector<T, DefaultInitAllocator<T>>;

struct LightTree {
    // One tree per light type that has lights, one after the other in type
    // order (2n-1 nodes each); roots[type] is where each starts. Lights are
    // in leaf order, so a node's lights are a contiguous range; nodes'
    // rep_light index into `lights`.
    UninitializedVector<gpu::LightNode> nodes;
    UninitializedVector<gpu::Light> lights;
    std::array<std::uint32_t, gpu::kLightTypeCount> roots;
    // Lights with zero intensity: left out of the tree (they would only
    // widen the boxes of bright clusters) and out of `lights`.
    std::size_t black_lights = 0;
    double build_seconds = 0.0;

    LightTree() { roots.fill(gpu::kInvalidIndex); }

    std::uint32_t root_count() const;
    // The most entries a cut's heap can hold: the heap keeps only interior
    // nodes, and never more than the cut (max(max_cut, roots) clusters).
    // At least 1, whatever max_cut is.
    std::uint32_t cut_heap_capacity(std::uint32_t max_cut) const;
    // The slots a cut heap of capacity `cut_heap` (render.cut_heap) gets:
    // no more than cut_heap_capacity(max_cut) ever holds. At least 1.
    std::uint32_t cut_heap_slots(std::uint32_t max_cut, std::uint32_t cut_heap) const;
};

enum class TreeBuilder {
    kFast,    // locally-ordered clustering over a Morton order (light_tree.cpp)
    kExact,   // exhaustive greedy pairing, O(n^2) per merge; small n only
};

// Builds one tree per light type from lights of any types. Deterministic for
// a given seed (representative choice) whatever the thread count. Cluster
// intensities are summed in double; the loader has checked that every
// type's total fits a float.
// `cone_scale` multiplies c, the weight of the metric's cone term (the
// diagonal of the tree's lights by default, light_tree.cpp); 0 leaves the
// term out, to measure what it buys (bench/tree_quality).
// `threads`: how many threads the build's parallel parts use (0: one per
// hardware thread); the tree is the same for any count.
LightTree build_light_tree(std::span<const gpu::Light> lights, std::uint32_t seed,
                           TreeBuilder builder = TreeBuilder::kFast, double cone_scale = 1.0,
                           unsigned threads = 0);

}  // namespace lc
