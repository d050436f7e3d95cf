#include "resoct/io/formats/raw_volume.hpp"

#include <bit>
#include <cerrno>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <utility>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/formats/samples.hpp"
#include "resoct/base/error.hpp"

namespace resoct {

std::string_view to_string(Endian e) noexcept {
  return e == Endian::little ? "little" : "big";
}

std::optional<Endian> parse_endian(std::string_view s) noexcept {
  if (s == "little" || s == "le") return Endian::little;
  if (s == "big" || s == "be") return Endian::big;
  return std::nullopt;
}

namespace {

constexpr Endian host_endian() noexcept {
  return std::endian::native == std::endian::big ? Endian::big : Endian::little;
}

/// Closes a descriptor on every path out of open_raw_volume.
class FdGuard {
 public:
  explicit FdGuard(int fd) noexcept : fd_(fd) {}
  ~FdGuard() {
    if (fd_ >= 0) ::close(fd_);
  }
  FdGuard(const FdGuard&) = delete;
  FdGuard& operator=(const FdGuard&) = delete;
  int get() const noexcept { return fd_; }

 private:
  int fd_;
};

/// A read-only mapping, unmapped when the last DenseVolume copy referring to it is destroyed.
struct Mapping {
  void* base = MAP_FAILED;
  std::size_t length = 0;
  Mapping() = default;
  Mapping(const Mapping&) = delete;
  Mapping& operator=(const Mapping&) = delete;
  ~Mapping() {
    if (base != MAP_FAILED) ::munmap(base, length);
  }
};

std::string describe(const RawVolumeOptions& o) {
  return std::to_string(o.channels) + " channel(s) of " + std::to_string(o.extent.x) + "x" +
         std::to_string(o.extent.y) + "x" + std::to_string(o.extent.z) + " " +
         std::string(o.data_type ? to_string(*o.data_type) : to_string(o.type));
}

void swap_bytes(std::byte* data, std::size_t bytes, std::size_t width) {
  for (std::size_t i = 0; i + width <= bytes; i += width) {
    for (std::size_t a = 0, b = width - 1; a < b; ++a, --b) std::swap(data[i + a], data[i + b]);
  }
}

}  // namespace

DenseVolume open_raw_volume(const std::string& path, const RawVolumeOptions& options) {
  VolumeDesc desc;
  desc.extent = options.extent;
  desc.spacing = options.spacing;
  desc.origin = options.origin;
  desc.channels = options.channels;
  desc.type = options.type;
  desc.ranges = options.ranges;
  const DataType file_type = options.data_type.value_or(data_type_of(options.type));
  desc.type = data_mapping(file_type).stored;
  if (data_type_of(desc.type) != file_type) {
    desc.data_type = file_type;
    for (ValueRange& r : desc.ranges) r = {r.lo + desc.value_offset(), r.hi + desc.value_offset()};
  }
  // Names the offending parameter (extent.x, channels, ...) prefixed by the path, and rejects
  // byte counts beyond 64 bits before anything is opened.
  desc.validate(path);
  if (options.endian != Endian::little && options.endian != Endian::big) {
    throw Error(ErrorCode::invalid_argument, path + ": parameter 'endian': unknown byte order");
  }
  const std::size_t width = data_size(file_type);
  const std::uint64_t voxel_bytes = desc.voxel_count() * desc.channels * width;
  if (options.offset > std::numeric_limits<std::uint64_t>::max() - voxel_bytes) {
    throw Error(ErrorCode::overflow,
                path + ": parameter 'offset': " + std::to_string(options.offset) + " plus " +
                    std::to_string(voxel_bytes) + " voxel bytes overflows 64 bits");
  }
  const std::uint64_t needed = options.offset + voxel_bytes;
  if (needed > std::numeric_limits<std::size_t>::max() ||
      needed > std::uint64_t(std::numeric_limits<off_t>::max())) {
    throw Error(ErrorCode::overflow, path + ": " + std::to_string(needed) +
                                         " bytes do not fit this platform's address space");
  }

  const FdGuard fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) {
    throw file_error(ErrorCode::io, path, 0,
                     std::string("cannot open for reading: ") + std::strerror(errno));
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) {
    throw file_error(ErrorCode::io, path, 0,
                     std::string("cannot query the size: ") + std::strerror(errno));
  }
  if (!S_ISREG(st.st_mode)) throw file_error(ErrorCode::io, path, 0, "not a regular file");
  const auto file_size = std::uint64_t(st.st_size);
  if (file_size < needed) {
    throw file_error(ErrorCode::truncated, path, file_size,
                     "file is " + std::to_string(file_size) + " bytes, expected at least " +
                         std::to_string(needed) + " (offset " + std::to_string(options.offset) +
                         " + " + std::to_string(voxel_bytes) + " bytes of " + describe(options) +
                         ")");
  }

  // mmap wants a page-aligned file offset: map from the page holding the first voxel.
  const auto page = std::uint64_t(::sysconf(_SC_PAGESIZE));
  const std::uint64_t map_start = options.offset / page * page;
  auto mapping = std::make_shared<Mapping>();
  mapping->length = std::size_t(needed - map_start);
  mapping->base =
      ::mmap(nullptr, mapping->length, PROT_READ, MAP_PRIVATE, fd.get(), off_t(map_start));
  if (mapping->base == MAP_FAILED) {
    throw file_error(ErrorCode::io, path, map_start,
                     std::string("cannot memory-map: ") + std::strerror(errno));
  }
  const std::byte* voxels =
      static_cast<const std::byte*>(mapping->base) + (options.offset - map_start);

  if (desc.data_type) {
    std::vector<std::byte> kept(std::size_t(desc.voxel_count() * desc.channels) *
                                voxel_size(desc.type));
    detail::convert_samples({voxels, std::size_t(voxel_bytes)}, file_type, options.endian, false,
                            1.0, 0.0, kept);
    return DenseVolume::from_bytes(std::move(desc), std::move(kept));
  }
  const bool native = width == 1 || options.endian == host_endian();
  // Odd header sizes would leave multi-byte voxels misaligned; a copy realigns them.
  const bool aligned = options.offset % width == 0;
  if (native && aligned) {
    return DenseVolume::from_pointer(std::move(desc), voxels, std::size_t(voxel_bytes),
                                     std::shared_ptr<const void>(mapping, mapping->base));
  }
  std::vector<std::byte> owned(static_cast<std::size_t>(voxel_bytes));
  std::memcpy(owned.data(), voxels, owned.size());
  if (!native) swap_bytes(owned.data(), owned.size(), width);
  return DenseVolume::from_bytes(std::move(desc), std::move(owned));
}

}  // namespace resoct
