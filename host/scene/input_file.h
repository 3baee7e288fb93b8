// Reading the files a scene names, with errors that name them.
#pragma once

#include <filesystem>
#include <string>

namespace lc::loader {

// A path as error messages show it: as given, with "a/./b" and "a/../b" folded.
std::string display(const std::filesystem::path& path);

// The whole file in memory. Throws InputError "FILE: file not found" or
// "FILE: cannot read file".
std::string read_input_file(const std::filesystem::path& path);

}  // namespace lc::loader
