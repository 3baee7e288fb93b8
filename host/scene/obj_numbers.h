// What tinyobjloader reads as 0 without a word: a number it cannot parse
// ("nan", "inf", "1,5", a typo) in an OBJ vertex line or an MTL value. The
// loader checks the text first, so that such a file is refused naming the
// line, as a bad CSV line is.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace lc::loader {

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
