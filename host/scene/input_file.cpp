// Whole-file reads for the scene, CSV and (through tinyobjloader) OBJ inputs.
#include "input_file.h"

#include <fstream>

#include "lightcuts/error.h"

namespace lc::loader {

namespace fs = std::filesystem;

std::string display(const fs::path& path) { return path.lexically_normal().string(); }

// One read is much faster than line-wise streams for the million-line CSV case.
std::string read_input_file(const fs::path& path) {
    const std::string name = display(path);
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw InputError(name, "", "file not found");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(name, "", "cannot read file");
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) throw InputError(name, "", "cannot read file");
    std::string text(static_cast<std::size_t>(size), '\0');
    in.seekg(0, std::ios::beg);
    in.read(text.data(), size);
    if (!in) throw InputError(name, "", "cannot read file");
    return text;
}

}  // namespace lc::loader
