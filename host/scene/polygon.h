// The triangles of an OBJ face with more than three corners.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace lc::loader {

// The triangles covering a planar (or nearly planar) simple polygon, as
// corner numbers in the polygon's order, so that each keeps its winding.
// A quad is cut along its shorter diagonal where both diagonals lie inside
// it (tinyobjloader's choice, so convex quads render as they always did),
// else along the one that does; a larger polygon is cut by ear clipping in
// the plane of its Newell normal, its straight corners (on the line
// through their neighbours) in no triangle. A polygon that is not simple
// (it crosses itself) or has no area is cut as a fan from its first corner.
std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(const std::vector<glm::vec3>& corners);

}  // namespace lc::loader
