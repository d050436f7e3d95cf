#pragma once
// JSON helpers shared by the zarr v2 (`.zarray`) and v3 (`zarr.json`) metadata parsers
// (internal): errors that name the file and key, dimension lists, fill values.

#include <cstdint>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "resoct/base/error.hpp"
#include "resoct/volume/voxel_type.hpp"

namespace resoct::detail {

/// Error(corrupt): "<location>: key '<key>': <why>".
Error corrupt(std::string_view location, std::string_view key, std::string_view why);
/// Error(unsupported): "<location>: key '<key>': <why>".
Error unsupported(std::string_view location, std::string_view key, std::string_view why);

/// Parses a zarr metadata document (`.zarray`, `zarr.json`): a JSON object whose `zarr_format`
/// is `version`. Error(corrupt) naming `location` for malformed JSON, another root, a missing or
/// non-integer `zarr_format`; Error(unsupported_version) naming the key for another version.
nlohmann::json parse_zarr_document(std::string_view json, std::string_view location, int version);

/// j[key] of an object; Error(corrupt) "<location>: key '<key>': missing" when absent.
const nlohmann::json& required(const nlohmann::json& j, const char* key, std::string_view location);

/// An array of 1..32 positive integers (shape, chunk shape); Error(corrupt) otherwise.
std::vector<std::uint64_t> dims(const nlohmann::json& j, std::string_view location,
                                std::string_view key);

/// A fill value in the file's units: null (0), a number, "NaN", "Infinity", "-Infinity", and
/// for float32 / float64 (v3) a "0x" + 8 / 16 hex digit bit pattern. Integer types need an
/// integer within the type's range. Errors name `key` (normally "fill_value").
double parse_fill(const nlohmann::json& j, std::string_view location, DataType t,
                  std::string_view key = "fill_value");

}  // namespace resoct::detail
