#pragma once
/// \file
/// TIFF stacks as brick sources, read with libtiff: a multi-page file (each page a z slice) or
/// a directory of TIFF files (.tif / .tiff, sorted by name; every page of every file is a z
/// slice in that order). Pages are single-sample grayscale, 8-, 16- or 32-bit signed or unsigned
/// integers or 32- or 64-bit IEEE float (kept through data_mapping(), voxel_type.hpp), stored in
/// strips or tiles with any compression libtiff decodes; all pages share width, height and
/// sample format. Voxel values are used as stored (MinIsWhite is not
/// inverted), spacing is 1, and each channel's value range is its data's finite min/max.

#include <memory>
#include <string>

#include "resoct/sources/brick_source.hpp"

namespace resoct {

/// Opens a multi-page TIFF file or a directory of TIFF files. Voxels are held in memory;
/// coarser levels are built on demand (pyramid_source.hpp). Throws Error(io) naming the path
/// when it cannot be read, Error(bad_magic) when libtiff does not recognise a file (its message
/// included), Error(unsupported) naming the file and page for other sample layouts,
/// Error(corrupt) naming the file and page when pages disagree in size or type or a strip or
/// tile fails to decode or a page claims more pixels than its file can hold,
/// Error(invalid_argument) for a directory without TIFF files or with an entry that resolves,
/// through a symbolic link, to a file outside the directory (naming the directory and the
/// entry). Thread-safety: a pure function
/// (libtiff messages are captured per file, not through global handlers); the source is
/// thread-safe as BrickSource requires.
std::unique_ptr<BrickSource> open_tiff_stack(const std::string& path,
                                             const BrickLayout& layout = {});

}  // namespace resoct
