// PNG and JPEG textures through Debian's libstb (no *_IMPLEMENTATION macro here).
#include "textures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <system_error>
#include <utility>
#include <vector>

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
    // Grown geometrically: reserving each image's texels exactly copied
    // every texel before it for every image (102 s for 2000 images).
    if (scene.texels.capacity() < scene.texels.size() + count)
        scene.texels.reserve(std::max(scene.texels.size() + count, 2 * scene.texels.capacity()));
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
                   (sampling.nearest ? gpu::kTextureNearest : 0u) | (sampling.mipmaps ? 0u : gpu::kTextureNoMipmaps);
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

namespace {

// How a mipmap chain's texels read (decode) and are written (encode) as
// values in [0, 1]: colour through sRGB, the rest and alpha as stored.
struct MipFilter {
    std::array<float, 256> decode{};  // a stored byte -> its value (linear for sRGB)
    bool srgb = false;

    explicit MipFilter(bool srgb_) : srgb(srgb_) {
        for (int i = 0; i < 256; ++i) {
            const double c = i / 255.0;
            decode[std::size_t(i)] =
                float(srgb ? (c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4)) : c);
        }
    }

    static std::uint32_t quantize(double v) { return std::uint32_t(std::clamp(v, 0.0, 1.0) * 255.0 + 0.5); }

    std::uint32_t encode(const double rgba[4]) const {
        std::uint32_t packed = quantize(rgba[3]) << 24;
        for (int c = 0; c < 3; ++c) {
            double v = rgba[c];
            if (srgb) v = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
            packed |= quantize(v) << (8 * c);
        }
        return packed;
    }
};

// Which texels of a row (or column) of `from` texels a texel of a row of
// `to` covers, and with what weights (summing to 1): texel i covers
// [i from / to, (i + 1) from / to).
struct Footprint {
    std::uint32_t first = 0;
    std::array<double, 3> weight{};  // of texels first, first + 1, first + 2
};

std::vector<Footprint> box_footprints(std::uint32_t from, std::uint32_t to) {
    std::vector<Footprint> out(to);
    const double scale = double(from) / double(to);  // 1, 2, or between 2 and 3
    for (std::uint32_t i = 0; i < to; ++i) {
        const double lo = i * scale;
        const double hi = (i + 1) * scale;
        Footprint& f = out[i];
        f.first = std::uint32_t(std::floor(lo));
        for (std::uint32_t k = 0; k < 3 && f.first + k < from; ++k) {
            const double a = std::max(lo, double(f.first + k));
            const double b = std::min(hi, double(f.first + k + 1));
            f.weight[k] = std::max(b - a, 0.0) / scale;
        }
    }
    return out;
}

// Appends to `texels` the level below the w x h one at `offset`.
void append_level(std::vector<std::uint32_t>& texels, std::size_t offset, std::uint32_t w, std::uint32_t h,
                  const MipFilter& filter) {
    const std::uint32_t dw = std::max(w / 2, 1u);
    const std::uint32_t dh = std::max(h / 2, 1u);
    const std::vector<Footprint> columns = box_footprints(w, dw);
    const std::vector<Footprint> rows = box_footprints(h, dh);
    for (std::uint32_t y = 0; y < dh; ++y) {
        for (std::uint32_t x = 0; x < dw; ++x) {
            double sum[4] = {0.0, 0.0, 0.0, 0.0};
            for (std::uint32_t j = 0; j < 3; ++j) {
                if (rows[y].weight[j] == 0.0) continue;
                for (std::uint32_t i = 0; i < 3; ++i) {
                    const double weight = rows[y].weight[j] * columns[x].weight[i];
                    if (weight == 0.0) continue;
                    const std::uint32_t t =
                        texels[offset + std::size_t(rows[y].first + j) * w + columns[x].first + i];
                    for (int c = 0; c < 3; ++c) sum[c] += weight * filter.decode[t >> (8 * c) & 0xFFu];
                    sum[3] += weight * double(t >> 24) / 255.0;
                }
            }
            texels.push_back(filter.encode(sum));
        }
    }
}

}  // namespace

void add_mipmaps(Scene& scene) {
    // A material's texture slots, and whether each reads colour (sRGB).
    constexpr std::pair<std::uint32_t gpu::Material::*, bool> kSlots[] = {
        {&gpu::Material::base_color_texture, true},
        {&gpu::Material::emissive_texture, true},
        {&gpu::Material::metallic_roughness_texture, false},
        {&gpu::Material::normal_texture, false},
    };
    const auto chained = [&](std::uint32_t texture) {
        const gpu::TextureInfo& t = scene.textures.at(texture);
        return (t.sampling & gpu::kTextureNoMipmaps) == 0u && std::max(t.width, t.height) >= 2;
    };
    // The chains to make: one for each image (by its first texel) and way
    // it is read.
    struct Chain {
        std::uint32_t width = 0, height = 0;
        std::uint32_t mip_offset = 0;
    };
    std::map<std::pair<std::uint32_t, bool>, Chain> chains;
    for (const gpu::Material& m : scene.materials) {
        if ((m.flags & gpu::kMaterialTextured) == 0u) continue;
        for (const auto& [slot, srgb] : kSlots) {
            const std::uint32_t texture = m.*slot;
            if (texture == gpu::kInvalidIndex || !chained(texture)) continue;
            const gpu::TextureInfo& t = scene.textures[texture];
            chains[{t.offset, srgb}] = {t.width, t.height, 0};
        }
    }
    // Reserved at once, so that the chains' levels do not grow the vector a
    // level at a time.
    std::size_t added = 0;
    for (const auto& [key, chain] : chains)
        for (std::uint32_t w = chain.width, h = chain.height; w > 1 || h > 1;) {
            w = std::max(w / 2, 1u);
            h = std::max(h / 2, 1u);
            added += std::size_t(w) * h;
        }
    scene.texels.reserve(scene.texels.size() + added);
    for (auto& [key, chain] : chains) {
        const MipFilter filter(key.second);
        chain.mip_offset = std::uint32_t(scene.texels.size());
        std::size_t level = key.first;
        for (std::uint32_t w = chain.width, h = chain.height; w > 1 || h > 1;) {
            const std::size_t next = scene.texels.size();
            append_level(scene.texels, level, w, h, filter);
            level = next;
            w = std::max(w / 2, 1u);
            h = std::max(h / 2, 1u);
        }
    }
    // Each record read gets the chain of the way it is read; a record read
    // both ways, a copy for the second.
    std::map<std::pair<std::uint32_t, bool>, std::uint32_t> records;  // (record, srgb) -> record
    for (gpu::Material& m : scene.materials) {
        if ((m.flags & gpu::kMaterialTextured) == 0u) continue;
        for (const auto& [slot, srgb] : kSlots) {
            const std::uint32_t texture = m.*slot;
            if (texture == gpu::kInvalidIndex || !chained(texture)) continue;
            const auto [found, fresh] = records.try_emplace({texture, srgb}, texture);
            if (fresh) {
                const auto other = records.find({texture, !srgb});
                if (other != records.end() && other->second == texture) {
                    scene.textures.push_back(scene.textures[texture]);
                    found->second = std::uint32_t(scene.textures.size() - 1);
                }
                gpu::TextureInfo& t = scene.textures[found->second];
                t.sampling |= gpu::kTextureMipmapped;
                t.mip_offset = chains.at({t.offset, srgb}).mip_offset;
            }
            m.*slot = found->second;
        }
    }
}

std::string encoded_image_problem(const unsigned char* bytes, std::size_t size, std::uint64_t* texels) {
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
    if (w * h > kMaxTexels)
        return "is " + std::to_string(w) + " x " + std::to_string(h) + " texels, more than the " +
               std::to_string(kMaxTexels) + " that textures may hold in all";
    // stb_image's own limit, which it reports only as "too large".
    constexpr std::uint64_t kMaxSide = std::uint64_t(1) << 24;
    if (w > kMaxSide || h > kMaxSide)
        return "is " + std::to_string(w) + " x " + std::to_string(h) + " texels, more than the " +
               std::to_string(kMaxSide) + " a side that the image decoder reads";
    if (texels != nullptr) *texels = w * h;
    return "";
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
