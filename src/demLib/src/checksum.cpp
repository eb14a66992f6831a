#include "demLib/checksum.hpp"

namespace dem {

namespace {

std::uint64_t fnv1a64(const unsigned char* bytes, std::size_t n) {
    std::uint64_t h = 14695981039346656037ull;
    for (std::size_t k = 0; k < n; ++k) {
        h ^= bytes[k];
        h *= 1099511628211ull;
    }
    return h;
}

// splitmix64's finaliser: spreads every input bit over the whole word.
std::uint64_t mix(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

}  // namespace

std::uint64_t datasetChecksum(const void* rowsData, std::size_t rows, std::size_t rowBytes, std::uint64_t firstRow) {
    const auto* bytes = static_cast<const unsigned char*>(rowsData);
    std::uint64_t sum = 0;
    // The row's index enters the mix: two rows swapped change the sum.
    for (std::size_t i = 0; i < rows; ++i)
        sum += mix(fnv1a64(bytes + i * rowBytes, rowBytes) ^ mix(firstRow + i));
    return sum;
}

}  // namespace dem
