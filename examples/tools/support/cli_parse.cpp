#include "support/cli_parse.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <vector>

#include <CLI/CLI.hpp>

#include "resoct/base/error.hpp"

namespace resoct::tools {

namespace {

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t at = s.find(sep, start);
    parts.push_back(s.substr(start, at == std::string_view::npos ? at : at - start));
    if (at == std::string_view::npos) return parts;
    start = at + 1;
  }
}

template <typename T>
bool parse_number(std::string_view s, T& out) {
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, out);
  return r.ec == std::errc() && r.ptr == end && !s.empty();
}

Error bad(std::string_view option, std::string_view expected, std::string_view got) {
  return invalid_parameter(
      option, "expected " + std::string(expected) + ", got '" + std::string(got) + "'");
}

}  // namespace

glm::u64vec3 parse_dims(std::string_view s, std::string_view option) {
  const auto parts = split(s, 'x');
  glm::u64vec3 d{0};
  if (parts.size() != 3) throw bad(option, "WxHxD (three positive integers)", s);
  for (int i = 0; i < 3; ++i) {
    if (!parse_number(parts[std::size_t(i)], d[i]) || d[i] == 0) {
      throw bad(option, "WxHxD (three positive integers)", s);
    }
  }
  return d;
}

glm::uvec3 parse_brick(std::string_view s, std::string_view option) {
  const auto parts = split(s, 'x');
  if (parts.size() != 1 && parts.size() != 3) throw bad(option, "N or NxNxN", s);
  glm::uvec3 b{0};
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (!parse_number(parts[i], b[int(i)])) throw bad(option, "N or NxNxN", s);
  }
  if (parts.size() == 1) b = glm::uvec3(b.x);
  return b;
}

glm::dvec3 parse_spacing(std::string_view s, std::string_view option) {
  const auto parts = split(s, ',');
  if (parts.size() != 1 && parts.size() != 3) throw bad(option, "X,Y,Z or one value", s);
  glm::dvec3 v{0.0};
  for (std::size_t i = 0; i < parts.size(); ++i) {
    double x = 0.0;
    if (!parse_number(parts[i], x) || !std::isfinite(x) || x <= 0.0) {
      throw bad(option, "positive finite numbers X,Y,Z", s);
    }
    v[int(i)] = x;
  }
  if (parts.size() == 1) v = glm::dvec3(v.x);
  return v;
}

ValueRange parse_range(std::string_view s, std::string_view option) {
  const auto parts = split(s, ',');
  ValueRange r;
  if (parts.size() != 2 || !parse_number(parts[0], r.lo) || !parse_number(parts[1], r.hi) ||
      !std::isfinite(r.lo) || !std::isfinite(r.hi) || !(r.lo < r.hi)) {
    throw bad(option, "LO,HI with finite LO < HI", s);
  }
  return r;
}

std::pair<std::uint32_t, std::uint32_t> parse_index_range(std::string_view s,
                                                          std::string_view option) {
  const auto parts = split(s, ':');
  std::uint32_t first = 0, last = 0;
  if (parts.size() != 2 || !parse_number(parts[0], first) || !parse_number(parts[1], last) ||
      first > last) {
    throw bad(option, "FIRST:LAST with integers FIRST <= LAST", s);
  }
  return {first, last};
}

std::string format_bytes(std::uint64_t bytes) {
  static constexpr const char* kUnits[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB"};
  double v = double(bytes);
  std::size_t u = 0;
  while (v >= 1024.0 && u + 1 < std::size(kUnits)) {
    v /= 1024.0;
    ++u;
  }
  char buf[32];
  if (u == 0) {
    std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
  } else {
    std::snprintf(buf, sizeof buf, "%.*f %s", v < 10.0 ? 2 : 1, v, kUnits[u]);
  }
  return buf;
}

void one_line_usage_errors(CLI::App& app, std::string tool) {
  app.failure_message([tool = std::move(tool)](const CLI::App*, const CLI::Error& e) {
    return tool + ": error [usage]: " + std::string(e.what()) + " (see --help)\n";
  });
}

}  // namespace resoct::tools
