// What tinyobjloader reads as 0 without a word: a number it cannot parse
// ("nan", "inf", "1,5", a typo) in an OBJ vertex line or an MTL value. The
// loader checks the text first, so that such a file is refused naming the
// line, as a bad CSV line is.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace lc::loader {

// One line of OBJ or MTL text: its number and its words (also the
// loader's scan of `mtllib` lines).
struct Line {
    std::size_t number;                   // from 1
    std::vector<std::string_view> words;  // up to a '#' comment
};

inline bool is_obj_space(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }

// Calls visit(Line) for each line that has a word. Lines end as
// tinyobjloader ends them: at "\n", "\r\n" or a lone "\r".
template <class Visit>
void for_each_line(std::string_view text, Visit&& visit) {
    Line line{0, {}};
    std::size_t at = 0;
    while (at <= text.size()) {
        const std::size_t end = std::min(text.find_first_of("\r\n", at), text.size());
        ++line.number;
        line.words.clear();
        std::size_t i = at;
        while (i < end) {
            while (i < end && is_obj_space(text[i])) ++i;
            if (i == end || text[i] == '#') break;
            const std::size_t start = i;
            while (i < end && !is_obj_space(text[i])) ++i;
            line.words.push_back(text.substr(start, i - start));
        }
        if (!line.words.empty()) visit(line);
        at = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
    }
}

// Every number of every `v`, `vn` and `vt` line of `text` (an OBJ, shown as
// `name` in errors) is a decimal number, and the line has as many as it
// needs (3 for v and vn, 1 for vt); a vn may also hold NaN or infinity
// spelt out (the loader falls back to the face normal). Every index of an
// `f` line, and the vertex and joints of a `vw` line, are whole numbers
// within int's range. Throws InputError "NAME: line N (v): 'nan' is not a
// number". `text` starts after any byte order mark (without_bom: the
// loader strips it once, for these checks and tinyobjloader alike).
// Returns the vn lines (0 for the first) with any NaN or infinity:
// tinyobjloader reads each such word as 0 and keeps the others, so the
// loader zeroes the whole normal, which then counts as none.
std::vector<std::size_t> check_obj_numbers(std::string_view text, const std::string& name);

// The same for the MTL values the loader reads: the colours Kd, Ks and Ke
// (three numbers each) and the scalars Ns, Pr, Pm, Ps, Pc and Pcr.
void check_mtl_numbers(std::string_view text, const std::string& name);

}  // namespace lc::loader
