// JsonReader: typed getters over the parsed scene JSON, each naming its field.
#include "json_reader.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>

#include "lightcuts/error.h"

namespace lc::loader {

std::string join_key(const std::string& path, std::string_view key) {
    return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string join_index(const std::string& path, std::size_t i) {
    return path + "[" + std::to_string(i) + "]";
}

void JsonReader::fail(const std::string& field, const std::string& problem) const {
    throw InputError(file_, field, problem);
}

void JsonReader::expect_object(const json& j, const std::string& path) const {
    if (!j.is_object()) fail(path, std::string("expected an object, got ") + j.type_name());
}

void JsonReader::expect_array(const json& j, const std::string& path) const {
    if (!j.is_array()) fail(path, std::string("expected an array, got ") + j.type_name());
}

void JsonReader::check_keys(const json& obj, const std::string& path,
                            std::initializer_list<std::string_view> allowed) const {
    for (const auto& [key, value] : obj.items()) {
        if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
        std::string expected;
        for (std::string_view a : allowed) {
            expected += expected.empty() ? "" : ", ";
            expected += a;
        }
        fail(join_key(path, key), "unknown key (expected one of: " + expected + ")");
    }
}

const json& JsonReader::require(const json& obj, const std::string& path, std::string_view key) const {
    const auto it = obj.find(key);
    if (it == obj.end()) fail(join_key(path, key), "missing required key");
    return *it;
}

const json* JsonReader::find(const json& obj, std::string_view key) {
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
}

double JsonReader::number_value(const json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, std::string("expected a number, got ") + j.type_name());
    return j.get<double>();
}

float JsonReader::number(const json& j, const std::string& path) const {
    const double v = number_value(j, path);
    if (!std::isfinite(v)) fail(path, "number is not finite");
    if (std::abs(v) > static_cast<double>(std::numeric_limits<float>::max())) {
        fail(path, "number is out of range for a 32-bit float");
    }
    return static_cast<float>(v);
}

float JsonReader::number_in(const json& j, const std::string& path, float lo, float hi,
                            bool lo_open, bool hi_open) const {
    const float v = number(j, path);
    const bool below = lo_open ? !(v > lo) : !(v >= lo);
    const bool above = hi_open ? !(v < hi) : !(v <= hi);
    if (below || above) {
        fail(path, "must be in " + std::string(lo_open ? "(" : "[") + format(lo) + ", " +
                       (hi == std::numeric_limits<float>::infinity() ? "inf" : format(hi)) +
                       (hi_open ? ")" : "]") + ", got " + format(v));
    }
    return v;
}

std::uint32_t JsonReader::unsigned_int(const json& j, const std::string& path, std::uint32_t lo,
                                       std::uint32_t hi) const {
    if (!j.is_number_integer()) {
        fail(path, std::string("expected an integer, got ") +
                       (j.is_number_float() ? "a non-integer number" : j.type_name()));
    }
    // Compare in 64 bits before narrowing so -1 or 2^40 are reported, not wrapped.
    const bool negative = j.is_number_unsigned() ? false : j.get<std::int64_t>() < 0;
    const std::uint64_t v = negative ? 0 : j.get<std::uint64_t>();
    if (negative || v < lo || v > hi) {
        fail(path, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                       "], got " + j.dump());
    }
    return static_cast<std::uint32_t>(v);
}

std::string JsonReader::string(const json& j, const std::string& path) const {
    if (!j.is_string()) fail(path, std::string("expected a string, got ") + j.type_name());
    return j.get<std::string>();
}

bool JsonReader::boolean(const json& j, const std::string& path) const {
    if (!j.is_boolean()) fail(path, std::string("expected true or false, got ") + j.type_name());
    return j.get<bool>();
}

glm::vec3 JsonReader::vec3(const json& j, const std::string& path) const {
    if (!j.is_array() || j.size() != 3) {
        fail(path, std::string("expected an array of 3 numbers, got ") +
                       (j.is_array() ? "an array of " + std::to_string(j.size())
                                     : std::string(j.type_name())));
    }
    return {number(j[0], join_index(path, 0)), number(j[1], join_index(path, 1)),
            number(j[2], join_index(path, 2))};
}

glm::vec3 JsonReader::colour(const json& j, const std::string& path, float max_component) const {
    const glm::vec3 c = vec3(j, path);
    for (int i = 0; i < 3; ++i) {
        const std::string field = join_index(path, static_cast<std::size_t>(i));
        if (c[i] < 0.0f) fail(field, "must not be negative, got " + format(c[i]));
        if (c[i] > max_component) {
            fail(field, "must be at most " + format(max_component) + ", got " + format(c[i]));
        }
    }
    return c;
}

std::string JsonReader::format(float v) {
    std::array<char, 32> buf{};
    const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
    return std::string(buf.data(), r.ptr);
}

}  // namespace lc::loader
