// Dataset checksums (demLib/checksum.hpp): the same however the rows are split among
// writers, and changed by a flipped bit or two swapped rows.
#include <gtest/gtest.h>

#include <cstdint>
#include <algorithm>
#include <vector>

#include "demLib/checksum.hpp"

namespace {
std::vector<double> rows(std::size_t n) {
    std::vector<double> v(3 * n);
    for (std::size_t k = 0; k < v.size(); ++k) v[k] = 1e-3 * static_cast<double>(k) - 0.25;
    return v;
}
}  // namespace

TEST(Checksum, PartialSumsOfAnySplitAddUpToTheWhole) {
    const std::vector<double> v = rows(1000);
    const std::size_t rowBytes = 3 * sizeof(double);
    const std::uint64_t whole = dem::datasetChecksum(v.data(), 1000, rowBytes);
    for (std::size_t split : {1u, 333u, 999u}) {  // two ranks, rows [0, split) and [split, 1000)
        const std::uint64_t first = dem::datasetChecksum(v.data(), split, rowBytes, 0);
        const std::uint64_t second = dem::datasetChecksum(v.data() + 3 * split, 1000 - split, rowBytes, split);
        EXPECT_EQ(first + second, whole) << "split at row " << split;
    }
}

TEST(Checksum, AFlippedBitOrSwappedRowsChangeIt) {
    std::vector<double> v = rows(50);
    const std::size_t rowBytes = 3 * sizeof(double);
    const std::uint64_t original = dem::datasetChecksum(v.data(), 50, rowBytes);
    for (std::size_t byte : {0u, 7u, 600u, 50u * 24u - 1u}) {
        std::vector<double> flipped = v;
        auto* bytes = reinterpret_cast<unsigned char*>(flipped.data());
        bytes[byte] ^= 0x01;
        EXPECT_NE(dem::datasetChecksum(flipped.data(), 50, rowBytes), original) << "bit flipped in byte " << byte;
    }
    std::vector<double> swapped = v;
    std::swap_ranges(swapped.begin(), swapped.begin() + 3, swapped.begin() + 3);
    EXPECT_NE(dem::datasetChecksum(swapped.data(), 50, rowBytes), original);
}
