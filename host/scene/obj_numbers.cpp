// Number checks of OBJ and MTL text ahead of tinyobjloader (obj_numbers.h).
#include "obj_numbers.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "lightcuts/error.h"

namespace lc::loader {
namespace {

// A decimal number as tinyobjloader parses one: [+-] digits [. digits]
// [(e|E) [+-] digits], with at least one digit before the exponent.
bool is_number(std::string_view w) {
    std::size_t i = 0;
    auto digits = [&] {
        const std::size_t start = i;
        while (i < w.size() && std::isdigit(static_cast<unsigned char>(w[i]))) ++i;
        return i - start;
    };
    if (i < w.size() && (w[i] == '+' || w[i] == '-')) ++i;
    std::size_t mantissa = digits();
    if (i < w.size() && w[i] == '.') {
        ++i;
        mantissa += digits();
    }
    if (mantissa == 0) return false;
    if (i < w.size() && (w[i] == 'e' || w[i] == 'E')) {
        ++i;
        if (i < w.size() && (w[i] == '+' || w[i] == '-')) ++i;
        if (digits() == 0) return false;
    }
    return i == w.size();
}

// "nan", "-nan(ind)", "inf", "Infinity" and the like, any case.
bool is_non_finite(std::string_view w) {
    if (!w.empty() && (w[0] == '+' || w[0] == '-')) w.remove_prefix(1);
    auto starts = [&](std::string_view prefix) {
        if (w.size() < prefix.size()) return false;
        for (std::size_t i = 0; i < prefix.size(); ++i)
            if (std::tolower(static_cast<unsigned char>(w[i])) != prefix[i]) return false;
        return true;
    };
    return starts("nan") || starts("inf");
}

// A number past float's range ("1e99999", "4e38"), which tinyobjloader
// reads as 0 or as infinity without a word (a vertex at 1e99999 made its
// triangle degenerate, and the error said only that none were left).
// What rounds to the largest float is within it ("3.4028235e38", the
// shortest text of it); halfway to the next power of two rounds to
// infinity.
bool past_float_range(std::string_view w) {
    const double value = std::strtod(std::string(w).c_str(), nullptr);
    return !(std::abs(value) < double(std::numeric_limits<float>::max()) + 0x1p103);
}

// Words 1.. of `line` are `least` or more numbers (all of them numbers
// within float's range; with `non_finite_ok`, NaN and infinity spelt out
// count as numbers).
void check_numbers(const Line& line, std::size_t least, const std::string& name, bool non_finite_ok = false) {
    const std::string field = "line " + std::to_string(line.number) + " (" + std::string(line.words[0]) + ")";
    for (std::size_t k = 1; k < line.words.size(); ++k) {
        if (non_finite_ok && is_non_finite(line.words[k])) continue;
        if (!is_number(line.words[k]))
            throw InputError(name, field, "'" + std::string(line.words[k]) + "' is not a number");
        if (past_float_range(line.words[k]))
            throw InputError(name, field,
                             "'" + std::string(line.words[k]) + "' is past the largest float (3.4e38)");
    }
    if (line.words.size() - 1 < least)
        throw InputError(name, field, "needs " + std::to_string(least) + " numbers, has " +
                                          std::to_string(line.words.size() - 1));
}

// An integer within int's range, as tinyobjloader's indices and joint ids
// must be: it converts them with int() (a larger one wraps, or is undefined
// behaviour; the fuzzer found "vw 1 44444444444 0.5").
bool is_int(std::string_view w) {
    std::size_t i = w.size() > 0 && (w[0] == '+' || w[0] == '-') ? 1 : 0;
    if (i == w.size() || w.size() - i > 10) return false;
    long long value = 0;
    for (; i < w.size(); ++i) {
        if (!std::isdigit(static_cast<unsigned char>(w[i]))) return false;
        value = value * 10 + (w[i] - '0');
    }
    return value <= 2147483647LL;
}

// A face's corners: v, v/vt, v//vn or v/vt/vn, each index an int; at most
// 255 of them (tinyobjloader keeps a face's corner count in a byte). A
// relative (negative) index counts back from the elements read so far
// (`seen`: vertices, texture coordinates, normals) and must not reach back
// before the first: tinyobjloader would read one that reaches one too far
// as "none" and drop the face's normal or texture coordinate.
void check_face(const Line& line, const std::string& name, const std::size_t (&seen)[3]) {
    if (line.words.size() > 256)
        throw InputError(name, "line " + std::to_string(line.number) + " (f)",
                         "a face of " + std::to_string(line.words.size() - 1) + " corners; at most 255 are read");
    for (std::size_t k = 1; k < line.words.size(); ++k) {
        std::string_view corner = line.words[k];
        for (int part = 0; part < 3 && !corner.empty(); ++part) {
            const std::size_t slash = corner.find('/');
            const std::string_view index = corner.substr(0, slash);
            if (!(index.empty() && part > 0) && !is_int(index))
                throw InputError(name, "line " + std::to_string(line.number) + " (f)",
                                 "corner '" + std::string(line.words[k]) + "': index '" + std::string(index) +
                                     "' is not a whole number within 2^31");
            if (!index.empty() && index[0] == '-') {
                long long back = 0;
                for (char c : index.substr(1)) back = back * 10 + (c - '0');
                if (std::size_t(back) > seen[part]) {
                    static constexpr const char* kWhat[3] = {"vertices", "texture coordinates", "normals"};
                    throw InputError(name, "line " + std::to_string(line.number) + " (f)",
                                     "corner '" + std::string(line.words[k]) + "': relative index " +
                                         std::string(index) + " reaches back before the first of the " +
                                         std::to_string(seen[part]) + " " + kWhat[part] + " read so far");
                }
            }
            corner = slash == std::string_view::npos ? std::string_view() : corner.substr(slash + 1);
        }
    }
}

// vw VERTEX JOINT WEIGHT [JOINT WEIGHT ...] (tinyobjloader's skin weights,
// which the renderer ignores): numbers, the vertex and joints ints.
void check_weights(const Line& line, const std::string& name) {
    check_numbers(line, 1, name);
    for (std::size_t k = 1; k < line.words.size(); k += k == 1 ? 1 : 2)
        if (!is_int(line.words[k]))
            throw InputError(name, "line " + std::to_string(line.number) + " (vw)",
                             "'" + std::string(line.words[k]) + "' is not a whole number within 2^31");
}

}  // namespace

std::vector<std::size_t> check_obj_numbers(std::string_view text, const std::string& name) {
    std::vector<std::size_t> non_finite_normals;
    std::size_t seen[3] = {};  // vertices, texture coordinates, normals so far
    std::size_t& normals = seen[2];
    for_each_line(text, [&](const Line& line) {
        const std::string_view key = line.words[0];
        if (key == "v") {
            check_numbers(line, 3, name);
            ++seen[0];
        }
        // Some exporters write "vn nan nan nan" for a degenerate face;
        // tinyobjloader reads 0 and the loader takes the face normal for a
        // zero vertex normal, as documented. Words that are no number at
        // all are still refused.
        else if (key == "vn") {
            check_numbers(line, 3, name, true);
            for (std::size_t k = 1; k < line.words.size(); ++k)
                if (is_non_finite(line.words[k])) {
                    non_finite_normals.push_back(normals);
                    break;
                }
            ++normals;
        }
        else if (key == "vt") {
            check_numbers(line, 1, name);
            ++seen[1];
        }
        else if (key == "f") check_face(line, name, seen);
        else if (key == "vw") check_weights(line, name);
    });
    return non_finite_normals;
}

void check_mtl_numbers(std::string_view text, const std::string& name) {
    for_each_line(text, [&](const Line& line) {
        const std::string_view key = line.words[0];
        // The keys materials.cpp reads (convert_mtl); the others are not
        // used, whatever they hold. A colour needs all three numbers:
        // tinyobjloader reads "Kd 0.5" as (0.5, 0, 0), where the MTL
        // format means grey.
        if (key == "Kd" || key == "Ks" || key == "Ke") {
            check_numbers(line, 3, name);
        } else if (key == "Ns" || key == "Pr" || key == "Pm" || key == "Ps" || key == "Pc" || key == "Pcr") {
            check_numbers(line, 1, name);
        } else if (key == "map_Kd" || key == "map_Ke" || key == "norm") {
            // The map options the loader applies, -s and -o, take three
            // numbers before the file name; tinyobjloader reads "nan" as
            // the option's default, "inf" and "0,5" as 0.
            for (std::size_t k = 1; k + 1 < line.words.size(); ++k) {
                if (line.words[k] != "-s" && line.words[k] != "-o") continue;
                for (std::size_t j = k + 1; j < std::min(k + 4, line.words.size() - 1); ++j)
                    if (!is_number(line.words[j]) || past_float_range(line.words[j]))
                        throw InputError(name, "line " + std::to_string(line.number) + " (" + std::string(key) + ")",
                                         std::string(line.words[k]) + " takes three numbers within float's range: '" +
                                             std::string(line.words[j]) + "' is not one");
            }
        }
    });
}


}  // namespace lc::loader
