#include <string>
#include <string_view>
#include <utility>

#include <nlohmann/json.hpp>

#include "resoct/base/error.hpp"
#include "io/formats/zarr_json.hpp"
#include "resoct/io/formats/zarr_array.hpp"

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
  // numpy's typestr: byte order ('<', '>', '|'), kind, bytes.
  static const std::pair<std::string_view, DataType> kTypes[] = {
      {"u1", DataType::u8},  {"i1", DataType::i8},  {"u2", DataType::u16}, {"i2", DataType::i16},
      {"u4", DataType::u32}, {"i4", DataType::i32}, {"f4", DataType::f32}, {"f8", DataType::f64},
  };
  const std::string d = j.get<std::string>();
  const bool order = d.size() == 3 && (d[0] == '<' || d[0] == '>' || d[0] == '|');
  for (const auto& [name, type] : kTypes) {
    if (!order || std::string_view(d).substr(1) != name) continue;
    if (d[0] == '|' && data_size(type) != 1) break;  // multi-byte values need a byte order
    m.data_type = type;
    m.type = data_mapping(type).stored;
    m.endian = d[0] == '>' ? Endian::big : Endian::little;
    return;
  }
  throw unsupported(
      location, "dtype",
      "'" + d + "' is not supported (u1, i1, u2, i2, u4, i4, f4, f8 with '<' or '>')");
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
  const Json j = detail::parse_zarr_document(json, location, 2);
  auto need = [&](const char* key) -> const Json& { return detail::required(j, key, location); };
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
  m.fill_value = parse_fill(need("fill_value"), location, m.data_type);
  if (j.contains("dimension_separator")) {
    const Json& s = j["dimension_separator"];
    if (s.is_string() && (s.get<std::string>() == "." || s.get<std::string>() == "/")) {
      m.dimension_separator = s.get<std::string>()[0];
    } else {
      throw corrupt(location, "dimension_separator", "expected \".\" or \"/\", got " + s.dump());
    }
  }
  // Overflow-safe: every factor is >= 1, so dividing the limit bounds the product.
  std::uint64_t bytes = data_size(m.data_type);  // never below voxel_size(m.type)
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
