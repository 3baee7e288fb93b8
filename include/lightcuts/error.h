// Errors reported to the user. Every problem with user input is an InputError
// whose message names the file and the field (JSON path or CSV line).
#pragma once

#include <stdexcept>
#include <string>

namespace lc {

// `text` with its control characters but newlines and tabs written as
// escapes ("\0", "\x1b"): a name or a value quoted from a file can hold
// them, and a NUL would end the message where it is printed.
inline std::string printable(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        const auto byte = static_cast<unsigned char>(c);
        if (byte == 0) {
            out += "\\0";
        } else if ((byte < 0x20 && c != '\n' && c != '\t') || byte == 0x7f) {
            const char* hex = "0123456789abcdef";
            out += "\\x";
            out += hex[byte >> 4];
            out += hex[byte & 15];
        } else {
            out += c;
        }
    }
    return out;
}

class InputError : public std::runtime_error {
public:
    // Message reads "FILE: FIELD: PROBLEM" (FIELD omitted when empty),
    // made printable.
    InputError(const std::string& file, const std::string& field, const std::string& problem)
        : std::runtime_error(printable(field.empty() ? file + ": " + problem : file + ": " + field + ": " + problem)) {}
};

}  // namespace lc
