// The `mirage` command line: subcommands are listed, bad usage and bad input exit non-zero with
// a message, never a crash.
#include <gtest/gtest.h>

#include "tests/support/TestSupport.h"

namespace mirage::test {
namespace {

TEST(Cli, HelpListsSubcommands) {
    auto r = runMirage({"--help"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("info"), std::string::npos) << r.output;
}

TEST(Cli, UnknownSubcommandFails) {
    auto r = runMirage({"no-such-command"});
    EXPECT_NE(r.exitCode, 0);
}

TEST(Cli, NoSubcommandFails) {
    auto r = runMirage({});
    EXPECT_NE(r.exitCode, 0);
}

TEST(Cli, InfoMakesAHeadlessContext) {
    auto r = runMirage({"info"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("OpenGL"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mirage::test
