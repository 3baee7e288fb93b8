// Specialization on the host: a kernel's SPIR-V with every specialization
// constant replaced by its value and the code those values switch off
// removed, by SPIRV-Tools' optimizer. lavapipe translates and optimises a
// whole module before it specializes anything, so the code for features a
// scene does not use (the Disney BRDF, textures, ...) cost it a quarter of a
// second per render (docs/results/lavapipe.md); handed the specialized
// module, a render's set-up on the room took about 0.3 s instead of 0.45,
// and the kernel it runs is the same.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <unordered_map>
#include <vector>

namespace lc::vk {

// The value of each specialization constant, by constant id: "true",
// "false" or a decimal integer, as the module declares the constant.
using SpecValues = std::unordered_map<std::uint32_t, std::string>;

// `words` (`word_count` 32-bit words of a valid Vulkan 1.2 SPIR-V module)
// with the constants of `values` frozen to those values (constants absent
// from `values` keep their defaults), constants folded, and the branches,
// functions and instructions they make dead removed. Nothing is left to
// specialize. Throws std::runtime_error naming `name` and SPIRV-Tools'
// messages if the optimizer fails.
std::vector<std::uint32_t> specialize_spirv(const std::uint32_t* words, std::size_t word_count,
                                            const SpecValues& values, const std::string& name);

// specialize_spirv's module, kept in `cache_dir` between runs (as Mesa keeps
// the machine code it compiles): one file per module and set of values,
// named by a hash of both and holding both again, so that a file made for
// other inputs, or cut short, or changed, is never used; it is made afresh
// and written over. SPIRV-Tools takes 0.07-0.09 s for the room's Lightcuts
// kernel, on the critical path of every lavapipe render's set-up
// (docs/results/lavapipe.md, section 11). Files are written to a temporary
// name and renamed, so concurrent renders share the folder safely. An empty
// `cache_dir`, or one that cannot be read or written, only means no cache.
// The folder keeps the `keep_files` modules used last (a file's time is
// brought up to date when it is used): each new file removes the oldest
// beyond that, and temporaries a killed writer left an hour or more ago.
// Each file is 50-80 KiB for the Lightcuts kernel.
std::vector<std::uint32_t> specialize_spirv_cached(const std::uint32_t* words, std::size_t word_count,
                                                   const SpecValues& values, const std::string& name,
                                                   const std::filesystem::path& cache_dir,
                                                   std::size_t keep_files = 64);

// Where specialize_spirv_cached keeps modules: LC_SPIRV_CACHE if set ("off"
// or empty: nowhere), else $XDG_CACHE_HOME/lightcuts, else
// $HOME/.cache/lightcuts, else nowhere.
std::filesystem::path spirv_cache_dir();

}  // namespace lc::vk
