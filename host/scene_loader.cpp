// Scene loading: JSON scene description, Wavefront OBJ/MTL meshes and CSV
// point-light sets (docs/scene-format.md).
//
// Every problem with the input becomes an lc::InputError naming the file and
// the field, so a user can fix a scene without reading this code. The scene is
// built in a local value and only returned when complete, so a throw can never
// leave a half-loaded scene behind.
#include "lightcuts/scene.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <nlohmann/json.hpp>
#include <tiny_obj_loader.h>

#include "lightcuts/error.h"

namespace lc {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// Lambert grey for faces that name no material (the contract).
constexpr float kDefaultAlbedo = 0.8f;
// Roughness used by a JSON material override that gives ks but no roughness.
constexpr float kDefaultRoughness = 0.5f;
// GGX alpha floor: below this the fp32 NDF peak (1 / (pi alpha^2)) gets large
// enough that single point-light highlights turn into isolated fireflies.
constexpr float kMinGgxAlpha = 1e-3f;
constexpr std::uint32_t kMaxImageSide = 16384;

bool is_finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string display(const fs::path& p) { return p.lexically_normal().string(); }

// Reads a whole file into memory. One read is much faster than line-wise
// streams for the million-line CSV case.
std::optional<std::string> read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return std::nullopt;
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) return std::nullopt;
    std::string text(static_cast<std::size_t>(size), '\0');
    in.seekg(0, std::ios::beg);
    in.read(text.data(), size);
    if (!in) return std::nullopt;
    return text;
}

std::string join_key(const std::string& path, std::string_view key) {
    return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string join_index(const std::string& path, std::size_t i) {
    return path + "[" + std::to_string(i) + "]";
}

std::pair<std::size_t, std::size_t> line_and_column(std::string_view text, std::size_t offset) {
    offset = std::min(offset, text.size());
    std::size_t line = 1;
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < offset; ++i) {
        if (text[i] == '\n') {
            ++line;
            line_start = i + 1;
        }
    }
    return {line, offset - line_start + 1};
}

// ---------------------------------------------------------------------------
// JSON parsing
//
// nlohmann's DOM parser keeps the last of two duplicate keys silently and
// reports a number overflow (1e999) without any location. This SAX handler
// builds the same DOM but knows the JSON path of the value being parsed, so
// both problems are reported with the field that caused them.
// ---------------------------------------------------------------------------
class JsonDomBuilder final : public json::json_sax_t {
public:
    explicit JsonDomBuilder(std::string_view text) : text_(text) {}

    json root;
    std::string error_field;    // JSON path of the failing value, if known
    std::string error_problem;  // set when parsing stopped

    bool null() override { return add(json(nullptr)); }
    bool boolean(bool v) override { return add(json(v)); }
    bool number_integer(number_integer_t v) override { return add(json(v)); }
    bool number_unsigned(number_unsigned_t v) override { return add(json(v)); }
    bool number_float(number_float_t v, const string_t&) override { return add(json(v)); }
    bool string(string_t& v) override { return add(json(std::move(v))); }
    bool binary(binary_t& v) override { return add(json(std::move(v))); }

    bool start_object(std::size_t) override { return open(json::object()); }
    bool start_array(std::size_t) override { return open(json::array()); }
    bool end_object() override { return close(); }
    bool end_array() override { return close(); }

    bool key(string_t& k) override {
        Frame& top = stack_.back();
        if (top.value->contains(k)) {
            error_field = join_key(top.path, k);
            error_problem = "duplicate key";
            return false;
        }
        top.pending_key = std::move(k);
        return true;
    }

    bool parse_error(std::size_t position, const std::string&,
                     const json::exception& e) override {
        // Only an overflow pins the problem on one value; a syntax error is
        // better located by line and column than by a guessed path.
        error_field = (e.id == 406 && !stack_.empty()) ? current_path() : std::string();
        // Drop nlohmann's "[json.exception.parse_error.101] " prefix.
        std::string message = e.what();
        if (const auto close = message.find("] "); message.starts_with("[json.") &&
                                                   close != std::string::npos) {
            message.erase(0, close + 2);
        }
        if (message.find(" line ") == std::string::npos) {
            const auto [line, column] = line_and_column(text_, position);
            message += " at line " + std::to_string(line) + ", column " + std::to_string(column);
        }
        error_problem = std::move(message);
        return false;
    }

private:
    struct Frame {
        json* value;
        std::string path;
        std::string pending_key;
    };
    std::string_view text_;
    std::vector<Frame> stack_;

    std::string current_path() const {
        const Frame& top = stack_.back();
        return top.value->is_array() ? join_index(top.path, top.value->size())
                                     : join_key(top.path, top.pending_key);
    }

    // Pointers on the stack stay valid: only the innermost open container
    // grows, and none of its children is open at that moment.
    json* insert(json&& v) {
        if (stack_.empty()) {
            root = std::move(v);
            return &root;
        }
        json& parent = *stack_.back().value;
        if (parent.is_array()) {
            parent.push_back(std::move(v));
            return &parent.back();
        }
        return &(parent[stack_.back().pending_key] = std::move(v));
    }

    bool add(json&& v) {
        insert(std::move(v));
        return true;
    }

    bool open(json&& container) {
        // Each open level keeps its path, so the memory grows with the square
        // of the nesting depth: 400 KB of '[' took over 2 GB (found by
        // tests/fuzz). A scene is five levels deep; refuse far more.
        constexpr std::size_t kMaxDepth = 64;
        if (stack_.size() >= kMaxDepth) {
            error_field = current_path();
            error_problem = "nested more than " + std::to_string(kMaxDepth) + " levels deep";
            return false;
        }
        std::string path = stack_.empty() ? std::string() : current_path();
        json* slot = insert(std::move(container));
        stack_.push_back(Frame{slot, std::move(path), {}});
        return true;
    }

    bool close() {
        stack_.pop_back();
        return true;
    }
};

json parse_json_file(const fs::path& file) {
    const std::string name = display(file);
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) throw InputError(name, "", "file not found");
    const std::optional<std::string> text = read_file(file);
    if (!text) throw InputError(name, "", "cannot read file");

    JsonDomBuilder builder(*text);
    if (!json::sax_parse(*text, &builder)) {
        throw InputError(name, builder.error_field, builder.error_problem);
    }
    return std::move(builder.root);
}

// ---------------------------------------------------------------------------
// Typed access to the JSON tree. Every accessor takes the JSON path of the
// value so its error names the exact field.
// ---------------------------------------------------------------------------
class JsonReader {
public:
    explicit JsonReader(std::string file) : file_(std::move(file)) {}

    [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
        throw InputError(file_, field, problem);
    }

    const std::string& file() const { return file_; }

    void expect_object(const json& j, const std::string& path) const {
        if (!j.is_object()) fail(path, std::string("expected an object, got ") + j.type_name());
    }

    void expect_array(const json& j, const std::string& path) const {
        if (!j.is_array()) fail(path, std::string("expected an array, got ") + j.type_name());
    }

    // Rejects keys outside `allowed`: a typo must not silently become a default.
    void check_keys(const json& obj, const std::string& path,
                    std::initializer_list<std::string_view> allowed) const {
        for (const auto& [key, value] : obj.items()) {
            if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
                std::string expected;
                for (std::string_view a : allowed) {
                    expected += expected.empty() ? "" : ", ";
                    expected += a;
                }
                fail(join_key(path, key), "unknown key (expected one of: " + expected + ")");
            }
        }
    }

    const json& require(const json& obj, const std::string& path, std::string_view key) const {
        const auto it = obj.find(key);
        if (it == obj.end()) fail(join_key(path, key), "missing required key");
        return *it;
    }

    static const json* find(const json& obj, std::string_view key) {
        const auto it = obj.find(key);
        return it == obj.end() ? nullptr : &*it;
    }

    float number(const json& j, const std::string& path) const {
        if (!j.is_number()) fail(path, std::string("expected a number, got ") + j.type_name());
        const double v = j.get<double>();
        if (!std::isfinite(v)) fail(path, "number is not finite");
        if (std::abs(v) > static_cast<double>(std::numeric_limits<float>::max())) {
            fail(path, "number is out of range for a 32-bit float");
        }
        return static_cast<float>(v);
    }

    float number_in(const json& j, const std::string& path, float lo, float hi,
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

    std::uint32_t unsigned_int(const json& j, const std::string& path, std::uint32_t lo,
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

    std::string string(const json& j, const std::string& path) const {
        if (!j.is_string()) fail(path, std::string("expected a string, got ") + j.type_name());
        return j.get<std::string>();
    }

    glm::vec3 vec3(const json& j, const std::string& path) const {
        if (!j.is_array() || j.size() != 3) {
            fail(path, std::string("expected an array of 3 numbers, got ") +
                           (j.is_array() ? "an array of " + std::to_string(j.size())
                                         : std::string(j.type_name())));
        }
        return {number(j[0], join_index(path, 0)), number(j[1], join_index(path, 1)),
                number(j[2], join_index(path, 2))};
    }

    // RGB quantities (intensity, irradiance, reflectance) must not be negative.
    glm::vec3 colour(const json& j, const std::string& path, float max_component) const {
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

    static std::string format(float v) {
        std::array<char, 32> buf{};
        const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
        return std::string(buf.data(), r.ptr);
    }

private:
    std::string file_;
};

// ---------------------------------------------------------------------------
// Materials
// ---------------------------------------------------------------------------
gpu::Material make_material(glm::vec3 kd, glm::vec3 ks, float alpha) {
    gpu::Material m{};
    m.kd_r = kd.r;
    m.kd_g = kd.g;
    m.kd_b = kd.b;
    m.ks_r = ks.r;
    m.ks_g = ks.g;
    m.ks_b = ks.b;
    m.alpha = std::clamp(alpha, kMinGgxAlpha, 1.0f);
    m.flags = (ks.r > 0.0f || ks.g > 0.0f || ks.b > 0.0f) ? gpu::kMaterialHasSpecular : 0u;
    return m;
}

gpu::Material convert_mtl(const tinyobj::material_t& mtl, const std::string& obj_name) {
    const std::string field = "material '" + mtl.name + "'";
    const auto rgb = [&](const tinyobj::real_t* v, const char* key) {
        glm::vec3 c;
        for (int i = 0; i < 3; ++i) {
            if (!std::isfinite(v[i]) || v[i] < 0.0 || v[i] > 1.0) {
                throw InputError(obj_name, field + "." + key,
                                 "components must be in [0, 1], got " + std::to_string(v[i]));
            }
            c[i] = static_cast<float>(v[i]);
        }
        return c;
    };
    const glm::vec3 kd = rgb(mtl.diffuse, "Kd");
    const glm::vec3 ks = rgb(mtl.specular, "Ks");
    // tinyobj leaves roughness at 0 when the MTL has no "Pr", so Pr = 0 means
    // "not given" and the Blinn-Phong exponent decides (Walter et al. 2007).
    float alpha = 1.0f;
    if (mtl.roughness > 0.0) {
        if (!std::isfinite(mtl.roughness) || mtl.roughness > 1.0) {
            throw InputError(obj_name, field + ".Pr", "must be in [0, 1]");
        }
        alpha = static_cast<float>(mtl.roughness * mtl.roughness);
    } else {
        if (!std::isfinite(mtl.shininess) || mtl.shininess < 0.0) {
            throw InputError(obj_name, field + ".Ns", "must be a finite number >= 0");
        }
        alpha = static_cast<float>(std::sqrt(2.0 / (mtl.shininess + 2.0)));
    }
    return make_material(kd, ks, alpha);
}

// ---------------------------------------------------------------------------
// Scene parser
// ---------------------------------------------------------------------------
class SceneParser {
public:
    explicit SceneParser(const fs::path& file)
        : file_(file), dir_(file.parent_path()), in_(display(file)) {}

    Scene parse() {
        const json root = parse_json_file(file_);
        in_.expect_object(root, "");
        in_.check_keys(root, "", {"description", "camera", "meshes", "lights", "render"});
        if (const json* d = JsonReader::find(root, "description")) in_.string(*d, "description");

        scene_.file = file_;
        parse_camera(in_.require(root, "", "camera"));
        parse_meshes(in_.require(root, "", "meshes"));
        parse_lights(in_.require(root, "", "lights"));
        if (const json* r = JsonReader::find(root, "render")) parse_render(*r);
        update_bounds(scene_);
        return std::move(scene_);
    }

private:
    fs::path file_;
    fs::path dir_;
    JsonReader in_;
    Scene scene_;
    std::optional<std::uint32_t> default_material_;

    fs::path resolve(const std::string& relative) const { return dir_ / relative; }

    void parse_camera(const json& j) {
        const std::string path = "camera";
        in_.expect_object(j, path);
        in_.check_keys(j, path, {"position", "look_at", "up", "fov_y_degrees", "width", "height"});
        Camera& cam = scene_.camera;
        cam.position = in_.vec3(in_.require(j, path, "position"), "camera.position");
        cam.look_at = in_.vec3(in_.require(j, path, "look_at"), "camera.look_at");
        if (const json* v = JsonReader::find(j, "up")) cam.up = in_.vec3(*v, "camera.up");
        if (const json* v = JsonReader::find(j, "fov_y_degrees")) {
            cam.fov_y_degrees = in_.number_in(*v, "camera.fov_y_degrees", 0.0f, 180.0f, true, true);
        }
        if (const json* v = JsonReader::find(j, "width")) {
            cam.width = in_.unsigned_int(*v, "camera.width", 1, kMaxImageSide);
        }
        if (const json* v = JsonReader::find(j, "height")) {
            cam.height = in_.unsigned_int(*v, "camera.height", 1, kMaxImageSide);
        }

        // The camera basis is cross(forward, up): both must be usable.
        const glm::vec3 forward = cam.look_at - cam.position;
        const float forward_len = glm::length(forward);
        if (!(forward_len > 0.0f) || !std::isfinite(forward_len)) {
            in_.fail("camera.look_at", "must differ from camera.position");
        }
        const float up_len = glm::length(cam.up);
        if (!(up_len > 0.0f) || !std::isfinite(up_len)) in_.fail("camera.up", "must not be zero");
        const float sin_angle = glm::length(glm::cross(forward / forward_len, cam.up / up_len));
        if (!(sin_angle > 1e-6f)) in_.fail("camera.up", "must not be parallel to the view direction");
    }

    void parse_render(const json& j) {
        const std::string path = "render";
        in_.expect_object(j, path);
        in_.check_keys(j, path, {"method", "spp", "relative_error", "max_cut", "seed"});
        RenderSettings& r = scene_.render;
        if (const json* v = JsonReader::find(j, "method")) {
            r.method = in_.string(*v, "render.method");
            if (r.method != "brute" && r.method != "lightcuts") {
                in_.fail("render.method", "must be \"brute\" or \"lightcuts\", got \"" + r.method + "\"");
            }
        }
        constexpr std::uint32_t kMaxU32 = std::numeric_limits<std::uint32_t>::max();
        if (const json* v = JsonReader::find(j, "spp")) r.spp = in_.unsigned_int(*v, "render.spp", 1, kMaxU32);
        if (const json* v = JsonReader::find(j, "relative_error")) {
            r.relative_error = in_.number_in(*v, "render.relative_error", 0.0f,
                                             std::numeric_limits<float>::infinity(), false, true);
        }
        if (const json* v = JsonReader::find(j, "max_cut")) {
            r.max_cut = in_.unsigned_int(*v, "render.max_cut", 1, kMaxU32);
        }
        if (const json* v = JsonReader::find(j, "seed")) r.seed = in_.unsigned_int(*v, "render.seed", 0, kMaxU32);
    }

    // -- meshes -------------------------------------------------------------

    struct MeshTransform {
        glm::mat4 position{1.0f};
        glm::mat3 normal{1.0f};
        bool mirrors = false;  // odd number of negative scales flips winding
    };

    MeshTransform parse_transform(const json& j, const std::string& path) const {
        in_.expect_object(j, path);
        in_.check_keys(j, path, {"translate", "rotate_degrees", "scale"});
        glm::vec3 translate{0.0f}, rotate{0.0f}, scale{1.0f};
        if (const json* v = JsonReader::find(j, "translate")) translate = in_.vec3(*v, path + ".translate");
        if (const json* v = JsonReader::find(j, "rotate_degrees")) rotate = in_.vec3(*v, path + ".rotate_degrees");
        if (const json* v = JsonReader::find(j, "scale")) {
            const std::string field = path + ".scale";
            scale = v->is_array() ? in_.vec3(*v, field) : glm::vec3(in_.number(*v, field));
            for (int i = 0; i < 3; ++i) {
                if (scale[i] == 0.0f) {
                    in_.fail(v->is_array() ? join_index(field, static_cast<std::size_t>(i)) : field,
                             "must not be zero");
                }
            }
        }
        // M = T * Rz * Ry * Rx * S: scale first, then rotate about X, Y, Z, then translate.
        glm::mat4 m = glm::translate(glm::mat4(1.0f), translate);
        m = glm::rotate(m, glm::radians(rotate.z), glm::vec3(0, 0, 1));
        m = glm::rotate(m, glm::radians(rotate.y), glm::vec3(0, 1, 0));
        m = glm::rotate(m, glm::radians(rotate.x), glm::vec3(1, 0, 0));
        m = glm::scale(m, scale);
        MeshTransform t;
        t.position = m;
        t.normal = glm::inverseTranspose(glm::mat3(m));
        t.mirrors = scale.x * scale.y * scale.z < 0.0f;
        return t;
    }

    gpu::Material parse_material_override(const json& j, const std::string& path) const {
        in_.expect_object(j, path);
        in_.check_keys(j, path, {"kd", "ks", "roughness"});
        glm::vec3 kd{kDefaultAlbedo}, ks{0.0f};
        float roughness = kDefaultRoughness;
        if (const json* v = JsonReader::find(j, "kd")) kd = in_.colour(*v, path + ".kd", 1.0f);
        if (const json* v = JsonReader::find(j, "ks")) ks = in_.colour(*v, path + ".ks", 1.0f);
        if (const json* v = JsonReader::find(j, "roughness")) {
            roughness = in_.number_in(*v, path + ".roughness", 0.0f, 1.0f, true, false);
        }
        return make_material(kd, ks, roughness * roughness);
    }

    std::uint32_t default_material() {
        if (!default_material_) {
            default_material_ = static_cast<std::uint32_t>(scene_.materials.size());
            scene_.materials.push_back(make_material(glm::vec3(kDefaultAlbedo), glm::vec3(0.0f), 1.0f));
        }
        return *default_material_;
    }

    void parse_meshes(const json& j) {
        in_.expect_array(j, "meshes");
        if (j.empty()) in_.fail("meshes", "must contain at least one mesh");
        for (std::size_t i = 0; i < j.size(); ++i) parse_mesh(j[i], join_index("meshes", i));
    }

    void parse_mesh(const json& j, const std::string& path) {
        in_.expect_object(j, path);
        in_.check_keys(j, path, {"obj", "transform", "material"});
        const std::string obj_field = path + ".obj";
        const fs::path obj_path = resolve(in_.string(in_.require(j, path, "obj"), obj_field));
        MeshTransform transform;
        if (const json* t = JsonReader::find(j, "transform")) transform = parse_transform(*t, path + ".transform");
        std::optional<gpu::Material> override_material;
        if (const json* m = JsonReader::find(j, "material")) {
            override_material = parse_material_override(*m, path + ".material");
        }

        std::error_code ec;
        if (!fs::is_regular_file(obj_path, ec)) in_.fail(obj_field, "file not found: " + display(obj_path));
        load_obj(obj_path, transform, override_material);
    }

    void load_obj(const fs::path& obj_path, const MeshTransform& transform,
                  const std::optional<gpu::Material>& override_material) {
        const std::string obj_name = display(obj_path);
        tinyobj::ObjReaderConfig config;
        config.triangulate = true;
        config.vertex_color = false;
        tinyobj::ObjReader reader;
        if (!reader.ParseFromFile(obj_path.string(), config)) {
            std::string err = reader.Error();
            while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
            throw InputError(obj_name, "", "tinyobjloader: " + (err.empty() ? "parse failed" : err));
        }
        // tinyobj treats a missing .mtl or an unknown usemtl name as a warning and
        // falls back to "no material"; silently grey walls are worse than an error.
        const std::string& warning = reader.Warning();
        if (!override_material) {
            if (warning.find("Failed to load material file") != std::string::npos ||
                warning.find("Material file [") != std::string::npos) {
                // tinyobj's warning reads "Material file [ NAME ] not found ...".
                std::string library = "material library";
                if (const auto open = warning.find("[ "), close = warning.find(" ]");
                    open != std::string::npos && close != std::string::npos && close > open) {
                    library = "'" + warning.substr(open + 2, close - open - 2) + "'";
                }
                throw InputError(obj_name, "mtllib", library + " not found next to the OBJ");
            }
            if (const auto at = warning.find("not found in .mtl"); at != std::string::npos) {
                const auto begin = warning.rfind('\n', at);
                const auto from = begin == std::string::npos ? 0 : begin + 1;
                throw InputError(obj_name, "usemtl",
                                 "tinyobjloader: " + warning.substr(from, at - from) + "not found in .mtl");
            }
        }

        // Materials: either the one override or every MTL material of this OBJ.
        const std::uint32_t material_base = static_cast<std::uint32_t>(scene_.materials.size());
        if (override_material) {
            scene_.materials.push_back(*override_material);
        } else {
            for (const tinyobj::material_t& m : reader.GetMaterials()) {
                scene_.materials.push_back(convert_mtl(m, obj_name));
            }
        }
        const std::size_t mtl_count = override_material ? 0 : reader.GetMaterials().size();

        const tinyobj::attrib_t& attrib = reader.GetAttrib();
        const std::size_t vertex_count = attrib.vertices.size() / 3;
        const std::size_t normal_count = attrib.normals.size() / 3;
        const auto position = [&](int index) {
            const auto k = static_cast<std::size_t>(index) * 3;
            return glm::vec3(transform.position *
                             glm::vec4(static_cast<float>(attrib.vertices[k]),
                                       static_cast<float>(attrib.vertices[k + 1]),
                                       static_cast<float>(attrib.vertices[k + 2]), 1.0f));
        };
        const auto normal = [&](int index) {
            const auto k = static_cast<std::size_t>(index) * 3;
            return transform.normal * glm::vec3(static_cast<float>(attrib.normals[k]),
                                                static_cast<float>(attrib.normals[k + 1]),
                                                static_cast<float>(attrib.normals[k + 2]));
        };

        std::size_t kept = 0;
        for (const tinyobj::shape_t& shape : reader.GetShapes()) {
            const tinyobj::mesh_t& mesh = shape.mesh;
            std::size_t offset = 0;
            for (std::size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
                const std::size_t corners = mesh.num_face_vertices[f];
                const std::size_t first = offset;
                offset += corners;
                // Built only on error: this loop runs once per triangle.
                const auto face_field = [&] {
                    return "triangle " + std::to_string(f + 1) +
                           (shape.name.empty() ? std::string() : " of shape '" + shape.name + "'");
                };
                if (corners != 3) {
                    throw InputError(obj_name, face_field(),
                                     "has " + std::to_string(corners) + " corners after triangulation");
                }
                // tinyobj only warns about out-of-range indices and keeps them.
                std::array<tinyobj::index_t, 3> idx{};
                for (std::size_t c = 0; c < 3; ++c) {
                    idx[c] = mesh.indices[first + c];
                    if (idx[c].vertex_index < 0 || static_cast<std::size_t>(idx[c].vertex_index) >= vertex_count) {
                        throw InputError(obj_name, face_field(),
                                         "vertex index " + std::to_string(idx[c].vertex_index + 1) +
                                             " out of range (" + std::to_string(vertex_count) + " vertices)");
                    }
                    if (idx[c].normal_index >= 0 && static_cast<std::size_t>(idx[c].normal_index) >= normal_count) {
                        throw InputError(obj_name, face_field(),
                                         "normal index " + std::to_string(idx[c].normal_index + 1) +
                                             " out of range (" + std::to_string(normal_count) + " normals)");
                    }
                }

                const glm::vec3 v0 = position(idx[0].vertex_index);
                const glm::vec3 v1 = position(idx[1].vertex_index);
                const glm::vec3 v2 = position(idx[2].vertex_index);
                const glm::vec3 cross = glm::cross(v1 - v0, v2 - v0);
                const float twice_area = glm::length(cross);
                const bool finite = is_finite(v0) && is_finite(v1) && is_finite(v2) &&
                                    std::isfinite(twice_area);
                if (!finite || !(twice_area > 0.0f)) {
                    ++scene_.degenerate_triangles_dropped;
                    continue;
                }
                // Keep the face normal on the side the OBJ winding says, even
                // when a mirroring scale has flipped the winding.
                const glm::vec3 face_normal = cross / twice_area * (transform.mirrors ? -1.0f : 1.0f);

                std::array<glm::vec3, 3> n{face_normal, face_normal, face_normal};
                if (idx[0].normal_index >= 0 && idx[1].normal_index >= 0 && idx[2].normal_index >= 0) {
                    std::array<glm::vec3, 3> vn{};
                    bool usable = true;
                    for (std::size_t c = 0; c < 3; ++c) {
                        vn[c] = normal(idx[c].normal_index);
                        const float len = glm::length(vn[c]);
                        usable = usable && len > 0.0f && std::isfinite(len);
                        vn[c] /= len;
                    }
                    // A zero or broken vertex normal would poison shading; the
                    // face normal is the honest fallback.
                    if (usable) n = vn;
                }

                std::uint32_t material = 0;
                const int mtl_id = mesh.material_ids.empty() ? -1 : mesh.material_ids[f];
                if (override_material) {
                    material = material_base;
                } else if (mtl_id >= 0 && static_cast<std::size_t>(mtl_id) < mtl_count) {
                    material = material_base + static_cast<std::uint32_t>(mtl_id);
                } else {
                    material = default_material();
                }

                const gpu::Triangle tri{v0.x, v0.y, v0.z, v1.x, v1.y, v1.z,
                                        v2.x, v2.y, v2.z, material, 0u, 0u};
                const gpu::TriangleNormals tn{n[0].x, n[0].y, n[0].z, n[1].x, n[1].y, n[1].z,
                                              n[2].x, n[2].y, n[2].z, 0u, 0u, 0u};
                scene_.triangles.push_back(tri);
                scene_.normals.push_back(tn);
                ++kept;
            }
        }
        if (kept == 0) {
            throw InputError(obj_name, "", "no usable triangles (after dropping degenerate ones)");
        }
    }

    // -- lights -------------------------------------------------------------

    void parse_lights(const json& j) {
        in_.expect_array(j, "lights");
        for (std::size_t i = 0; i < j.size(); ++i) parse_light(j[i], join_index("lights", i));
        if (scene_.lights.empty()) in_.fail("lights", "the scene has no lights (after loading CSV files)");
    }

    void parse_light(const json& j, const std::string& path) {
        in_.expect_object(j, path);
        const std::string type = in_.string(in_.require(j, path, "type"), path + ".type");
        gpu::Light light{};
        if (type == "point") {
            in_.check_keys(j, path, {"type", "position", "intensity"});
            const glm::vec3 p = in_.vec3(in_.require(j, path, "position"), path + ".position");
            const glm::vec3 c = in_.colour(in_.require(j, path, "intensity"), path + ".intensity",
                                           std::numeric_limits<float>::max());
            light = {p.x, p.y, p.z, c.r, c.g, c.b, gpu::kLightPoint, 0u};
            scene_.lights.push_back(light);
        } else if (type == "directional") {
            in_.check_keys(j, path, {"type", "direction", "irradiance"});
            const glm::vec3 d = in_.vec3(in_.require(j, path, "direction"), path + ".direction");
            const float len = glm::length(d);
            if (!(len > 0.0f) || !std::isfinite(len)) in_.fail(path + ".direction", "must not be zero-length");
            const glm::vec3 c = in_.colour(in_.require(j, path, "irradiance"), path + ".irradiance",
                                           std::numeric_limits<float>::max());
            // The file gives the way light travels; shading wants the way to the light.
            const glm::vec3 to_light = -d / len;
            light = {to_light.x, to_light.y, to_light.z, c.r, c.g, c.b, gpu::kLightDirectional, 0u};
            scene_.lights.push_back(light);
        } else if (type == "points_csv") {
            in_.check_keys(j, path, {"type", "file"});
            const std::string field = path + ".file";
            const fs::path csv = resolve(in_.string(in_.require(j, path, "file"), field));
            std::error_code ec;
            if (!fs::is_regular_file(csv, ec)) in_.fail(field, "file not found: " + display(csv));
            std::vector<gpu::Light> loaded = load_points_csv(csv);
            scene_.lights.insert(scene_.lights.end(), loaded.begin(), loaded.end());
        } else {
            in_.fail(path + ".type",
                     "unknown light type \"" + type + "\" (expected point, directional or points_csv)");
        }
    }
};

// ---------------------------------------------------------------------------
// CSV point lights
// ---------------------------------------------------------------------------
constexpr std::array<const char*, 6> kCsvColumns{"x", "y", "z", "r", "g", "b"};

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
    return s;
}

enum class FieldStatus { ok, not_a_number, out_of_range };

FieldStatus parse_float(std::string_view text, float& out) {
    if (!text.empty() && text.front() == '+') text.remove_prefix(1);  // from_chars rejects '+'
    if (text.empty()) return FieldStatus::not_a_number;
    const char* end = text.data() + text.size();
    const auto [ptr, ec] = std::from_chars(text.data(), end, out);
    if (ec == std::errc::invalid_argument || ptr != end) return FieldStatus::not_a_number;
    if (ec == std::errc::result_out_of_range) {
        // from_chars also reports underflow (1e-60) as out of range; that
        // value is simply zero for a light, only overflow is an error.
        const std::string copy(text);
        const double d = std::strtod(copy.c_str(), nullptr);
        if (std::isfinite(d) && std::abs(d) < 1.0) {
            out = static_cast<float>(d);
            return FieldStatus::ok;
        }
        return FieldStatus::out_of_range;
    }
    return FieldStatus::ok;
}

}  // namespace

std::vector<gpu::Light> load_points_csv(const fs::path& file) {
    const std::string name = display(file);
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) throw InputError(name, "", "file not found");
    const std::optional<std::string> text = read_file(file);
    if (!text) throw InputError(name, "", "cannot read file");

    std::vector<gpu::Light> lights;
    // ~30 bytes per line is typical; reserving avoids regrowth for 10^6 lights.
    lights.reserve(text->size() / 32 + 1);

    const std::string_view all(*text);
    std::size_t line_number = 0;
    bool seen_content = false;
    std::size_t pos = 0;
    while (pos < all.size()) {
        std::size_t eol = all.find('\n', pos);
        if (eol == std::string_view::npos) eol = all.size();
        std::string_view line = all.substr(pos, eol - pos);
        pos = eol + 1;
        ++line_number;

        if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
        line = trim(line);
        if (line.empty()) continue;
        const bool first_content = !seen_content;
        seen_content = true;

        std::array<float, 6> values{};
        std::array<std::string_view, 6> fields{};
        std::size_t count = 0;
        bool too_many = false;
        for (std::size_t start = 0;;) {
            const std::size_t comma = line.find(',', start);
            const std::string_view field = trim(line.substr(start, comma == std::string_view::npos
                                                                       ? std::string_view::npos
                                                                       : comma - start));
            if (count < fields.size()) fields[count] = field;
            else too_many = true;
            ++count;
            if (comma == std::string_view::npos) break;
            start = comma + 1;
        }

        // Header: only the first content line, and only if nothing in it is a
        // number, so that a typo in the first data line is still an error.
        if (first_content) {
            bool any_number = false;
            for (std::size_t i = 0; i < std::min<std::size_t>(count, 6); ++i) {
                float ignored = 0.0f;
                any_number = any_number || parse_float(fields[i], ignored) != FieldStatus::not_a_number;
            }
            if (!any_number) continue;
        }

        const std::string where = "line " + std::to_string(line_number);
        if (too_many || count != 6) {
            throw InputError(name, where,
                             "expected 6 comma-separated numbers x,y,z,r,g,b, found " +
                                 std::to_string(count) + " fields");
        }
        for (std::size_t i = 0; i < 6; ++i) {
            const std::string column = std::string("column ") + std::to_string(i + 1) + " (" +
                                       kCsvColumns[i] + ")";
            switch (parse_float(fields[i], values[i])) {
                case FieldStatus::not_a_number:
                    throw InputError(name, where, column + ": '" + std::string(fields[i]) + "' is not a number");
                case FieldStatus::out_of_range:
                    throw InputError(name, where, column + ": '" + std::string(fields[i]) +
                                                      "' is out of range for a 32-bit float");
                case FieldStatus::ok: break;
            }
            if (!std::isfinite(values[i])) {
                throw InputError(name, where, column + ": '" + std::string(fields[i]) + "' is not finite");
            }
            if (i >= 3 && values[i] < 0.0f) {
                throw InputError(name, where, column + ": intensity must not be negative");
            }
        }
        lights.push_back(gpu::Light{values[0], values[1], values[2], values[3], values[4], values[5],
                                    gpu::kLightPoint, 0u});
    }
    return lights;
}

Scene load_scene(const fs::path& file) { return SceneParser(file).parse(); }

void update_bounds(Scene& scene) {
    glm::vec3 lo(std::numeric_limits<float>::infinity());
    glm::vec3 hi(-std::numeric_limits<float>::infinity());
    const auto grow = [&](float x, float y, float z) {
        lo = glm::min(lo, glm::vec3(x, y, z));
        hi = glm::max(hi, glm::vec3(x, y, z));
    };
    for (const gpu::Triangle& t : scene.triangles) {
        grow(t.v0_x, t.v0_y, t.v0_z);
        grow(t.v1_x, t.v1_y, t.v1_z);
        grow(t.v2_x, t.v2_y, t.v2_z);
    }
    // Directional lights have no position; they do not widen the box.
    for (const gpu::Light& l : scene.lights) {
        if (l.type == gpu::kLightPoint) grow(l.x, l.y, l.z);
    }
    if (lo.x > hi.x) lo = hi = glm::vec3(0.0f);
    scene.bounds_min = lo;
    scene.bounds_max = hi;
}

std::size_t Scene::count_lights(std::uint32_t type) const {
    return static_cast<std::size_t>(
        std::count_if(lights.begin(), lights.end(), [type](const gpu::Light& l) { return l.type == type; }));
}

}  // namespace lc
