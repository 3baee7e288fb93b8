// Whole-file reads for the scene, CSV and (through tinyobjloader) OBJ inputs.
#include "input_file.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>

#include "huge_pages.h"
#include "lightcuts/error.h"

namespace lc::loader {

namespace fs = std::filesystem;

std::string display(const fs::path& path) { return path.lexically_normal().string(); }

namespace {
thread_local std::vector<fs::path>* g_input_files = nullptr;
}  // namespace

InputFileLog::InputFileLog(std::vector<fs::path>& files) { g_input_files = &files; }
InputFileLog::~InputFileLog() { g_input_files = nullptr; }

void note_input_file(const fs::path& path) {
    if (g_input_files == nullptr) return;
    const fs::path normal = path.lexically_normal();
    if (std::find(g_input_files->begin(), g_input_files->end(), normal) == g_input_files->end())
        g_input_files->push_back(normal);
}

std::string_view without_bom(std::string_view text) {
    return text.substr(0, 3) == "\xEF\xBB\xBF" ? text.substr(3) : text;
}

void refuse_utf16(std::string_view text, const std::string& name) {
    if (text.starts_with("\xFF\xFE") || text.starts_with("\xFE\xFF"))
        throw InputError(name, "", "is UTF-16 text (it starts with a UTF-16 byte-order mark); save it as UTF-8 or ASCII");
}

std::string input_file_problem(const fs::path& path) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (fs::is_regular_file(status)) return "";
    // A path that cannot be looked at (a folder on it without search
    // permission, a loop of symbolic links, a name too long) says why.
    if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
        return "cannot be looked at: " + ec.message();
    switch (status.type()) {
        case fs::file_type::not_found:
        case fs::file_type::none: return kFileNotFound;
        case fs::file_type::directory: return "is a folder, not a file";
        case fs::file_type::character:
        case fs::file_type::block: return "is a device, not a regular file";
        case fs::file_type::fifo: return "is a pipe, not a regular file";
        case fs::file_type::socket: return "is a socket, not a regular file";
        default: return "is not a regular file";
    }
}

// One read is much faster than line-wise streams for the million-line CSV case.
std::string read_input_file(const fs::path& path) {
    const std::string name = display(path);
    if (const std::string problem = input_file_problem(path); !problem.empty()) throw InputError(name, "", problem);
    errno = 0;
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(name, "", errno != 0 ? std::string("cannot read file: ") + std::strerror(errno)
                                                   : std::string("cannot read file"));
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) throw InputError(name, "", "cannot read file");
    note_input_file(path);
    std::string text;
    reserve_huge(text, static_cast<std::size_t>(size));  // 586 MB for 10^7 lights
    text.resize(static_cast<std::size_t>(size));
    in.seekg(0, std::ios::beg);
    in.read(text.data(), size);
    if (!in) throw InputError(name, "", "cannot read file");
    return text;
}

}  // namespace lc::loader
