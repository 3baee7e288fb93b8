// One fuzz input is a whole scene: a JSON scene file, a CSV light file, an
// OBJ mesh and its MTL library, separated by NUL bytes (missing parts are
// empty files). Shared by the libFuzzer target and the regression replay.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "lightcuts/scene.h"

namespace lc::fuzz {

// The file names a fuzz input's scene JSON, OBJ and CSV refer to.
inline constexpr const char* kSceneFile = "scene.json";
inline constexpr const char* kLightsFile = "lights.csv";
inline constexpr const char* kObjFile = "mesh.obj";
inline constexpr const char* kMtlFile = "mesh.mtl";

// Splits `data` and writes the four files into `dir` (created if missing).
// Returns the scene file's path.
std::filesystem::path write_scene_files(std::string_view data, const std::filesystem::path& dir);

// A glTF fuzz input is one file: written as scene.glb when it starts with
// the binary magic "glTF", else as scene.gltf. Returns its path.
std::filesystem::path write_gltf_file(std::string_view data, const std::filesystem::path& dir);

// The loader's promises about a scene it returns (scene.h, scene-format.md):
// every number finite, normals unit length, indices in range, colours and
// roughness in range, a usable camera. Returns the first broken promise,
// or an empty string.
std::string check_scene_contract(const Scene& scene);

// One fuzz run: writes the input with `write` into this process's own
// temporary folder (removed when the process exits normally; per process,
// so parallel jobs, -jobs=N, share no files), loads the scene and aborts on
// anything but success with a scene that keeps check_scene_contract or an
// lc::InputError.
using InputWriter = std::filesystem::path (*)(std::string_view data, const std::filesystem::path& dir);
void load_or_abort(std::string_view data, InputWriter write);

}  // namespace lc::fuzz
