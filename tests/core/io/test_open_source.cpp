#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/base/error.hpp"
#include "resoct/io/open_source.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "support/expect_error.hpp"
#include "support/brick_compare.hpp"
#include "core/io/store/test_brick_store_util.hpp"

using namespace resoct;
using resoct::test::expect_same_bricks;
using resoct::test::TempDir;

namespace {

BrickLayout small_layout(std::uint32_t b) {
  BrickLayout l;
  l.brick_size = glm::uvec3(b);
  return l;
}

TEST(OpenSource, ProceduralSpecUsesTheLayout) {
  const auto src = open_source("procedural:sphere:24x20x16:2", small_layout(8));
  ASSERT_NE(dynamic_cast<const ProceduralSource*>(src.get()), nullptr);
  EXPECT_EQ(src->volume().extent, glm::u64vec3(24, 20, 16));
  EXPECT_EQ(src->volume().channels, 2u);
  EXPECT_EQ(src->hierarchy().layout(), small_layout(8));
  const ProceduralSource direct("procedural:sphere:24x20x16:2", small_layout(8));
  expect_same_bricks(*src, direct);
}

TEST(OpenSource, StoreIsDetectedByMagicAndKeepsItsLayout) {
  TempDir dir;
  const ProceduralSource proc("procedural:tubes:40x24x20", small_layout(8));
  // A misleading extension: detection must not depend on ".rbs".
  const std::string path = dir.file("volume.txt");
  write_brick_store(proc, path);
  const auto src = open_source(path, small_layout(16));
  const auto* store = dynamic_cast<const BrickStoreSource*>(src.get());
  ASSERT_NE(store, nullptr);
  EXPECT_EQ(src->name(), path);
  EXPECT_EQ(src->hierarchy().layout(), small_layout(8));  // the store's, not the argument's
  expect_same_bricks(*src, proc);
}

TEST(OpenSource, NonexistentPathIsAnIoErrorListingTheForms) {
  TempDir dir;
  const std::string missing = dir.file("missing.rbs");
  EXPECT_RESOCT_ERROR(open_source(missing), ErrorCode::io, missing);
  EXPECT_RESOCT_ERROR(open_source(missing), ErrorCode::io, "procedural:NAME");
  // A directory is a source only when it is an OME-Zarr image or holds TIFF files.
  EXPECT_RESOCT_ERROR(open_source(dir.path().string()), ErrorCode::invalid_argument,
                      "neither an OME-Zarr image");
}

TEST(OpenSource, FileThatIsNotAStoreIsNamed) {
  TempDir dir;
  const std::string text = dir.file("notes.rbs");
  const std::string content = "this is a text file, not a brick store\n";
  resoct::test::write_bytes(text, std::vector<std::uint8_t>(content.begin(), content.end()));
  EXPECT_RESOCT_ERROR(open_source(text), ErrorCode::invalid_argument, text);
  EXPECT_RESOCT_ERROR(open_source(text), ErrorCode::invalid_argument, "not a resoct brick store");
  const std::string tiny = dir.file("tiny");
  resoct::test::write_bytes(tiny, {0x89, 'R', 'B'});  // a prefix of the magic only
  EXPECT_RESOCT_ERROR(open_source(tiny), ErrorCode::invalid_argument, tiny);
}

TEST(OpenSource, DamagedStoreReportsTheReadersError) {
  TempDir dir;
  const ProceduralSource proc("procedural:ramp:16x16x16", small_layout(8));
  const std::string path = dir.file("damaged.rbs");
  write_brick_store(proc, path);
  std::vector<std::uint8_t> bytes = resoct::test::read_bytes(path);
  bytes.resize(bytes.size() / 2);
  resoct::test::write_bytes(path, bytes);
  try {
    open_source(path);
    FAIL() << "a truncated store opened";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(OpenSource, BadSpecs) {
  EXPECT_RESOCT_ERROR(open_source(""), ErrorCode::invalid_argument, "procedural:NAME");
  EXPECT_RESOCT_ERROR(open_source("procedural:nosuchthing"), ErrorCode::invalid_argument, "spec");
  EXPECT_RESOCT_ERROR(open_source("procedural:tubes:0x4x4"), ErrorCode::invalid_argument, "spec");
}

}  // namespace
