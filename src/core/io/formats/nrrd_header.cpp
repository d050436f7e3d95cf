#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "resoct/base/error.hpp"
#include "resoct/io/formats/nrrd.hpp"

namespace resoct {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

/// Splits on blanks, keeping "(...)" groups of space vectors together.
std::vector<std::string_view> tokens(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
    if (i >= s.size()) break;
    const std::size_t start = i;
    int depth = 0;
    while (i < s.size() && (depth > 0 || (s[i] != ' ' && s[i] != '\t'))) {
      if (s[i] == '(') ++depth;
      if (s[i] == ')') --depth;
      ++i;
    }
    out.push_back(s.substr(start, i - start));
  }
  return out;
}

struct Line {
  std::string_view field;
  std::string_view value;
  std::uint64_t offset;
};

class Parser {
 public:
  explicit Parser(std::string_view location) : location_(location) {}

  [[noreturn]] void fail(ErrorCode code, const Line& l, const std::string& why) const {
    throw file_error(code, location_, l.offset,
                     "NRRD field '" + std::string(l.field) + "': " + why);
  }

  std::optional<double> number(std::string_view t) const {
    const std::string s(t);
    if (s == "nan" || s == "NaN" || s == "NAN") return std::nullopt;
    char* end = nullptr;
    const double d = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(d)) return std::nullopt;
    return d;
  }

  std::int64_t integer(const Line& l, std::string_view t) const {
    std::int64_t v = 0;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (r.ec != std::errc() || r.ptr != t.data() + t.size()) {
      fail(ErrorCode::corrupt, l, "expected an integer, got '" + std::string(t) + "'");
    }
    return v;
  }

 private:
  std::string_view location_;
};

DataType parse_type(const Parser& p, const Line& l) {
  // The NRRD format's type names (teem's airEnum) and the value type each denotes.
  static constexpr std::pair<std::string_view, DataType> kNames[] = {
      {"signed char", DataType::i8},
      {"int8", DataType::i8},
      {"int8_t", DataType::i8},
      {"uchar", DataType::u8},
      {"unsigned char", DataType::u8},
      {"uint8", DataType::u8},
      {"uint8_t", DataType::u8},
      {"short", DataType::i16},
      {"short int", DataType::i16},
      {"signed short", DataType::i16},
      {"signed short int", DataType::i16},
      {"int16", DataType::i16},
      {"int16_t", DataType::i16},
      {"ushort", DataType::u16},
      {"unsigned short", DataType::u16},
      {"unsigned short int", DataType::u16},
      {"uint16", DataType::u16},
      {"uint16_t", DataType::u16},
      {"int", DataType::i32},
      {"signed int", DataType::i32},
      {"int32", DataType::i32},
      {"int32_t", DataType::i32},
      {"uint", DataType::u32},
      {"unsigned int", DataType::u32},
      {"uint32", DataType::u32},
      {"uint32_t", DataType::u32},
      {"float", DataType::f32},
      {"double", DataType::f64},
  };
  for (const auto& [name, type] : kNames) {
    if (l.value == name) return type;
  }
  p.fail(ErrorCode::unsupported, l,
         "type '" + std::string(l.value) +
             "' is not supported (int8, uint8, int16, uint16, int32, uint32, float, double are)");
}

/// "(x,y,z)" (1..3 numbers; missing components 0) as a vector.
glm::dvec3 vector3(const Parser& p, const Line& l, std::string_view text) {
  if (text.size() < 2 || text.front() != '(' || text.back() != ')') {
    p.fail(ErrorCode::corrupt, l, "expected (x,y,z)");
  }
  std::string_view inner = text.substr(1, text.size() - 2);
  glm::dvec3 out(0.0);
  int n = 0;
  while (true) {
    const std::size_t comma = inner.find(',');
    const auto c = p.number(trim(inner.substr(0, comma)));
    if (!c) p.fail(ErrorCode::corrupt, l, "vector components must be numbers");
    if (n >= 3) p.fail(ErrorCode::corrupt, l, "vectors have 1..3 components");
    out[n++] = *c;
    if (comma == std::string_view::npos) break;
    inner = inner.substr(comma + 1);
  }
  return out;
}

bool domain_kind(std::string_view k) {
  return k == "domain" || k == "space" || k == "time" || k == "???" || k == "none";
}

}  // namespace

glm::u64vec3 NrrdHeader::extent() const noexcept {
  glm::u64vec3 e(1);
  int a = 0;
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    if (int(i) == channel_axis) continue;
    if (a < 3) e[a++] = sizes[i];
  }
  return e;
}

std::uint32_t NrrdHeader::channels() const noexcept {
  return channel_axis < 0 ? 1u : std::uint32_t(sizes[std::size_t(channel_axis)]);
}

std::size_t NrrdHeader::stored_voxel_bytes() const noexcept {
  return data_size(type);
}

std::uint64_t NrrdHeader::data_bytes() const {
  std::uint64_t n = stored_voxel_bytes();
  for (std::uint64_t s : sizes) {
    if (n > ~std::uint64_t(0) / s) throw Error(ErrorCode::overflow, "NRRD data size overflows");
    n *= s;
  }
  return n;
}

NrrdHeader parse_nrrd_header(std::string_view text, std::string_view location) {
  if (!text.starts_with("NRRD000") || text.size() < 8 || text[7] < '1' || text[7] > '5') {
    throw file_error(ErrorCode::bad_magic, location, 0, "not an NRRD file (no NRRD000x magic)");
  }
  const Parser p(location);
  std::vector<Line> lines;
  std::size_t pos = text.find('\n');
  NrrdHeader h;
  h.header_bytes = text.size();
  while (pos != std::string_view::npos && pos + 1 <= text.size()) {
    const std::size_t start = pos + 1;
    std::size_t end = text.find('\n', start);
    const bool last = end == std::string_view::npos;
    if (last) end = text.size();
    const std::string_view raw = text.substr(start, end - start);
    const std::string_view line = trim(raw);
    if (raw.empty() || raw == "\r") {
      if (!last) h.header_bytes = end + 1;
      break;
    }
    pos = last ? std::string_view::npos : end;
    if (line.empty() || line.front() == '#') continue;
    const std::size_t kv = line.find(":=");
    const std::size_t colon = line.find(": ");
    if (kv != std::string_view::npos && (colon == std::string_view::npos || kv < colon)) continue;
    if (colon == std::string_view::npos) {
      throw file_error(ErrorCode::corrupt, location, start,
                       "NRRD header line without 'field: value': '" + std::string(line) + "'");
    }
    lines.push_back({line.substr(0, colon), trim(line.substr(colon + 2)), start});
  }

  const Line* type = nullptr;
  const Line* dimension = nullptr;
  const Line* sizes = nullptr;
  const Line* encoding = nullptr;
  const Line* spacings = nullptr;
  const Line* directions = nullptr;
  const Line* origin = nullptr;
  const Line* space = nullptr;
  const Line* kinds = nullptr;
  for (const Line& l : lines) {
    const std::string_view f = l.field;
    if (f == "type") {
      type = &l;
    } else if (f == "dimension") {
      dimension = &l;
    } else if (f == "sizes") {
      sizes = &l;
    } else if (f == "encoding") {
      encoding = &l;
    } else if (f == "spacings") {
      spacings = &l;
    } else if (f == "space directions") {
      directions = &l;
    } else if (f == "space origin") {
      origin = &l;
    } else if (f == "space") {
      space = &l;
    } else if (f == "kinds") {
      kinds = &l;
    } else if (f == "endian") {
      if (l.value == "little") {
        h.endian = Endian::little;
      } else if (l.value == "big") {
        h.endian = Endian::big;
      } else {
        p.fail(ErrorCode::corrupt, l, "expected little or big, got '" + std::string(l.value) + "'");
      }
    } else if (f == "data file" || f == "datafile") {
      if (l.value.starts_with("LIST") || l.value.find('%') != std::string_view::npos ||
          tokens(l.value).size() != 1) {
        p.fail(ErrorCode::unsupported, l, "only a single detached data file is supported");
      }
      h.data_file = std::string(l.value);
    } else if (f == "byte skip" || f == "byteskip") {
      h.byte_skip = p.integer(l, l.value);
      if (h.byte_skip < -1) p.fail(ErrorCode::corrupt, l, "must be >= -1");
    } else if (f == "line skip" || f == "lineskip") {
      const std::int64_t v = p.integer(l, l.value);
      if (v < 0) p.fail(ErrorCode::corrupt, l, "must be >= 0");
      h.line_skip = std::uint64_t(v);
    }
  }
  for (auto [ptr, name] : {std::pair{type, "type"}, std::pair{dimension, "dimension"},
                           std::pair{sizes, "sizes"}, std::pair{encoding, "encoding"}}) {
    if (ptr == nullptr) {
      throw file_error(ErrorCode::corrupt, location, 0,
                       "NRRD field '" + std::string(name) + "' is missing");
    }
  }
  h.type = parse_type(p, *type);
  const std::int64_t d = p.integer(*dimension, dimension->value);
  if (d < 1 || d > 16) p.fail(ErrorCode::corrupt, *dimension, "must be 1..16");
  if (d > 4) p.fail(ErrorCode::unsupported, *dimension, "at most 4 axes are supported");
  const auto dim = std::size_t(d);
  const auto size_tokens = tokens(sizes->value);
  if (size_tokens.size() != dim) {
    p.fail(ErrorCode::corrupt, *sizes, "expected " + std::to_string(dim) + " sizes");
  }
  for (std::string_view t : size_tokens) {
    const std::int64_t s = p.integer(*sizes, t);
    if (s < 1) p.fail(ErrorCode::corrupt, *sizes, "sizes must be >= 1");
    h.sizes.push_back(std::uint64_t(s));
  }
  if (encoding->value == "raw") {
    h.gzip = false;
  } else if (encoding->value == "gzip" || encoding->value == "gz") {
    h.gzip = true;
  } else {
    p.fail(ErrorCode::unsupported, *encoding,
           "encoding '" + std::string(encoding->value) + "' is not supported (raw, gzip are)");
  }
  if (h.byte_skip == -1 && h.gzip) {
    throw file_error(ErrorCode::corrupt, location, 0,
                     "NRRD field 'byte skip': -1 is only defined for raw encoding");
  }

  // Which axes are not spatial: kinds first, else "none" space directions.
  std::vector<bool> non_spatial(dim, false);
  if (kinds != nullptr) {
    const auto k = tokens(kinds->value);
    if (k.size() != dim) p.fail(ErrorCode::corrupt, *kinds, "expected " + std::to_string(dim));
    for (std::size_t i = 0; i < dim; ++i) non_spatial[i] = !domain_kind(k[i]);
  }
  std::vector<std::optional<double>> lengths(dim);
  std::vector<glm::dvec3> steps(dim, glm::dvec3(0.0));
  if (directions != nullptr) {
    const auto v = tokens(directions->value);
    if (v.size() != dim) {
      p.fail(ErrorCode::corrupt, *directions, "expected " + std::to_string(dim) + " entries");
    }
    for (std::size_t i = 0; i < dim; ++i) {
      if (v[i] == "none") {
        non_spatial[i] = true;
        continue;
      }
      if (v[i].size() < 2 || v[i].front() != '(' || v[i].back() != ')') {
        p.fail(ErrorCode::corrupt, *directions, "expected (x,y,z) or none");
      }
      steps[i] = vector3(p, *directions, v[i]);
      lengths[i] =
          std::sqrt(steps[i].x * steps[i].x + steps[i].y * steps[i].y + steps[i].z * steps[i].z);
    }
  }
  if (dim == 4) {
    if (non_spatial[0]) {
      h.channel_axis = 0;
    } else {
      h.channel_axis = 3;
    }
    if (h.sizes[std::size_t(h.channel_axis)] > 256) {
      p.fail(ErrorCode::unsupported, *sizes, "a channel axis holds at most 256 channels");
    }
  } else {
    for (std::size_t i = 0; i < dim; ++i) {
      if (non_spatial[i] && h.sizes[i] != 1 && dim > 1) {
        p.fail(ErrorCode::unsupported, kinds != nullptr ? *kinds : *directions,
               "a non-spatial axis is only supported as the first or last of 4 axes");
      }
    }
  }
  std::vector<std::optional<double>> spacing(dim);
  if (spacings != nullptr) {
    const auto v = tokens(spacings->value);
    if (v.size() != dim) {
      p.fail(ErrorCode::corrupt, *spacings, "expected " + std::to_string(dim) + " spacings");
    }
    for (std::size_t i = 0; i < dim; ++i) {
      spacing[i] = p.number(v[i]);
      if (spacing[i] && *spacing[i] <= 0.0) spacing[i] = std::fabs(*spacing[i]);
    }
  }
  int a = 0;
  for (std::size_t i = 0; i < dim && a < 3; ++i) {
    if (int(i) == h.channel_axis) continue;
    double s = 1.0;
    if (spacing[i] && *spacing[i] > 0.0) {
      s = *spacing[i];
    } else if (lengths[i] && *lengths[i] > 0.0 && std::isfinite(*lengths[i])) {
      s = *lengths[i];
    }
    h.spacing[a++] = s;
  }
  // World placement: the spatial axes' steps as columns, in a right-anterior-superior world.
  if (directions != nullptr) {
    glm::dvec3 sign(1.0);
    if (space != nullptr) {
      const std::string_view s = space->value;
      if (s == "left-posterior-superior" || s == "LPS" || s == "left-posterior-superior-time") {
        sign = {-1.0, -1.0, 1.0};
      } else if (s == "left-anterior-superior" || s == "LAS" ||
                 s == "left-anterior-superior-time") {
        sign = {-1.0, 1.0, 1.0};
      }
    }
    glm::dmat3 axes(1.0);
    int column = 0;
    for (std::size_t i = 0; i < dim && column < 3; ++i) {
      if (int(i) == h.channel_axis) continue;
      axes[column++] = steps[i] * sign;
    }
    h.world_axes = axes;
    if (origin != nullptr) h.world_origin = vector3(p, *origin, trim(origin->value)) * sign;
  }
  try {
    (void)h.data_bytes();
  } catch (const Error&) {
    p.fail(ErrorCode::overflow, *sizes, "data size overflows 64 bits");
  }
  return h;
}

}  // namespace resoct
