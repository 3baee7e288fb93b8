// Large arrays backed by transparent huge pages: the loader's light files
// and the light tree at 10^6 to 10^7 lights touch gigabytes of fresh memory,
// and faulting it in 4 KiB at a time is a large part of their time
// (docs/results/scale.md). And the release of such arrays once used.
#pragma once

#include <cstddef>
#include <cstdint>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace lc {

// Reserves room for n elements of v (a vector or string) and asks the
// kernel to back the whole 2 MiB pages inside it with transparent huge
// pages (where they are enabled, even only for madvise). Only an advice:
// nothing else changes where it is not taken.
template <typename Container>
void reserve_huge(Container& v, std::size_t n) {
    using T = typename Container::value_type;
    v.reserve(n);
#ifdef __linux__
    constexpr std::uintptr_t kHuge = std::uintptr_t(2) << 20;
    const auto first = reinterpret_cast<std::uintptr_t>(v.data());
    const std::uintptr_t begin = (first + kHuge - 1) & ~(kHuge - 1);
    const std::uintptr_t end = (first + v.capacity() * sizeof(T)) & ~(kHuge - 1);
    if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#endif
}

// Gives v's memory back now. (`v = {}` only empties it: the assignment
// from an initializer list keeps the capacity.)
template <typename Container>
void release(Container& v) {
    Container().swap(v);
}

}  // namespace lc
