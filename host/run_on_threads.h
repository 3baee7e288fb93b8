// The CPU code's parallel loops start their threads here: the light tree's
// build, the CSV reader, the area lights' sampling, the VPLs' paths, the
// renderers' tiles and the large uploads to a mapped buffer.
#pragma once

#include <exception>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace lc {

// Starts a std::thread running fn(t) (run_on_threads' default starter).
struct StartThread {
    template <typename Fn>
    std::thread operator()(Fn& fn, unsigned t) const {
        return std::thread(fn, t);
    }
};

// Runs work(t) once for every t in [0, shares): share 0 on the calling
// thread, each other share on a thread of its own, all of them joined before
// this returns. A thread that cannot be started (std::system_error, say at
// the process's thread limit) has its share run on the calling thread
// instead, after share 0; so the shares must not wait for one another. An
// exception thrown by a share reaches the caller once every thread has been
// joined, the first in share order; neither case ends the process in
// std::terminate. `start` starts one thread (tests stand in for it).
template <typename Work, typename Start = StartThread>
void run_on_threads(unsigned shares, Work&& work, Start start = Start{}) {
    if (shares <= 1u) {
        if (shares == 1u) work(0u);
        return;
    }
    std::vector<std::exception_ptr> errors(shares);
    auto run = [&](unsigned t) {
        try {
            work(t);
        } catch (...) {
            errors[t] = std::current_exception();
        }
    };
    std::vector<std::thread> pool;
    std::vector<unsigned> not_started;
    pool.reserve(shares - 1u);
    not_started.reserve(shares - 1u);
    for (unsigned t = 1; t < shares; ++t) {
        try {
            pool.push_back(start(run, t));
        } catch (const std::system_error&) {
            not_started.push_back(t);
        }
    }
    run(0u);
    for (const unsigned t : not_started) run(t);
    for (std::thread& th : pool) th.join();
    for (const std::exception_ptr& e : errors)
        if (e) std::rethrow_exception(e);
}

}  // namespace lc
