// All-or-nothing outputs (lightcuts/output_set.h): refusals come before any
// work, and after any failure no output and no temporary is left and the
// files the outputs would have replaced are as they were.
#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "lightcuts/image.h"
#include "lightcuts/output_set.h"
#include "test_util.h"

namespace lc {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class OutputSetTest : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("lc_test_output_set_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    fs::path at(const std::string& name) const { return dir_ / name; }
    std::set<std::string> entries() const {
        std::set<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
        return names;
    }
    static void write(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }
    static std::string read(const fs::path& file) {
        std::ostringstream s;
        s << std::ifstream(file).rdbuf();
        return s.str();
    }
    template <class F>
    static std::string error_of(F&& f) {
        try {
            f();
        } catch (const std::exception& e) {
            return e.what();
        }
        return "(no exception)";
    }

    fs::path dir_;
};

TEST_F(OutputSetTest, CommitPutsEveryFileInPlace) {
    write(at("b.txt"), "old");
    {
        OutputSet set;
        write(set.add(at("a.txt"), "first"), "A");
        write(set.add(at("b.txt"), "second"), "B");
        EXPECT_EQ(entries().size(), 3u) << "the temporaries exist from add() on";
        set.commit();
    }
    EXPECT_EQ(entries(), (std::set<std::string>{"a.txt", "b.txt"}));
    EXPECT_EQ(read(at("a.txt")), "A");
    EXPECT_EQ(read(at("b.txt")), "B");
}

TEST_F(OutputSetTest, UncommittedSetLeavesNothing) {
    write(at("b.txt"), "old");
    {
        OutputSet set;
        write(set.add(at("a.txt"), "first"), "A");
        set.add(at("b.txt"), "second");
        OutputSet moved(std::move(set));
    }
    EXPECT_EQ(entries(), (std::set<std::string>{"b.txt"}));
    EXPECT_EQ(read(at("b.txt")), "old");
}

// A signal that ends the process mid-render: with remove_temporaries_on_signal
// nothing is left but the file that was there before; without it (the
// control) the temporaries stay, so the test sees the difference.
TEST_F(OutputSetTest, SignalLeavesNoTemporaries) {
    // The "fast" style forks here, so the child writes in this test's folder
    // (the "threadsafe" one would run the test again, in a folder of its own).
    const std::string style = GTEST_FLAG_GET(death_test_style);
    GTEST_FLAG_SET(death_test_style, "fast");
    write(at("b.txt"), "old");
    auto render_then_signal = [&](bool handled, int signal_number) {
        // SIGQUIT and SIGXFSZ would dump core into this folder.
        const rlimit no_core{0, 0};
        setrlimit(RLIMIT_CORE, &no_core);
        if (handled) remove_temporaries_on_signal();
        OutputSet set;
        write(set.add(at("a.txt"), "first"), "A");
        set.add(at("b.txt"), "second");
        std::raise(signal_number);
    };
    std::vector<int> signals = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE, SIGXFSZ};
    // The crashes, where nothing else handles them (the sanitizers' builds
    // handle SIGSEGV and SIGBUS, and remove_temporaries_on_signal leaves them).
    for (int crash : {SIGABRT, SIGSEGV, SIGBUS}) {
        struct sigaction current {};
        if (::sigaction(crash, nullptr, &current) == 0 && (current.sa_flags & SA_SIGINFO) == 0 &&
            current.sa_handler == SIG_DFL)
            signals.push_back(crash);
    }
    for (int signal_number : signals) {
        SCOPED_TRACE(strsignal(signal_number));
        EXPECT_EXIT(render_then_signal(true, signal_number), ::testing::KilledBySignal(signal_number), "");
        EXPECT_EQ(entries(), (std::set<std::string>{"b.txt"}));
        EXPECT_EQ(read(at("b.txt")), "old");
    }

    EXPECT_EXIT(render_then_signal(false, SIGPIPE), ::testing::KilledBySignal(SIGPIPE), "");
    EXPECT_EQ(entries().size(), 3u) << "without the handler the two temporaries stay";
    GTEST_FLAG_SET(death_test_style, style);
}

// A signal during a commit (ReplacementJournal, as OutputSet::commit uses
// it): the commit of a.txt, which replaces an old file, and b.txt, which is
// new, stopped by SIGTERM after each of its steps in turn. Before finish()
// every file is as it was; after it, both are new; never is a backup or a
// temporary left. (Before the journal, a signal between moving a.txt aside
// and renaming its temporary onto it left no a.txt, and the old one under
// a hidden name.)
TEST_F(OutputSetTest, SignalDuringACommitPutsBackOrKeepsEveryFile) {
    const std::string style = GTEST_FLAG_GET(death_test_style);
    GTEST_FLAG_SET(death_test_style, "fast");
    write(at("a.txt"), "old");
    constexpr int kSteps = 6;
    auto commit_until = [&](int stop) {
        remove_temporaries_on_signal();
        int step = 0;
        const auto next = [&] {
            if (++step == stop) std::raise(SIGTERM);
        };
        const fs::path temporary_a = temporary_path_for(at("a.txt")), temporary_b = temporary_path_for(at("b.txt"));
        const int tracked_a = track_temporary(temporary_a), tracked_b = track_temporary(temporary_b);
        write(temporary_a, "new A");
        write(temporary_b, "new B");
        const fs::path backup = temporary_path_for(at("a.txt"));
        ReplacementJournal journal;
        if (!journal.active()) std::abort();
        journal.begin(at("a.txt"), backup);
        next();  // 1
        fs::rename(at("a.txt"), backup);
        next();  // 2
        fs::rename(temporary_a, at("a.txt"));
        next();  // 3
        journal.begin(at("b.txt"), {});
        fs::rename(temporary_b, at("b.txt"));
        next();  // 4
        journal.finish();
        next();  // 5
        untrack_temporary(tracked_a);
        untrack_temporary(tracked_b);
        fs::remove(backup);
        next();  // 6
        std::exit(3);
    };
    for (int stop = 1; stop <= kSteps; ++stop) {
        SCOPED_TRACE("signal after step " + std::to_string(stop));
        EXPECT_EXIT(commit_until(stop), ::testing::KilledBySignal(SIGTERM), "");
        if (stop <= 4) {
            EXPECT_EQ(entries(), (std::set<std::string>{"a.txt"}));
            EXPECT_EQ(read(at("a.txt")), "old");
        } else {
            EXPECT_EQ(entries(), (std::set<std::string>{"a.txt", "b.txt"}));
            EXPECT_EQ(read(at("a.txt")), "new A");
            EXPECT_EQ(read(at("b.txt")), "new B");
            fs::remove(at("b.txt"));
            write(at("a.txt"), "old");
        }
    }
    GTEST_FLAG_SET(death_test_style, style);
}

// One journal at a time: a second, while the first lives, records nothing.
TEST(ReplacementJournal, OneAtATime) {
    ReplacementJournal first;
    EXPECT_TRUE(first.active());
    {
        ReplacementJournal second;
        EXPECT_FALSE(second.active());
    }
    EXPECT_TRUE(first.active());
}

// The table of tracked temporaries is bounded; a full table refuses (-1),
// and untracking frees its slots for reuse.
TEST(TrackTemporary, FullTableRefusesAndFreedSlotsAreReused) {
    std::vector<int> handles;
    for (int i = 0; i < 70; ++i) handles.push_back(track_temporary("/nonexistent/lc_tracked_" + std::to_string(i)));
    EXPECT_EQ(std::count(handles.begin(), handles.end(), -1), 6);
    for (int handle : handles) untrack_temporary(handle);
    const int again = track_temporary("/nonexistent/lc_tracked_again");
    EXPECT_GE(again, 0);
    untrack_temporary(again);
}

TEST_F(OutputSetTest, RefusesWhatCannotBeWrittenBeforeTheWork) {
    write(at("scene.json"), "{}");
    fs::create_directory(at("folder"));
    fs::create_symlink(at("scene.json"), at("symlink.json"));
    fs::create_hard_link(at("scene.json"), at("hardlink.json"));
    OutputSet set;
    set.add_input(at("scene.json"), "scene");
    set.add(at("a.png"), "preview");
    EXPECT_THAT(error_of([&] { set.add(at("missing") / "x.exr", "image"); }),
                HasSubstr("image " + (at("missing") / "x.exr").string() + ": folder " + at("missing").string() +
                          " does not exist"));
    EXPECT_THAT(error_of([&] { set.add(at("folder"), "stats file"); }),
                HasSubstr("stats file " + at("folder").string() + ": is a folder"));
    for (const fs::path& scene : {dir_ / "." / "scene.json", at("symlink.json"), at("hardlink.json")})
        EXPECT_THAT(error_of([&] { set.add(scene, "stats file"); }), HasSubstr(": is the scene")) << scene;
    EXPECT_THAT(error_of([&] { set.add(dir_ / "folder" / ".." / "a.png", "cut heatmap"); }),
                HasSubstr(": is also the preview"));
    // The one accepted output reserved its temporary; the refused ones nothing.
    std::set<std::string> now = entries();
    ASSERT_EQ(now.size(), 5u);
    for (const char* kept : {"folder", "hardlink.json", "scene.json", "symlink.json"}) EXPECT_TRUE(now.count(kept));
    auto temporary = [](const std::string& name) { return name.starts_with("a.png.tmp-"); };
    EXPECT_EQ(std::count_if(now.begin(), now.end(), temporary), 1);
}

// Outputs are renamed into place: onto a symbolic link that would replace
// the link instead of writing where it points, onto a device or a pipe it
// would replace their names with plain files. Each is refused, as is an
// empty name, and nothing is created or changed.
TEST_F(OutputSetTest, RefusesLinksDevicesPipesAndEmptyNames) {
    write(at("target.json"), "kept");
    fs::create_symlink(at("target.json"), at("link.json"));
    ASSERT_EQ(::mkfifo(at("pipe").c_str(), 0600), 0);
    OutputSet set;
    EXPECT_THAT(error_of([&] { set.add(at("link.json"), "stats file"); }),
                HasSubstr("stats file " + at("link.json").string() + ": is a symbolic link (to " +
                          at("target.json").string() + ")"));
    EXPECT_THAT(error_of([&] { set.add(at("pipe"), "stats file"); }), HasSubstr(": is not a regular file"));
    EXPECT_THAT(error_of([&] { set.add("", "stats file"); }), HasSubstr("stats file: the file name is empty"));
    EXPECT_EQ(entries(), (std::set<std::string>{"link.json", "pipe", "target.json"}));
    EXPECT_TRUE(fs::is_symlink(at("link.json")));
    EXPECT_EQ(read(at("target.json")), "kept");
}

// A file name of 255 bytes, the most Linux's file systems take, is written,
// over an existing file too (which is moved aside under a temporary's name
// first): the temporaries' names are cut to fit. One of 256 is refused
// before anything is created, with a message that names the output.
TEST_F(OutputSetTest, LongestFileNamesAreWrittenAndLongerOnesRefused) {
    const std::string longest(255, 'a');
    write(at(longest), "old");
    {
        OutputSet set;
        write(set.add(at(longest), "image"), "new");
        set.commit();
    }
    EXPECT_EQ(entries(), (std::set<std::string>{longest}));
    EXPECT_EQ(read(at(longest)), "new");
    OutputSet set;
    const std::string longer(256, 'b');
    EXPECT_THAT(error_of([&] { set.add(at(longer), "image"); }),
                HasSubstr("image " + at(longer).string() +
                          ": the file name is 256 bytes long; a file system takes at most 255"));
    EXPECT_EQ(entries(), (std::set<std::string>{longest}));
}

// The rename of the last output fails (its path became a folder during the
// work): the outputs renamed before it are taken back, the file one of them
// replaced is restored, and no temporary or moved-aside file remains.
TEST_F(OutputSetTest, FailedCommitTakesEverythingBack) {
    write(at("a.txt"), "old a");
    {
        OutputSet set;
        write(set.add(at("a.txt"), "first"), "new a");
        write(set.add(at("b.txt"), "second"), "new b");
        write(set.add(at("c.txt"), "third"), "new c");
        fs::create_directory(at("c.txt"));
        EXPECT_THAT(error_of([&] { set.commit(); }), HasSubstr(at("c.txt").string() + ": cannot rename"));
    }
    EXPECT_EQ(entries(), (std::set<std::string>{"a.txt", "c.txt"}));
    EXPECT_EQ(read(at("a.txt")), "old a");
    EXPECT_TRUE(fs::is_empty(at("c.txt")));
}

TEST_F(OutputSetTest, RenderOutputsRefuseImpossibleCombinations) {
    write(at("scene.json"), "{}");
    RenderOutputs o;
    o.image = at("a.png");
    EXPECT_THAT(error_of([&] { reserve_render_outputs(o, at("scene.json"), "brute"); }),
                HasSubstr("must end in .exr"));
    o.image = at("a.exr");
    o.cut_heatmap = at("cuts.png");
    EXPECT_THAT(error_of([&] { reserve_render_outputs(o, at("scene.json"), "brute"); }),
                HasSubstr("needs method lightcuts"));
    o.cut_heatmap = at("cuts.exr");  // the heatmap is a PNG, whatever its name says
    EXPECT_THAT(error_of([&] { reserve_render_outputs(o, at("scene.json"), "lightcuts"); }),
                HasSubstr("cuts.exr: must end in .png"));
    o.cut_heatmap = at("a.png");
    EXPECT_THAT(error_of([&] { reserve_render_outputs(o, at("scene.json"), "lightcuts"); }),
                HasSubstr("is also the PNG preview"));
    o.png_preview = false;
    o.stats = at("scene.json");
    EXPECT_THAT(error_of([&] { reserve_render_outputs(o, at("scene.json"), "lightcuts"); }),
                HasSubstr("is the scene"));
    EXPECT_EQ(entries(), (std::set<std::string>{"scene.json"}));
}

// A write that fails names the output the user asked for, not the
// temporary standing for it, and leaves nothing behind. (The temporary is
// replaced by a folder, which cannot be opened for writing.)
TEST_F(OutputSetTest, AFailedWriteNamesTheOutput) {
    Scene s = test::room_scene({test::point_light({0.0f, 1.5f, 0.0f}, glm::vec3(1.0f))}, 4);
    const PreparedScene prepared = prepare_scene(std::move(s), 1);
    const RenderResult result = render_cpu(prepared, test::options("lightcuts", 4));
    const RenderOutputs o{at("a.exr"), true, at("a.json"), {}};
    {
        OutputSet set = reserve_render_outputs(o, at("scene.json"), "lightcuts");
        const fs::path temporary = set.temporary(at("a.json"));
        fs::remove(temporary);
        fs::create_directory(temporary);
        const std::string message = error_of([&] { write_render_outputs(set, o, result, "{}\n"); });
        EXPECT_EQ(message.rfind(at("a.json").string() + ": cannot write: ", 0), 0u) << message;
        fs::remove(temporary);
    }
    EXPECT_TRUE(entries().empty());
}

TEST_F(OutputSetTest, RenderOutputsAreWrittenTogether) {
    Scene s = test::room_scene({test::point_light({0.0f, 1.5f, 0.0f}, glm::vec3(1.0f))}, 4);
    const PreparedScene prepared = prepare_scene(std::move(s), 1);
    const RenderResult result = render_cpu(prepared, test::options("lightcuts", 4));
    const RenderOutputs o{at("a.exr"), true, at("a.json"), at("cuts.png")};
    OutputSet set = reserve_render_outputs(o, at("scene.json"), "lightcuts");
    write_render_outputs(set, o, result, "{}\n");
    EXPECT_EQ(entries(), (std::set<std::string>{"a.exr", "a.json", "a.png", "cuts.png"}));
    EXPECT_EQ(read(at("a.json")), "{}\n");
    EXPECT_EQ(read_exr(at("a.exr")).rgb, result.image.rgb);
}

}  // namespace
}  // namespace lc
