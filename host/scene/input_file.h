// Reading the files a scene names, with errors that name them.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace lc::loader {

// A path as error messages show it: as given, with "a/./b" and "a/../b" folded.
std::string display(const std::filesystem::path& path);

// input_file_problem's words for a path where nothing is; callers that
// treat a missing file apart from one of the wrong kind compare with it.
inline constexpr const char* kFileNotFound = "file not found";

// Why `path` cannot be read as an input: "file not found", "is a folder,
// not a file", "is a device, not a regular file" (a pipe, a socket); ""
// where it is a regular file (symbolic links followed).
std::string input_file_problem(const std::filesystem::path& path);

// The whole file in memory. Throws InputError "FILE: " and
// input_file_problem's words, or "FILE: cannot read file". Notes the file
// (note_input_file).
std::string read_input_file(const std::filesystem::path& path);

// `text` without the UTF-8 byte order mark that editors and spreadsheets
// may write first; it is no part of line 1 (tinyobjloader read it as part
// of the first keyword and dropped the line).
std::string_view without_bom(std::string_view text);

// Throws InputError naming `name` where `text` starts with a UTF-16
// byte-order mark (the loaders read UTF-8 or ASCII; such a file otherwise
// reads as text without a single usable line).
void refuse_utf16(std::string_view text, const std::string& name);

// While an InputFileLog lives, every file read_input_file reads, and every
// file given to note_input_file (those read by other means: an EXR through
// tinyexr, a glTF's buffers through tinygltf), is appended to its list once;
// load_scene keeps them in Scene::input_files, the files a render must not
// write over. One per thread at a time.
class InputFileLog {
public:
    explicit InputFileLog(std::vector<std::filesystem::path>& files);
    ~InputFileLog();
    InputFileLog(const InputFileLog&) = delete;
    InputFileLog& operator=(const InputFileLog&) = delete;
};
void note_input_file(const std::filesystem::path& path);

}  // namespace lc::loader
