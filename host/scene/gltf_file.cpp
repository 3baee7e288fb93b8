// read_gltf_file (gltf_file.h).
#include "gltf_file.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <limits>
#include <map>
#include <string_view>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "gltf_types.h"
#include "input_file.h"
#include "lightcuts/error.h"
#include "textures.h"

namespace lc::loader {
namespace {

namespace fs = std::filesystem;

// Extensions whose meaning this loader honours: a file may require them.
constexpr std::array kSupportedExtensions{"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                          "KHR_materials_clearcoat", "KHR_materials_sheen",
                                          "KHR_texture_transform"};

bool supported(const std::string& extension) {
    return std::find(kSupportedExtensions.begin(), kSupportedExtensions.end(), extension) !=
           kSupportedExtensions.end();
}

// Deeper JSON than any glTF needs; tinygltf converts `extras` recursively,
// so a file of nested brackets would otherwise run the stack out.
constexpr int kMaxJsonDepth = 64;

bool too_deep(std::string_view json) {
    int depth = 0;
    bool in_string = false;
    for (std::size_t i = 0; i < json.size(); ++i) {
        const char c = json[i];
        if (in_string) {
            if (c == '\\') ++i;
            else if (c == '"') in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth) return true;
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return false;
}

std::string trimmed(std::string text) {
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    return text;
}

int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return 0;
}

// A URI's file name as tinygltf 2.7 opens it: "%20" and the like are the
// bytes they encode, "+" is a space.
std::string decoded_uri(const std::string& uri) {
    std::string out;
    for (std::size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '+') {
            out += ' ';
        } else if (uri[i] == '%' && i + 2 < uri.size()) {
            out += char(hex_digit(uri[i + 1]) * 16 + hex_digit(uri[i + 2]));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

// The bytes a base64 data URI decodes to (tinygltf decodes only base64).
std::uint64_t data_uri_bytes(const std::string& uri) {
    const std::size_t comma = uri.find(',');
    if (comma == std::string::npos) return 0;
    std::uint64_t digits = uri.size() - comma - 1;
    std::size_t end = uri.size();
    while (end > comma + 1 && uri[end - 1] == '=') --end, --digits;
    return digits * 3 / 4;
}

// What makes a data URI's base64 undecodable ("" if nothing): a character
// outside the alphabet (tinygltf decodes unpadded base64 too).
std::string base64_problem(const std::string& uri) {
    const std::size_t comma = uri.find(',');
    if (comma == std::string::npos) return "the data URI has no ',' before its data";
    for (std::size_t i = comma + 1; i < uri.size(); ++i) {
        const unsigned char c = static_cast<unsigned char>(uri[i]);
        const bool padding = c == '=' && i + 2 >= uri.size() && (i + 1 == uri.size() || uri[i + 1] == '=');
        if (!(std::isalnum(c) || c == '+' || c == '/' || padding))
            return "the data URI's base64 holds " +
                   (std::isprint(c) ? "'" + std::string(1, char(c)) + "'" : "byte " + std::to_string(int(c))) +
                   " at character " + std::to_string(i - comma - 1) + " of its data";
    }
    return "";
}

// A data URI's media type, as written ("" where it has none).
std::string data_uri_type(const std::string& uri) {
    const std::size_t end = uri.find_first_of(";,", 5);
    return uri.substr(5, end == std::string::npos ? std::string::npos : end - 5);
}

// tinygltf's messages quote a data URI whole (megabytes on one line):
// each is cut to its start and its length.
std::string shortened_data_uris(std::string text) {
    constexpr std::size_t kKeep = 48;
    for (std::size_t at = text.find("data:"); at != std::string::npos; at = text.find("data:", at + 1)) {
        std::size_t end = at;
        while (end < text.size() && !std::isspace(static_cast<unsigned char>(text[end])) && text[end] != '\'' &&
               text[end] != '"')
            ++end;
        if (end - at > kKeep + 16)
            text.replace(at + kKeep, end - at - kKeep, "... (" + std::to_string(end - at) + " characters)");
    }
    return text;
}

// A glTF's images as the JSON names them, before tinygltf decodes them.
struct GltfImages {
    std::vector<std::string> uris;  // the file each names; "" for a data URI or a buffer view
    std::vector<bool> used;         // whether a material reads a texture of the image
    std::uint64_t texels = 0;       // of the used images decoded so far, from their headers
    // The buffers' files longer than their byteLength, by the path tinygltf
    // opens: glTF allows them, tinygltf wants exactly byteLength bytes, so
    // gltf_read_file gives it those.
    std::map<std::string, std::uint64_t> buffer_lengths;
    // Images no material reads whose data URIs tinygltf does not decode
    // (image/webp, say): noted once here, tinygltf's two warnings dropped.
    std::vector<std::size_t> unread_data_images;
};

// The file tinygltf 2.7 opens for a buffer's or an image's URI: the decoded
// URI after the base folder and a '/', even when the URI is absolute.
fs::path uri_file(const std::string& base, const std::string& uri) {
    return fs::path(base + "/" + decoded_uri(uri));
}

// tinygltf reads a buffer's or an image's file whole, taking its size from a
// seek to its end: a folder's "size" makes it ask for about 2^63 bytes
// (std::bad_alloc), and a device or a pipe may never end. So every URI that
// tinygltf would open must name a regular file, checked in the file's JSON
// before tinygltf reads it. A missing buffer or image is refused here, an
// image used or not (tinygltf would only warn, and a texture of it fail
// without naming the file), and a buffer whose file or data URI does not
// hold its byteLength. JSON that
// does not parse is left to tinygltf's message. Returns each image's uri
// ("" for a data URI or a buffer view) and whether a material reads it, for
// load_image_checked.
GltfImages check_uri_files(const nlohmann::json& doc, const std::string& base, const std::string& name) {
    GltfImages out;
    std::vector<std::string>& image_uris = out.uris;
    if (!doc.is_object()) return out;
    if (const auto images = doc.find("images"); images != doc.end() && images->is_array())
        for (const nlohmann::json& image : *images) {
            const auto uri = image.is_object() ? image.find("uri") : image.end();
            const bool named = image.is_object() && uri != image.end() && uri->is_string() &&
                               uri->get_ref<const std::string&>().rfind("data:", 0) != 0;
            image_uris.push_back(named ? uri->get<std::string>() : std::string());
        }
    // The images of the textures that the materials' read slots name
    // (gltf_materials.cpp; an occlusion texture, say, is not read).
    out.used.assign(image_uris.size(), false);
    const auto member = [](const nlohmann::json& object, const char* key) -> const nlohmann::json* {
        if (!object.is_object()) return nullptr;
        const auto found = object.find(key);
        return found != object.end() ? &*found : nullptr;
    };
    const nlohmann::json* textures = member(doc, "textures");
    const nlohmann::json* materials = member(doc, "materials");
    if (textures != nullptr && textures->is_array() && materials != nullptr && materials->is_array())
        for (const nlohmann::json& material : *materials) {
            const nlohmann::json* pbr = member(material, "pbrMetallicRoughness");
            for (const nlohmann::json* info :
                 {pbr ? member(*pbr, "baseColorTexture") : nullptr, pbr ? member(*pbr, "metallicRoughnessTexture") : nullptr,
                  member(material, "normalTexture"), member(material, "emissiveTexture")}) {
                const nlohmann::json* texture = info ? member(*info, "index") : nullptr;
                if (texture == nullptr || !texture->is_number_unsigned() ||
                    texture->get<std::uint64_t>() >= textures->size())
                    continue;
                const nlohmann::json* source = member((*textures)[texture->get<std::size_t>()], "source");
                if (source != nullptr && source->is_number_unsigned() && source->get<std::uint64_t>() < out.used.size())
                    out.used[source->get<std::size_t>()] = true;
            }
        }
    for (const char* list : {"buffers", "images"}) {
        const auto entries = doc.find(list);
        if (entries == doc.end() || !entries->is_array()) continue;
        const bool buffers = list == std::string("buffers");
        for (std::size_t i = 0; i < entries->size(); ++i) {
            const nlohmann::json& entry = (*entries)[i];
            if (!entry.is_object()) continue;
            const auto uri = entry.find("uri");
            if (uri == entry.end() || !uri->is_string()) continue;
            const std::string& text = uri->get_ref<const std::string&>();
            const std::string field = std::string(list) + "[" + std::to_string(i) + "]";
            // A buffer must hold at least byteLength bytes (glTF 2.0,
            // "Buffers"); tinygltf said only "Failed to decode" with the
            // whole data URI, or "File size mismatch", where it did not.
            const auto length = entry.find("byteLength");
            const bool has_length = buffers && length != entry.end() && length->is_number_unsigned();
            const std::uint64_t byte_length = has_length ? length->get<std::uint64_t>() : 0;
            if (text.empty()) continue;
            if (text.rfind("data:", 0) == 0) {
                if (!tinygltf::IsDataURI(text)) {
                    // A type tinygltf does not decode (image/webp, say): no
                    // error for an image no material reads, which a texture
                    // may offer beside a PNG (tinygltf notes it as missing).
                    if (!buffers && !(i < out.used.size() && out.used[i])) {
                        out.unread_data_images.push_back(i);
                        continue;
                    }
                    throw InputError(name, field + ".uri",
                                     "a data URI of type '" + data_uri_type(text) + "', which is not read (" +
                                         (buffers ? "a buffer's is application/octet-stream or application/gltf-buffer"
                                                  : "an image a material reads is a PNG or a JPEG") +
                                         ", in base64)");
                }
                if (const std::string problem = base64_problem(text); !problem.empty())
                    throw InputError(name, field + ".uri", problem);
                const std::uint64_t held = data_uri_bytes(text);
                if (has_length && held != byte_length)
                    throw InputError(name, field + ".byteLength",
                                     std::to_string(byte_length) + ", but its data URI holds " + std::to_string(held) +
                                         " bytes" +
                                         (held > byte_length ? " (the glTF loader, tinygltf, reads a data URI of "
                                                               "exactly byteLength bytes)"
                                                             : ""));
                continue;
            }
            // "%00" decodes to a NUL, which would end the name where the
            // system reads it, and another file be opened.
            if (decoded_uri(text).find('\0') != std::string::npos)
                throw InputError(name, field + ".uri", "'" + text + "' decodes to a file name with a NUL character");
            const fs::path file = uri_file(base, text);
            const std::string problem = input_file_problem(file);
            if (problem == kFileNotFound) {
                // tinygltf 2.7 reads '+' as a space, as in a query string.
                const bool plus_named = text.find('+') != std::string::npos &&
                                        input_file_problem(fs::path(base + "/" + text)).empty();
                throw InputError(name, field + ".uri",
                                 "'" + text + "' not found next to the glTF" +
                                     (plus_named ? " (the glTF loader, tinygltf, reads '+' in a URI as a space; "
                                                   "write it as %2B)"
                                                 : ""));
            }
            if (!problem.empty()) throw InputError(name, field + ".uri", "'" + text + "' " + problem);
            std::error_code ec;
            const std::uintmax_t bytes = fs::file_size(file, ec);
            if (has_length && !ec && bytes < byte_length)
                throw InputError(name, field + ".byteLength",
                                 std::to_string(byte_length) + ", but '" + text + "' holds " + std::to_string(bytes) +
                                     " bytes");
            if (has_length && !ec && bytes > byte_length)
                out.buffer_lengths[file.lexically_normal().string()] = byte_length;
        }
    }
    return out;
}

// tinygltf's own image loader (stb_image) after a look at the image's
// header: one larger than the scene's textures may hold, or one that would
// take the images the materials read past that together, is refused before
// its pixels are allocated (encoded_image_problem). An image no material
// reads is not decoded, nor its format checked. An image that stb_image cannot decode is named with
// stb's reason (tinygltf says "Unknown image format" for all of them);
// `user_data` is check_uri_files' GltfImages.
bool load_image_checked(tinygltf::Image* image, const int index, std::string* err, std::string* warn,
                        int req_width, int req_height, const unsigned char* bytes, int size, void* user_data) {
    GltfImages& images = *static_cast<GltfImages*>(user_data);
    const std::vector<std::string>& uris = images.uris;
    const bool known = index >= 0 && std::size_t(index) < uris.size();
    const std::string uri = known && !uris[std::size_t(index)].empty() ? " ('" + uris[std::size_t(index)] + "')"
                                                                       : std::string();
    // Not read, so neither decoded nor held to PNG or JPEG: a WebP or KTX2
    // image whose texture falls back to a PNG (EXT_texture_webp,
    // KHR_texture_basisu) is such an image.
    if (known && !images.used[std::size_t(index)]) return true;
    const std::size_t size_bytes = std::size_t(std::max(size, 0));
    std::uint64_t texels = 0;
    const std::string problem = encoded_image_problem(bytes, size_bytes, &texels);
    if (!problem.empty()) {
        if (err != nullptr) *err += "images[" + std::to_string(index) + "]" + uri + " " + problem + "\n";
        return false;
    }
    images.texels += texels;
    if (images.texels > kMaxTexels) {
        if (err != nullptr)
            *err += "images[" + std::to_string(index) + "]" + uri + ": the images the materials read would hold more than " +
                    std::to_string(kMaxTexels) + " texels in all\n";
        return false;
    }
    const std::size_t before = err != nullptr ? err->size() : 0;
    if (tinygltf::LoadImageData(image, index, err, warn, req_width, req_height, bytes, size, nullptr)) return true;
    if (err != nullptr) {
        err->resize(before);
        *err += "images[" + std::to_string(index) + "]" + uri + " cannot be decoded as PNG or JPEG (" +
                image_decode_problem(bytes, size_bytes) + ")\n";
    }
    return false;
}

// tinygltf's file access, through ours (its FsCallbacks). A URI is looked
// for in the glTF's folder only: tinygltf would try the current folder
// next, where a file of that name would be read in its place. It must be a
// regular file there (check_uri_files names the field where it is not),
// is read by read_input_file, which notes it as one of the scene's inputs,
// and its name is taken as written (tinygltf's own ExpandFilePath runs it
// through wordexp).
struct GltfFolder {
    std::string prefix;  // the folder and a '/', as tinygltf joins it to a URI
    const std::map<std::string, std::uint64_t>* buffer_lengths;  // GltfImages'
};

bool gltf_file_exists(const std::string& path, void* folder) {
    return path.rfind(static_cast<const GltfFolder*>(folder)->prefix, 0) == 0 && input_file_problem(path).empty();
}

std::string gltf_expand_path(const std::string& path, void*) { return path; }

bool gltf_read_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* folder) {
    try {
        const std::string bytes = read_input_file(path);
        std::size_t keep = bytes.size();
        const auto& lengths = *static_cast<const GltfFolder*>(folder)->buffer_lengths;
        if (const auto it = lengths.find(fs::path(path).lexically_normal().string()); it != lengths.end())
            keep = std::min<std::uint64_t>(keep, it->second);
        out->assign(bytes.begin(), bytes.begin() + std::ptrdiff_t(keep));
        return true;
    } catch (const std::exception& e) {
        if (err != nullptr) *err = e.what();
        return false;
    }
}

bool gltf_write_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err != nullptr) *err = "the renderer writes no glTF files";
    return false;
}

}  // namespace

tinygltf::Model read_gltf_file(const fs::path& file, GltfNotes& notes) {
    const std::string& name = notes.file();
    // Before it is read: a GLB's lengths are 32-bit, and tinygltf takes an
    // unsigned int (a 4 GiB file took 12 s and 4 GiB of memory to refuse).
    std::error_code ec;
    const std::uintmax_t size = fs::file_size(file, ec);
    constexpr std::uintmax_t kMost = std::numeric_limits<unsigned int>::max();
    if (!ec && size > kMost)
        throw InputError(name, "", "the file is " + std::to_string(size) + " bytes; a glTF file holds at most " +
                                       std::to_string(kMost) + " (GLB's lengths are 32-bit)");
    const std::string bytes = read_input_file(file);  // names the file when missing
    if (bytes.size() > kMost) throw InputError(name, "", "file too large");
    const bool binary = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
    std::string_view json(bytes);
    if (binary && bytes.size() >= 20) {
        std::uint32_t length = 0;
        std::copy_n(bytes.data() + 12, 4, reinterpret_cast<char*>(&length));
        json = json.substr(20, length);
    }
    if (too_deep(json)) throw InputError(name, "", "JSON nested more than " + std::to_string(kMaxJsonDepth) + " levels deep");
    const std::string base = file.parent_path().empty() ? std::string(".") : file.parent_path().string();
    const nlohmann::json doc = nlohmann::json::parse(json.begin(), json.end(), nullptr, false);
    GltfImages images = check_uri_files(doc, base, name);
    // Before tinygltf, whose messages for a value of the wrong JSON type
    // name neither the value nor where it is.
    check_gltf_types(json, name);
    // Before tinygltf too: it would decode the images that an extension the
    // loader lacks (EXT_texture_webp, say) provides, and fail on those.
    if (const auto required = doc.is_object() ? doc.find("extensionsRequired") : doc.end();
        required != doc.end() && required->is_array())
        for (std::size_t i = 0; i < required->size(); ++i) {
            const nlohmann::json& ext = (*required)[i];
            if (ext.is_string() && !supported(ext.get<std::string>()))
                throw InputError(name, "extensionsRequired[" + std::to_string(i) + "]",
                                 ext.get<std::string>() +
                                     " is required by the file but not supported (supported: KHR_lights_punctual, "
                                     "KHR_materials_emissive_strength, KHR_materials_clearcoat, KHR_materials_sheen, "
                                     "KHR_texture_transform)");
        }

    tinygltf::TinyGLTF gltf;
    gltf.SetImageLoader(load_image_checked, &images);
    GltfFolder folder{base.back() == '/' ? base : base + "/", &images.buffer_lengths};
    gltf.SetFsCallbacks({gltf_file_exists, gltf_expand_path, gltf_read_file, gltf_write_file, &folder});
    tinygltf::Model model;
    std::string err, warn;
    bool ok = false;
    try {
        const auto size = static_cast<unsigned int>(bytes.size());
        ok = binary ? gltf.LoadBinaryFromMemory(&model, &err, &warn,
                                                reinterpret_cast<const unsigned char*>(bytes.data()), size, base)
                    : gltf.LoadASCIIFromString(&model, &err, &warn, bytes.data(), size, base);
    } catch (const std::exception& e) {
        err = e.what();
        ok = false;
    }
    if (!ok)
        throw InputError(name, "", "tinygltf: " + (err.empty() ? std::string("cannot parse the file")
                                                                : shortened_data_uris(trimmed(err))));
    warn = trimmed(warn);
    // tinygltf takes a data URI of a type it does not decode for a file
    // name: its "File not found" and "Failed to load" for such an unread
    // image give way to one note.
    const auto about_unread_data_image = [&](const std::string& line) {
        if (line.rfind("File not found : data:", 0) == 0) return !images.unread_data_images.empty();
        for (const std::size_t i : images.unread_data_images)
            if (line.find("for image[" + std::to_string(i) + "]") != std::string::npos) return true;
        return false;
    };
    for (std::size_t from = 0; from < warn.size();) {
        const std::size_t end = std::min(warn.find('\n', from), warn.size());
        const std::string line = warn.substr(from, end - from);
        if (end > from && !about_unread_data_image(line)) notes.add("", "tinygltf: " + shortened_data_uris(line));
        from = end + 1;
    }
    for (const std::size_t i : images.unread_data_images)
        notes.add("images[" + std::to_string(i) + "].uri",
                  "a data URI of a type that is not read, and no material reads it (an extension's offer beside "
                  "a PNG or JPEG, say)");
    for (const std::string& ext : model.extensionsUsed)
        if (!supported(ext)) notes.add("extensionsUsed", ext + " is not supported; what it adds is ignored");
    if (!model.animations.empty())
        notes.add("animations", std::to_string(model.animations.size()) +
                                    " animation(s) ignored; the scene is drawn as stored");
    return model;
}

}  // namespace lc::loader
