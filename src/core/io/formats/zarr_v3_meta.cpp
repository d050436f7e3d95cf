// Zarr v3 array metadata (`zarr.json`): data type, regular chunk grid, chunk key encoding, fill
// value, dimension names and the codec pipeline, checked for the bounds the reader relies on.

#include <algorithm>
#include <string>

#include <nlohmann/json.hpp>

#include "io/formats/zarr_json.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/formats/zarr_v3.hpp"

namespace resoct {

namespace {

using Json = nlohmann::json;
using detail::corrupt;
using detail::dims;
using detail::unsupported;

/// Nested sharding deeper than this is refused (a hostile file could nest without end).
constexpr int kMaxShardingDepth = 4;

const Json& member(const Json& j, const char* name, std::string_view location,
                   const std::string& key) {
  if (!j.is_object() || !j.contains(name)) throw corrupt(location, key + "." + name, "missing");
  return j[name];
}

/// `configuration` of a named object ({"name": ..., "configuration": {...}}); an empty object
/// when absent.
const Json& configuration(const Json& j, std::string_view location, const std::string& key) {
  static const Json kEmpty = Json::object();
  if (!j.contains("configuration")) return kEmpty;
  const Json& c = j["configuration"];
  if (!c.is_object()) throw corrupt(location, key + ".configuration", "expected an object");
  return c;
}

std::string name_of(const Json& j, std::string_view location, const std::string& key) {
  // A bare string is the short form of {"name": s} (zarr v3 spec, "extension points").
  if (j.is_string()) return j.get<std::string>();
  if (!j.is_object() || !j.contains("name") || !j["name"].is_string()) {
    throw corrupt(location, key, "expected a string or an object with a string 'name'");
  }
  return j["name"].get<std::string>();
}

std::uint64_t product_bounded(std::span<const std::uint64_t> shape, std::uint64_t unit,
                              std::uint64_t limit, std::string_view location,
                              const std::string& key, std::string_view what) {
  std::uint64_t n = unit;
  for (std::uint64_t d : shape) {
    if (d > limit / n) {
      throw corrupt(location, key, std::string(what) + " exceeds " + std::to_string(limit));
    }
    n *= d;
  }
  return n;
}

struct PipelineParser {
  std::string_view location;
  DataType type;

  /// Parses `j` (a codec list) for chunks of `shape`; `depth` counts enclosing shards.
  ZarrCodecs parse(const Json& j, std::vector<std::uint64_t> shape, const std::string& key,
                   int depth) const {
    if (!j.is_array() || j.empty() || j.size() > 16) {
      throw corrupt(location, key, "expected an array of 1..16 codecs");
    }
    ZarrCodecs out;
    bool have_array_to_bytes = false;
    for (std::size_t i = 0; i < j.size(); ++i) {
      const std::string k = key + "[" + std::to_string(i) + "]";
      const std::string name = name_of(j[i], location, k);
      const Json& conf = j[i].is_object() ? configuration(j[i], location, k) : Json::object();
      ZarrCodec c;
      if (name == "transpose") {
        if (have_array_to_bytes) throw corrupt(location, k, "transpose after the bytes codec");
        c.kind = ZarrCodecKind::transpose;
        c.order = order(member(conf, "order", location, k + ".configuration"), shape.size(),
                        k + ".configuration.order");
        std::vector<std::uint64_t> t(shape.size());
        for (std::size_t d = 0; d < shape.size(); ++d) t[d] = shape[c.order[d]];
        shape = t;
      } else if (name == "bytes" || name == "sharding_indexed") {
        if (have_array_to_bytes) throw corrupt(location, k, "a second array-to-bytes codec");
        have_array_to_bytes = true;
        if (name == "bytes") {
          c.kind = ZarrCodecKind::bytes;
          c.endian = endian(conf, k);
        } else {
          c.kind = ZarrCodecKind::sharding_indexed;
          c.sharding = sharding(conf, shape, k, depth);
        }
      } else if (name == "blosc" || name == "gzip" || name == "zstd" || name == "crc32c") {
        if (!have_array_to_bytes) {
          throw corrupt(location, k, "bytes-to-bytes codec '" + name + "' before the bytes codec");
        }
        c.kind = name == "blosc"  ? ZarrCodecKind::blosc
                 : name == "gzip" ? ZarrCodecKind::gzip
                 : name == "zstd" ? ZarrCodecKind::zstd
                                  : ZarrCodecKind::crc32c;
      } else {
        throw unsupported(location, k,
                          "codec '" + name +
                              "' is not supported (transpose, bytes, sharding_indexed, blosc, "
                              "gzip, zstd, crc32c are)");
      }
      out.push_back(std::move(c));
    }
    if (!have_array_to_bytes) throw corrupt(location, key, "no array-to-bytes codec (bytes)");
    return out;
  }

  std::vector<std::size_t> order(const Json& j, std::size_t rank, const std::string& key) const {
    std::vector<std::size_t> o;
    if (j.is_string() && (j.get<std::string>() == "C" || j.get<std::string>() == "F")) {
      // Early v3 drafts: "C" is the identity, "F" the reversal.
      for (std::size_t d = 0; d < rank; ++d)
        o.push_back(j.get<std::string>() == "C" ? d : rank - 1 - d);
      return o;
    }
    if (!j.is_array() || j.size() != rank) {
      throw corrupt(location, key, "expected a permutation of 0.." + std::to_string(rank - 1));
    }
    std::vector<bool> seen(rank, false);
    for (const Json& v : j) {
      if (!v.is_number_unsigned() || v.get<std::uint64_t>() >= rank || seen[v.get<std::size_t>()]) {
        throw corrupt(location, key, "expected a permutation of 0.." + std::to_string(rank - 1));
      }
      seen[v.get<std::size_t>()] = true;
      o.push_back(v.get<std::size_t>());
    }
    return o;
  }

  Endian endian(const Json& conf, const std::string& key) const {
    if (!conf.contains("endian")) {
      if (data_size(type) > 1) {
        throw corrupt(location, key + ".configuration.endian",
                      "missing (required for multi-byte data types)");
      }
      return Endian::little;
    }
    const Json& e = conf["endian"];
    if (e.is_string() && e.get<std::string>() == "little") return Endian::little;
    if (e.is_string() && e.get<std::string>() == "big") return Endian::big;
    throw corrupt(location, key + ".configuration.endian",
                  "expected \"little\" or \"big\", got " + e.dump());
  }

  std::shared_ptr<const ZarrShardingCodec> sharding(const Json& conf,
                                                    const std::vector<std::uint64_t>& shape,
                                                    const std::string& key, int depth) const {
    const std::string ck = key + ".configuration";
    if (depth >= kMaxShardingDepth) {
      throw unsupported(location, key,
                        "sharding nested deeper than " + std::to_string(kMaxShardingDepth));
    }
    auto s = std::make_shared<ZarrShardingCodec>();
    s->chunk_shape = dims(member(conf, "chunk_shape", location, ck), location, ck + ".chunk_shape");
    if (s->chunk_shape.size() != shape.size()) {
      throw corrupt(location, ck + ".chunk_shape",
                    "rank " + std::to_string(s->chunk_shape.size()) + " differs from the chunk's " +
                        std::to_string(shape.size()));
    }
    for (std::size_t d = 0; d < shape.size(); ++d) {
      if (shape[d] % s->chunk_shape[d] != 0) {
        throw corrupt(location, ck + ".chunk_shape",
                      "inner chunk extent " + std::to_string(s->chunk_shape[d]) +
                          " does not divide the shard extent " + std::to_string(shape[d]) +
                          " (dimension " + std::to_string(d) + ")");
      }
    }
    std::vector<std::uint64_t> per_shard(shape.size());
    for (std::size_t d = 0; d < shape.size(); ++d) per_shard[d] = shape[d] / s->chunk_shape[d];
    product_bounded(per_shard, 1, kMaxZarrShardChunks, location, ck + ".chunk_shape",
                    "inner chunks per shard");
    product_bounded(s->chunk_shape, data_size(type), kMaxZarrChunkBytes, location,
                    ck + ".chunk_shape", "decoded bytes of an inner chunk");
    s->codecs =
        parse(member(conf, "codecs", location, ck), s->chunk_shape, ck + ".codecs", depth + 1);
    if (conf.contains("index_location")) {
      const Json& l = conf["index_location"];
      if (!l.is_string() || (l.get<std::string>() != "start" && l.get<std::string>() != "end")) {
        throw corrupt(location, ck + ".index_location",
                      "expected \"start\" or \"end\", got " + l.dump());
      }
      s->index_at_end = l.get<std::string>() == "end";
    }
    // The index is an array of uint64 (offset, nbytes) pairs; its codecs are checked by
    // zarr_shard_index_bytes, which accepts exactly what parse_zarr_shard_index decodes.
    const PipelineParser index_parser{location, DataType::u16};  // multi-byte: endian required
    std::vector<std::uint64_t> index_shape = per_shard;
    index_shape.push_back(2);
    s->index_codecs = index_parser.parse(member(conf, "index_codecs", location, ck), index_shape,
                                         ck + ".index_codecs", kMaxShardingDepth);
    (void)zarr_shard_index_bytes(*s, 1, location);
    return s;
  }
};

std::vector<std::string> dimension_names(const Json& j, std::size_t rank,
                                         std::string_view location) {
  if (!j.is_array() || j.size() != rank) {
    throw corrupt(location, "dimension_names",
                  "expected " + std::to_string(rank) + " names or nulls (one per dimension)");
  }
  std::vector<std::string> out;
  for (const Json& n : j) {
    if (n.is_null()) {
      out.emplace_back();
    } else if (n.is_string()) {
      out.push_back(n.get<std::string>());
    } else {
      throw corrupt(location, "dimension_names", "expected strings or nulls, got " + n.dump());
    }
  }
  return out;
}

}  // namespace

DataType parse_zarr_v3_data_type(std::string_view name, std::string_view location,
                                 std::string_view key) {
  static constexpr std::pair<std::string_view, DataType> kNames[] = {
      {"uint8", DataType::u8},    {"int8", DataType::i8},     {"uint16", DataType::u16},
      {"int16", DataType::i16},   {"uint32", DataType::u32},  {"int32", DataType::i32},
      {"float32", DataType::f32}, {"float64", DataType::f64},
  };
  for (const auto& [n, t] : kNames) {
    if (name == n) return t;
  }
  throw unsupported(location, key,
                    "data type '" + std::string(name) +
                        "' is not supported (uint8, int8, uint16, int16, uint32, int32, float32, "
                        "float64 are)");
}

ZarrArrayMeta parse_zarr_v3_array_meta(std::string_view json, std::string_view location) {
  const Json j = detail::parse_zarr_document(json, location, 3);
  auto need = [&](const char* key) -> const Json& { return detail::required(j, key, location); };
  const Json& node = need("node_type");
  if (!node.is_string() || node.get<std::string>() != "array") {
    throw corrupt(location, "node_type", "expected \"array\", got " + node.dump());
  }
  ZarrArrayMeta m;
  m.zarr_format = 3;
  auto layout = std::make_shared<ZarrV3Layout>();
  m.shape = dims(need("shape"), location, "shape");

  const Json& type = need("data_type");
  if (!type.is_string()) throw corrupt(location, "data_type", "expected a string");
  m.data_type = parse_zarr_v3_data_type(type.get<std::string>(), location, "data_type");
  m.type = data_mapping(m.data_type).stored;

  const Json& grid = need("chunk_grid");
  const std::string grid_name = name_of(grid, location, "chunk_grid");
  if (grid_name != "regular") {
    throw unsupported(location, "chunk_grid.name",
                      "chunk grid '" + grid_name + "' is not supported (regular is)");
  }
  const std::vector<std::uint64_t> grid_chunks =
      dims(member(configuration(grid, location, "chunk_grid"), "chunk_shape", location,
                  "chunk_grid.configuration"),
           location, "chunk_grid.configuration.chunk_shape");
  if (grid_chunks.size() != m.shape.size()) {
    throw corrupt(location, "chunk_grid.configuration.chunk_shape",
                  "rank " + std::to_string(grid_chunks.size()) + " differs from the rank " +
                      std::to_string(m.shape.size()) + " of 'shape'");
  }

  const Json& encoding = need("chunk_key_encoding");
  const std::string enc = name_of(encoding, location, "chunk_key_encoding");
  if (enc != "default" && enc != "v2") {
    throw unsupported(location, "chunk_key_encoding.name",
                      "chunk key encoding '" + enc + "' is not supported (default, v2 are)");
  }
  m.dimension_separator = enc == "default" ? '/' : '.';
  const Json& enc_conf = configuration(encoding, location, "chunk_key_encoding");
  if (enc_conf.contains("separator")) {
    const Json& s = enc_conf["separator"];
    if (!s.is_string() || (s.get<std::string>() != "/" && s.get<std::string>() != ".")) {
      throw corrupt(location, "chunk_key_encoding.configuration.separator",
                    "expected \"/\" or \".\", got " + s.dump());
    }
    m.dimension_separator = s.get<std::string>()[0];
  }
  if (enc == "default") m.chunk_key_prefix = std::string("c") + m.dimension_separator;

  m.fill_value = detail::parse_fill(need("fill_value"), location, m.data_type);

  if (j.contains("storage_transformers") &&
      !(j["storage_transformers"].is_array() && j["storage_transformers"].empty())) {
    throw unsupported(location, "storage_transformers", "storage transformers are not supported");
  }
  if (j.contains("dimension_names") && !j["dimension_names"].is_null()) {
    layout->dimension_names = dimension_names(j["dimension_names"], m.shape.size(), location);
  }

  const PipelineParser parser{location, m.data_type};
  layout->codecs = parser.parse(need("codecs"), grid_chunks, "codecs", 0);
  const bool read_by_ranges =
      layout->codecs.size() == 1 && layout->codecs[0].kind == ZarrCodecKind::sharding_indexed;
  if (read_by_ranges) {
    layout->shard_shape = grid_chunks;
    m.chunks = layout->codecs[0].sharding->chunk_shape;
  } else {
    m.chunks = grid_chunks;
    product_bounded(m.chunks, data_size(m.data_type), kMaxZarrChunkBytes, location,
                    "chunk_grid.configuration.chunk_shape", "decoded bytes of a chunk");
  }
  m.v3 = std::move(layout);
  return m;
}

}  // namespace resoct
