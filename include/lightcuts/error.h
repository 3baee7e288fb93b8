// Errors reported to the user. Every problem with user input is an InputError
// whose message names the file and the field (JSON path or CSV line).
#pragma once

#include <stdexcept>
#include <string>

namespace lc {

class InputError : public std::runtime_error {
public:
    // Message reads "FILE: FIELD: PROBLEM" (FIELD omitted when empty).
    InputError(const std::string& file, const std::string& field, const std::string& problem)
        : std::runtime_error(field.empty() ? file + ": " + problem
                                           : file + ": " + field + ": " + problem) {}
};

}  // namespace lc
