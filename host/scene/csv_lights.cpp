// The points_csv and spots_csv readers: a hand-written parser over the whole
// file in memory, its chunks parsed on every core (10^6 lines in well under
// a second; docs/scene-format.md).
#include "csv_lights.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>
#include <thread>

#include "huge_pages.h"
#include "input_file.h"
#include "light_records.h"
#include "lightcuts/error.h"
#include "lightcuts/scene.h"
#include "run_on_threads.h"

namespace lc {
namespace loader {
namespace {

constexpr std::size_t kMaxColumns = 11;

// One kind of CSV: its columns, and which of them are intensities (>= 0).
struct Format {
    std::size_t columns;
    std::array<const char*, kMaxColumns> names;
    std::size_t first_intensity;
    const char* spelled;  // for "expected N comma-separated numbers ..."
};

constexpr Format kPoints{6, {"x", "y", "z", "r", "g", "b"}, 3, "x,y,z,r,g,b"};
constexpr Format kSpots{11,
                        {"x", "y", "z", "dx", "dy", "dz", "r", "g", "b", "inner_cone_degrees", "outer_cone_degrees"},
                        6,
                        "x,y,z,dx,dy,dz,r,g,b,inner_cone_degrees,outer_cone_degrees"};

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
    return s;
}

enum class FieldStatus { ok, not_a_number, out_of_range };

FieldStatus parse_float(std::string_view text, float& out) {
    // from_chars rejects a leading '+', and would read a sign after it.
    if (!text.empty() && text.front() == '+') {
        text.remove_prefix(1);
        if (!text.empty() && (text.front() == '+' || text.front() == '-')) return FieldStatus::not_a_number;
    }
    if (text.empty()) return FieldStatus::not_a_number;
    const char* end = text.data() + text.size();
    const auto [ptr, ec] = std::from_chars(text.data(), end, out);
    if (ec == std::errc::invalid_argument || ptr != end) return FieldStatus::not_a_number;
    if (ec == std::errc::result_out_of_range) {
        // from_chars also reports underflow (1e-60) as out of range; that
        // value is simply zero for a light, only overflow is an error.
        const std::string copy(text);
        const double d = std::strtod(copy.c_str(), nullptr);
        if (std::isfinite(d) && std::abs(d) < 1.0) {
            out = static_cast<float>(d);
            return FieldStatus::ok;
        }
        return FieldStatus::out_of_range;
    }
    return FieldStatus::ok;
}

// A content line's comma-separated fields, trimmed; count goes on past the
// last column so that the error can say how many there were.
struct Fields {
    std::array<std::string_view, kMaxColumns> text{};
    std::size_t count = 0;
};

Fields split_fields(std::string_view line) {
    Fields fields;
    for (std::size_t start = 0;;) {
        const std::size_t comma = line.find(',', start);
        const std::size_t length = comma == std::string_view::npos ? std::string_view::npos : comma - start;
        if (fields.count < kMaxColumns) fields.text[fields.count] = trim(line.substr(start, length));
        ++fields.count;
        if (comma == std::string_view::npos) return fields;
        start = comma + 1;
    }
}

// A header is only the first content line, and only if nothing in it is a
// number, so that a typo in the first data line is still an error.
bool is_header(const Fields& fields) {
    for (std::size_t i = 0; i < std::min(fields.count, kMaxColumns); ++i) {
        float ignored = 0.0f;
        if (parse_float(fields.text[i], ignored) != FieldStatus::not_a_number) return false;
    }
    return true;
}

std::string line_field(std::size_t line) { return "line " + std::to_string(line); }

[[noreturn]] void fail_column(const Format& format, const std::string& file, std::size_t line, std::size_t i,
                              const std::string& problem) {
    throw InputError(file, line_field(line),
                     "column " + std::to_string(i + 1) + " (" + format.names[i] + "): " + problem);
}

std::string quoted(std::string_view text, const char* problem) {
    return std::string("'").append(text).append("' ").append(problem);
}

// A row's numbers, each finite, intensities not negative.
std::array<float, kMaxColumns> parse_row(const Format& format, const Fields& fields, const std::string& file,
                                         std::size_t line) {
    if (fields.count != format.columns) {
        throw InputError(file, line_field(line),
                         "expected " + std::to_string(format.columns) + " comma-separated numbers " +
                             format.spelled + ", found " + std::to_string(fields.count) + " fields");
    }
    // Messages are built only on error: this runs per field of a
    // million-line file.
    std::array<float, kMaxColumns> v{};
    for (std::size_t i = 0; i < format.columns; ++i) {
        const std::string_view text = fields.text[i];
        switch (parse_float(text, v[i])) {
            case FieldStatus::not_a_number: fail_column(format, file, line, i, quoted(text, "is not a number"));
            case FieldStatus::out_of_range:
                fail_column(format, file, line, i, quoted(text, "is out of range for a 32-bit float"));
            case FieldStatus::ok: break;
        }
        if (!std::isfinite(v[i])) fail_column(format, file, line, i, quoted(text, "is not finite"));
        if (i >= format.first_intensity && i < format.first_intensity + 3 && v[i] < 0.0f)
            fail_column(format, file, line, i, "intensity must not be negative");
    }
    return v;
}

gpu::Light make_light(const Format& format, const std::array<float, kMaxColumns>& v, const std::string& file,
                      std::size_t line) {
    if (&format == &kPoints) return point_light({v[0], v[1], v[2]}, {v[3], v[4], v[5]});
    LightProblem problem;
    const gpu::Light l = spot_light({v[0], v[1], v[2]}, {v[3], v[4], v[5]}, {v[6], v[7], v[8]}, v[9], v[10], problem);
    if (problem) throw InputError(file, line_field(line), problem.field + ": " + problem.problem);
    return l;
}

// A stretch of the file's lines, parsed on its own (read_csv) into its own
// range of the file's light array.
struct Chunk {
    std::string_view text;        // whole lines
    std::size_t first_line = 1;   // the line number of its first line
    std::size_t first_light = 0;  // where its range of the light array starts
    std::size_t lights = 0;       // its lights up to its first error
    std::exception_ptr error;     // its first error
};

// Calls fn(line_number, line) for each content line of `text`, whose first
// line is line `first_line`: comments cut off, blanks trimmed, empty lines
// skipped; stops where fn returns false.
template <typename Fn>
void for_each_content_line(std::string_view text, std::size_t first_line, Fn fn) {
    std::size_t line_number = first_line;
    for (std::size_t pos = 0; pos < text.size(); ++line_number) {
        std::size_t eol = text.find('\n', pos);
        if (eol == std::string_view::npos) eol = text.size();
        std::string_view line = text.substr(pos, eol - pos);
        pos = eol + 1;
        if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
        line = trim(line);
        if (!line.empty() && !fn(line_number, line)) return;
    }
}

// Parses the chunk's lines into out[0], out[1], ... (room for every line).
void parse_chunk(const Format& format, const std::string& name, Chunk& chunk, gpu::Light* out) {
    try {
        for_each_content_line(chunk.text, chunk.first_line, [&](std::size_t line_number, std::string_view line) {
            out[chunk.lights++] =
                make_light(format, parse_row(format, split_fields(line), name, line_number), name, line_number);
            return true;
        });
    } catch (...) {
        chunk.error = std::current_exception();
    }
}

// The line number of the chunk's light `index`: its index-th content line.
std::size_t line_of_light(const Chunk& chunk, std::size_t index) {
    std::size_t found = 0;
    for_each_content_line(chunk.text, chunk.first_line, [&](std::size_t line_number, std::string_view) {
        if (index-- > 0) return true;
        found = line_number;
        return false;
    });
    return found;
}

// Runs fn(i) for i in [0, n) on up to `threads` threads (0: one per core).
template <typename Fn>
void for_each_index(std::size_t n, unsigned threads_asked, Fn fn) {
    const unsigned cores = threads_asked != 0u ? threads_asked : std::max(1u, std::thread::hardware_concurrency());
    const std::size_t threads = std::min<std::size_t>(n, cores);
    std::atomic<std::size_t> next{0};
    auto work = [&] {
        for (std::size_t i; (i = next.fetch_add(1)) < n;) fn(i);
    };
    run_on_threads(unsigned(threads), [&](unsigned) { work(); });
}

// The file, but a header, is cut into chunks of about chunk_bytes at line
// ends, parsed on every core, each into its range of one array with room
// for every line (comments and blank lines leave gaps, closed afterwards);
// then the lights go through `limits` in file order. The first problem in
// file order is the one reported, as a reading line by line would: a chunk
// stops at its first error, and the limits are checked only up to the
// first chunk that stopped. (At 10^7 lights the array is 458 MB: parsing
// into chunks' own arrays and joining them took that twice over.)
std::vector<gpu::Light> read_csv(const Format& format, const std::filesystem::path& file, LightLimits& limits,
                                 unsigned threads, std::size_t chunk_bytes) {
    const std::string name = display(file);
    const std::string text = read_input_file(file);
    refuse_utf16(text, name);
    std::string_view all = without_bom(text);  // spreadsheets write one

    // A header is only the first content line, and only if nothing in it is
    // a number, so that a typo in the first data line is still an error:
    // skipped here, before the rest is cut into chunks. It must name as many
    // columns as the format has, so that a file of another format (or of
    // other separators: a line "0;2.5;-1;1;1;1" is one field, no number) is
    // not taken for a header and skipped without a word.
    std::size_t first_line = 1;
    for_each_content_line(all, 1, [&](std::size_t line_number, std::string_view line) {
        if (const Fields fields = split_fields(line); is_header(fields)) {
            if (fields.count != format.columns)
                throw InputError(name, line_field(line_number),
                                 "a header of " + std::to_string(fields.count) + " field" +
                                     (fields.count == 1 ? "" : "s") + " (no number in it), where the " +
                                     std::to_string(format.columns) + " columns are " + format.spelled);
            for (; first_line <= line_number; ++first_line) {
                const std::size_t eol = all.find('\n');
                all.remove_prefix(eol == std::string_view::npos ? all.size() : eol + 1);
            }
        }
        return false;
    });

    chunk_bytes = std::max<std::size_t>(chunk_bytes, 1);
    std::vector<Chunk> chunks;
    for (std::size_t begin = 0; begin < all.size();) {
        std::size_t end = all.size();
        if (all.size() - begin > chunk_bytes) {
            const std::size_t eol = all.find('\n', begin + chunk_bytes - 1);
            if (eol != std::string_view::npos) end = eol + 1;
        }
        chunks.emplace_back().text = all.substr(begin, end - begin);
        begin = end;
    }
    // Line numbers: each chunk starts after the newlines of those before it.
    std::vector<std::size_t> newlines(chunks.size());
    for_each_index(chunks.size(), threads, [&](std::size_t c) {
        newlines[c] = std::size_t(std::count(chunks[c].text.begin(), chunks[c].text.end(), '\n'));
    });
    // A chunk has at most one line more than newlines (the file's last line
    // may lack one).
    std::size_t room = 0;
    for (std::size_t c = 0; c < chunks.size(); ++c) {
        chunks[c].first_line = c == 0 ? first_line : chunks[c - 1].first_line + newlines[c - 1];
        chunks[c].first_light = room;
        room += newlines[c] + 1;
    }
    std::vector<gpu::Light> lights;
    reserve_huge(lights, room);
    lights.resize(room);
    for_each_index(chunks.size(), threads,
                   [&](std::size_t c) { parse_chunk(format, name, chunks[c], lights.data() + chunks[c].first_light); });

    std::size_t count = 0;
    for (const Chunk& chunk : chunks) {
        const gpu::Light* parsed = lights.data() + chunk.first_light;
        for (std::size_t i = 0; i < chunk.lights; ++i) {
            if (const LightLimits::Problem p = limits.add(parsed[i]); p.fault != LightLimits::Fault::none)
                throw InputError(name, line_field(line_of_light(chunk, i)), p.text);
        }
        if (chunk.error) std::rethrow_exception(chunk.error);
        // Moved down over the gaps before it (never onto a chunk not yet moved).
        if (chunk.first_light != count) std::copy(parsed, parsed + chunk.lights, lights.data() + count);
        count += chunk.lights;
    }
    lights.resize(count);
    return lights;
}

}  // namespace

std::vector<gpu::Light> read_points_csv(const std::filesystem::path& file, LightLimits& limits, unsigned threads,
                                        std::size_t chunk_bytes) {
    return read_csv(kPoints, file, limits, threads, chunk_bytes);
}

std::vector<gpu::Light> read_spots_csv(const std::filesystem::path& file, LightLimits& limits, unsigned threads,
                                       std::size_t chunk_bytes) {
    return read_csv(kSpots, file, limits, threads, chunk_bytes);
}

}  // namespace loader

std::vector<gpu::Light> load_points_csv(const std::filesystem::path& file) {
    loader::LightLimits limits;
    return loader::read_points_csv(file, limits, 0u);
}

}  // namespace lc
