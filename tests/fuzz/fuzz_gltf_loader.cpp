// libFuzzer target for the glTF loader: one input is one .gltf or .glb file
// (fuzz_input.h), loaded as a whole scene. As for the JSON target, an
// lc::InputError is the loader doing its job; a crash, a sanitizer report,
// any other exception, or a returned scene that breaks the loader's promises
// is a bug. tinygltf itself is Debian's library, not instrumented: the
// fuzzer steers by the coverage of this project's loader.
#include <cstdint>
#include <string_view>

#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    lc::fuzz::load_or_abort(std::string_view(reinterpret_cast<const char*>(data), size), lc::fuzz::write_gltf_file);
    return 0;
}
