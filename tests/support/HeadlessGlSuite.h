#pragma once
// A test fixture whose tests share one headless GL context (EGL surfaceless, llvmpipe without a
// GPU), made before the suite's first test and destroyed after its last: creating a context per
// test costs more than many of the tests themselves.
#include <memory>

#include <gtest/gtest.h>

#include "core/gl/Context.h"

namespace mirage::test {

class HeadlessGlSuite : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        context_ = std::make_unique<gl::Context>(gl::Context::headless());
    }
    static void TearDownTestSuite() { context_.reset(); }

private:
    static inline std::unique_ptr<gl::Context> context_;
};

}  // namespace mirage::test
