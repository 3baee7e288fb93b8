// libFuzzer target for the glTF loader: one input is one .gltf or .glb file
// (fuzz_input.h), loaded as a whole scene. As for the JSON target, an
// lc::InputError is the loader doing its job; a crash, a sanitizer report,
// any other exception, or a returned scene that breaks the loader's promises
// is a bug. tinygltf itself is Debian's library, not instrumented: the
// fuzzer steers by the coverage of this project's loader.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <unistd.h>

#include "fuzz_input.h"
#include "lightcuts/error.h"

namespace {

struct WorkDir {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("lc_fuzz_gltf_" + std::to_string(::getpid()));
    ~WorkDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
};

const std::filesystem::path& work_dir() {
    static const WorkDir dir;
    return dir.path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    const std::filesystem::path file = lc::fuzz::write_gltf_file(input, work_dir());
    try {
        const lc::Scene scene = lc::load_scene(file);
        const std::string broken = lc::fuzz::check_scene_contract(scene);
        if (!broken.empty()) {
            std::fprintf(stderr, "loaded scene breaks the loader's contract: %s\n", broken.c_str());
            std::abort();
        }
    } catch (const lc::InputError&) {
        // Rejected with a message naming the file and field: correct.
    } catch (const std::exception& e) {
        std::fprintf(stderr, "load_scene threw something other than lc::InputError: %s\n", e.what());
        std::abort();
    }
    std::error_code ec;
    std::filesystem::remove(file, ec);
    return 0;
}
