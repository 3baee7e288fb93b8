// Output files written all or nothing. A program that writes several files
// from one long computation (an image, its preview, a stats file) names them
// all before the computation, so every refusal comes before the work, writes
// each to the temporary it is given, then commits: either every file is in
// place or none is changed, and no temporary is left behind; also when a
// signal ends the program, once it has called remove_temporaries_on_signal
// (temporaries.h).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "render.h"
#include "temporaries.h"

namespace lc {

// Not thread-safe; one set per render. Move-only.
class OutputSet {
public:
    OutputSet() = default;
    OutputSet(OutputSet&& other) noexcept;
    OutputSet& operator=(OutputSet&&) = delete;
    OutputSet(const OutputSet&) = delete;
    OutputSet& operator=(const OutputSet&) = delete;
    // An uncommitted set removes its temporaries.
    ~OutputSet();

    // A file no output may replace (the scene being rendered, say).
    void add_input(const std::filesystem::path& file, std::string_view what);

    // Adds an output and creates its temporary (empty) beside it, so an
    // unwritable folder shows now, not after the work. Throws
    // std::invalid_argument, starting with `what` and the file, when the
    // name is empty, its folder does not exist, it is a folder, a symbolic
    // link (/dev/stdout, say: the rename would replace the link) or any
    // other file that is not a regular one (a device, a pipe), or it is an
    // input or an output added before (under another name, a hard or a
    // symbolic link, included);
    // std::runtime_error when the temporary cannot be created. Returns the
    // temporary to write.
    std::filesystem::path add(const std::filesystem::path& file, std::string_view what);

    // The temporary of an added output; throws std::out_of_range otherwise.
    std::filesystem::path temporary(const std::filesystem::path& file) const;

    // Renames every temporary onto its file. When one cannot be (its path is
    // now a folder, say), the outputs already renamed are removed, the files
    // they replaced are put back, every temporary is removed and
    // std::runtime_error names the file; so too, without the error, when a
    // signal ends the program before every file is in place
    // (ReplacementJournal). Call at most once.
    void commit();

private:
    struct Named {
        std::filesystem::path file;
        std::filesystem::path identity;  // absolute, symbolic links resolved
        std::string what;
    };
    struct Output {
        Named name;
        std::filesystem::path temporary;
        int tracked = -1;  // track_temporary's handle
    };
    std::vector<Named> inputs_;
    std::vector<Output> outputs_;
    bool committed_ = false;
};

// The files of one render.
struct RenderOutputs {
    std::filesystem::path image;         // linear OpenEXR; must end in .exr
    bool png_preview = true;             // tone-mapped PNG beside it (the image's name, .png)
    std::filesystem::path stats;         // JSON report (report.h); empty for none
    std::filesystem::path cut_heatmap;   // per-pixel cut size as a PNG; lightcuts and stochastic only; empty for none
};

// Refuses, before anything is rendered, every combination that could not be
// written (std::invalid_argument): an image not ending in .exr, a cut heatmap
// without a method that selects cuts (lightcuts, stochastic), and whatever
// OutputSet::add refuses: the scene file and every file of `inputs` (the
// scene's meshes, light lists, textures, environment: Scene::input_files)
// are inputs no output may replace. Returns the set holding the temporaries.
OutputSet reserve_render_outputs(const RenderOutputs& outputs, const std::filesystem::path& scene_file,
                                 std::string_view method, const std::vector<std::filesystem::path>& inputs = {});

// Writes each of `outputs` to its temporary in `set` (reserved by
// reserve_render_outputs), then commits. On any failure no output is left
// and the exception says why.
void write_render_outputs(OutputSet& set, const RenderOutputs& outputs, const RenderResult& result,
                          std::string_view stats_json);

}  // namespace lc
