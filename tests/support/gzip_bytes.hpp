#pragma once
// gzip streams made with zlib, for tests that write compressed files (.nii.gz, .hdr.gz, ...).

#include <cstdint>
#include <vector>

namespace resoct::test {

/// `in` as one gzip member (zlib level 6).
std::vector<std::uint8_t> gzip_bytes(const std::vector<std::uint8_t>& in);

}  // namespace resoct::test
