// parallelFor: every item runs once; an exception in a worker reaches the caller (not
// std::terminate), after every thread has joined.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "core/ParallelFor.h"

namespace mirage {
namespace {

TEST(ParallelFor, RunsEveryItemOnce) {
    std::vector<std::atomic<int>> hits(1000);
    parallelFor(1000, 4, [&](int i) { ++hits[size_t(i)]; });
    for (const auto& h : hits) EXPECT_EQ(h.load(), 1);
}

TEST(ParallelFor, AWorkersExceptionReachesTheCaller) {
    std::atomic<int> ran{0};
    EXPECT_THROW(parallelFor(1000, 4,
                             [&](int i) {
                                 ++ran;
                                 if (i == 17) throw std::runtime_error("item 17");
                             }),
                 std::runtime_error);
    EXPECT_GE(ran.load(), 1);
}

}  // namespace
}  // namespace mirage
