// tinygltf 2.7 keeps its default where a glTF value has the wrong JSON type
// ("roughnessFactor": "5" reads as 1, "bufferView": -5 as no buffer view).
// The loader checks the types of every value it reads in the file's JSON
// first, so such a file is refused naming the value.
#pragma once

#include <string>
#include <string_view>

namespace lc::loader {

// Throws InputError "NAME: materials[0].pbrMetallicRoughness.roughnessFactor:
// must be a number, not a string" for the first value of the wrong type:
// factors and transforms must be numbers (arrays of as many as the
// specification says), indices and counts whole numbers >= 0, an aspect
// ratio above 0, the lights' extension objects and arrays. `json` is the
// glTF's JSON (a .glb's JSON chunk), checked before tinygltf reads it;
// JSON that does not parse is left to tinygltf's message.
void check_gltf_types(std::string_view json, const std::string& name);

}  // namespace lc::loader
