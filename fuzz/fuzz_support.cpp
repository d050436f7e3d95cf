#include "fuzz_support.hpp"

#include <cerrno>
#include <cstring>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

namespace resoct::fuzz {

void exercise_source(const BrickSource& src, std::uint64_t max_bricks) {
  const BrickHierarchy& h = src.hierarchy();
  const VolumeDesc& v = h.volume();
  std::vector<std::byte> buf(std::size_t(h.layout().padded_voxels()) * voxel_size(v.type));
  const Box3 all{glm::i64vec3(0), glm::i64vec3(v.extent)};
  for (std::uint32_t c = 0; c < v.channels && c < 4; ++c) {
    for (std::uint64_t i = 0; i < h.bricks_per_channel() && i < max_bricks; ++i) {
      const BrickKey key = h.key_from_linear(c, i);
      errors_only([&] {
        src.read_brick(key, buf);
        (void)src.brick_meta(key);
      });
    }
    (void)src.region_meta(c, all);
  }
}

ScratchFile::ScratchFile(const char* stem) {
  // Memory-backed /dev/shm when TMPDIR does not say otherwise: the brick store target rewrites
  // the file for every input and runs about 3x faster there than on a disk-backed /tmp.
  const char* env = std::getenv("TMPDIR");
  std::string dir = env != nullptr && *env != '\0' ? env : "/tmp";
  if (env == nullptr && ::access("/dev/shm", W_OK) == 0) dir = "/dev/shm";
  std::string pattern = dir + "/" + stem + "-XXXXXX";
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  fd_ = ::mkstemp(buf.data());
  if (fd_ < 0) fail(std::string("cannot create a scratch file: ") + std::strerror(errno));
  path_ = buf.data();
}

ScratchFile::~ScratchFile() {
  ::close(fd_);
  ::unlink(path_.c_str());
}

void ScratchFile::write(const std::uint8_t* data, std::size_t size) {
  if (::ftruncate(fd_, 0) != 0) fail("ftruncate of the scratch file failed");
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::pwrite(fd_, data + done, size - done, off_t(done));
    if (n <= 0) fail("write of the scratch file failed");
    done += std::size_t(n);
  }
}

}  // namespace resoct::fuzz
