// The scene JSON: parsing that knows where each value sits, and typed access
// whose errors name the field ("camera.width", "lights[2].intensity[1]").
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace lc::loader {

using json = nlohmann::json;

// JSON paths as error messages spell them: "camera" + "width" is
// "camera.width", "lights" + 2 is "lights[2]".
std::string join_key(const std::string& path, std::string_view key);
std::string join_index(const std::string& path, std::size_t i);

// Parses a JSON file. Unlike nlohmann's DOM parser, a duplicate key is an
// error, and a number overflow names the value's path. Throws InputError.
json parse_json_file(const std::filesystem::path& file);

// Typed access to a parsed tree. Every accessor takes the JSON path of the
// value so that its InputError names the exact field.
class JsonReader {
public:
    explicit JsonReader(std::string file) : file_(std::move(file)) {}

    [[noreturn]] void fail(const std::string& field, const std::string& problem) const;
    const std::string& file() const { return file_; }

    void expect_object(const json& j, const std::string& path) const;
    void expect_array(const json& j, const std::string& path) const;
    // Rejects keys outside `allowed`: a typo must not silently become a default.
    void check_keys(const json& obj, const std::string& path,
                    std::initializer_list<std::string_view> allowed) const;
    const json& require(const json& obj, const std::string& path, std::string_view key) const;
    static const json* find(const json& obj, std::string_view key);

    // Any JSON number, as parsed; the caller judges its range.
    double number_value(const json& j, const std::string& path) const;
    // A number that fits a 32-bit float.
    float number(const json& j, const std::string& path) const;
    float number_in(const json& j, const std::string& path, float lo, float hi, bool lo_open,
                    bool hi_open) const;
    // A JSON integer (not 256.0) in [lo, hi].
    std::uint32_t unsigned_int(const json& j, const std::string& path, std::uint32_t lo,
                               std::uint32_t hi) const;
    std::string string(const json& j, const std::string& path) const;
    bool boolean(const json& j, const std::string& path) const;
    glm::vec3 vec3(const json& j, const std::string& path) const;
    // RGB quantities (intensity, irradiance, reflectance): each in [0, max_component].
    glm::vec3 colour(const json& j, const std::string& path, float max_component) const;

    // Shortest text that reads back as the same float.
    static std::string format(float v);

private:
    std::string file_;
};

}  // namespace lc::loader
