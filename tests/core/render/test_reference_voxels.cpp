// Level 0 of a source materialized for the dense reference (reference_voxels.hpp): every voxel
// equals what the procedural generator computes for it, also where bricks are partial at the far
// faces; the memory limit and channel errors name their parameter; and render_reference gives the
// same image on any number of threads.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "resoct/render/reference_renderer.hpp"
#include "resoct/render/reference_voxels.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "support/expect_error.hpp"

using namespace resoct;

namespace {

template <typename T>
double value_at(const std::vector<std::byte>& bytes, std::size_t i) {
  T v;
  std::memcpy(&v, bytes.data() + i * sizeof(T), sizeof(T));
  return double(v);
}

}  // namespace

TEST(ReferenceVoxels, Level0EqualsTheGeneratorsVoxels) {
  // 37 x 21 x 50 with 16^3 bricks: partial bricks on every far face; two of the 16 channels of
  // cells.
  for (const char* spec : {"procedural:tubes:37x21x50", "procedural:cells:37x21x50:16"}) {
    const ProceduralSource src(spec);
    const VolumeDesc& v = src.volume();
    const std::vector<std::uint32_t> channels =
        v.channels > 1 ? std::vector<std::uint32_t>{9, 0} : std::vector<std::uint32_t>{0};
    std::uint64_t calls = 0, total = 0;
    const reference::VoxelFunction f =
        reference::level0_voxels(src, channels, std::uint64_t(1) << 30, "reference-mb",
                                 [&](std::uint64_t done, std::uint64_t all) {
                                   ++calls;
                                   EXPECT_EQ(done, calls);
                                   total = all;
                                 });
    EXPECT_EQ(calls, total);
    EXPECT_EQ(total, src.hierarchy().level(0).brick_count * channels.size());
    const Box3 all{glm::i64vec3(0), glm::i64vec3(v.extent)};
    for (const std::uint32_t c : channels) {
      std::vector<std::byte> bytes(std::size_t(v.voxel_count()) * voxel_size(v.type));
      src.read_region(0, c, all, bytes);
      std::size_t i = 0;
      for (std::int64_t z = 0; z < std::int64_t(v.extent.z); ++z)
        for (std::int64_t y = 0; y < std::int64_t(v.extent.y); ++y)
          for (std::int64_t x = 0; x < std::int64_t(v.extent.x); ++x, ++i) {
            const double expected = v.type == VoxelType::u8    ? value_at<std::uint8_t>(bytes, i)
                                    : v.type == VoxelType::u16 ? value_at<std::uint16_t>(bytes, i)
                                                               : value_at<float>(bytes, i);
            ASSERT_EQ(f(c, {x, y, z}), expected)
                << spec << " channel " << c << " at " << x << "," << y << "," << z;
          }
    }
    if (v.channels > 1) {
      EXPECT_RESOCT_ERROR(f(1, {0, 0, 0}), ErrorCode::out_of_range, "channel 1");
    }
  }
}

TEST(ReferenceVoxels, LimitsAndChannelsNameTheParameter) {
  const ProceduralSource src("procedural:tubes:32x32x32");
  const std::vector<std::uint32_t> one{0};
  // 32^3 voxels x 4 bytes = 128 KiB.
  EXPECT_RESOCT_ERROR(reference::level0_voxels(src, one, 100 << 10, "reference-mb"),
                      ErrorCode::invalid_argument, "reference-mb");
  EXPECT_NO_THROW(reference::level0_voxels(src, one, 128 << 10, "reference-mb"));
  const std::vector<std::uint32_t> bad{1};
  EXPECT_RESOCT_ERROR(reference::level0_voxels(src, bad, 1 << 30, "reference-mb"),
                      ErrorCode::invalid_argument, "channel 1");
}

TEST(ReferenceVoxels, ReferenceImageDoesNotDependOnThreads) {
  const ProceduralSource src("procedural:tubes:24x24x24");
  const std::vector<std::uint32_t> one{0};
  const reference::VoxelFunction f = reference::level0_voxels(src, one, 1 << 30, "reference-mb");
  Scene scene;
  scene.camera.eye = {1.4, 1.1, 1.6};
  scene.camera.target = {0.5, 0.5, 0.5};
  scene.viewport = {19, 13};
  ChannelSettings c;
  c.channel = 0;
  c.tf = TransferFunction({{0.0, {1, 1, 1, 0}}, {0.3, {1, 0.5, 0.2, 0.4}}, {1.0, {1, 1, 1, 0.9}}});
  scene.channels.push_back(c);
  reference::ReferenceOptions o;
  o.step = 0.25;
  const Image one_thread = reference::render_reference(scene, src.volume(), f, o);
  for (const std::uint32_t t : {3u, 0u, 40u}) {
    o.threads = t;
    const Image many = reference::render_reference(scene, src.volume(), f, o);
    ASSERT_EQ(many.pixels().size(), one_thread.pixels().size());
    for (std::size_t i = 0; i < many.pixels().size(); ++i) {
      ASSERT_EQ(many.pixels()[i], one_thread.pixels()[i]) << "threads " << t << " pixel " << i;
    }
  }
  double alpha = 0.0;
  for (const glm::vec4& p : one_thread.pixels()) alpha += p.a;
  EXPECT_GT(alpha, 0.0);  // the view shows something
}
