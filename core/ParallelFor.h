#pragma once
// Runs fn(i) for i in [0, count) on `threads` threads (the caller's among them). Work is claimed
// through an atomic counter, so which thread runs an item varies but each item's result does not.
// The first exception thrown by any fn stops the remaining items and is rethrown here, after
// every thread has joined.
#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace mirage {

template <typename Fn>
void parallelFor(int count, int threads, Fn&& fn) {
    std::atomic<int> next{0};
    auto worker = [&] {
        for (int i = next++; i < count; i = next++) fn(i);
    };
    const int n = std::max(1, std::min(threads, count));
    std::vector<std::thread> pool;
    pool.reserve(size_t(n - 1));
    std::exception_ptr error;
    std::mutex errorMutex;
    auto guarded = [&] {
        try {
            worker();
        } catch (...) {
            std::lock_guard lock(errorMutex);
            if (!error) error = std::current_exception();
            next = count;
        }
    };
    for (int t = 1; t < n; ++t) pool.emplace_back(guarded);
    guarded();
    for (auto& t : pool) t.join();
    if (error) std::rethrow_exception(error);
}

}  // namespace mirage
