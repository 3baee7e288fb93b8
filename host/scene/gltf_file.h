// Reading a glTF file through tinygltf (2.7.0, Debian's library): the bytes,
// a depth check of its JSON, the extensions it requires.
#pragma once

#include <filesystem>

#include <tiny_gltf.h>

#include "gltf_materials.h"

namespace lc::loader {

// The file's model, its buffers and images decoded. Throws InputError
// naming the file when tinygltf cannot read it, when its JSON nests more
// than 64 levels, or when it requires an extension this loader does not
// honour; notes tinygltf's warnings, the used extensions that are not read
// and the animations that are ignored.
tinygltf::Model read_gltf_file(const std::filesystem::path& file, GltfNotes& notes);

}  // namespace lc::loader
