#include <gtest/gtest.h>

#include "core/Csv.h"

namespace mirage {
namespace {

TEST(Csv, SplitsPlainAndQuotedFields) {
    auto f = splitCsvLine("0,0.5,ok,\"11 tag(s), RMS 0.17 px\",1.5,,\"a \"\"q\"\"\"");
    ASSERT_EQ(f.size(), 7u);
    EXPECT_EQ(f[3], "11 tag(s), RMS 0.17 px");
    EXPECT_EQ(f[4], "1.5");
    EXPECT_EQ(f[5], "");
    EXPECT_EQ(f[6], "a \"q\"");
}

TEST(Csv, QuotingRoundTrips) {
    for (std::string v : {"plain", "with, comma", "with \"quote\"", ""}) {
        auto f = splitCsvLine(csvField(v) + ",x");
        ASSERT_EQ(f.size(), 2u);
        EXPECT_EQ(f[0], v);
    }
}

TEST(Csv, UnterminatedQuoteDoesNotThrow) {
    auto f = splitCsvLine("1,\"broken");
    ASSERT_EQ(f.size(), 2u);
    EXPECT_EQ(f[1], "broken");
}

}  // namespace
}  // namespace mirage
