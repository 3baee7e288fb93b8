// OpenEXR and PNG writers/readers. tinyexr and stb are the compiled Debian
// libraries (libtinyexr, libstb): no *_IMPLEMENTATION macro here.
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

#include <stb_image_write.h>
#include <tinyexr.h>
#include <zlib.h>

#include "lightcuts/error.h"
#include "lightcuts/image.h"
#include "lightcuts/temporaries.h"
#include "scene/input_file.h"

namespace lc {

namespace fs = std::filesystem;

namespace {

// write_file's work: "" when every byte is written and the file closed,
// else the reason.
std::string write_bytes(const fs::path& file, std::string_view bytes) {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) return std::string("cannot write: ") + std::strerror(errno);
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const std::string why = n < 0 ? std::strerror(errno) : "no byte written";
            ::close(fd);
            return "cannot write: " + why;
        }
        done += std::size_t(n);
    }
    // Some file systems (NFS, say) report a failed write only here.
    if (::close(fd) != 0) return std::string("cannot write: ") + std::strerror(errno);
    return {};
}

// Runs `write(tmp)`, which returns an empty string on success or the reason
// it failed, then renames the temporary over `file`. On any failure the
// temporary is removed and std::runtime_error names `file`.
template <class Write>
void write_via_temp(const fs::path& file, Write&& write) {
    const fs::path tmp = temporary_path_for(file);
    const int tracked = track_temporary(tmp);  // a signal removes it (remove_temporaries_on_signal)
    std::string problem;
    try {
        problem = write(tmp);
    } catch (const std::exception& e) {
        problem = e.what();
    }
    if (problem.empty()) {
        std::error_code ec;
        fs::rename(tmp, file, ec);
        if (!ec) {
            untrack_temporary(tracked);
            return;
        }
        problem = "cannot rename temporary file into place: " + ec.message();
    }
    std::error_code ignored;
    fs::remove(tmp, ignored);
    untrack_temporary(tracked);
    throw std::runtime_error(file.string() + ": " + problem);
}

void check_image(const Image& image, const char* what) {
    if (image.rgb.size() != std::size_t(image.width) * image.height * 3)
        throw std::invalid_argument(std::string(what) + ": Image::rgb does not hold width * height * 3 floats");
}

// Takes ownership of a tinyexr error string.
std::string exr_message(const char* err, const char* fallback) {
    std::string message = err ? err : fallback;
    if (err) FreeEXRErrorMessage(err);
    return message;
}

// "cannot be read: it is truncated or corrupt, or uses what tinyexr does not
// support (WHY)" for a file tinyexr cannot parse or decode, WHY being
// tinyexr's message without its trailing newlines and full stop: tinyexr
// says "Unknown compression type" for a valid file compressed with DWAA as
// for a damaged one.
std::string exr_unreadable(const char* err, const char* fallback) {
    std::string why = exr_message(err, fallback);
    while (!why.empty() && (why.back() == '\n' || why.back() == '.' || why.back() == ' ')) why.pop_back();
    return "cannot be read: it is truncated or corrupt, or uses what tinyexr does not support (" + why + ")";
}

struct ExrHeaderGuard {
    EXRHeader* header;
    ~ExrHeaderGuard() { FreeEXRHeader(header); }
};
struct ExrImageGuard {
    EXRImage* image;
    ~ExrImageGuard() { FreeEXRImage(image); }
};

float srgb_encode(float linear) {
    return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

// Exposure that maps the 99th percentile luminance of the lit (positive,
// finite) pixels to 1; 1 for an image with no such pixel.
float auto_exposure(const Image& image) {
    std::vector<float> lum;
    lum.reserve(std::size_t(image.width) * image.height);
    for (std::size_t i = 0; i + 2 < image.rgb.size(); i += 3) {
        const float y = luminance({image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]});
        if (y > 0.0f && std::isfinite(y)) lum.push_back(y);
    }
    if (lum.empty()) return 1.0f;
    const std::size_t k = std::min(lum.size() - 1, std::size_t(0.99 * double(lum.size() - 1) + 0.5));
    std::nth_element(lum.begin(), lum.begin() + std::ptrdiff_t(k), lum.end());
    return 1.0f / lum[k];
}

}  // namespace

void write_file(const fs::path& file, std::string_view bytes, const fs::path& shown_as) {
    const std::string problem = write_bytes(file, bytes);
    if (!problem.empty()) throw std::runtime_error((shown_as.empty() ? file : shown_as).string() + ": " + problem);
}

// Concurrent writers (threads or processes) never share a temporary. The
// name is the file's with a suffix, its start cut where the two would pass
// the 255 bytes a file name may have on Linux's file systems.
fs::path temporary_path_for(const fs::path& file) {
    static std::atomic<unsigned> counter{0};
    const std::string suffix = ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    std::string name = file.filename().native();
    if (name.size() + suffix.size() > kMaxFileNameBytes) name.resize(kMaxFileNameBytes - suffix.size());
    return file.parent_path() / (name + suffix);
}

std::string encode_exr(const Image& image, const fs::path& file) {
    check_image(image, "encode_exr");
    if (image.width == 0 || image.height == 0 ||
        image.width > std::uint32_t(std::numeric_limits<int>::max()) ||
        image.height > std::uint32_t(std::numeric_limits<int>::max()))
        throw std::runtime_error(file.string() + ": cannot write an image of size " +
                                 std::to_string(image.width) + "x" + std::to_string(image.height));

    // OpenEXR readers expect channels sorted by name, so the planes go B, G, R.
    const std::size_t pixels = std::size_t(image.width) * image.height;
    std::vector<float> planes[3];
    for (int c = 0; c < 3; ++c) {
        planes[c].resize(pixels);
        const int src = 2 - c;
        for (std::size_t i = 0; i < pixels; ++i) planes[c][i] = image.rgb[i * 3 + std::size_t(src)];
    }
    unsigned char* plane_ptrs[3] = {reinterpret_cast<unsigned char*>(planes[0].data()),
                                    reinterpret_cast<unsigned char*>(planes[1].data()),
                                    reinterpret_cast<unsigned char*>(planes[2].data())};

    EXRChannelInfo channels[3];
    std::memset(channels, 0, sizeof(channels));
    channels[0].name[0] = 'B';
    channels[1].name[0] = 'G';
    channels[2].name[0] = 'R';
    int pixel_types[3] = {TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT};
    int requested_types[3] = {TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT};

    // The header points at the arrays above; it is not FreeEXRHeader'd.
    EXRHeader header;
    InitEXRHeader(&header);
    header.num_channels = 3;
    header.channels = channels;
    header.pixel_types = pixel_types;
    header.requested_pixel_types = requested_types;
    header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;  // lossless

    EXRImage exr;
    InitEXRImage(&exr);
    exr.num_channels = 3;
    exr.images = plane_ptrs;
    exr.width = int(image.width);
    exr.height = int(image.height);

    // Encoded in memory and written by write_bytes: tinyexr's own file
    // writer does not check its writes, and on a full disk left a truncated
    // file behind a successful return.
    const char* err = nullptr;
    unsigned char* encoded = nullptr;
    const std::size_t size = SaveEXRImageToMemory(&exr, &header, &encoded, &err);
    std::unique_ptr<unsigned char, decltype(&std::free)> owned(encoded, &std::free);
    if (size == 0 || encoded == nullptr)
        throw std::runtime_error(file.string() + ": " + exr_message(err, "cannot encode OpenEXR image"));
    if (err) FreeEXRErrorMessage(err);
    return std::string(reinterpret_cast<const char*>(encoded), size);
}

void write_exr(const fs::path& file, const Image& image) {
    const std::string bytes = encode_exr(image, file);
    write_via_temp(file, [&](const fs::path& tmp) { return write_bytes(tmp, bytes); });
}

namespace {

// Refuses the header attributes on which tinyexr (1.0.1, Debian's shared
// library, built with its asserts on) aborts the process instead of
// returning an error: a `tiles` attribute of other than 9 bytes, a tile
// level or rounding mode outside the format's, a `type` it does not know
// or one that contradicts the version's tiled flag. The attributes are
// walked as the format lays them out (name, type name, 4-byte size,
// value); where the list itself is broken, tinyexr's own parse says so.
void check_exr_attributes(std::string_view bytes, const EXRVersion& version, const std::string& name) {
    std::size_t at = 8;  // after the magic number and the version field
    const auto text = [&](std::string& out) {
        const std::size_t end = bytes.find('\0', at);
        if (end == std::string_view::npos || end - at > 255) return false;
        out.assign(bytes.substr(at, end - at));
        at = end + 1;
        return true;
    };
    for (;;) {
        std::string attribute, type;
        if (!text(attribute) || attribute.empty() || !text(type) || bytes.size() - at < 4) return;
        std::uint32_t size = 0;
        for (int i = 0; i < 4; ++i) size |= std::uint32_t(std::uint8_t(bytes[at + std::size_t(i)])) << (8 * i);
        at += 4;
        if (size > bytes.size() - at) return;
        const std::string_view value = bytes.substr(at, size);
        at += size;
        if (attribute == "tiles") {
            if (size != 9) throw InputError(name, "tiles", "holds " + std::to_string(size) + " bytes, not 9");
            const unsigned mode = std::uint8_t(value[8]);
            if ((mode & 0x0fu) > 2u || (mode >> 4) > 1u)
                throw InputError(name, "tiles", "level or rounding mode is not one of OpenEXR's");
        } else if (attribute == "type") {
            const std::string kind(value.substr(0, value.find('\0')));
            const bool tiled = kind == "tiledimage" || kind == "deeptile";
            if (!tiled && kind != "scanlineimage" && kind != "deepscanline")
                throw InputError(name, "type", "'" + kind + "' is not an OpenEXR part type");
            if (tiled != bool(version.tiled))
                throw InputError(name, "type", "'" + kind + "' contradicts the file's tiled flag");
        }
    }
}

// read_exr, which also gives the display window where `display` is given.
Image read_exr_windows(const fs::path& file, std::uint64_t max_pixels, glm::ivec2* origin, EXRBox2i* display) {
    const std::string name = file.string();
    // The file is read once and decoded from memory. tinyexr's file calls
    // open it at each step (version, header, pixels), so a file changed in
    // between is read as two; and its pixel step trusts its read to return
    // every byte, and leaves the file open when it is under 16 bytes.
    const std::string bytes = loader::read_input_file(file);
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    EXRVersion version;
    if (ParseEXRVersionFromMemory(&version, data, bytes.size()) != TINYEXR_SUCCESS)
        throw InputError(name, "", "is not an OpenEXR file");
    if (version.multipart || version.non_image)
        throw InputError(name, "", "multi-part and deep OpenEXR files are not supported");

    check_exr_attributes(bytes, version, name);

    // tinyexr fills the header (channels, attributes) even when parsing
    // fails, so the guard is in place before the parse.
    EXRHeader header;
    InitEXRHeader(&header);
    ExrHeaderGuard header_guard{&header};
    const char* err = nullptr;
    if (ParseEXRHeaderFromMemory(&header, &version, data, bytes.size(), &err) != TINYEXR_SUCCESS)
        throw InputError(name, "", exr_unreadable(err, "cannot parse the OpenEXR header"));
    // The line order says only in which order the blocks are stored, each
    // with its own y or tile coordinates; tinyexr (1.0.1) takes any but
    // INCREASING_Y to mean an image stored upside down (and for tiles, each
    // tile flipped, reading past the short ones at an edge).
    header.line_order = 0;
    const EXRBox2i& window = header.data_window;
    const std::int64_t width = std::int64_t(window.max_x) - window.min_x + 1;
    const std::int64_t height = std::int64_t(window.max_y) - window.min_y + 1;
    if (width <= 0 || height <= 0) throw InputError(name, "", "image is empty");
    if (origin != nullptr) *origin = glm::ivec2(window.min_x, window.min_y);
    if (display != nullptr) {
        *display = header.display_window;
        const std::int64_t display_width = std::int64_t(display->max_x) - display->min_x + 1;
        const std::int64_t display_height = std::int64_t(display->max_y) - display->min_y + 1;
        if (display_width <= 0 || display_height <= 0)
            throw InputError(name, "displayWindow", "is empty");
        if (std::uint64_t(display_width) * std::uint64_t(display_height) > max_pixels)
            throw InputError(name, "displayWindow",
                             "is " + std::to_string(display_width) + " x " + std::to_string(display_height) +
                                 " pixels, more than the " + std::to_string(max_pixels) + " it may hold");
    }
    if (std::uint64_t(width) * std::uint64_t(height) > max_pixels)
        throw InputError(name, "", "is " + std::to_string(width) + " x " + std::to_string(height) +
                                       " pixels, more than the " + std::to_string(max_pixels) + " it may hold");
    // tinyexr asserts that a level's size plus a tile's does not overflow an
    // int; no real file has tiles near 2^31 pixels a side.
    constexpr int kMaxTileSide = 1 << 24;
    if (header.tiled && (header.tile_size_x < 1 || header.tile_size_y < 1 || header.tile_size_x > kMaxTileSide ||
                         header.tile_size_y > kMaxTileSide))
        throw InputError(name, "tiles", "tile size " + std::to_string(header.tile_size_x) + " x " +
                                            std::to_string(header.tile_size_y) + " is out of range");

    int rgb_channel[3] = {-1, -1, -1};
    for (int c = 0; c < header.num_channels; ++c) {
        const std::string channel = header.channels[c].name;
        const int slot = channel == "R" ? 0 : channel == "G" ? 1 : channel == "B" ? 2 : -1;
        if (slot < 0) continue;  // A and anything else is ignored
        if (header.pixel_types[c] == TINYEXR_PIXELTYPE_UINT)
            throw InputError(name, "", "channel " + channel + " holds integers, expected HALF or FLOAT");
        rgb_channel[slot] = c;
    }
    for (int slot = 0; slot < 3; ++slot)
        if (rgb_channel[slot] < 0)
            throw InputError(name, "", std::string("has no ") + "RGB"[slot] + " channel");
    for (int c = 0; c < header.num_channels; ++c)
        if (header.pixel_types[c] == TINYEXR_PIXELTYPE_HALF) header.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;

    // When decoding fails, tinyexr (1.0.1) calls FreeEXRImage on the image
    // itself, before it has set the image's channel count: it frees the
    // array of channel planes but not the planes. With the count set here
    // first, that call frees the planes too. It leaves the freed pointers in
    // the image, so after a failure the image must not be freed again.
    EXRImage exr;
    InitEXRImage(&exr);
    exr.num_channels = header.num_channels;
    if (LoadEXRImageFromMemory(&exr, &header, data, bytes.size(), &err) != TINYEXR_SUCCESS)
        throw InputError(name, "", exr_unreadable(err, "cannot decode the OpenEXR pixels"));
    ExrImageGuard image_guard{&exr};
    // The size checked against max_pixels above is the one decoded.
    if (exr.width != width || exr.height != height)
        throw InputError(name, "", "decoded size differs from the header's data window");

    Image image(std::uint32_t(exr.width), std::uint32_t(exr.height));
    if (exr.images) {
        const std::size_t pixels = std::size_t(exr.width) * std::size_t(exr.height);
        for (int slot = 0; slot < 3; ++slot) {
            const float* src = reinterpret_cast<const float*>(exr.images[rgb_channel[slot]]);
            for (std::size_t i = 0; i < pixels; ++i) image.rgb[i * 3 + std::size_t(slot)] = src[i];
        }
    } else if (exr.tiles) {
        // Level 0 of a tiled file: tiles are placed on a tile_size grid, from
        // coordinates the file gives (tinyexr takes any, negative ones too),
        // so each tile must lie on the grid inside the image and every pixel
        // must come from exactly one tile.
        std::vector<bool> covered(std::size_t(exr.width) * std::size_t(exr.height), false);
        std::uint64_t placed = 0;
        for (int t = 0; t < exr.num_tiles; ++t) {
            const EXRTile& tile = exr.tiles[t];
            const std::int64_t x0 = std::int64_t(tile.offset_x) * header.tile_size_x;
            const std::int64_t y0 = std::int64_t(tile.offset_y) * header.tile_size_y;
            if (tile.offset_x < 0 || tile.offset_y < 0 || x0 >= exr.width || y0 >= exr.height || tile.width < 0 ||
                tile.height < 0 || tile.width > header.tile_size_x || tile.height > header.tile_size_y)
                throw InputError(name, "tiles", "tile " + std::to_string(t) + " lies outside the image");
            const int w = int(std::min<std::int64_t>(tile.width, exr.width - x0));
            const int h = int(std::min<std::int64_t>(tile.height, exr.height - y0));
            for (int y = 0; y < h; ++y) {
                for (int x = 0; x < w; ++x) {
                    const std::size_t pixel = std::size_t(y0 + y) * image.width + std::size_t(x0 + x);
                    if (covered[pixel])
                        throw InputError(name, "tiles", "tile " + std::to_string(t) + " overlaps another tile");
                    covered[pixel] = true;
                    ++placed;
                    const std::size_t from = std::size_t(y) * std::size_t(header.tile_size_x) + std::size_t(x);
                    for (int slot = 0; slot < 3; ++slot)
                        image.rgb[pixel * 3 + std::size_t(slot)] =
                            reinterpret_cast<const float*>(tile.images[rgb_channel[slot]])[from];
                }
            }
        }
        if (placed != covered.size()) throw InputError(name, "tiles", "some pixels lie in no tile");
    } else {
        throw InputError(name, "", "OpenEXR file holds no pixel data");
    }
    return image;
}

}  // namespace

Image read_exr(const fs::path& file, std::uint64_t max_pixels, glm::ivec2* origin) {
    return read_exr_windows(file, max_pixels, origin, nullptr);
}

Image read_exr_display_window(const fs::path& file, std::uint64_t max_pixels) {
    EXRBox2i display;
    glm::ivec2 origin;
    Image data = read_exr_windows(file, max_pixels, &origin, &display);
    if (origin == glm::ivec2(display.min_x, display.min_y) &&
        std::int64_t(data.width) == std::int64_t(display.max_x) - display.min_x + 1 &&
        std::int64_t(data.height) == std::int64_t(display.max_y) - display.min_y + 1)
        return data;
    Image image(std::uint32_t(std::int64_t(display.max_x) - display.min_x + 1),
                std::uint32_t(std::int64_t(display.max_y) - display.min_y + 1));  // black
    for (std::uint32_t y = 0; y < data.height; ++y) {
        const std::int64_t to_y = std::int64_t(origin.y) + y - display.min_y;
        if (to_y < 0 || to_y >= std::int64_t(image.height)) continue;
        for (std::uint32_t x = 0; x < data.width; ++x) {
            const std::int64_t to_x = std::int64_t(origin.x) + x - display.min_x;
            if (to_x < 0 || to_x >= std::int64_t(image.width)) continue;
            for (int c = 0; c < 3; ++c)
                image.rgb[(std::size_t(to_y) * image.width + std::size_t(to_x)) * 3 + std::size_t(c)] =
                    data.rgb[(std::size_t(y) * data.width + x) * 3 + std::size_t(c)];
        }
    }
    return image;
}

std::string encode_png_rgb8(std::uint32_t width, std::uint32_t height, const std::vector<std::uint8_t>& rgb8,
                            const fs::path& file) {
    if (rgb8.size() != std::size_t(width) * height * 3)
        throw std::invalid_argument("encode_png_rgb8: " + file.string() + ": expected width * height * 3 bytes");
    if (width == 0 || height == 0 || width > std::uint32_t(std::numeric_limits<int>::max() / 3) ||
        height > std::uint32_t(std::numeric_limits<int>::max()))
        throw std::runtime_error(file.string() + ": cannot write a PNG of size " + std::to_string(width) +
                                 "x" + std::to_string(height));
    // Encoded in memory, then written by write_bytes (stb's file writer
    // does not check its writes either).
    std::string encoded;
    auto append = [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<const char*>(data), std::size_t(size));
    };
    if (stbi_write_png_to_func(append, &encoded, int(width), int(height), 3, rgb8.data(), int(width * 3)) == 0)
        throw std::runtime_error(file.string() + ": cannot encode PNG image");
    // The bytes are sRGB (the tone-mapped images and the heat maps' ramp
    // alike), which stb does not say: an sRGB chunk, with the gAMA chunk the
    // PNG specification asks to go with it for older readers, after IHDR.
    constexpr std::size_t kAfterHeader = 8 + 25;  // the signature, then IHDR's length, type, 13 bytes and CRC
    const auto chunk = [](const char* type, std::string data) {
        std::string c(4, '\0');
        const auto put32 = [](char* at, std::uint32_t v) {
            for (int i = 0; i < 4; ++i) at[i] = char(v >> (24 - 8 * i));
        };
        put32(c.data(), std::uint32_t(data.size()));
        c += type;
        c += data;
        const auto crc = std::uint32_t(::crc32(::crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(c.data() + 4),
                                               uInt(c.size() - 4)));
        c.resize(c.size() + 4);
        put32(c.data() + c.size() - 4, crc);
        return c;
    };
    encoded.insert(kAfterHeader, chunk("sRGB", std::string(1, '\0')) +  // rendering intent: perceptual
                                     chunk("gAMA", std::string("\x00\x00\xb1\x8f", 4)));  // 45455: 1/2.2
    return encoded;
}

void write_png_rgb8(const fs::path& file, std::uint32_t width, std::uint32_t height,
                    const std::vector<std::uint8_t>& rgb8) {
    const std::string bytes = encode_png_rgb8(width, height, rgb8, file);
    write_via_temp(file, [&](const fs::path& tmp) { return write_bytes(tmp, bytes); });
}

std::string encode_png_tonemapped(const Image& image, float exposure, const fs::path& file) {
    check_image(image, "encode_png_tonemapped");
    if (!(exposure > 0.0f)) exposure = auto_exposure(image);
    std::vector<std::uint8_t> rgb8(image.rgb.size());
    for (std::size_t i = 0; i < image.rgb.size(); ++i) {
        float v = exposure * image.rgb[i];
        v = std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f);
        rgb8[i] = std::uint8_t(srgb_encode(v) * 255.0f + 0.5f);
    }
    return encode_png_rgb8(image.width, image.height, rgb8, file);
}

void write_png_tonemapped(const fs::path& file, const Image& image, float exposure) {
    const std::string bytes = encode_png_tonemapped(image, exposure, file);
    write_via_temp(file, [&](const fs::path& tmp) { return write_bytes(tmp, bytes); });
}

}  // namespace lc
