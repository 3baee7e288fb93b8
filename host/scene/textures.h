// Textures the materials sample (shaders/lc_shared/textures.h): decoded once to
// RGBA8 and appended to Scene::texels, one TextureInfo each.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include "lightcuts/scene.h"

namespace lc::loader {

// Appends a width x height RGBA8 image (row 0 at the top, 4 bytes a texel)
// and returns its index into scene.textures, sampled as by default
// (repeated, bilinear, untransformed). Throws InputError naming
// `file` and `field` when the image is empty or the scene's texels would
// pass kMaxTexels.
std::uint32_t add_texture(Scene& scene, std::uint32_t width, std::uint32_t height, const std::uint8_t* rgba,
                          const std::string& file, const std::string& field);

// How a material samples a texture: gpu::TextureInfo's sampling and
// uv_transform, from a glTF sampler and KHR_texture_transform or an MTL
// map's options.
struct TextureSampling {
    std::uint32_t wrap_u = gpu::kTextureWrapRepeat;
    std::uint32_t wrap_v = gpu::kTextureWrapRepeat;
    bool nearest = false;
    // Minified lookups read the mipmap chain (add_mipmaps); false where a
    // glTF sampler's minFilter is NEAREST or LINEAR, which have none.
    bool mipmaps = true;
    // u' = t[0] u + t[1] v + t[2], v' = t[3] u + t[4] v + t[5].
    std::array<float, 6> uv_transform{1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f};
};

// The texture `image` (an index add_texture or load_texture returned)
// sampled as `sampling`: `image` itself where that is how it samples, or
// else a record sharing its texels, made once for each sampling.
std::uint32_t sampled_texture(Scene& scene, std::uint32_t image, const TextureSampling& sampling);

// Gives every texture that the materials sample, and that may have one
// (TextureSampling::mipmaps), its image's mipmap chain
// (gpu::TextureInfo::mip_offset; kTextureMipmapped): each level half the
// size of the one above (rounded down, at least 1 texel), each texel the
// mean of the texels of the level above that its area covers (a box filter,
// with fractional weights where a size is odd). Colour textures (base
// colour, emissive) are averaged as linear values and stored in sRGB again;
// the others, and alpha, as they are. Textures that share an image share
// its chain, made once for each way it is read; a texture record read both
// ways gets a copy for the second, and the materials that read it so are
// pointed at the copy. The chains add a third to a square image's texels,
// up to as many again for an image one texel wide.
void add_mipmaps(Scene& scene);

// Loads a PNG or JPEG (stb_image; grey, grey-alpha and RGB get alpha 1) and
// adds it. When it is missing or cannot be decoded, throws InputError
// "REFERRER: FIELD: texture 'IMAGE' ...": the file and key that named it,
// and the image.
std::uint32_t load_texture(Scene& scene, const std::filesystem::path& image, const std::string& referrer,
                           const std::string& field);

// Why stb_image cannot decode an encoded image (its failure reason, "bad
// zlib header" say), or "" where it can.
std::string image_decode_problem(const unsigned char* bytes, std::size_t size);

// All textures of a scene together hold at most this many texels (512 MiB).
inline constexpr std::uint64_t kMaxTexels = std::uint64_t(1) << 27;

// What is wrong with an encoded image before anything is decoded: not a PNG
// or a JPEG, a PNG's chunks not inside the file, or the size its header
// declares; or "" (decoding then says what else may be wrong). stb_image allocates the pixels a header
// declares however small the file: a 1 MB PNG of 16384 x 16384 zeros took
// 2 GB and 8.5 s to decode before kMaxTexels refused it.
// Where the header gives its size and there is no problem, `texels` (if
// not null) gets its width x height; otherwise it is left as it was.
std::string encoded_image_problem(const unsigned char* bytes, std::size_t size, std::uint64_t* texels = nullptr);

}  // namespace lc::loader
