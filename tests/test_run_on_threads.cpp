// run_on_threads (host/run_on_threads.h): every share runs once, whether its
// thread starts or not, and an exception from any share reaches the caller
// after every thread has been joined instead of ending the process.
#include <atomic>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "run_on_threads.h"

namespace lc {
namespace {

// A starter that cannot start the threads of the shares in `refused`, as
// std::thread cannot at the process's thread limit.
struct RefusingStart {
    unsigned refused;  // bit t: share t's thread is refused
    template <typename Fn>
    std::thread operator()(Fn& fn, unsigned t) const {
        if ((refused >> t & 1u) != 0u)
            throw std::system_error(std::make_error_code(std::errc::resource_unavailable_try_again));
        return std::thread(fn, t);
    }
};

TEST(RunOnThreads, EveryShareRunsOnceWhateverThreadsStart) {
    for (const unsigned shares : {0u, 1u, 2u, 5u}) {
        for (const unsigned refused : {0u, 0x2u, 0x14u, ~0u}) {
            std::vector<std::atomic<int>> runs(shares);
            std::vector<std::thread::id> on(shares);
            run_on_threads(
                shares,
                [&](unsigned t) {
                    runs[t] += 1;
                    on[t] = std::this_thread::get_id();
                },
                RefusingStart{refused});
            for (unsigned t = 0; t < shares; ++t) {
                EXPECT_EQ(runs[t].load(), 1) << shares << " shares, share " << t;
                // Share 0 and every share whose thread was refused run on
                // the calling thread; the others do not.
                const bool here = t == 0u || (refused >> t & 1u) != 0u;
                EXPECT_EQ(on[t] == std::this_thread::get_id(), here) << shares << " shares, share " << t;
            }
        }
    }
}

TEST(RunOnThreads, AShareThrowingReachesTheCallerAfterTheOthersEnd) {
    for (const unsigned thrower : {0u, 2u, 3u}) {
        std::atomic<int> finished{0};
        try {
            run_on_threads(4u, [&](unsigned t) {
                if (t == thrower) throw std::runtime_error("share " + std::to_string(t));
                finished += 1;
            });
            ADD_FAILURE() << "no exception from share " << thrower;
        } catch (const std::runtime_error& e) {
            EXPECT_EQ(std::string(e.what()), "share " + std::to_string(thrower));
        }
        EXPECT_EQ(finished.load(), 3);  // the other shares ran to their end, their threads joined
    }
    // Two shares throwing: the first in share order wins; one whose thread
    // was refused throws from the calling thread all the same.
    try {
        run_on_threads(
            3u, [](unsigned t) { if (t > 0u) throw std::runtime_error("share " + std::to_string(t)); },
            RefusingStart{0x4u});
        ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()), "share 1");
    }
}

}  // namespace
}  // namespace lc
