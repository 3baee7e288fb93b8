// All-or-nothing output files (include/lightcuts/output_set.h).
#include "lightcuts/output_set.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include <fcntl.h>
#include <unistd.h>

#include "lightcuts/image.h"
#include "lightcuts/settings.h"

namespace lc {

namespace fs = std::filesystem;

namespace {

// What commit did for one output, so that a later failure can undo it.
struct Placement {
    fs::path backup;   // where the file the output replaces was moved; "" if none
    bool placed = false;
};

fs::path identity_of(const fs::path& file) {
    std::error_code ec;
    fs::path id = fs::weakly_canonical(fs::absolute(file), ec);
    return ec ? fs::absolute(file).lexically_normal() : id;
}

// Equal identities, or one file under two names (a hard link).
bool same_file(const fs::path& a, const fs::path& b) {
    std::error_code ec;
    return a == b || (fs::equivalent(a, b, ec) && !ec);
}

// The temporary exists from the start so that a folder we may not write to
// is found before the work, not after it.
void create_empty(const fs::path& file, const std::string& label) {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) throw std::runtime_error(label + ": cannot create a file beside it: " + std::strerror(errno));
    ::close(fd);
}

// Keeps a file already at `file` under a backup name, then renames
// `temporary` onto `file`, each step in the journal before it is taken.
// The backup is a hard link where the file system makes one, so that the
// rename replaces `file` in one step and a reader never finds it missing;
// elsewhere the file is moved aside first. Returns the problem, or "" on
// success.
std::string place(const fs::path& temporary, const fs::path& file, Placement& step, ReplacementJournal& journal) {
    std::error_code ec;
    const fs::file_status status = fs::symlink_status(file, ec);
    // A folder is never moved aside: the rename below must fail on it.
    if (fs::exists(status) && !fs::is_directory(status)) {
        const fs::path backup = temporary_path_for(file);
        journal.begin(file, backup);
        fs::create_hard_link(file, backup, ec);
        if (ec) {
            ec.clear();
            fs::rename(file, backup, ec);
        }
        if (ec) return "cannot move the existing file aside: " + ec.message();
        step.backup = backup;
    } else {
        journal.begin(file, {});
    }
    fs::rename(temporary, file, ec);
    if (ec) return "cannot rename the temporary file into place: " + ec.message();
    step.placed = true;
    return "";
}

// Undoes `place` for steps [0, end), newest first.
void roll_back(const std::vector<fs::path>& files, const std::vector<Placement>& steps, std::size_t end) {
    for (std::size_t i = end; i-- > 0;) {
        std::error_code ec;
        if (steps[i].placed) fs::remove(files[i], ec);
        if (!steps[i].backup.empty()) {
            fs::rename(steps[i].backup, files[i], ec);
            // A hard link renamed onto its own file stays where it is.
            fs::remove(steps[i].backup, ec);
        }
    }
}

fs::path preview_path(const fs::path& image) { return fs::path(image).replace_extension(".png"); }

}  // namespace

OutputSet::OutputSet(OutputSet&& other) noexcept
    : inputs_(std::move(other.inputs_)), outputs_(std::move(other.outputs_)), committed_(other.committed_) {
    other.outputs_.clear();
}

OutputSet::~OutputSet() {
    if (committed_) return;
    for (const Output& out : outputs_) {
        std::error_code ignored;
        fs::remove(out.temporary, ignored);
        untrack_temporary(out.tracked);
    }
}

void OutputSet::add_input(const fs::path& file, std::string_view what) {
    inputs_.push_back({file, identity_of(file), std::string(what)});
}

fs::path OutputSet::add(const fs::path& file, std::string_view what) {
    if (file.empty()) throw std::invalid_argument(std::string(what) + ": the file name is empty");
    const std::string label = std::string(what) + " " + file.string();
    // Found here rather than by the first file system call, whose message
    // would not name the output.
    if (file.filename().native().size() > kMaxFileNameBytes)
        throw std::invalid_argument(label + ": the file name is " + std::to_string(file.filename().native().size()) +
                                    " bytes long; a file system takes at most " + std::to_string(kMaxFileNameBytes));
    fs::path folder = file.parent_path();
    if (folder.empty()) folder = ".";
    if (!fs::is_directory(folder))
        throw std::invalid_argument(label + ": folder " + folder.string() + " does not exist");
    if (fs::is_directory(file)) throw std::invalid_argument(label + ": is a folder");
    Named name{file, identity_of(file), std::string(what)};
    for (const Named& input : inputs_)
        if (same_file(name.identity, input.identity)) throw std::invalid_argument(label + ": is the " + input.what);
    for (const Output& out : outputs_)
        if (same_file(name.identity, out.name.identity))
            throw std::invalid_argument(label + ": is also the " + out.name.what);
    // An output is written to a temporary and renamed into place. Renamed
    // onto a symbolic link (/dev/stdout is one), that would replace the
    // link, not write where it points; onto a device or a pipe, replace its
    // name with a plain file. Both are refused.
    std::error_code ec;
    const fs::file_status link = fs::symlink_status(file, ec);
    if (fs::is_symlink(link))
        throw std::invalid_argument(label + ": is a symbolic link (to " + fs::read_symlink(file, ec).string() +
                                    "); outputs are written whole and renamed into place, which would replace the "
                                    "link: name the file itself");
    if (fs::exists(link) && !fs::is_regular_file(link))
        throw std::invalid_argument(label + ": is not a regular file (a device, a pipe or a socket); outputs are "
                                            "written whole and renamed into place");
    fs::path temporary = temporary_path_for(file);
    // Tracked before it exists, so no signal can come between the two.
    const int tracked = track_temporary(temporary);
    try {
        create_empty(temporary, label);
    } catch (...) {
        untrack_temporary(tracked);
        throw;
    }
    outputs_.push_back({std::move(name), temporary, tracked});
    return temporary;
}

fs::path OutputSet::temporary(const fs::path& file) const {
    for (const Output& out : outputs_)
        if (out.name.file == file) return out.temporary;
    throw std::out_of_range("OutputSet: " + file.string() + " was not added");
}

void OutputSet::commit() {
    if (committed_) throw std::logic_error("OutputSet::commit called twice");
    std::vector<fs::path> files;
    for (const Output& out : outputs_) files.push_back(out.name.file);
    std::vector<Placement> steps(outputs_.size());
    // A signal while the files are being placed puts back what was there
    // (and leaves no backup), as a failure below does; one after they all
    // are keeps them.
    ReplacementJournal journal;
    for (std::size_t i = 0; i < outputs_.size(); ++i) {
        const std::string problem = place(outputs_[i].temporary, files[i], steps[i], journal);
        if (problem.empty()) continue;
        roll_back(files, steps, i + 1);
        throw std::runtime_error(files[i].string() + ": " + problem);
    }
    journal.finish();
    committed_ = true;
    for (const Output& out : outputs_) untrack_temporary(out.tracked);
    for (const Placement& step : steps) {
        std::error_code ignored;
        if (!step.backup.empty()) fs::remove(step.backup, ignored);
    }
}

OutputSet reserve_render_outputs(const RenderOutputs& outputs, const fs::path& scene_file, std::string_view method,
                                 const std::vector<fs::path>& inputs) {
    // ".exr" alone is a name with no extension (a hidden file's).
    if (outputs.image.extension() != ".exr")
        throw std::invalid_argument("image " + outputs.image.string() + ": must end in .exr" +
                                    (outputs.image.filename() == ".exr" ? ", after a name" : ""));
    if (!outputs.cut_heatmap.empty() && !method_selects_cuts(method))
        throw std::invalid_argument("cut heatmap " + outputs.cut_heatmap.string() +
                                    ": needs method lightcuts or stochastic, not " + std::string(method));
    if (!outputs.cut_heatmap.empty() && outputs.cut_heatmap.extension() != ".png")
        throw std::invalid_argument("cut heatmap " + outputs.cut_heatmap.string() + ": must end in .png");
    OutputSet set;
    set.add_input(scene_file, "scene");
    for (const fs::path& input : inputs) set.add_input(input, "file the scene reads (" + input.string() + ")");
    set.add(outputs.image, "image");
    if (outputs.png_preview) set.add(preview_path(outputs.image), "PNG preview");
    if (!outputs.stats.empty()) set.add(outputs.stats, "stats file");
    if (!outputs.cut_heatmap.empty()) set.add(outputs.cut_heatmap, "cut heatmap");
    return set;
}

void write_render_outputs(OutputSet& set, const RenderOutputs& outputs, const RenderResult& result,
                          std::string_view stats_json) {
    // Each output encoded, then written to its temporary; a failure names
    // the output, not the temporary.
    auto write = [&](const fs::path& file, std::string_view bytes) {
        write_file(set.temporary(file), bytes, file);
    };
    write(outputs.image, encode_exr(result.image, outputs.image));
    if (outputs.png_preview) {
        const fs::path preview = preview_path(outputs.image);
        write(preview, encode_png_tonemapped(result.image, 0.0f, preview));
    }
    if (!outputs.stats.empty()) write(outputs.stats, stats_json);
    if (!outputs.cut_heatmap.empty()) {
        const std::vector<float>& cuts = result.stats.cut_size;
        // The scale runs from 0 to the largest cut, so the map uses its whole range.
        const float largest = cuts.empty() ? 1.0f : *std::max_element(cuts.begin(), cuts.end());
        write(outputs.cut_heatmap, encode_heatmap_png(result.image.width, result.image.height, cuts,
                                                      std::max(1.0f, largest), outputs.cut_heatmap));
    }
    set.commit();
}

}  // namespace lc
