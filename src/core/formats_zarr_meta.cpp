#include <string>

#include <nlohmann/json.hpp>

#include "resoct/error.hpp"
#include "formats_zarr_json.hpp"
#include "resoct/formats/zarr_array.hpp"

namespace resoct {

namespace {

using Json = nlohmann::json;
using detail::corrupt;
using detail::dims;
using detail::parse_fill;
using detail::unsupported;

void parse_dtype(const Json& j, std::string_view location, ZarrArrayMeta& m) {
  if (!j.is_string()) {
    throw j.is_array() ? unsupported(location, "dtype", "structured dtypes are not supported")
                       : corrupt(location, "dtype", "expected a string");
  }
  const std::string d = j.get<std::string>();
  if (d == "|u1" || d == "<u1" || d == ">u1") {
    m.type = VoxelType::u8;
  } else if (d == "<u2" || d == ">u2") {
    m.type = VoxelType::u16;
    m.endian = d[0] == '<' ? Endian::little : Endian::big;
  } else if (d == "<f4" || d == ">f4") {
    m.type = VoxelType::f32;
    m.endian = d[0] == '<' ? Endian::little : Endian::big;
  } else {
    throw unsupported(location, "dtype",
                      "'" + d + "' is not supported (|u1, <u2, >u2, <f4, >f4 are)");
  }
}

ZarrCompressor parse_compressor(const Json& j, std::string_view location) {
  if (j.is_null()) return ZarrCompressor::none;
  if (!j.is_object() || !j.contains("id") || !j["id"].is_string()) {
    throw corrupt(location, "compressor", "expected null or an object with a string 'id'");
  }
  const std::string id = j["id"].get<std::string>();
  if (id == "blosc") return ZarrCompressor::blosc;
  if (id == "lz4") return ZarrCompressor::lz4;
  if (id == "zstd") return ZarrCompressor::zstd;
  if (id == "zlib") return ZarrCompressor::zlib;
  if (id == "gzip") return ZarrCompressor::gzip;
  throw unsupported(location, "compressor",
                    "id '" + id + "' is not supported (blosc, lz4, zstd, zlib, gzip or null)");
}

}  // namespace

std::string_view to_string(ZarrCompressor c) noexcept {
  switch (c) {
    case ZarrCompressor::none: return "none";
    case ZarrCompressor::blosc: return "blosc";
    case ZarrCompressor::lz4: return "lz4";
    case ZarrCompressor::zstd: return "zstd";
    case ZarrCompressor::zlib: return "zlib";
    case ZarrCompressor::gzip: return "gzip";
  }
  return "?";
}

std::vector<std::uint64_t> ZarrArrayMeta::chunk_grid() const {
  std::vector<std::uint64_t> g(shape.size());
  for (std::size_t i = 0; i < shape.size(); ++i)
    g[i] = shape[i] / chunks[i] + (shape[i] % chunks[i] != 0);
  return g;
}

std::uint64_t ZarrArrayMeta::chunk_voxels() const {
  std::uint64_t n = 1;
  for (std::uint64_t c : chunks) n *= c;
  return n;
}

std::string ZarrArrayMeta::chunk_key(std::span<const std::uint64_t> chunk_index) const {
  std::string key = chunk_key_prefix;
  for (std::size_t i = 0; i < chunk_index.size(); ++i) {
    if (i != 0) key += dimension_separator;
    key += std::to_string(chunk_index[i]);
  }
  return key;
}

ZarrArrayMeta parse_zarr_array_meta(std::string_view json, std::string_view location) {
  Json j;
  try {
    j = Json::parse(json.begin(), json.end());
  } catch (const Json::exception& e) {
    throw Error(ErrorCode::corrupt, std::string(location) + ": not valid JSON: " + e.what());
  }
  if (!j.is_object()) throw corrupt(location, "(root)", "expected a JSON object");
  auto need = [&](const char* key) -> const Json& {
    if (!j.contains(key)) throw corrupt(location, key, "missing");
    return j[key];
  };
  const Json& format = need("zarr_format");
  if (!format.is_number_integer()) throw corrupt(location, "zarr_format", "expected an integer");
  if (format.get<std::int64_t>() != 2) {
    throw Error(ErrorCode::unsupported_version, std::string(location) +
                                                    ": key 'zarr_format': " + format.dump() +
                                                    " is not supported (zarr v2 only)");
  }
  ZarrArrayMeta m;
  m.shape = dims(need("shape"), location, "shape");
  m.chunks = dims(need("chunks"), location, "chunks");
  if (m.chunks.size() != m.shape.size()) {
    throw corrupt(location, "chunks",
                  "rank " + std::to_string(m.chunks.size()) + " differs from the rank " +
                      std::to_string(m.shape.size()) + " of 'shape'");
  }
  parse_dtype(need("dtype"), location, m);
  const Json& order = need("order");
  if (!order.is_string()) throw corrupt(location, "order", "expected \"C\" or \"F\"");
  if (order.get<std::string>() != "C") {
    throw unsupported(location, "order", "only C order is supported, got " + order.dump());
  }
  if (j.contains("filters") && !j["filters"].is_null() &&
      !(j["filters"].is_array() && j["filters"].empty())) {
    throw unsupported(location, "filters", "filters are not supported");
  }
  m.compressor = parse_compressor(need("compressor"), location);
  m.fill_value = parse_fill(need("fill_value"), location, m.type);
  if (j.contains("dimension_separator")) {
    const Json& s = j["dimension_separator"];
    if (s.is_string() && (s.get<std::string>() == "." || s.get<std::string>() == "/")) {
      m.dimension_separator = s.get<std::string>()[0];
    } else {
      throw corrupt(location, "dimension_separator", "expected \".\" or \"/\", got " + s.dump());
    }
  }
  // Overflow-safe: every factor is >= 1, so dividing the limit bounds the product.
  std::uint64_t bytes = voxel_size(m.type);
  for (std::uint64_t c : m.chunks) {
    if (c > kMaxZarrChunkBytes / bytes) {
      throw corrupt(location, "chunks",
                    "a chunk exceeds " + std::to_string(kMaxZarrChunkBytes) + " decoded bytes");
    }
    bytes *= c;
  }
  return m;
}

}  // namespace resoct
