// The scene checks that the loaders, check_scene and prepare_scene share.
#pragma once

#include <string>

#include "float_limits.h"
#include "lightcuts/scene.h"

namespace lc::loader {

// What makes a camera unusable: the field ("camera.look_at", ...) and the
// problem, both empty where the camera is usable: finite, look_at apart from
// position by a distance whose square is a normal float, up neither zero nor
// along the view.
struct CameraProblem {
    std::string field;
    std::string problem;
};

CameraProblem camera_problem(const Camera& camera);

// check_scene (lightcuts/scene.h), giving the box around the triangles that
// it computes on the way (what update_bounds would set): prepare_scene
// takes the bounds from it without a second pass over the triangles.
Box check_scene_geometry(const Scene& scene);

}  // namespace lc::loader
