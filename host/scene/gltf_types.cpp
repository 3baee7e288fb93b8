// Type checks of a glTF's JSON ahead of tinygltf (gltf_types.h).
#include "gltf_types.h"

#include <nlohmann/json.hpp>

#include "lightcuts/error.h"

namespace lc::loader {
namespace {

using json = nlohmann::json;

class TypeCheck {
public:
    explicit TypeCheck(const std::string& name) : name_(name) {}

    [[noreturn]] void fail(const std::string& path, const std::string& problem) const {
        throw InputError(name_, path, problem);
    }

    // "path.key", or "key" at the top level.
    static std::string at(const std::string& path, const char* key) {
        return path.empty() ? std::string(key) : path + "." + key;
    }

    // "a string", "an array": a value's JSON type with its article.
    static std::string a(const json& v) {
        const std::string type = v.type_name();
        return (type[0] == 'a' || type[0] == 'o' ? "an " : "a ") + type;
    }

    // The member `key` of `object`, if both are there and it is an object.
    static const json* member(const json& object, const char* key) {
        if (!object.is_object()) return nullptr;
        const auto it = object.find(key);
        return it == object.end() ? nullptr : &*it;
    }

    void number(const json& object, const char* key, const std::string& path) const {
        if (const json* v = member(object, key); v && !v->is_number())
            fail(at(path, key), "must be a number, not " + a(*v));
    }

    void numbers(const json& object, const char* key, std::size_t count, const std::string& path) const {
        const json* v = member(object, key);
        if (!v) return;
        if (!v->is_array() || v->size() != count)
            fail(at(path, key), "must be an array of " + std::to_string(count) + " numbers");
        for (std::size_t i = 0; i < count; ++i)
            if (!(*v)[i].is_number())
                fail(at(path, key) + "[" + std::to_string(i) + "]",
                     "must be a number, not " + a((*v)[i]));
    }

    // Objects and arrays of the wrong JSON type, which tinygltf would skip
    // (a KHR_lights_punctual that is not an object reads as no lights).
    void object(const json& object, const char* key, const std::string& path) const {
        if (const json* v = member(object, key); v && !v->is_object())
            fail(at(path, key), "must be an object, not " + a(*v));
    }

    void array(const json& object, const char* key, const std::string& path) const {
        if (const json* v = member(object, key); v && !v->is_array())
            fail(at(path, key), "must be an array, not " + a(*v));
    }

    void index(const json& object, const char* key, const std::string& path) const {
        if (const json* v = member(object, key); v && !(v->is_number_unsigned()))
            fail(at(path, key), "must be a whole number >= 0, not " +
                                       (v->is_number() ? v->dump() : a(*v)));
    }

    void indices(const json& object, const char* key, const std::string& path) const {
        const json* v = member(object, key);
        if (!v) return;
        if (!v->is_array()) fail(at(path, key), "must be an array of whole numbers >= 0");
        for (std::size_t i = 0; i < v->size(); ++i)
            if (!(*v)[i].is_number_unsigned())
                fail(at(path, key) + "[" + std::to_string(i) + "]", "must be a whole number >= 0");
    }

    // Calls f(element, "key[i]") for each element of the array `key` of `object`.
    template <class F>
    void each(const json& object, const char* key, const std::string& path, F&& f) const {
        const json* v = member(object, key);
        if (!v || !v->is_array()) return;
        for (std::size_t i = 0; i < v->size(); ++i)
            f((*v)[i], at(path, key) + "[" + std::to_string(i) + "]");
    }

    void texture_info(const json& material, const char* key, const std::string& path) const {
        const json* t = member(material, key);
        if (!t) return;
        const std::string where = at(path, key);
        index(*t, "index", where);
        index(*t, "texCoord", where);
        number(*t, "scale", where);
        number(*t, "strength", where);
        object(*t, "extensions", where);
        if (const json* ext = member(*t, "extensions")) {
            // Read as an object (gltf_materials.cpp), so its type is checked there.
            if (const json* transform = member(*ext, "KHR_texture_transform")) {
                const std::string at = where + ".extensions.KHR_texture_transform";
                numbers(*transform, "offset", 2, at);
                numbers(*transform, "scale", 2, at);
                number(*transform, "rotation", at);
                index(*transform, "texCoord", at);
            }
        }
    }

    void material(const json& m, const std::string& path) const {
        if (const json* pbr = member(m, "pbrMetallicRoughness")) {
            const std::string at = path + ".pbrMetallicRoughness";
            numbers(*pbr, "baseColorFactor", 4, at);
            number(*pbr, "metallicFactor", at);
            number(*pbr, "roughnessFactor", at);
            texture_info(*pbr, "baseColorTexture", at);
            texture_info(*pbr, "metallicRoughnessTexture", at);
        }
        numbers(m, "emissiveFactor", 3, path);
        number(m, "alphaCutoff", path);
        for (const char* t : {"normalTexture", "occlusionTexture", "emissiveTexture"}) texture_info(m, t, path);
        object(m, "extensions", path);
        const json* ext = member(m, "extensions");
        if (!ext) return;
        const std::string at = path + ".extensions";
        // A supported extension that is not an object was ignored
        // ("KHR_materials_emissive_strength": 5 rendered at strength 1).
        for (const char* name : {"KHR_materials_emissive_strength", "KHR_materials_clearcoat", "KHR_materials_sheen"})
            object(*ext, name, at);
        if (const json* e = member(*ext, "KHR_materials_emissive_strength"))
            number(*e, "emissiveStrength", at + ".KHR_materials_emissive_strength");
        if (const json* e = member(*ext, "KHR_materials_clearcoat")) {
            number(*e, "clearcoatFactor", at + ".KHR_materials_clearcoat");
            number(*e, "clearcoatRoughnessFactor", at + ".KHR_materials_clearcoat");
        }
        if (const json* e = member(*ext, "KHR_materials_sheen")) {
            numbers(*e, "sheenColorFactor", 3, at + ".KHR_materials_sheen");
            number(*e, "sheenRoughnessFactor", at + ".KHR_materials_sheen");
        }
    }

    void camera(const json& c, const std::string& path) const {
        const json* p = member(c, "perspective");
        if (!p) return;
        const std::string at = path + ".perspective";
        for (const char* key : {"yfov", "aspectRatio", "znear", "zfar"}) number(*p, key, at);
        // tinygltf reads an aspect ratio of 0 as none; the specification
        // asks for one above 0 where there is one.
        if (const json* a = member(*p, "aspectRatio"); a && !(a->get<double>() > 0.0))
            fail(at + ".aspectRatio", "must be above 0, not " + a->dump());
    }

    void document(const json& doc) const {
        index(doc, "scene", "");
        each(doc, "scenes", "", [&](const json& s, const std::string& at) { indices(s, "nodes", at); });
        each(doc, "nodes", "", [&](const json& n, const std::string& at) {
            numbers(n, "translation", 3, at);
            numbers(n, "rotation", 4, at);
            numbers(n, "scale", 3, at);
            numbers(n, "matrix", 16, at);
            index(n, "mesh", at);
            index(n, "camera", at);
            indices(n, "children", at);
            object(n, "extensions", at);
            if (const json* ext = member(n, "extensions")) {
                object(*ext, "KHR_lights_punctual", at + ".extensions");
                if (const json* light = member(*ext, "KHR_lights_punctual"))
                    index(*light, "light", at + ".extensions.KHR_lights_punctual");
            }
        });
        each(doc, "meshes", "", [&](const json& m, const std::string& at) {
            each(m, "primitives", at, [&](const json& p, const std::string& prim) {
                index(p, "indices", prim);
                index(p, "material", prim);
                index(p, "mode", prim);
                if (const json* attributes = member(p, "attributes"); attributes && attributes->is_object())
                    for (const auto& [key, value] : attributes->items()) index(*attributes, key.c_str(), prim + ".attributes");
            });
        });
        each(doc, "accessors", "", [&](const json& a, const std::string& at) {
            for (const char* key : {"bufferView", "byteOffset", "componentType", "count"}) index(a, key, at);
        });
        each(doc, "bufferViews", "", [&](const json& v, const std::string& at) {
            for (const char* key : {"buffer", "byteOffset", "byteLength", "byteStride"}) index(v, key, at);
        });
        each(doc, "buffers", "", [&](const json& b, const std::string& at) { index(b, "byteLength", at); });
        each(doc, "images", "", [&](const json& i, const std::string& at) { index(i, "bufferView", at); });
        each(doc, "textures", "", [&](const json& t, const std::string& at) {
            index(t, "source", at);
            index(t, "sampler", at);
        });
        each(doc, "materials", "", [&](const json& m, const std::string& at) { material(m, at); });
        each(doc, "cameras", "", [&](const json& c, const std::string& at) { camera(c, at); });
        object(doc, "extensions", "");
        const json* ext = member(doc, "extensions");
        if (ext) object(*ext, "KHR_lights_punctual", "extensions");
        if (const json* lights = ext ? member(*ext, "KHR_lights_punctual") : nullptr) {
            array(*lights, "lights", "extensions.KHR_lights_punctual");
            each(*lights, "lights", "extensions.KHR_lights_punctual",
                 [&](const json& l, const std::string& at) {
                     if (!l.is_object()) fail(at, "must be an object, not " + a(l));
                     if (const json* type = member(l, "type"); type && !type->is_string())
                         fail(at + ".type", "must be a string, not " + a(*type));
                     numbers(l, "color", 3, at);
                     number(l, "intensity", at);
                     number(l, "range", at);
                     object(l, "spot", at);
                     if (const json* spot = member(l, "spot")) {
                         number(*spot, "innerConeAngle", at + ".spot");
                         number(*spot, "outerConeAngle", at + ".spot");
                     }
                 });
        }
    }

private:
    const std::string& name_;
};

}  // namespace

void check_gltf_types(std::string_view text, const std::string& name) {
    const json doc = json::parse(text.begin(), text.end(), nullptr, false);
    if (doc.is_discarded()) return;  // not JSON: tinygltf, which reads it next, says so
    TypeCheck(name).document(doc);
}

}  // namespace lc::loader
