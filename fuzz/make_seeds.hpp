#pragma once
// Shared by the seed generator's files (make_seeds.cpp: resoct's own formats and strings;
// make_seeds_formats.cpp: the external volume and image formats).

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace resoct::fuzz::seeds {

namespace fs = std::filesystem;

struct Seed {
  std::string target, name;
  std::vector<std::byte> bytes;
  /// False when the bytes come from a third-party compressor, whose output may change with the
  /// library version: --check then only requires the committed file to exist.
  bool exact = true;
};

std::vector<std::byte> text_bytes(const std::string& s);

std::vector<std::byte> file_bytes(const fs::path& p);

/// Seeds of the format targets (zarr, OME, NIfTI, NRRD, TIFF, PNG); `scratch` is a writable
/// directory for files that only libraries can write.
void format_seeds(const fs::path& scratch, std::vector<Seed>& out);

}  // namespace resoct::fuzz::seeds
