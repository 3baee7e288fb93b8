// libFuzzer target for the scene loader (JSON, CSV, OBJ/MTL): see
// fuzz_input.h for the input layout and docs/testing.md for how to run it.
// An lc::InputError is the loader doing its job; a crash, a sanitizer
// report, any other exception, or a returned scene that breaks the loader's
// promises is a bug.
#include <cstdint>
#include <string_view>

#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    lc::fuzz::load_or_abort(std::string_view(reinterpret_cast<const char*>(data), size), lc::fuzz::write_scene_files);
    return 0;
}
