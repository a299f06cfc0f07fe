// Private to the transport table's writer (transport_table.cpp) and reader
// (transport_table_read.cpp): the file's format name and version, and the reader's bounds.
#pragma once

#include <cstddef>

namespace lucent::materials::detail {

inline constexpr const char* kTableFormat = "lucent-transport-table";
inline constexpr int kTableVersion = 1;
// A header line longer than this is not ours (and would be read whole before the check).
inline constexpr std::size_t kMaxHeaderBytes = 1 << 20;
// The largest table lucent reads (the shipped radial one is 1.2 MB; a slice at a fine grid tens of
// MB): a mistaken multi-gigabyte file is refused by its size.
inline constexpr std::size_t kMaxTableBytes = std::size_t(512) << 20;

}  // namespace lucent::materials::detail
