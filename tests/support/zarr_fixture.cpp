#include "support/zarr_fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "resoct/volume/dense_volume.hpp"
#include "resoct/io/formats/ome_zarr.hpp"
#include "support/brick_compare.hpp"
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

void expect_series_of_fixture(const std::string& dir, const nlohmann::json& c,
                              const BrickLayout& layout) {
  const std::string name = c["name"];
  const std::string axes = c["axes"];
  const std::uint64_t times = c["shape"][axes.find('t')];
  OmeZarrOptions o;
  o.pyramid.threads = 1;
  const std::shared_ptr<const BrickSource> first =
      open_ome_zarr(dir + "/" + name + ".zarr", layout, o);
  ASSERT_EQ(first->timepoints(), times);
  EXPECT_EQ(first->timepoint(), 0u);
  for (std::uint32_t t = 0; t < times; ++t) {
    const auto at = source_at_timepoint(first, t);
    EXPECT_EQ(at->timepoint(), t);
    EXPECT_EQ(at->hierarchy(), first->hierarchy());  // value ranges kept for the series
    const InMemorySource ref = fixture_reference(dir, c, *at, t, layout);
    expect_same_bricks(ref, *at);
    const Box3 all{glm::i64vec3(0), glm::i64vec3(at->volume().extent)};
    for (std::uint32_t ch = 0; ch < at->volume().channels; ++ch) {
      const RegionMeta want = ref.region_meta(ch, all), got = at->region_meta(ch, all);
      EXPECT_LE(got.min, want.min) << "t " << t << " c " << ch;
      EXPECT_GE(got.max, want.max) << "t " << t << " c " << ch;
      EXPECT_EQ(got.occupancy & want.occupancy, want.occupancy) << "t " << t << " c " << ch;
      // Eager metadata of this timepoint, not of timepoint 0: exact extremes.
      if (!std::isnan(want.min)) {
        EXPECT_EQ(got.min, want.min) << "t " << t << " c " << ch;
        EXPECT_EQ(got.max, want.max) << "t " << t << " c " << ch;
      }
    }
  }
}

}  // namespace resoct::test
