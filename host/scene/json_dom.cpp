// parse_json_file: the scene JSON into a DOM, with errors located by field.
//
// nlohmann's DOM parser keeps the last of two duplicate keys silently and
// reports a number overflow (1e999) without any location. The SAX handler
// here builds the same DOM but knows the JSON path of the value being
// parsed, so both problems are reported with the field that caused them.
#include "json_reader.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "input_file.h"
#include "lightcuts/error.h"

namespace lc::loader {
namespace {

std::pair<std::size_t, std::size_t> line_and_column(std::string_view text, std::size_t offset) {
    offset = std::min(offset, text.size());
    std::size_t line = 1;
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < offset; ++i) {
        if (text[i] == '\n') {
            ++line;
            line_start = i + 1;
        }
    }
    return {line, offset - line_start + 1};
}

class JsonDomBuilder final : public json::json_sax_t {
public:
    explicit JsonDomBuilder(std::string_view text) : text_(text) {}

    json root;
    std::string error_field;    // JSON path of the failing value, if known
    std::string error_problem;  // set when parsing stopped

    bool null() override { return add(json(nullptr)); }
    bool boolean(bool v) override { return add(json(v)); }
    bool number_integer(number_integer_t v) override { return add(json(v)); }
    bool number_unsigned(number_unsigned_t v) override { return add(json(v)); }
    bool number_float(number_float_t v, const string_t&) override { return add(json(v)); }
    bool string(string_t& v) override { return add(json(std::move(v))); }
    bool binary(binary_t& v) override { return add(json(std::move(v))); }

    bool start_object(std::size_t) override { return open(json::object()); }
    bool start_array(std::size_t) override { return open(json::array()); }
    bool end_object() override { return close(); }
    bool end_array() override { return close(); }

    bool key(string_t& k) override {
        Frame& top = stack_.back();
        if (top.value->contains(k)) {
            error_field = join_key(top.path, k);
            error_problem = "duplicate key";
            return false;
        }
        top.pending_key = std::move(k);
        return true;
    }

    bool parse_error(std::size_t position, const std::string&, const json::exception& e) override {
        // Only an overflow pins the problem on one value; a syntax error is
        // better located by line and column than by a guessed path.
        error_field = (e.id == 406 && !stack_.empty()) ? current_path() : std::string();
        // Drop nlohmann's "[json.exception.parse_error.101] " prefix.
        std::string message = e.what();
        if (const auto close = message.find("] ");
            message.starts_with("[json.") && close != std::string::npos) {
            message.erase(0, close + 2);
        }
        if (message.find(" line ") == std::string::npos) {
            const auto [line, column] = line_and_column(text_, position);
            message += " at line " + std::to_string(line) + ", column " + std::to_string(column);
        }
        error_problem = std::move(message);
        return false;
    }

private:
    struct Frame {
        json* value;
        std::string path;
        std::string pending_key;
    };
    std::string_view text_;
    std::vector<Frame> stack_;

    std::string current_path() const {
        const Frame& top = stack_.back();
        return top.value->is_array() ? join_index(top.path, top.value->size())
                                     : join_key(top.path, top.pending_key);
    }

    // Pointers on the stack stay valid: only the innermost open container
    // grows, and none of its children is open at that moment.
    json* insert(json&& v) {
        if (stack_.empty()) {
            root = std::move(v);
            return &root;
        }
        json& parent = *stack_.back().value;
        if (parent.is_array()) {
            parent.push_back(std::move(v));
            return &parent.back();
        }
        return &(parent[stack_.back().pending_key] = std::move(v));
    }

    bool add(json&& v) {
        insert(std::move(v));
        return true;
    }

    bool open(json&& container) {
        // Each open level keeps its path, so the memory grows with the square
        // of the nesting depth: 400 KB of '[' took over 2 GB (found by
        // tests/fuzz). A scene is five levels deep; refuse far more.
        constexpr std::size_t kMaxDepth = 64;
        if (stack_.size() >= kMaxDepth) {
            error_field = current_path();
            error_problem = "nested more than " + std::to_string(kMaxDepth) + " levels deep";
            return false;
        }
        std::string path = stack_.empty() ? std::string() : current_path();
        json* slot = insert(std::move(container));
        stack_.push_back(Frame{slot, std::move(path), {}});
        return true;
    }

    bool close() {
        stack_.pop_back();
        return true;
    }
};

}  // namespace

json parse_json_file(const std::filesystem::path& file) {
    const std::string text = read_input_file(file);
    JsonDomBuilder builder(text);
    if (!json::sax_parse(text, &builder)) {
        throw InputError(display(file), builder.error_field, builder.error_problem);
    }
    return std::move(builder.root);
}

}  // namespace lc::loader
