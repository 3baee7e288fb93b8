// Image files (EXR, PNG, heat map) and the comparison metrics.
#include <cerrno>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>
#include <stb/stb_image.h>
#include <tinyexr.h>

#include "lightcuts/error.h"
#include "lightcuts/image.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace {

// A fresh folder per test, removed afterwards.
class ImageFiles : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("lc_test_image_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    std::set<std::string> entries() const {
        std::set<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
        return names;
    }

    fs::path dir_;
};

struct Png {
    int width = 0, height = 0, channels = 0;
    std::vector<std::uint8_t> rgb;
    std::array<std::uint8_t, 3> at(int x, int y) const {
        const std::size_t i = (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3;
        return {rgb[i], rgb[i + 1], rgb[i + 2]};
    }
};

Png read_png(const fs::path& file) {
    Png png;
    unsigned char* data = stbi_load(file.c_str(), &png.width, &png.height, &png.channels, 3);
    if (!data) return png;
    png.rgb.assign(data, data + std::size_t(png.width) * std::size_t(png.height) * 3);
    stbi_image_free(data);
    return png;
}

lc::Image gray(std::uint32_t w, std::uint32_t h, float v) {
    lc::Image image(w, h);
    std::fill(image.rgb.begin(), image.rgb.end(), v);
    return image;
}

}  // namespace

TEST_F(ImageFiles, ExrRoundTripIsBitExact) {
    lc::Image image(7, 5);
    const float specials[] = {0.0f, -0.0f, 1.0f, -3.5f, 1e-40f /* denormal */, 3.0e38f,
                              std::numeric_limits<float>::infinity(), 0.1f, 1234.5678f};
    for (std::size_t i = 0; i < image.rgb.size(); ++i)
        image.rgb[i] = i < std::size(specials) ? specials[i] : std::sin(float(i)) * float(i);
    const fs::path file = dir_ / "round.exr";
    lc::write_exr(file, image);
    const lc::Image back = lc::read_exr(file);
    ASSERT_EQ(back.width, image.width);
    ASSERT_EQ(back.height, image.height);
    ASSERT_EQ(back.rgb.size(), image.rgb.size());
    EXPECT_EQ(std::memcmp(back.rgb.data(), image.rgb.data(), image.rgb.size() * sizeof(float)), 0);
    EXPECT_EQ(entries(), std::set<std::string>{"round.exr"});
}

// An OpenEXR file's line order says only in which order its blocks are
// stored; each block carries its own y. A file that says DECREASING_Y
// (here with its blocks in increasing order, as OpenEXR reads any order)
// reads the same: tinyexr turned such images upside down (an environment
// map's sky went below the horizon).
TEST_F(ImageFiles, ExrLineOrderDoesNotFlipTheImage) {
    lc::Image image(3, 37);
    for (std::uint32_t y = 0; y < image.height; ++y)
        for (std::uint32_t x = 0; x < image.width; ++x) image.set(x, y, glm::vec3(float(x), float(y), 0.5f));
    const fs::path file = dir_ / "decreasing.exr";
    lc::write_exr(file, image);
    const unsigned char decreasing_y = 1;
    lc::test::patch_exr_attribute(file, "lineOrder", "lineOrder", &decreasing_y, 1);
    const lc::Image back = lc::read_exr(file);
    ASSERT_EQ(back.height, image.height);
    EXPECT_EQ(back.rgb, image.rgb);
}

// A data window that starts away from (0, 0) reads the same pixels and
// says where they start (compare refuses two images that start apart).
TEST_F(ImageFiles, ExrDataWindowOriginIsReported) {
    lc::Image image(3, 2);
    image.set(2, 1, glm::vec3(1.0f, 2.0f, 3.0f));
    const fs::path file = dir_ / "moved.exr";
    lc::write_exr(file, image);
    glm::ivec2 origin(-1);
    EXPECT_EQ(lc::read_exr(file, lc::kMaxExrPixels, &origin).rgb, image.rgb);
    EXPECT_EQ(origin, glm::ivec2(0, 0));
    const std::int32_t window[4] = {10, 0, 12, 1};  // the scanline blocks keep their y
    lc::test::patch_exr_attribute(file, "dataWindow", "box2i", window, sizeof(window));
    EXPECT_EQ(lc::read_exr(file, lc::kMaxExrPixels, &origin).rgb, image.rgb);
    EXPECT_EQ(origin, glm::ivec2(10, 0));
}

// Laid out over the display window, as environment maps are read: where
// the data window does not fill it the pixels are black (an upper
// hemisphere stored alone left the map's lower half black, not the sky
// stretched over the sphere), and where it reaches past it they are dropped.
TEST_F(ImageFiles, ExrDisplayWindowPlacesTheStoredPixels) {
    lc::Image image(3, 2);
    for (std::uint32_t y = 0; y < image.height; ++y)
        for (std::uint32_t x = 0; x < image.width; ++x) image.set(x, y, glm::vec3(float(x + 1), float(y + 1), 7.0f));
    const fs::path file = dir_ / "windows.exr";
    lc::write_exr(file, image);
    EXPECT_EQ(lc::read_exr_display_window(file).rgb, image.rgb);  // the same windows: as read_exr
    const std::int32_t data[4] = {1, 0, 3, 1};                     // x 1 to 3 (the blocks keep their y)
    lc::test::patch_exr_attribute(file, "dataWindow", "box2i", data, sizeof(data));
    const std::int32_t display[4] = {0, 0, 4, 3};  // 5 x 4
    lc::test::patch_exr_attribute(file, "displayWindow", "box2i", display, sizeof(display));
    const lc::Image placed = lc::read_exr_display_window(file);
    ASSERT_EQ(placed.width, 5u);
    ASSERT_EQ(placed.height, 4u);
    for (std::uint32_t y = 0; y < placed.height; ++y)
        for (std::uint32_t x = 0; x < placed.width; ++x) {
            const bool stored = x >= 1 && x <= 3 && y <= 1;
            const glm::vec3 want = stored ? glm::vec3(float(x), float(y + 1), 7.0f) : glm::vec3(0.0f);
            EXPECT_EQ(placed.at(x, y), want) << x << ", " << y;
        }
    const std::int32_t inside[4] = {2, 1, 3, 1};  // 2 x 1, inside the data window
    lc::test::patch_exr_attribute(file, "displayWindow", "box2i", inside, sizeof(inside));
    const lc::Image cropped = lc::read_exr_display_window(file);
    ASSERT_EQ(cropped.width, 2u);
    ASSERT_EQ(cropped.height, 1u);
    EXPECT_EQ(cropped.at(0, 0), glm::vec3(2.0f, 2.0f, 7.0f));
    EXPECT_EQ(cropped.at(1, 0), glm::vec3(3.0f, 2.0f, 7.0f));
    const std::int32_t huge[4] = {0, 0, 99999, 99999};
    lc::test::patch_exr_attribute(file, "displayWindow", "box2i", huge, sizeof(huge));
    try {
        lc::read_exr_display_window(file, 4096);
        ADD_FAILURE() << "a display window past max_pixels was read";
    } catch (const lc::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("displayWindow: is 100000 x 100000 pixels"), std::string::npos) << e.what();
    }
}

TEST_F(ImageFiles, ExrStoresFloatChannelsSortedByName) {
    lc::Image image(2, 1);
    image.set(0, 0, {1.0f, 2.0f, 3.0f});
    const fs::path file = dir_ / "channels.exr";
    lc::write_exr(file, image);

    EXRVersion version;
    ASSERT_EQ(ParseEXRVersionFromFile(&version, file.c_str()), TINYEXR_SUCCESS);
    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    ASSERT_EQ(ParseEXRHeaderFromFile(&header, &version, file.c_str(), &err), TINYEXR_SUCCESS);
    ASSERT_EQ(header.num_channels, 3);
    EXPECT_STREQ(header.channels[0].name, "B");
    EXPECT_STREQ(header.channels[1].name, "G");
    EXPECT_STREQ(header.channels[2].name, "R");
    for (int c = 0; c < 3; ++c) EXPECT_EQ(header.pixel_types[c], TINYEXR_PIXELTYPE_FLOAT);
    FreeEXRHeader(&header);

    // And an independent reader sees R, G, B where they belong.
    float* rgba = nullptr;
    int w = 0, h = 0;
    ASSERT_EQ(LoadEXR(&rgba, &w, &h, file.c_str(), &err), TINYEXR_SUCCESS);
    EXPECT_EQ(rgba[0], 1.0f);
    EXPECT_EQ(rgba[1], 2.0f);
    EXPECT_EQ(rgba[2], 3.0f);
    std::free(rgba);
}

TEST_F(ImageFiles, ReadExrReportsBadInputAsInputError) {
    const fs::path missing = dir_ / "missing.exr";
    try {
        lc::read_exr(missing);
        FAIL() << "expected InputError";
    } catch (const lc::InputError& e) {
        EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
    }
    const fs::path text = dir_ / "text.exr";
    std::ofstream(text) << "this is not an OpenEXR file\n";
    EXPECT_THROW(lc::read_exr(text), lc::InputError);
}

// A 4x4 tiled OpenEXR file of 2x2 uncompressed tiles, each pixel (x, y,
// 1), laid out byte by byte as the format has it (tinyexr writes scanline
// files only); tiles_at gets the file offsets of the four tile blocks, each
// of which starts with its tile coordinates x, y as 4-byte integers.
std::string tiled_exr(std::vector<std::uint64_t>& tiles_at) {
    std::string bytes;
    const auto put = [&](const auto& value) { bytes.append(reinterpret_cast<const char*>(&value), sizeof(value)); };
    const auto attribute = [&](const std::string& name, const std::string& type, const std::string& value) {
        bytes += name + '\0' + type + '\0';
        put(std::uint32_t(value.size()));
        bytes += value;
    };
    const auto pack = [](std::initializer_list<std::int32_t> words) {
        return std::string(reinterpret_cast<const char*>(words.begin()), 4 * words.size());
    };
    put(std::uint32_t(20000630));  // the magic number
    put(std::uint32_t(2 | 0x200));  // version 2, tiled
    std::string channels;
    for (const char* name : {"B", "G", "R"})
        channels += std::string(name) + '\0' + pack({2, 0, 1, 1});  // FLOAT, pLinear and reserved 0, sampling 1, 1
    attribute("channels", "chlist", channels + '\0');
    attribute("compression", "compression", std::string(1, '\0'));
    attribute("dataWindow", "box2i", pack({0, 0, 3, 3}));
    attribute("displayWindow", "box2i", pack({0, 0, 3, 3}));
    attribute("lineOrder", "lineOrder", std::string(1, '\0'));
    const float one = 1.0f;
    attribute("pixelAspectRatio", "float", std::string(reinterpret_cast<const char*>(&one), 4));
    attribute("screenWindowCenter", "v2f", std::string(8, '\0'));
    attribute("screenWindowWidth", "float", std::string(reinterpret_cast<const char*>(&one), 4));
    attribute("tiles", "tiledesc", pack({2, 2}) + std::string(1, '\0'));  // 2x2, one level, rounding down
    bytes += '\0';
    const std::size_t table = bytes.size();
    bytes.append(4 * 8, '\0');
    tiles_at.clear();
    for (std::int32_t ty = 0; ty < 2; ++ty)
        for (std::int32_t tx = 0; tx < 2; ++tx) {
            tiles_at.push_back(bytes.size());
            std::memcpy(&bytes[table + 8 * (tiles_at.size() - 1)], &tiles_at.back(), 8);
            bytes += pack({tx, ty, 0, 0, 2 * 3 * 2 * 4});
            for (int y = 2 * ty; y < 2 * ty + 2; ++y)
                for (int c = 0; c < 3; ++c)  // B, G, R
                    for (int x = 2 * tx; x < 2 * tx + 2; ++x) put(c == 0 ? one : c == 1 ? float(y) : float(x));
        }
    return bytes;
}

// tinyexr places a tile where the file says, negative coordinates too, and
// aborts on some header values instead of failing: a tile outside the image
// (it was written outside the pixels, a crash), two tiles at one place
// (the other's pixels were left black), a tiles attribute of the wrong size
// or an unknown level mode (aborts) are each an InputError naming the file.
TEST_F(ImageFiles, TiledExrTilesMustCoverTheImageOnce) {
    std::vector<std::uint64_t> tiles_at;
    const std::string good = tiled_exr(tiles_at);
    const auto write = [&](const std::string& name, const std::string& bytes) {
        const fs::path file = dir_ / name;
        std::ofstream(file, std::ios::binary) << bytes;
        return file;
    };
    const lc::Image read = lc::read_exr(write("good.exr", good));
    ASSERT_EQ(read.width, 4u);
    for (std::uint32_t y = 0; y < 4; ++y)
        for (std::uint32_t x = 0; x < 4; ++x) EXPECT_EQ(read.at(x, y), glm::vec3(float(x), float(y), 1.0f));

    const auto refused = [&](const std::string& name, const std::string& bytes, const std::string& why) {
        const fs::path file = write(name, bytes);
        try {
            lc::read_exr(file);
        } catch (const lc::InputError& e) {
            const std::string message = e.what();
            EXPECT_NE(message.find(file.string()), std::string::npos) << message;
            EXPECT_NE(message.find(why), std::string::npos) << message;
            return;
        }
        ADD_FAILURE() << name << " was read";
    };
    const auto with_tile_x = [&](std::size_t tile, std::int32_t x, std::int32_t y) {
        std::string bytes = good;
        std::memcpy(&bytes[tiles_at[tile]], &x, 4);
        std::memcpy(&bytes[tiles_at[tile] + 4], &y, 4);
        return bytes;
    };
    refused("far_left.exr", with_tile_x(1, -16777216, 0), "outside the image");
    refused("left.exr", with_tile_x(1, -1, 0), "outside the image");
    refused("twice.exr", with_tile_x(3, 0, 0), "overlaps another tile");
    const auto with_tiles_attribute = [&](std::uint32_t x, std::uint32_t y, unsigned char mode) {
        std::string bytes = good;
        const std::string attribute = std::string("tiles") + '\0' + "tiledesc" + '\0';
        const std::size_t at = bytes.find(attribute) + attribute.size() + 4;
        std::memcpy(&bytes[at], &x, 4);
        std::memcpy(&bytes[at + 4], &y, 4);
        bytes[at + 8] = char(mode);
        return bytes;
    };
    refused("mode3.exr", with_tiles_attribute(2, 2, 3), "level or rounding mode");
    refused("huge_tiles.exr", with_tiles_attribute(0x7fffffff, 2, 0), "tile size");
    std::string ten = good;
    const std::string attribute = std::string("tiles") + '\0' + "tiledesc" + '\0';
    const std::size_t size_at = ten.find(attribute) + attribute.size();
    const std::uint32_t size10 = 10;
    std::memcpy(&ten[size_at], &size10, 4);
    ten.insert(size_at + 4 + 9, 1, '\0');
    refused("tiles10.exr", ten, "not 9");
}

// A file cut short in its header or in its pixels is an InputError naming
// the file. tinyexr allocates in both cases before it fails; the sanitizer
// build of the tests reports any of that left behind.
TEST_F(ImageFiles, ReadExrReportsTruncatedFilesAsInputError) {
    lc::Image image(64, 48);
    for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = std::sin(float(i));
    const fs::path whole = dir_ / "whole.exr";
    lc::write_exr(whole, image);
    std::string bytes;
    {
        std::ifstream in(whole, std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    ASSERT_GT(bytes.size(), 200u);
    // 8 bytes: the magic number and version only (tinyexr's file reader
    // left such a file open).
    for (const std::size_t keep : {std::size_t(8), std::size_t(100), bytes.size() / 2, bytes.size() - 1}) {
        const fs::path cut = dir_ / ("cut_" + std::to_string(keep) + ".exr");
        std::ofstream(cut, std::ios::binary) << bytes.substr(0, keep);
        try {
            lc::read_exr(cut);
            ADD_FAILURE() << "expected InputError for " << keep << " bytes";
        } catch (const lc::InputError& e) {
            const std::string message = e.what();
            EXPECT_EQ(message.rfind(cut.string() + ": cannot be read: it is truncated or corrupt", 0), 0u) << message;
        }
    }
}

// An OpenEXR header's data window is checked against the limit before
// tinyexr allocates the pixels it declares. The file here is a 2 x 2 image
// whose header claims 30000 x 30000 (10.8 GB of RGB floats); without the
// check tinyexr fails later, on the short offset table, with another
// message (and a valid file of that size would be decoded in full).
TEST_F(ImageFiles, ReadExrRefusesMorePixelsThanTheLimitFromTheHeader) {
    const fs::path file = dir_ / "small.exr";
    lc::write_exr(file, gray(2, 2, 0.5f));
    EXPECT_EQ(lc::read_exr(file, 4).width, 2u);
    try {
        lc::read_exr(file, 3);
        FAIL() << "expected InputError";
    } catch (const lc::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("is 2 x 2 pixels, more than the 3 it may hold"), std::string::npos)
            << e.what();
    }

    const fs::path huge = dir_ / "huge.exr";
    fs::copy_file(file, huge);
    lc::test::set_exr_data_window(huge, 29999, 29999);
    try {
        lc::read_exr(huge);
        FAIL() << "expected InputError";
    } catch (const lc::InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(huge.string()), std::string::npos) << message;
        EXPECT_NE(message.find("is 30000 x 30000 pixels, more than the 268435456"), std::string::npos) << message;
    }
}

TEST_F(ImageFiles, PngHasTheRightSizeAndPixels) {
    const std::uint32_t w = 7, h = 3;
    std::vector<std::uint8_t> rgb(w * h * 3);
    for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = std::uint8_t(i * 11);
    const fs::path file = dir_ / "bytes.png";
    lc::write_png_rgb8(file, w, h, rgb);
    const Png png = read_png(file);
    ASSERT_EQ(png.width, int(w));
    ASSERT_EQ(png.height, int(h));
    EXPECT_EQ(png.channels, 3);
    EXPECT_EQ(png.rgb, rgb);
    EXPECT_EQ(entries(), std::set<std::string>{"bytes.png"});
    EXPECT_THROW(lc::write_png_rgb8(dir_ / "short.png", w, h, std::vector<std::uint8_t>(5)), std::invalid_argument);
    // The pixels are sRGB, and the file says so: an sRGB chunk (perceptual
    // intent) and gAMA 45455 straight after IHDR, with their CRCs (from
    // Python's zlib.crc32 of each chunk's type and data).
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 33u + 13u + 16u);
    EXPECT_EQ(bytes.substr(12, 4), "IHDR");
    EXPECT_EQ(bytes.substr(33, 13), std::string("\0\0\0\x01sRGB\0\xae\xce\x1c\xe9", 13));
    EXPECT_EQ(bytes.substr(46, 16), std::string("\0\0\0\x04gAMA\0\0\xb1\x8f\x0b\xfc\x61\x05", 16));
}

TEST_F(ImageFiles, TonemappedPngAppliesExposureAndSrgb) {
    lc::Image image = gray(4, 2, 0.25f);
    image.set(1, 0, {std::numeric_limits<float>::quiet_NaN(), -1.0f, 100.0f});
    const fs::path file = dir_ / "tone.png";
    lc::write_png_tonemapped(file, image, 2.0f);  // 0.25 * 2 = 0.5 linear
    const Png png = read_png(file);
    ASSERT_EQ(png.width, 4);
    ASSERT_EQ(png.height, 2);
    EXPECT_EQ(png.at(0, 0)[0], 188);  // sRGB(0.5) = 0.7354 -> 187.5 -> 188
    EXPECT_EQ(png.at(1, 0)[0], 0);    // NaN -> black
    EXPECT_EQ(png.at(1, 0)[1], 0);    // negative clamps
    EXPECT_EQ(png.at(1, 0)[2], 255);  // over-exposed clamps

    // Auto exposure maps the 99th percentile luminance to white.
    lc::write_png_tonemapped(file, gray(10, 10, 40.0f));
    EXPECT_EQ(read_png(file).at(3, 3)[1], 255);
    // Of the lit pixels only, and their 99th percentile, not the largest:
    // 100 black pixels, 99 of luminance 1 to 99, one of 1e6. The 99th
    // percentile of the 100 lit ones is 99, so 98 maps to 254 and 99 to 255
    // (counting the black ones would give 98 and 255 for both; the largest
    // would leave both black).
    lc::Image lit(20, 10);
    for (std::uint32_t i = 0; i < 99; ++i) lit.set((100 + i) % 20, (100 + i) / 20, glm::vec3(float(i + 1)));
    lit.set(19, 9, glm::vec3(1e6f));
    lc::write_png_tonemapped(file, lit);
    const Png ramp = read_png(file);
    EXPECT_EQ(ramp.at((100 + 97) % 20, (100 + 97) / 20)[1], 254);  // luminance 98: sRGB(98 / 99) = 0.9957
    EXPECT_EQ(ramp.at((100 + 98) % 20, (100 + 98) / 20)[1], 255);  // luminance 99
    EXPECT_EQ(ramp.at(0, 0)[1], 0);
    lc::write_png_tonemapped(file, gray(3, 3, 0.0f));  // all black: exposure 1, no crash
    EXPECT_EQ(read_png(file).at(1, 1)[0], 0);
    EXPECT_EQ(entries(), std::set<std::string>{"tone.png"});
}

TEST_F(ImageFiles, WritingIntoAMissingFolderThrowsAndLeavesNothing) {
    const fs::path missing = dir_ / "no_such_folder";
    const lc::Image image = gray(2, 2, 1.0f);
    for (const char* name : {"a.exr", "a.png"}) {
        const fs::path file = missing / name;
        try {
            if (fs::path(name).extension() == ".exr")
                lc::write_exr(file, image);
            else
                lc::write_png_tonemapped(file, image, 1.0f);
            FAIL() << "expected std::runtime_error for " << file;
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
        }
    }
    EXPECT_FALSE(fs::exists(missing));
    EXPECT_TRUE(entries().empty());
}

// A full disk: every write to /dev/full fails with ENOSPC. tinyexr's and
// stb's own file writers ignored that and returned success with a file cut
// short; the writers now encode in memory and write through write_file.
TEST(WriteFile, AFullDiskThrowsNamingTheFileAndTheReason) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
    try {
        lc::write_file("/dev/full", std::string(100000, 'x'));
        FAIL() << "expected std::runtime_error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("/dev/full: cannot write: "), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(std::strerror(ENOSPC)), std::string::npos) << e.what();
    }
}

TEST_F(ImageFiles, WriteFileWritesEveryByte) {
    std::string bytes(1 << 20, '\0');
    for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = char(i * 7u);
    lc::write_file(dir_ / "bytes.bin", bytes);
    std::ifstream in(dir_ / "bytes.bin", std::ios::binary);
    const std::string back((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(back, bytes);
}

TEST_F(ImageFiles, FailedRenameRemovesTheTemporary) {
    // The target is a non-empty folder, so the final rename fails.
    fs::create_directories(dir_ / "taken.exr" / "inside");
    EXPECT_THROW(lc::write_exr(dir_ / "taken.exr", gray(2, 2, 1.0f)), std::runtime_error);
    EXPECT_EQ(entries(), std::set<std::string>{"taken.exr"});
}

TEST(CompareImages, IdenticalImagesHaveZeroError) {
    lc::Image a(5, 4);
    for (std::size_t i = 0; i < a.rgb.size(); ++i) a.rgb[i] = float(i % 7) * 0.3f;
    const lc::CompareResult r = lc::compare_images(a, a);
    EXPECT_EQ(r.relative_rmse, 0.0);
    EXPECT_EQ(r.fraction_above_1pct, 0.0);
    EXPECT_EQ(r.fraction_above_2pct, 0.0);
    EXPECT_EQ(r.fraction_above_5pct, 0.0);
    EXPECT_EQ(r.max_relative_error, 0.0);
    ASSERT_EQ(r.per_pixel.size(), 20u);
    for (float e : r.per_pixel) EXPECT_EQ(e, 0.0f);
}

TEST(CompareImages, KnownErrorsGiveKnownMetrics) {
    // 20 grey pixels of 2.0; three are off by 25%, 3.125% and 1.5625%
    // (all exact in binary).
    const lc::Image reference = gray(5, 4, 2.0f);
    lc::Image image = reference;
    image.set(1, 1, glm::vec3(2.5f));
    image.set(4, 2, glm::vec3(2.0625f));
    image.set(0, 3, glm::vec3(2.03125f));
    const lc::CompareResult r = lc::compare_images(image, reference);
    EXPECT_DOUBLE_EQ(r.fraction_above_1pct, 3.0 / 20.0);
    EXPECT_DOUBLE_EQ(r.fraction_above_2pct, 2.0 / 20.0);
    EXPECT_DOUBLE_EQ(r.fraction_above_5pct, 1.0 / 20.0);
    EXPECT_NEAR(r.max_relative_error, 0.25, 1e-12);
    EXPECT_NEAR(r.per_pixel[1 * 5 + 1], 0.25f, 1e-6f);
    EXPECT_NEAR(r.per_pixel[2 * 5 + 4], 0.03125f, 1e-7f);
    const double sum_d2 = 3.0 * (0.5 * 0.5 + 0.0625 * 0.0625 + 0.03125 * 0.03125);
    const double sum_r2 = 60.0 * 4.0;
    EXPECT_NEAR(r.relative_rmse, std::sqrt(sum_d2 / sum_r2), 1e-15);
    // Grey pixels: luminance = value. (0.5 + 0.0625 + 0.03125) / (20 * 2).
    EXPECT_NEAR(r.mean_difference, 0.59375 / 40.0, 1e-12);
}

TEST(CompareImages, DarkReferencePixelsUseTheMeanFloor) {
    // Reference: 3 pixels of luminance 1 and one black; mean Y = 0.75.
    lc::Image reference = gray(2, 2, 1.0f);
    reference.set(1, 1, glm::vec3(0.0f));
    lc::Image image = reference;
    image.set(1, 1, glm::vec3(0.0015f));
    const lc::CompareResult r = lc::compare_images(image, reference);
    EXPECT_NEAR(r.per_pixel[3], 0.0015 / (1e-3 * 0.75), 1e-5);
    EXPECT_DOUBLE_EQ(r.fraction_above_5pct, 0.25);
    // A negative reference floors at its magnitude (it was 1e-30: errors of 1e30).
    const lc::Image negative = gray(2, 2, -1.0f);
    EXPECT_NEAR(lc::compare_images(gray(2, 2, 1.0f), negative).max_relative_error, 2.0 / 1e-3, 1e-6);
}

TEST(CompareImages, ZeroAndNonFiniteImagesDoNotCrash) {
    const lc::Image black = gray(3, 2, 0.0f);
    EXPECT_EQ(lc::compare_images(black, black).relative_rmse, 0.0);
    const lc::CompareResult lit = lc::compare_images(gray(3, 2, 1.0f), black);
    EXPECT_TRUE(std::isinf(lit.relative_rmse));
    EXPECT_DOUBLE_EQ(lit.fraction_above_5pct, 1.0);
    EXPECT_FALSE(std::isnan(lit.max_relative_error));
    // The mean difference takes the image's sign against a black reference,
    // and is relative to the magnitude of a negative one.
    EXPECT_EQ(lit.mean_difference, std::numeric_limits<double>::infinity());
    EXPECT_EQ(lc::compare_images(gray(3, 2, -1.0f), black).mean_difference, -std::numeric_limits<double>::infinity());
    EXPECT_EQ(lc::compare_images(black, black).mean_difference, 0.0);
    EXPECT_DOUBLE_EQ(lc::compare_images(gray(3, 2, -3.0f), gray(3, 2, -2.0f)).mean_difference, -0.5);
    EXPECT_DOUBLE_EQ(lc::compare_images(gray(3, 2, -1.0f), gray(3, 2, -2.0f)).mean_difference, 0.5);

    lc::Image with_nan = gray(3, 2, 1.0f);
    with_nan.set(2, 1, {std::numeric_limits<float>::quiet_NaN(), 1.0f, 1.0f});
    const lc::CompareResult r = lc::compare_images(with_nan, gray(3, 2, 1.0f));
    EXPECT_TRUE(std::isnan(r.relative_rmse));
    EXPECT_TRUE(std::isnan(r.max_relative_error));
    EXPECT_TRUE(std::isnan(r.mean_difference));
    EXPECT_TRUE(std::isnan(lc::compare_images(black, with_nan).mean_difference));  // a NaN reference too
    EXPECT_DOUBLE_EQ(r.fraction_above_1pct, 1.0 / 6.0);  // the NaN pixel counts as wrong

    lc::Image with_inf = gray(3, 2, 1.0f);
    with_inf.set(0, 0, glm::vec3(std::numeric_limits<float>::infinity()));
    EXPECT_TRUE(std::isinf(lc::compare_images(with_inf, gray(3, 2, 1.0f)).relative_rmse));
}

TEST(CompareImages, SizeMismatchThrows) {
    EXPECT_THROW(lc::compare_images(gray(3, 2, 1.0f), gray(2, 3, 1.0f)), std::invalid_argument);
}

TEST_F(ImageFiles, HeatmapOnSmallAndWideImages) {
    for (std::uint32_t w : {1u, 16u, 400u}) {
        const std::uint32_t h = 4;
        std::vector<float> values(std::size_t(w) * h);
        for (std::size_t i = 0; i < values.size(); ++i) values[i] = 0.1f * float(i % w) / float(w);
        values[0] = 0.0f;
        values.back() = 7.0f;  // above max: clamped
        const fs::path file = dir_ / ("heat" + std::to_string(w) + ".png");
        lc::write_heatmap_png(file, w, h, values, 0.1f);
        const Png png = read_png(file);
        ASSERT_EQ(png.width, int(w));
        ASSERT_GT(png.height, int(h));  // legend below
        EXPECT_EQ(png.at(0, 0), (std::array<std::uint8_t, 3>{68, 1, 84}));                    // ramp(0)
        EXPECT_EQ(png.at(int(w) - 1, int(h) - 1), (std::array<std::uint8_t, 3>{253, 231, 37}));  // ramp(1)
    }
    // The wide legend has room for its labels: some light ink below the bar.
    const Png wide = read_png(dir_ / "heat400.png");
    int ink = 0;
    for (int y = 4; y < wide.height; ++y)
        for (int x = 0; x < wide.width; ++x) ink += wide.at(x, y) == std::array<std::uint8_t, 3>{235, 235, 235};
    EXPECT_GT(ink, 20);
    EXPECT_EQ(entries().size(), 3u);
    EXPECT_THROW(lc::write_heatmap_png(dir_ / "bad.png", 4, 4, std::vector<float>(3), 1.0f), std::invalid_argument);
}
