#include "resoct/io/storage/byte_store.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "io/storage/confined_path.hpp"
#include "resoct/base/error.hpp"
#include "resoct/base/file_io.hpp"

namespace resoct {

void check_store_key(std::string_view key) {
  if (key.empty()) throw invalid_parameter("key", "empty store key");
  if (key.front() == '/') {
    throw invalid_parameter("key", "store key '" + std::string(key) + "' is absolute");
  }
  std::size_t start = 0;
  while (start <= key.size()) {
    std::size_t end = key.find('/', start);
    if (end == std::string_view::npos) end = key.size();
    std::string_view part = key.substr(start, end - start);
    if (part.empty() || part == "." || part == "..") {
      throw invalid_parameter(
          "key", "store key '" + std::string(key) + "' has an empty, '.' or '..' component");
    }
    start = end + 1;
  }
}

namespace {

class DirectoryStore final : public ByteStore {
 public:
  explicit DirectoryStore(std::string root) : root_(std::move(root)) {
    while (root_.size() > 1 && root_.back() == '/') root_.pop_back();
    std::error_code ec;
    if (!std::filesystem::is_directory(root_, ec)) {
      throw Error(ErrorCode::io, root_ + ": not a readable directory");
    }
    canonical_root_ = detail::canonical_root(root_);
  }

  std::optional<std::vector<std::byte>> get(std::string_view key,
                                            std::uint64_t max_bytes) const override {
    const std::string path = resolve(key);
    std::error_code ec;
    // A missing object is an answer (zarr: fill value); anything else that stops the read is
    // an error reported by ReadFile with the path.
    if (!std::filesystem::exists(path, ec)) return std::nullopt;
    ReadFile file(path);
    if (file.size() > max_bytes) {
      throw file_error(ErrorCode::out_of_range, path, 0,
                       "object of " + std::to_string(file.size()) + " bytes exceeds the limit of " +
                           std::to_string(max_bytes));
    }
    std::vector<std::byte> bytes(file.size());
    file.read_at(0, bytes);
    return bytes;
  }

  std::vector<std::byte> get_range(std::string_view key, std::uint64_t offset,
                                   std::uint64_t size) const override {
    ReadFile file(resolve(key));
    // Checked before allocating: a corrupt index must not make us allocate what is not there.
    if (offset > file.size() || size > file.size() - offset) {
      throw file_error(ErrorCode::truncated, file.path(), offset,
                       "range of " + std::to_string(size) + " bytes runs past the end (" +
                           std::to_string(file.size()) + " bytes)");
    }
    std::vector<std::byte> bytes(size);
    file.read_at(offset, bytes);
    return bytes;
  }

  std::optional<std::vector<std::byte>> get_range_if_present(std::string_view key,
                                                             std::uint64_t offset,
                                                             std::uint64_t size) const override {
    std::error_code ec;
    if (!std::filesystem::exists(resolve(key), ec)) return std::nullopt;
    return get_range(key, offset, size);
  }

  std::optional<ObjectTail> get_suffix(std::string_view key, std::uint64_t size) const override {
    const std::string path = resolve(key);
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return std::nullopt;
    ReadFile file(path);
    if (size > file.size()) {
      throw file_error(ErrorCode::truncated, path, 0,
                       "object of " + std::to_string(file.size()) + " bytes is shorter than the " +
                           std::to_string(size) + " bytes wanted from its end");
    }
    ObjectTail tail{std::vector<std::byte>(size), file.size()};
    file.read_at(file.size() - size, tail.bytes);
    return tail;
  }

  std::string location(std::string_view key) const override {
    return root_ + "/" + std::string(key);
  }

 private:
  /// The file a key names. check_store_key() rules out absolute keys and '..' lexically; a
  /// symbolic link inside the store (a chunk, a level directory) could still lead out of it, so
  /// the resolved path must stay below the store's root as well.
  std::string resolve(std::string_view key) const {
    check_store_key(key);
    return detail::confined_path(canonical_root_, key, root_, "store key").string();
  }

  std::string root_;
  std::filesystem::path canonical_root_;
};

}  // namespace

std::shared_ptr<ByteStore> open_directory_store(std::string root) {
  return std::make_shared<DirectoryStore>(std::move(root));
}

}  // namespace resoct
