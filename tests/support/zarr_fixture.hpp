#pragma once
// The zarr test images' expected contents (tests/data/make_ome_zarr*.py dump every case's numpy
// array to <dir>/<name>.raw: all axes, C order, little-endian values of the case's dtype) in
// resoct's voxel order, shared by the OME-Zarr 0.4 and 0.5 tests.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "resoct/sources/brick_source.hpp"
#include "resoct/sources/in_memory_source.hpp"

namespace resoct::test {

/// The file values of (t, channel) of manifest case `c` as stored in the dump (dtype's size
/// each, little-endian), ordered as resoct lays voxels out: x fastest, then y, then z.
std::vector<std::byte> fixture_values(const std::string& dir, const nlohmann::json& c,
                                      std::uint64_t t, std::uint64_t channel);

/// fixture_values as resoct keeps them, by voxel_type.hpp's documented mapping written out here
/// independently of the reader: int8 / int16 plus 128 / 32768 as uint8 / uint16; int32, uint32
/// and float64 rounded to float32; uint8, uint16, float32 unchanged.
std::vector<std::byte> fixture_voxels(const std::string& dir, const nlohmann::json& c,
                                      std::uint64_t t, std::uint64_t channel);

/// An InMemorySource over fixture_voxels of every channel with `zarr`'s description: the
/// brute-force reference for every brick of every level (coarse levels computed eagerly).
InMemorySource fixture_reference(const std::string& dir, const nlohmann::json& c,
                                 const BrickSource& zarr, std::uint64_t t,
                                 const BrickLayout& layout);

/// Opens manifest case `c` (an image with a `t` axis) at timepoint 0 and checks the series:
/// timepoints() is the t extent, and every timepoint opened through source_at_timepoint keeps
/// the series' hierarchy (value ranges included), serves that timepoint's bricks at every level
/// (fixture_reference) and answers region metadata of that timepoint's voxels (exact extremes,
/// a superset of the occupancy).
void expect_series_of_fixture(const std::string& dir, const nlohmann::json& c,
                              const BrickLayout& layout);

}  // namespace resoct::test
