#include "io/formats/zarr_json.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace resoct::detail {

using Json = nlohmann::json;

Error corrupt(std::string_view location, std::string_view key, std::string_view why) {
  return Error(ErrorCode::corrupt,
               std::string(location) + ": key '" + std::string(key) + "': " + std::string(why));
}

Error unsupported(std::string_view location, std::string_view key, std::string_view why) {
  return Error(ErrorCode::unsupported,
               std::string(location) + ": key '" + std::string(key) + "': " + std::string(why));
}

Json parse_zarr_document(std::string_view json, std::string_view location, int version) {
  Json j;
  try {
    j = Json::parse(json.begin(), json.end());
  } catch (const Json::exception& e) {
    throw Error(ErrorCode::corrupt, std::string(location) + ": not valid JSON: " + e.what());
  }
  if (!j.is_object()) throw corrupt(location, "(root)", "expected a JSON object");
  const Json& format = required(j, "zarr_format", location);
  if (!format.is_number_integer()) throw corrupt(location, "zarr_format", "expected an integer");
  if (format.get<std::int64_t>() != version) {
    throw Error(ErrorCode::unsupported_version,
                std::string(location) + ": key 'zarr_format': " + format.dump() +
                    " is not supported here (expected " + std::to_string(version) + ")");
  }
  return j;
}

const Json& required(const Json& j, const char* key, std::string_view location) {
  if (!j.contains(key)) throw corrupt(location, key, "missing");
  return j[key];
}

std::vector<std::uint64_t> dims(const Json& j, std::string_view location, std::string_view key) {
  if (!j.is_array() || j.empty() || j.size() > 32) {
    throw corrupt(location, key, "expected an array of 1..32 positive integers");
  }
  std::vector<std::uint64_t> out;
  for (const Json& v : j) {
    if (!v.is_number_unsigned() || v.get<std::uint64_t>() == 0) {
      throw corrupt(location, key, "expected positive integers, got " + v.dump());
    }
    out.push_back(v.get<std::uint64_t>());
  }
  return out;
}

double parse_fill(const Json& j, std::string_view location, DataType t, std::string_view key) {
  if (j.is_null()) return 0.0;
  const bool real = t == DataType::f32 || t == DataType::f64;
  double v = 0.0;
  if (j.is_string()) {
    const std::string s = j.get<std::string>();
    const std::size_t hex_digits = t == DataType::f64 ? 16 : 8;
    if (s == "NaN") {
      v = std::numeric_limits<double>::quiet_NaN();
    } else if (s == "Infinity") {
      v = std::numeric_limits<double>::infinity();
    } else if (s == "-Infinity") {
      v = -std::numeric_limits<double>::infinity();
    } else if (real && s.size() == 2 + hex_digits && s.starts_with("0x") &&
               s.find_first_not_of("0123456789abcdefABCDEF", 2) == std::string::npos) {
      // zarr v3 writes a float's exact bit pattern as hex (e.g. a NaN payload).
      const std::uint64_t bits = std::stoull(s.substr(2), nullptr, 16);
      v = t == DataType::f64 ? std::bit_cast<double>(bits)
                             : double(std::bit_cast<float>(std::uint32_t(bits)));
    } else {
      throw corrupt(location, key, "unknown string '" + s + "'");
    }
  } else if (j.is_number()) {
    v = j.get<double>();
  } else {
    throw corrupt(location, key, "expected a number, null or NaN/Infinity");
  }
  if (!real) {
    // The integer types' value ranges (i32 and u32 values beyond 2^24 are rounded in f32, as
    // their voxels are).
    const double lo = t == DataType::i8    ? -128.0
                      : t == DataType::i16 ? -32768.0
                      : t == DataType::i32 ? -2147483648.0
                                           : 0.0;
    const double hi = t == DataType::u8    ? 255.0
                      : t == DataType::i8  ? 127.0
                      : t == DataType::u16 ? 65535.0
                      : t == DataType::i16 ? 32767.0
                      : t == DataType::i32 ? 2147483647.0
                                           : 4294967295.0;
    if (!(v >= lo && v <= hi && v == std::floor(v))) {
      throw corrupt(location, key,
                    "must be an integer in " + std::to_string(std::int64_t(lo)) + ".." +
                        std::to_string(std::int64_t(hi)) + " for data type " +
                        std::string(to_string(t)) + ", got " + j.dump());
    }
  }
  return v;
}

}  // namespace resoct::detail
