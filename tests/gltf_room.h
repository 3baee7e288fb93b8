// The shipped room twice: scenes/room/room.json (OBJ, MTL, CSV) and
// scenes/room/room.gltf (scripts/make_gltf.py), for the tests that check
// both load into the same scene and render the same image on each device.
#pragma once

#include <map>
#include <string>

#include <gtest/gtest.h>

#include "lightcuts/scene.h"

namespace lc::test {

struct RoomTwins {
    Scene json;
    Scene gltf;  // with the JSON scene's materials, triangle by triangle
};

// glTF's metallic-roughness materials are Disney materials; the JSON room's
// are Lambert + GGX, which glTF cannot state. So the glTF scene gets the
// JSON scene's materials through the triangles they share (each glTF
// material must meet exactly one JSON material): the images then differ only
// by what the two loaders made of the geometry, the lights and the camera.
inline RoomTwins room_twins() {
    RoomTwins t{load_scene(LC_SOURCE_DIR "/scenes/room/room.json"),
                load_scene(LC_SOURCE_DIR "/scenes/room/room.gltf")};
    EXPECT_EQ(t.gltf.triangles.size(), t.json.triangles.size());
    std::map<std::uint32_t, std::uint32_t> json_of;
    for (std::size_t i = 0; i < std::min(t.gltf.triangles.size(), t.json.triangles.size()); ++i) {
        const auto [it, added] = json_of.emplace(t.gltf.triangles[i].material, t.json.triangles[i].material);
        EXPECT_EQ(it->second, t.json.triangles[i].material) << "triangle " << i;
    }
    std::vector<gpu::Material> materials(t.gltf.materials.size());
    for (const auto& [g, j] : json_of) materials[g] = t.json.materials[j];
    t.gltf.materials = std::move(materials);
    return t;
}

}  // namespace lc::test
