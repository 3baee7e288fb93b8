// PNG and JPEG textures through Debian's libstb (no *_IMPLEMENTATION macro here).
#include "textures.h"

#include <filesystem>
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
    scene.texels.reserve(scene.texels.size() + count);
    for (std::uint64_t i = 0; i < count; ++i) {
        const std::uint8_t* t = rgba + 4 * i;
        scene.texels.push_back(std::uint32_t(t[0]) | std::uint32_t(t[1]) << 8 | std::uint32_t(t[2]) << 16 |
                               std::uint32_t(t[3]) << 24);
    }
    scene.textures.push_back(info);
    return std::uint32_t(scene.textures.size() - 1);
}

std::uint32_t load_texture(Scene& scene, const std::filesystem::path& image, const std::string& referrer,
                           const std::string& field) {
    const std::string name = "texture '" + display(image) + "'";
    std::error_code ec;
    if (!std::filesystem::is_regular_file(image, ec)) throw InputError(referrer, field, name + " not found");
    std::string bytes;
    try {
        bytes = read_input_file(image);
    } catch (const InputError&) {
        throw InputError(referrer, field, name + " cannot be read");
    }
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
