// PNG and JPEG textures through Debian's libstb (no *_IMPLEMENTATION macro here).
#include "textures.h"

#include <algorithm>
#include <filesystem>
#include <limits>
#include <memory>
#include <system_error>

#include <stb_image.h>

#include "input_file.h"
#include "lightcuts/error.h"

namespace lc::loader {

std::uint32_t add_texture(Scene& scene, std::uint32_t width, std::uint32_t height, const std::uint8_t* rgba,
                          const std::string& file, const std::string& field) {
    if (width == 0 || height == 0) throw InputError(file, field, "image has no texels");
    const std::uint64_t count = std::uint64_t(width) * height;
    if (scene.texels.size() + count > kMaxTexels)
        throw InputError(file, field,
                         "textures would hold more than " + std::to_string(kMaxTexels) + " texels in all");
    gpu::TextureInfo info{};
    info.offset = std::uint32_t(scene.texels.size());
    info.width = width;
    info.height = height;
    const TextureSampling untransformed;
    std::copy(untransformed.uv_transform.begin(), untransformed.uv_transform.end(), info.uv_transform);
    scene.texels.reserve(scene.texels.size() + count);
    for (std::uint64_t i = 0; i < count; ++i) {
        const std::uint8_t* t = rgba + 4 * i;
        scene.texels.push_back(std::uint32_t(t[0]) | std::uint32_t(t[1]) << 8 | std::uint32_t(t[2]) << 16 |
                               std::uint32_t(t[3]) << 24);
    }
    scene.textures.push_back(info);
    return std::uint32_t(scene.textures.size() - 1);
}

std::uint32_t sampled_texture(Scene& scene, std::uint32_t image, const TextureSampling& sampling) {
    gpu::TextureInfo info = scene.textures.at(image);
    info.sampling = sampling.wrap_u | sampling.wrap_v << gpu::kTextureWrapVShift |
                   (sampling.nearest ? gpu::kTextureNearest : 0u);
    const TextureSampling identity;
    if (sampling.uv_transform != identity.uv_transform) info.sampling |= gpu::kTextureTransformed;
    std::copy(sampling.uv_transform.begin(), sampling.uv_transform.end(), info.uv_transform);
    const auto same = [&](const gpu::TextureInfo& t) {
        return t.offset == info.offset && t.width == info.width && t.height == info.height &&
               t.sampling == info.sampling && std::equal(t.uv_transform, t.uv_transform + 6, info.uv_transform);
    };
    if (same(scene.textures[image])) return image;
    const auto found = std::find_if(scene.textures.begin(), scene.textures.end(), same);
    if (found != scene.textures.end()) return std::uint32_t(found - scene.textures.begin());
    scene.textures.push_back(info);
    return std::uint32_t(scene.textures.size() - 1);
}

std::string encoded_image_problem(const unsigned char* bytes, std::size_t size) {
    static constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    const bool png = size >= 8 && std::equal(kPngSignature, kPngSignature + 8, bytes);
    // Only PNG and JPEG (whose files start FF D8 FF): stb_image would
    // decode BMP, GIF, TGA, PSD, PIC, PNM and HDR files as well, and no
    // scene has a use for its decoders of those.
    if (!png && !(size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF))
        return "is neither a PNG nor a JPEG file (textures must be one or the other)";
    const auto big_endian = [&](std::size_t at) {
        return std::uint64_t(bytes[at]) << 24 | std::uint64_t(bytes[at + 1]) << 16 |
               std::uint64_t(bytes[at + 2]) << 8 | bytes[at + 3];
    };
    std::uint64_t w = 0, h = 0;
    if (png) {
        // A PNG's chunks, each a 4-byte big-endian length, a 4-byte type,
        // the data and a CRC, must lie inside the file: stb_image reserves
        // an IDAT chunk's length before it finds the data missing (1.2 GB
        // for a 70-byte file in the fuzzer's corpus).
        std::size_t chunk = 0;
        bool ended = false;
        for (std::size_t at = 8; at + 8 <= size; ++chunk) {
            const std::uint64_t length = big_endian(at);
            if (length + 12 > size - at)
                return "is a corrupt or truncated PNG: chunk " + std::to_string(chunk + 1) + " claims " +
                       std::to_string(length) + " bytes of data, " + std::to_string(length + 12) +
                       " with its length, type and CRC, and " + std::to_string(size - at) + " are left";
            if (std::equal(bytes + at + 4, bytes + at + 8, "IEND")) {
                ended = true;
                break;
            }
            at += std::size_t(length) + 12;
        }
        // A file cut between chunks: stb_image would name the last chunk
        // type it read, bytes of the file.
        if (!ended)
            return "is a corrupt or truncated PNG: it ends after " + std::to_string(chunk) +
                   (chunk == 1 ? " chunk" : " chunks") + " without the IEND chunk that closes a PNG";
        // The size from the header chunk itself: stb_image does not say one
        // above 2^24 a side.
        if (!std::equal(bytes + 12, bytes + 16, "IHDR")) return "";  // decoding says what is wrong
        w = big_endian(16);
        h = big_endian(20);
    } else {
        int iw = 0, ih = 0, channels = 0;
        if (size > std::size_t(std::numeric_limits<int>::max()) ||
            stbi_info_from_memory(bytes, int(size), &iw, &ih, &channels) == 0)
            return "";
        w = std::uint64_t(iw);
        h = std::uint64_t(ih);
    }
    if (w * h <= kMaxTexels) return "";
    return "is " + std::to_string(w) + " x " + std::to_string(h) + " texels, more than the " +
           std::to_string(kMaxTexels) + " that textures may hold in all";
}

std::string image_decode_problem(const unsigned char* bytes, std::size_t size) {
    if (size > std::size_t(std::numeric_limits<int>::max())) return "too large to decode";
    int w = 0, h = 0, channels = 0;
    std::unique_ptr<stbi_uc, void (*)(void*)> pixels(stbi_load_from_memory(bytes, int(size), &w, &h, &channels, 4),
                                                     stbi_image_free);
    if (pixels) return "";
    const char* why = stbi_failure_reason();
    return why != nullptr ? why : "unknown";
}

std::uint32_t load_texture(Scene& scene, const std::filesystem::path& image, const std::string& referrer,
                           const std::string& field) {
    const std::string name = "texture '" + display(image) + "'";
    if (const std::string problem = input_file_problem(image); !problem.empty())
        throw InputError(referrer, field, name + (problem == kFileNotFound ? " not found" : ": " + problem));
    std::string bytes;
    try {
        bytes = read_input_file(image);
    } catch (const InputError&) {
        throw InputError(referrer, field, name + " cannot be read");
    }
    const std::string problem = encoded_image_problem(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
    if (!problem.empty()) throw InputError(referrer, field, name + " " + problem);
    int w = 0, h = 0, channels = 0;
    std::unique_ptr<stbi_uc, void (*)(void*)> pixels(
        stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()), int(bytes.size()), &w, &h, &channels,
                              4),
        stbi_image_free);
    if (!pixels) {
        const char* why = stbi_failure_reason();
        throw InputError(referrer, field,
                         name + " cannot be decoded as PNG or JPEG" + (why ? std::string(" (") + why + ")" : ""));
    }
    return add_texture(scene, std::uint32_t(w), std::uint32_t(h), pixels.get(), referrer, field);
}

}  // namespace lc::loader
