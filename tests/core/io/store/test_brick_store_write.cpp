// The store writer's failure behaviour (nothing half-written is ever visible at the target path)
// and the atomic file writer / positional reader underneath it.

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <stdexcept>

#include <unistd.h>

#include "resoct/io/store/brick_store.hpp"
#include "resoct/base/file_io.hpp"
#include "support/expect_error.hpp"
#include "support/function_source.hpp"
#include "core/io/store/test_brick_store_util.hpp"

using namespace resoct;
using resoct::test::FunctionSource;
using resoct::test::TempDir;

namespace {

VolumeDesc small_volume() {
  VolumeDesc v;
  v.extent = {40, 33, 17};
  v.channels = 2;
  v.type = VoxelType::u8;
  return v;
}

double value(std::uint32_t c, const glm::u64vec3& p) {
  return test::test_value(VoxelType::u8, c, p, {40, 33, 17});
}

// Fails on the n-th brick read, as a broken input file would.
class FailingSource : public FunctionSource {
 public:
  FailingSource(int fail_at, bool resoct_error)
      : FunctionSource(small_volume(), BrickLayout{glm::uvec3(8), 1}, value),
        fail_at_(fail_at),
        resoct_error_(resoct_error) {}
  void read_brick(BrickKey key, std::span<std::byte> out) const override {
    if (reads_.fetch_add(1) == fail_at_) {
      if (resoct_error_) throw Error(ErrorCode::corrupt, "input.raw: offset 12: broken input");
      throw std::runtime_error("disk on fire");
    }
    FunctionSource::read_brick(key, out);
  }

 private:
  int fail_at_;
  bool resoct_error_;
  mutable std::atomic<int> reads_{0};
};

TEST(BrickStoreWrite, SourceFailureMidWriteLeavesNothingBehind) {
  TempDir dir;
  const std::string path = dir.file("out.rbs");
  for (const std::uint32_t threads : {1u, 4u}) {
    StoreWriteOptions opt;
    opt.threads = threads;
    const FailingSource err(40, true);
    EXPECT_RESOCT_ERROR(write_brick_store(err, path, opt), ErrorCode::corrupt, "broken input");
    EXPECT_TRUE(dir.entries().empty());
    const FailingSource other(0, false);
    EXPECT_THROW(write_brick_store(other, path, opt), std::runtime_error);
    EXPECT_TRUE(dir.entries().empty());
  }
}

TEST(BrickStoreWrite, FailedRewriteKeepsThePreviousFile) {
  TempDir dir;
  const std::string path = dir.file("out.rbs");
  const FunctionSource good(small_volume(), BrickLayout{glm::uvec3(8), 1}, value);
  write_brick_store(good, path, StoreWriteOptions{});
  const std::vector<std::uint8_t> before = test::read_bytes(path);
  const FailingSource bad(100, true);
  EXPECT_RESOCT_ERROR(write_brick_store(bad, path, StoreWriteOptions{}), ErrorCode::corrupt,
                      "broken input");
  EXPECT_EQ(test::read_bytes(path), before);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.rbs"});
  EXPECT_NO_THROW(BrickStoreSource{path});
}

TEST(BrickStoreWrite, UnwritableDestinationIsAnIoErrorAndLeavesNoFile) {
  TempDir dir;
  const FunctionSource src(small_volume(), BrickLayout{glm::uvec3(8), 1}, value);
  const std::string missing = dir.file("no/such/dir/out.rbs");
  EXPECT_RESOCT_ERROR(write_brick_store(src, missing, StoreWriteOptions{}), ErrorCode::io, missing);
  EXPECT_TRUE(dir.entries().empty());
  if (::geteuid() != 0) {  // root ignores directory permissions
    const std::filesystem::path ro = dir.path() / "ro";
    std::filesystem::create_directory(ro);
    std::filesystem::permissions(
        ro, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    const std::string path = (ro / "out.rbs").string();
    EXPECT_RESOCT_ERROR(write_brick_store(src, path, StoreWriteOptions{}), ErrorCode::io, path);
    std::filesystem::permissions(ro, std::filesystem::perms::owner_all);
    EXPECT_TRUE(std::filesystem::is_empty(ro));
  }
}

TEST(BrickStoreWrite, BadOptionsAreRejectedBeforeAnythingIsWritten) {
  TempDir dir;
  const FunctionSource src(small_volume(), BrickLayout{glm::uvec3(8), 1}, value);
  const std::string path = dir.file("out.rbs");
  StoreWriteOptions opt;
  opt.metadata_block = 12;
  EXPECT_RESOCT_ERROR(write_brick_store(src, path, opt), ErrorCode::invalid_argument,
                      "metadata_block");
  opt = StoreWriteOptions{Codec::zstd, 99};
  EXPECT_RESOCT_ERROR(write_brick_store(src, path, opt), ErrorCode::invalid_argument, "level");
  opt = StoreWriteOptions{Codec::lz4, 13};
  EXPECT_RESOCT_ERROR(write_brick_store(src, path, opt), ErrorCode::invalid_argument, "level");
  EXPECT_TRUE(dir.entries().empty());
}

std::span<const std::byte> as_bytes(const std::string& s) {
  return std::as_bytes(std::span<const char>(s.data(), s.size()));
}

TEST(AtomicFileWriter, AppearsOnlyOnCommitAndPatchesInPlace) {
  TempDir dir;
  const std::string path = dir.file("f.bin");
  {
    AtomicFileWriter w(path);
    w.append(as_bytes("hello "));
    w.append(as_bytes("world"));
    EXPECT_EQ(w.position(), 11u);
    w.write_at(0, as_bytes("J"));
    EXPECT_FALSE(std::filesystem::exists(path));
    EXPECT_TRUE(std::filesystem::exists(w.temp_path()));
    EXPECT_EQ(std::filesystem::path(w.temp_path()).parent_path(), dir.path());
    EXPECT_RESOCT_ERROR(w.write_at(8, as_bytes("xyzw")), ErrorCode::invalid_argument, "offset");
    w.commit();
  }
  const std::vector<std::uint8_t> got = test::read_bytes(path);
  EXPECT_EQ(std::string(got.begin(), got.end()), "Jello world");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"f.bin"});
  {
    AtomicFileWriter w(dir.file("g.bin"));
    std::vector<std::byte> big((3u << 20) + 5, std::byte{1});  // larger than the write buffer
    w.append(big);
  }  // abandoned: removed
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"f.bin"});
}

TEST(ReadFile, PositionalReadsAndTheirErrors) {
  TempDir dir;
  const std::string path = dir.file("r.bin");
  test::write_bytes(path, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10});
  const ReadFile f(path);
  EXPECT_EQ(f.size(), 10u);
  std::vector<std::byte> out(3);
  f.read_at(7, out);
  EXPECT_EQ(out, (std::vector<std::byte>{std::byte{8}, std::byte{9}, std::byte{10}}));
  EXPECT_RESOCT_ERROR(f.read_at(8, out), ErrorCode::truncated, path + ": offset 10");
  EXPECT_RESOCT_ERROR(ReadFile{dir.file("none")}, ErrorCode::io, dir.file("none"));
  EXPECT_RESOCT_ERROR(ReadFile{dir.path().string()}, ErrorCode::io, "not a regular file");
}

}  // namespace
