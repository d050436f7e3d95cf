#include "formats_zarr_json.hpp"

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

double parse_fill(const Json& j, std::string_view location, VoxelType t, std::string_view key) {
  if (j.is_null()) return 0.0;
  double v = 0.0;
  if (j.is_string()) {
    const std::string s = j.get<std::string>();
    if (s == "NaN") {
      v = std::numeric_limits<double>::quiet_NaN();
    } else if (s == "Infinity") {
      v = std::numeric_limits<double>::infinity();
    } else if (s == "-Infinity") {
      v = -std::numeric_limits<double>::infinity();
    } else if (t == VoxelType::f32 && s.size() == 10 && s.starts_with("0x") &&
               s.find_first_not_of("0123456789abcdefABCDEF", 2) == std::string::npos) {
      // zarr v3 writes a float's exact bit pattern as hex (e.g. a NaN payload).
      const auto bits = std::uint32_t(std::stoul(s.substr(2), nullptr, 16));
      float f = 0.0f;
      std::memcpy(&f, &bits, 4);
      v = double(f);
    } else {
      throw corrupt(location, key, "unknown string '" + s + "'");
    }
  } else if (j.is_number()) {
    v = j.get<double>();
  } else {
    throw corrupt(location, key, "expected a number, null or NaN/Infinity");
  }
  if (t != VoxelType::f32) {
    const double hi = t == VoxelType::u8 ? 255.0 : 65535.0;
    if (!(v >= 0.0 && v <= hi && v == std::floor(v))) {
      throw corrupt(location, key,
                    "must be an integer in 0.." + std::to_string(int(hi)) + ", got " + j.dump());
    }
  }
  return v;
}

}  // namespace resoct::detail
