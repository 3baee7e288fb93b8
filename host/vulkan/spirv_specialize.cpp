#include "spirv_specialize.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <utility>

#include <spirv-tools/optimizer.hpp>

namespace lc::vk {

std::vector<std::uint32_t> specialize_spirv(const std::uint32_t* words, std::size_t word_count,
                                            const SpecValues& values, const std::string& name) {
    spvtools::Optimizer optimizer(SPV_ENV_VULKAN_1_2);
    std::string messages;
    optimizer.SetMessageConsumer(
        [&messages](spv_message_level_t level, const char*, const spv_position_t& position, const char* text) {
            if (level > SPV_MSG_WARNING) return;
            messages += "\n  word " + std::to_string(position.index) + ": " + text;
        });
    optimizer.RegisterPass(spvtools::CreateSetSpecConstantDefaultValuePass(values))
        .RegisterPass(spvtools::CreateFreezeSpecConstantValuePass())
        .RegisterPass(spvtools::CreateFoldSpecConstantOpAndCompositePass())
        // Constant propagation carries the values into the conditions
        // computed from them; without it one round of the passes below left
        // the Disney BRDF and the texture lookups in (the room's Lightcuts
        // module: 109 KB, 89 KB after two rounds, 83 KB with it).
        .RegisterPass(spvtools::CreateCCPPass())
        .RegisterPass(spvtools::CreateDeadBranchElimPass())
        .RegisterPass(spvtools::CreateAggressiveDCEPass())
        .RegisterPass(spvtools::CreateEliminateDeadFunctionsPass())
        // Then every call inlined and the locals turned into SSA values, as
        // lavapipe would do next: done here once and kept in the cache
        // (specialize_spirv_cached), it spares lavapipe about 0.05 s of
        // pipeline creation in every render; the first render of a module
        // takes 0.03 to 0.08 s longer (docs/results/lavapipe.md, section 12).
        .RegisterPass(spvtools::CreateInlineExhaustivePass())
        .RegisterPass(spvtools::CreateLocalSingleBlockLoadStoreElimPass())
        .RegisterPass(spvtools::CreateLocalSingleStoreElimPass())
        .RegisterPass(spvtools::CreateSSARewritePass())
        .RegisterPass(spvtools::CreateAggressiveDCEPass())
        // Then the locals that are structures and arrays of constant index
        // split into scalars and those made SSA values too, and what that
        // leaves folded, shared and merged: lavapipe's part of the
        // Lightcuts pipeline for the room fell from 0.11 to 0.085 s, the
        // shading the same (docs/results/lavapipe.md, section 18). Not
        // instruction simplification: it changes the last bits of the
        // images (Vulkan.HostSpecializationGivesTheDriversImages), and not
        // merge-return, which made the shading 4% slower.
        .RegisterPass(spvtools::CreatePrivateToLocalPass())
        .RegisterPass(spvtools::CreateScalarReplacementPass())
        .RegisterPass(spvtools::CreateLocalAccessChainConvertPass())
        .RegisterPass(spvtools::CreateLocalSingleBlockLoadStoreElimPass())
        .RegisterPass(spvtools::CreateLocalSingleStoreElimPass())
        .RegisterPass(spvtools::CreateLocalMultiStoreElimPass())
        .RegisterPass(spvtools::CreateAggressiveDCEPass())
        .RegisterPass(spvtools::CreateCCPPass())
        .RegisterPass(spvtools::CreateRedundancyEliminationPass())
        .RegisterPass(spvtools::CreateDeadBranchElimPass())
        .RegisterPass(spvtools::CreateBlockMergePass())
        .RegisterPass(spvtools::CreateAggressiveDCEPass());
    // The module comes from glslangValidator, which checked it; validating
    // it again would double the time this takes.
    spvtools::OptimizerOptions options;
    options.set_run_validator(false);
    std::vector<std::uint32_t> specialized;
    if (!optimizer.Run(words, word_count, &specialized, options) || specialized.empty())
        throw std::runtime_error("could not specialize the SPIR-V of " + name + " on the host:" +
                                 (messages.empty() ? std::string(" SPIRV-Tools gave no reason") : messages));
    return specialized;
}

namespace {

// 64-bit FNV-1a, continued from `hash`.
std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t hash = 14695981039346656037ull) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) hash = (hash ^ p[i]) * 1099511628211ull;
    return hash;
}

// The values in constant-id order, as text: part of the cache's key and of
// its files.
std::string values_text(const SpecValues& values) {
    std::vector<std::pair<std::uint32_t, std::string>> sorted(values.begin(), values.end());
    std::sort(sorted.begin(), sorted.end());
    std::string text;
    for (const auto& [id, value] : sorted) text += std::to_string(id) + "=" + value + ";";
    return text;
}

// A cache file: this magic, the input's word count and hash, the values'
// text and its length, the output's word count and hash, the output.
// The version names the passes: a file made by other passes is not used.
constexpr char kCacheMagic[8] = {'L', 'C', 'S', 'P', 'V', 'C', '3', '\n'};

struct CacheHeader {
    char magic[8];
    std::uint64_t input_words, input_hash, values_bytes, output_words, output_hash;
};

std::vector<std::uint32_t> read_cached(const std::filesystem::path& file, const CacheHeader& want,
                                       const std::string& values) {
    std::ifstream in(file, std::ios::binary);
    CacheHeader got{};
    if (!in.read(reinterpret_cast<char*>(&got), sizeof got)) return {};
    if (std::memcmp(got.magic, want.magic, sizeof got.magic) != 0 || got.input_words != want.input_words ||
        got.input_hash != want.input_hash || got.values_bytes != values.size() || got.output_words == 0 ||
        got.output_words > (std::uint64_t(1) << 26))
        return {};
    std::string stored(values.size(), '\0');
    if (!in.read(stored.data(), std::streamsize(stored.size())) || stored != values) return {};
    std::vector<std::uint32_t> words(got.output_words);
    if (!in.read(reinterpret_cast<char*>(words.data()), std::streamsize(words.size() * sizeof(std::uint32_t))))
        return {};
    if (in.peek() != std::ifstream::traits_type::eof()) return {};
    if (fnv1a(words.data(), words.size() * sizeof(std::uint32_t)) != got.output_hash) return {};
    return words;
}

void write_cached(const std::filesystem::path& dir, const std::filesystem::path& file, CacheHeader header,
                  const std::string& values, const std::vector<std::uint32_t>& words) {
    std::error_code error;
    std::filesystem::create_directories(dir, error);
    if (error) return;
    header.output_words = words.size();
    header.output_hash = fnv1a(words.data(), words.size() * sizeof(std::uint32_t));
    const std::filesystem::path temporary = file.string() + ".tmp-" + std::to_string(::getpid());
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(&header), sizeof header);
        out.write(values.data(), std::streamsize(values.size()));
        out.write(reinterpret_cast<const char*>(words.data()), std::streamsize(words.size() * sizeof(std::uint32_t)));
        if (!out.flush()) {
            out.close();
            std::filesystem::remove(temporary, error);
            return;
        }
    }
    std::filesystem::rename(temporary, file, error);
    if (error) std::filesystem::remove(temporary, error);
}

// Removes the cache's modules beyond the `keep` used last, and temporaries
// older than an hour (a writer killed between writing and renaming).
// Another process may be removing the same files: every error is ignored.
void prune_cache(const std::filesystem::path& dir, std::size_t keep) {
    namespace fs = std::filesystem;
    std::error_code error;
    const auto now = fs::file_time_type::clock::now();
    std::vector<std::pair<fs::file_time_type, fs::path>> modules;
    for (fs::directory_iterator it(dir, error), end; !error && it != end; it.increment(error)) {
        const std::string file = it->path().filename().string();
        if (file.rfind("spirv-", 0) != 0) continue;
        std::error_code time_error;
        const fs::file_time_type time = fs::last_write_time(it->path(), time_error);
        if (time_error) continue;
        if (file.find(".bin.tmp-") != std::string::npos) {
            if (now - time > std::chrono::hours(1)) fs::remove(it->path(), time_error);
        } else if (file.size() > 4 && file.compare(file.size() - 4, 4, ".bin") == 0) {
            modules.emplace_back(time, it->path());
        }
    }
    if (modules.size() <= keep) return;
    std::sort(modules.begin(), modules.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    for (std::size_t i = keep; i < modules.size(); ++i) fs::remove(modules[i].second, error);
}

}  // namespace

std::vector<std::uint32_t> specialize_spirv_cached(const std::uint32_t* words, std::size_t word_count,
                                                   const SpecValues& values, const std::string& name,
                                                   const std::filesystem::path& cache_dir, std::size_t keep_files) {
    if (cache_dir.empty()) return specialize_spirv(words, word_count, values, name);
    const std::string text = values_text(values);
    CacheHeader header{};
    std::memcpy(header.magic, kCacheMagic, sizeof header.magic);
    header.input_words = word_count;
    header.input_hash = fnv1a(words, word_count * sizeof(std::uint32_t));
    header.values_bytes = text.size();
    char key[17];
    std::snprintf(key, sizeof key, "%016llx",
                  static_cast<unsigned long long>(fnv1a(text.data(), text.size(), header.input_hash)));
    const std::filesystem::path file = cache_dir / ("spirv-" + std::string(key) + ".bin");
    std::vector<std::uint32_t> cached = read_cached(file, header, text);
    if (!cached.empty()) {
        std::error_code ignored;  // marks it used, for prune_cache
        std::filesystem::last_write_time(file, std::filesystem::file_time_type::clock::now(), ignored);
        return cached;
    }
    std::vector<std::uint32_t> specialized = specialize_spirv(words, word_count, values, name);
    write_cached(cache_dir, file, header, text, specialized);
    prune_cache(cache_dir, std::max<std::size_t>(keep_files, 1));
    return specialized;
}

std::filesystem::path spirv_cache_dir() {
    if (const char* v = std::getenv("LC_SPIRV_CACHE")) {
        const std::string dir = v;
        return dir.empty() || dir == "off" ? std::filesystem::path() : std::filesystem::path(dir);
    }
    if (const char* v = std::getenv("XDG_CACHE_HOME"); v != nullptr && *v != '\0')
        return std::filesystem::path(v) / "lightcuts";
    if (const char* v = std::getenv("HOME"); v != nullptr && *v != '\0')
        return std::filesystem::path(v) / ".cache" / "lightcuts";
    return {};
}

}  // namespace lc::vk
