// Cutting OBJ polygons into triangles (polygon.h). tinyobjloader's own
// triangulation cut every quad along its shorter diagonal, outside the quad
// where that one is concave, and tested its ear clipping's convexity with
// a quantity that depends on where the polygon lies rather than on its
// turn: concave faces covered area outside themselves.
#include "polygon.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>

namespace lc::loader {

namespace {

using Triangles = std::vector<std::array<std::uint32_t, 3>>;

Triangles fan(const std::vector<std::uint32_t>& corners) {
    Triangles out;
    for (std::size_t k = 1; k + 1 < corners.size(); ++k) out.push_back({corners[0], corners[k], corners[k + 1]});
    return out;
}

// Twice the signed area of the 2D triangle (a, b, c): positive if it turns
// left.
double turn(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Whether b lies on the line through a and c to the precision of float
// corners whose coordinates are at most `reach` in size (each is rounded by
// up to 6e-8 of that, which moves the turn by that times the edges): a
// straight corner, or a spike back along the line, which bounds no area.
bool straight(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, double reach) {
    const double ab = glm::length(b - a), bc = glm::length(c - b);
    return std::abs(turn(a, b, c)) <= 1e-6 * ab * bc + 5e-7 * reach * (ab + bc);
}

}  // namespace

Triangles triangulate_polygon(const std::vector<glm::vec3>& corners) {
    const std::size_t n = corners.size();
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    if (n < 3) return {};
    if (n == 3) return {{0u, 1u, 2u}};

    // Newell's normal: the polygon's area vector, whatever its shape.
    glm::dvec3 normal(0.0);
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 a(corners[i]), b(corners[(i + 1) % n]);
        normal += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
    }
    if (!(glm::dot(normal, normal) > 0.0)) return fan(order);
    // The plane's coordinates, dropping the normal's largest axis, in the
    // order that makes the polygon turn left.
    const glm::dvec3 m = glm::abs(normal);
    const int drop = m.x >= m.y && m.x >= m.z ? 0 : m.y >= m.z ? 1 : 2;
    const int u = (drop + 1) % 3, v = (drop + 2) % 3;
    const bool flip = normal[drop] < 0.0;
    std::vector<glm::dvec2> p(n);
    double reach = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 c(corners[i]);
        p[i] = flip ? glm::dvec2(c[v], c[u]) : glm::dvec2(c[u], c[v]);
        reach = std::max({reach, std::abs(c.x), std::abs(c.y), std::abs(c.z)});
    }

    if (n == 4) {
        // tinyobjloader's diagonal, from float squared lengths as it takes
        // them, where it lies inside the quad.
        const glm::vec3 d02 = corners[2] - corners[0], d13 = corners[3] - corners[1];
        const bool along02 = glm::dot(d02, d02) < glm::dot(d13, d13);
        const bool inside02 = turn(p[0], p[1], p[2]) > 0.0 && turn(p[0], p[2], p[3]) > 0.0;
        const bool inside13 = turn(p[0], p[1], p[3]) > 0.0 && turn(p[1], p[2], p[3]) > 0.0;
        if (along02 ? inside02 || !inside13 : !inside13 && inside02) return {{0u, 1u, 2u}, {0u, 2u, 3u}};
        return {{0u, 1u, 3u}, {1u, 2u, 3u}};
    }

    // Ear clipping: cut off a corner that turns left and whose triangle
    // holds no other corner, until three are left. Straight corners are
    // dropped first, without a triangle: none of no area is made.
    Triangles out;
    std::vector<std::uint32_t> left = order;
    const auto at = [&](std::size_t k, std::size_t step) { return left[(k + step) % left.size()]; };
    while (left.size() > 3) {
        bool cut = false;
        for (std::size_t k = 0; k < left.size() && !cut; ++k)
            if (straight(p[at(k, left.size() - 1)], p[left[k]], p[at(k, 1)], reach)) {
                left.erase(left.begin() + std::ptrdiff_t(k));
                cut = true;
            }
        if (cut) continue;
        for (std::size_t k = 0; k < left.size() && !cut; ++k) {
            const std::uint32_t a = left[(k + left.size() - 1) % left.size()], b = left[k],
                                c = left[(k + 1) % left.size()];
            if (!(turn(p[a], p[b], p[c]) > 0.0)) continue;
            bool empty = true;
            for (const std::uint32_t other : left) {
                if (other == a || other == b || other == c) continue;
                const glm::dvec2 q = p[other];
                if (q == p[a] || q == p[b] || q == p[c]) continue;
                if (turn(p[a], p[b], q) >= 0.0 && turn(p[b], p[c], q) >= 0.0 && turn(p[c], p[a], q) >= 0.0) {
                    empty = false;
                    break;
                }
            }
            if (!empty) continue;
            out.push_back({a, b, c});
            left.erase(left.begin() + std::ptrdiff_t(k));
            cut = true;
        }
        if (!cut) {  // it crosses itself: the rest as a fan
            const Triangles rest = fan(left);
            out.insert(out.end(), rest.begin(), rest.end());
            return out;
        }
    }
    if (!straight(p[left[0]], p[left[1]], p[left[2]], reach)) out.push_back({left[0], left[1], left[2]});
    return out;
}

}  // namespace lc::loader
