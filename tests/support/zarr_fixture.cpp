#include "support/zarr_fixture.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "resoct/dense_volume.hpp"
#include "support/tool_process.hpp"

namespace resoct::test {

std::vector<std::byte> fixture_values(const std::string& dir, const nlohmann::json& c,
                                      std::uint64_t t, std::uint64_t channel) {
  const std::string axes = c["axes"];
  const auto shape = c["shape"].get<std::vector<std::uint64_t>>();
  const std::string dtype = c["dtype"];
  const std::size_t vs = std::size_t(dtype[2] - '0');  // "<u2" -> 2, "|i1" -> 1, "<f8" -> 8
  const std::string raw = slurp(dir + "/" + std::string(c["name"]) + ".raw");
  std::uint64_t total = 1;
  for (auto s : shape) total *= s;
  EXPECT_EQ(raw.size(), total * vs);
  // C-order strides of the full array.
  std::vector<std::uint64_t> stride(shape.size(), 1);
  for (std::size_t i = shape.size() - 1; i > 0; --i) stride[i - 1] = stride[i] * shape[i];
  auto dim = [&](char a) -> std::int64_t {
    const auto p = axes.find(a);
    return p == std::string::npos ? -1 : std::int64_t(p);
  };
  auto extent = [&](char a) { return dim(a) < 0 ? 1 : shape[std::size_t(dim(a))]; };
  auto step = [&](char a) { return dim(a) < 0 ? 0 : stride[std::size_t(dim(a))]; };
  const std::uint64_t base = t * step('t') + channel * step('c');
  std::vector<std::byte> out;
  for (std::uint64_t z = 0; z < extent('z'); ++z)
    for (std::uint64_t y = 0; y < extent('y'); ++y)
      for (std::uint64_t x = 0; x < extent('x'); ++x) {
        const std::uint64_t i = base + z * step('z') + y * step('y') + x * step('x');
        for (std::size_t b = 0; b < vs; ++b) out.push_back(std::byte(raw[i * vs + b]));
      }
  return out;
}

std::vector<std::byte> fixture_voxels(const std::string& dir, const nlohmann::json& c,
                                      std::uint64_t t, std::uint64_t channel) {
  const std::string dtype = std::string(c["dtype"]).substr(1);
  std::vector<std::byte> raw = fixture_values(dir, c, t, channel);
  if (dtype == "u1" || dtype == "u2" || dtype == "f4") return raw;
  const std::size_t vs = std::size_t(dtype[1] - '0');
  std::vector<std::byte> out;
  for (std::size_t i = 0; i + vs <= raw.size(); i += vs) {
    auto put = [&](auto v) {
      const auto* p = reinterpret_cast<const std::byte*>(&v);
      out.insert(out.end(), p, p + sizeof v);
    };
    auto get = [&](auto v) {
      std::memcpy(&v, raw.data() + i, sizeof v);
      return v;
    };
    if (dtype == "i1") put(std::uint8_t(int(get(std::int8_t())) + 128));
    if (dtype == "i2") put(std::uint16_t(int(get(std::int16_t())) + 32768));
    if (dtype == "i4") put(float(get(std::int32_t())));
    if (dtype == "u4") put(float(get(std::uint32_t())));
    if (dtype == "f8") put(float(get(double())));
  }
  return out;
}

InMemorySource fixture_reference(const std::string& dir, const nlohmann::json& c,
                                 const BrickSource& zarr, std::uint64_t t,
                                 const BrickLayout& layout) {
  std::vector<std::byte> all;
  for (std::uint32_t ch = 0; ch < zarr.volume().channels; ++ch) {
    const auto v = fixture_voxels(dir, c, t, ch);
    all.insert(all.end(), v.begin(), v.end());
  }
  return InMemorySource(DenseVolume::from_bytes(zarr.volume(), std::move(all)), layout, 16, "ref");
}

}  // namespace resoct::test
