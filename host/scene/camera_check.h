// The camera checks that the scene loaders and check_scene share.
#pragma once

#include <string>

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

}  // namespace lc::loader
