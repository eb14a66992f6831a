#pragma once
// Checksums of datasets (restart and particle files; docs/input-format.md, "Restart files").
// A dataset's checksum is the sum, modulo 2^64, over its rows i (particles, pairs, ...) of
// mix(i, FNV-1a-64 of the row's bytes): a writer that holds rows [first, first + n) of a
// dataset adds its partial sum to the others', so the checksum is the same however many
// ranks wrote (or will read) the data, and in whatever order.
#include <cstddef>
#include <cstdint>

namespace dem {

// The sum over rows [firstRow, firstRow + rows) of a dataset, given the bytes of those rows
// (rowBytes each, as stored: little-endian IEEE doubles, int64 or int32).
std::uint64_t datasetChecksum(const void* rowsData, std::size_t rows, std::size_t rowBytes,
                              std::uint64_t firstRow = 0);

}  // namespace dem
