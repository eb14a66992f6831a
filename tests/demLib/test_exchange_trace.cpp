// The exchange rounds' record (demLib/exchange_trace.hpp): what is recorded is what the
// file holds, three doubles a round in order, named by the rank; bench/exchangeTrace reads it.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "demLib/error.hpp"
#include "demLib/exchange_trace.hpp"

TEST(ExchangeTrace, TheFileHoldsTheRoundsInOrderNamedByRank) {
    const std::string dir = ::testing::TempDir();
    {
        dem::ExchangeTrace trace;
        trace.setRank(3);
        trace.record(1.5, 1.5000125, 18936.0);
        trace.record(1.6, 1.6000100, 72.0);
        trace.write(dir);
    }
    const std::string path = dir + "/" + dem::ExchangeTrace::fileName(3);
    EXPECT_EQ(dem::ExchangeTrace::fileName(3), "exchangeTrace.rank3.bin");
    std::ifstream in(path, std::ios::binary);
    ASSERT_TRUE(in) << path;
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_EQ(bytes.size(), 6 * sizeof(double));
    std::vector<double> v(6);
    std::copy(bytes.begin(), bytes.end(), reinterpret_cast<char*>(v.data()));
    EXPECT_EQ(v, (std::vector<double>{1.5, 1.5000125, 18936.0, 1.6, 1.6000100, 72.0}));
    std::remove(path.c_str());
}

TEST(ExchangeTrace, AnUnwritableDirectoryIsAnError) {
    dem::ExchangeTrace trace;
    trace.setRank(0);
    trace.record(0.0, 1.0, 8.0);
    EXPECT_THROW(trace.write("/nonexistent-directory-of-the-exchange-trace-test"), dem::RuntimeError);
}
