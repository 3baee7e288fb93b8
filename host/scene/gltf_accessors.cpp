// glTF accessors into positions, texture coordinates and indices (gltf_accessors.h).
#include "gltf_accessors.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <algorithm>

#include <tiny_gltf.h>

#include "lightcuts/error.h"

namespace lc::loader {
namespace {

// More elements than any scene the renderer can hold; keeps sizes in 64 bits.
constexpr std::uint64_t kMaxElements = std::uint64_t(1) << 31;
// An accessor without a bufferView is zeros (glTF 3.6.2.1; sparse values
// may replace some): nothing in the file bounds its count, so it is held to
// this many elements (a VEC3 of them takes 384 MiB here).
constexpr std::uint64_t kMaxZeroElements = std::uint64_t(1) << 24;

const char* component_type_name(int type) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
        case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
        case TINYGLTF_COMPONENT_TYPE_INT: return "INT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
        default: return "unknown";
    }
}

const char* type_name(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return "SCALAR";
        case TINYGLTF_TYPE_VEC2: return "VEC2";
        case TINYGLTF_TYPE_VEC3: return "VEC3";
        case TINYGLTF_TYPE_VEC4: return "VEC4";
        default: return "another type";
    }
}

std::uint64_t component_size(int type) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
        default: return 4;
    }
}

int component_count(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return 1;
        case TINYGLTF_TYPE_VEC2: return 2;
        case TINYGLTF_TYPE_VEC3: return 3;
        default: return 4;
    }
}

// One component at p (unaligned reads through memcpy); glTF's normalization
// rules (3.11: signed values clamp at -1).
double read_component(const unsigned char* p, int type, bool normalized) {
    const auto get = [p]<class T>(T) {
        T v;
        std::memcpy(&v, p, sizeof v);
        return v;
    };
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            const double v = get(std::int8_t{});
            return normalized ? std::max(v / 127.0, -1.0) : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
            const double v = get(std::uint8_t{});
            return normalized ? v / 255.0 : v;
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            const double v = get(std::int16_t{});
            return normalized ? std::max(v / 32767.0, -1.0) : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            const double v = get(std::uint16_t{});
            return normalized ? v / 65535.0 : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return get(std::uint32_t{});
        default: return get(float{});
    }
}

// A checked window into one buffer view: `count` elements of `element`
// bytes, `stride` apart, from `offset` bytes into the view.
class ViewWindow {
public:
    ViewWindow(const tinygltf::Model& model, const std::string& file, int view_index, const std::string& view_field,
               std::uint64_t offset, std::uint64_t count, std::uint64_t element, bool strided) {
        const auto fail = [&](const std::string& field, const std::string& problem) {
            throw InputError(file, field, problem);
        };
        if (view_index < 0 || std::size_t(view_index) >= model.bufferViews.size())
            fail(view_field, "buffer view " + std::to_string(view_index) + " out of range (" +
                                 std::to_string(model.bufferViews.size()) + " buffer views)");
        const std::string name = "bufferViews[" + std::to_string(view_index) + "]";
        const tinygltf::BufferView& view = model.bufferViews[std::size_t(view_index)];
        if (view.buffer < 0 || std::size_t(view.buffer) >= model.buffers.size())
            fail(name + ".buffer", "buffer " + std::to_string(view.buffer) + " out of range (" +
                                       std::to_string(model.buffers.size()) + " buffers)");
        const std::vector<unsigned char>& data = model.buffers[std::size_t(view.buffer)].data;
        const std::uint64_t view_offset = view.byteOffset, view_length = view.byteLength;
        if (view_offset > data.size() || view_length > data.size() - view_offset)
            fail(name, "bytes " + std::to_string(view_offset) + " + " + std::to_string(view_length) +
                           " run past the end of buffer " + std::to_string(view.buffer) + " (" +
                           std::to_string(data.size()) + " bytes)");
        stride_ = strided && view.byteStride != 0 ? view.byteStride : element;
        if (stride_ < element)
            fail(name + ".byteStride", "is " + std::to_string(stride_) + ", less than the element's " +
                                           std::to_string(element) + " bytes");
        // offset + stride * (count - 1) + element <= length, without overflow
        // (count and stride are small enough for 64 bits).
        if (count > 0 && (offset > view_length || element > view_length - offset ||
                          stride_ * (count - 1) > view_length - offset - element))
            fail(view_field, std::to_string(count) + " elements of " + std::to_string(element) +
                                 " bytes from byte " + std::to_string(offset) + " run past the end of " + name +
                                 " (" + std::to_string(view_length) + " bytes)");
        begin_ = data.data() + view_offset + offset;
    }

    const unsigned char* element(std::uint64_t i) const { return begin_ + stride_ * i; }

private:
    const unsigned char* begin_ = nullptr;
    std::uint64_t stride_ = 0;
};

}  // namespace

std::vector<double> GltfAccessors::components(int index, const std::string& field, int type,
                                              std::initializer_list<int> component_types) const {
    const auto fail = [&](const std::string& where, const std::string& problem) {
        throw InputError(file_, where, problem);
    };
    if (index < 0 || std::size_t(index) >= model_.accessors.size())
        fail(field, "accessor " + std::to_string(index) + " out of range (" +
                        std::to_string(model_.accessors.size()) + " accessors)");
    const std::string name = "accessors[" + std::to_string(index) + "]";
    const tinygltf::Accessor& a = model_.accessors[std::size_t(index)];
    if (a.type != type)
        fail(name + ".type", std::string("is ") + type_name(a.type) + ", expected " + type_name(type) + " for " +
                                 field);
    bool allowed = false;
    std::string names;
    for (const int t : component_types) {
        allowed = allowed || a.componentType == t;
        names += (names.empty() ? "" : ", ") + std::string(component_type_name(t));
    }
    if (!allowed)
        fail(name + ".componentType", std::string("is ") + component_type_name(a.componentType) + ", expected " +
                                          names + " for " + field);
    if (a.normalized && (a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                         a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        fail(name + ".normalized", std::string("must not be true for ") + component_type_name(a.componentType));
    if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && type != TINYGLTF_TYPE_SCALAR && !a.normalized)
        fail(name + ".normalized", std::string("must be true for ") + component_type_name(a.componentType) +
                                       " components of " + field);
    const std::uint64_t count = a.count;
    if (count > kMaxElements) fail(name + ".count", "is larger than " + std::to_string(kMaxElements));

    if (a.bufferView < 0 && count > kMaxZeroElements)
        fail(name + ".count", "is larger than " + std::to_string(kMaxZeroElements) +
                                  " for an accessor without a bufferView (its elements are zeros the file does not hold)");

    const int n = component_count(type);
    const std::uint64_t size = component_size(a.componentType);
    // The elements must lie in the buffer view before room is made for them:
    // a count of 4 * 10^8 in a 20-byte file asked for 9.9 GB (fuzzing).
    std::optional<ViewWindow> window;
    if (a.bufferView >= 0)
        window.emplace(model_, file_, a.bufferView, name + ".bufferView", a.byteOffset, count, size * std::uint64_t(n),
                       true);
    std::vector<double> values(std::size_t(count) * std::size_t(n), 0.0);  // no bufferView: zeros (3.6.2.1)
    const auto read_into = [&](std::size_t element, const unsigned char* p) {
        for (int c = 0; c < n; ++c)
            values[element * std::size_t(n) + std::size_t(c)] =
                read_component(p + size * std::uint64_t(c), a.componentType, a.normalized);
    };
    if (window)
        for (std::uint64_t i = 0; i < count; ++i) read_into(std::size_t(i), window->element(i));
    if (a.sparse.isSparse) {
        // glTF 3.6.2.3: `count` indices and the values that replace those elements.
        const std::string sparse = name + ".sparse";
        if (a.sparse.count < 1 || std::uint64_t(a.sparse.count) > count)
            fail(sparse + ".count", "must be from 1 to the accessor's count " + std::to_string(count));
        const auto sparse_count = std::uint64_t(a.sparse.count);
        const int index_type = a.sparse.indices.componentType;
        if (index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(sparse + ".indices.componentType", "must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
        if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0)
            fail(sparse, "byteOffset must not be negative");
        const ViewWindow indices(model_, file_, a.sparse.indices.bufferView, sparse + ".indices.bufferView",
                                 std::uint64_t(a.sparse.indices.byteOffset), sparse_count, component_size(index_type),
                                 false);
        const ViewWindow substitutes(model_, file_, a.sparse.values.bufferView, sparse + ".values.bufferView",
                                     std::uint64_t(a.sparse.values.byteOffset), sparse_count,
                                     size * std::uint64_t(n), false);
        for (std::uint64_t i = 0; i < sparse_count; ++i) {
            const double target = read_component(indices.element(i), index_type, false);
            if (target >= double(count))
                fail(sparse + ".indices", "index " + std::to_string(std::uint64_t(target)) + " out of range (" +
                                              std::to_string(count) + " elements)");
            read_into(std::size_t(target), substitutes.element(i));
        }
    }
    for (std::size_t i = 0; i < values.size(); ++i) {
        if (!std::isfinite(values[i]) || std::abs(values[i]) > double(std::numeric_limits<float>::max()))
            fail(field, "element " + std::to_string(i / std::size_t(n)) + " of " + name +
                            " is not a finite float (" + std::to_string(values[i]) + ")");
    }
    return values;
}

namespace {

// The entry of `index` in a list of recently decoded accessors, or null.
template <class T>
std::shared_ptr<const std::vector<T>> recent(
    const std::vector<std::pair<int, std::shared_ptr<const std::vector<T>>>>& list, int index) {
    for (const auto& [i, values] : list)
        if (i == index) return values;
    return nullptr;
}

// Adds a decoded accessor to the list, dropping the oldest past `most`.
template <class T>
std::shared_ptr<const std::vector<T>> remember(std::vector<std::pair<int, std::shared_ptr<const std::vector<T>>>>& list,
                                               std::size_t most, int index, std::vector<T>&& values) {
    auto kept = std::make_shared<const std::vector<T>>(std::move(values));
    if (list.size() == most) list.erase(list.begin());
    list.emplace_back(index, kept);
    return kept;
}

}  // namespace

std::shared_ptr<const std::vector<glm::vec3>> GltfAccessors::vec3s(int index, const std::string& field) const {
    if (auto kept = recent(recent_vec3s_, index)) return kept;
    const std::vector<double> v = components(index, field, TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT});
    std::vector<glm::vec3> out(v.size() / 3);
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = glm::vec3(float(v[3 * i]), float(v[3 * i + 1]), float(v[3 * i + 2]));
    return remember(recent_vec3s_, kRecent, index, std::move(out));
}

std::shared_ptr<const std::vector<glm::vec2>> GltfAccessors::vec2s(int index, const std::string& field) const {
    if (auto kept = recent(recent_vec2s_, index)) return kept;
    const std::vector<double> v =
        components(index, field, TINYGLTF_TYPE_VEC2,
                   {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    std::vector<glm::vec2> out(v.size() / 2);
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = glm::vec2(float(v[2 * i]), float(v[2 * i + 1]));
    return remember(recent_vec2s_, 1, index, std::move(out));
}

std::vector<std::uint32_t> GltfAccessors::indices(int index, const std::string& field,
                                                  std::size_t vertex_count) const {
    const std::vector<double> v =
        components(index, field, TINYGLTF_TYPE_SCALAR,
                   {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT});
    std::vector<std::uint32_t> out(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (v[i] >= double(vertex_count))
            throw InputError(file_, field, "index " + std::to_string(std::uint64_t(v[i])) + " at element " +
                                               std::to_string(i) + " out of range (" +
                                               std::to_string(vertex_count) + " vertices)");
        out[i] = std::uint32_t(v[i]);
    }
    return out;
}

}  // namespace lc::loader
