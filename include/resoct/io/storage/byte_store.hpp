#pragma once
/// \file
/// A read-only store of named byte objects: the common ground of chunked formats (a zarr
/// hierarchy is a set of keys such as "0/.zarray" and "0/3.1.7") and of the places they live
/// (a local directory, one or more HTTP servers). Readers of formats are written against this
/// interface, so every format that reads from a ByteStore also reads over the network.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace resoct {

/// The end of an object and the object's size (ByteStore::get_suffix).
struct ObjectTail {
  std::vector<std::byte> bytes;
  std::uint64_t object_size = 0;
};

/// Keys are relative, '/'-separated paths without "." or ".." components.
/// Thread-safety: implementations must allow every member to be called from any number of
/// threads at once (brick loader threads read concurrently).
class ByteStore {
 public:
  virtual ~ByteStore() = default;

  /// The whole object at `key`, or nullopt when the store has no such object (for zarr a
  /// missing chunk means "all fill value", so absence is an answer, not an error). Throws
  /// Error naming location(key) for any other failure: unreadable file, network error after
  /// retries, an object larger than `max_bytes` (a hostile or corrupt store must not make the
  /// reader allocate without bound).
  virtual std::optional<std::vector<std::byte>> get(std::string_view key,
                                                    std::uint64_t max_bytes) const = 0;

  /// Exactly `size` bytes of the object at `key` starting at `offset`. Throws
  /// Error(truncated) naming location(key) and the offset when the object is shorter, and
  /// Error for every failure get() reports.
  virtual std::vector<std::byte> get_range(std::string_view key, std::uint64_t offset,
                                           std::uint64_t size) const = 0;

  /// get_range(), except that an absent object is nullopt instead of an error (a missing zarr
  /// shard is all fill value: absence is an answer).
  virtual std::optional<std::vector<std::byte>> get_range_if_present(std::string_view key,
                                                                     std::uint64_t offset,
                                                                     std::uint64_t size) const = 0;

  /// The last `size` bytes of the object at `key` and the object's size, or nullopt when the
  /// store has no such object; read without reading the rest of the object (a zarr shard's index
  /// at its end). Throws Error(truncated) naming location(key) when the object is shorter than
  /// `size`, and Error for every failure get() reports.
  virtual std::optional<ObjectTail> get_suffix(std::string_view key, std::uint64_t size) const = 0;

  /// Where `key` lives, for messages: "/data/x.zarr/0/.zarray" or "http://host/x.zarr/0/.zarray".
  virtual std::string location(std::string_view key) const = 0;
};

/// Throws Error(invalid_argument) naming `key` when it is empty, absolute, or contains an empty,
/// "." or ".." component (a hostile metadata file must not be able to name files outside the
/// store).
void check_store_key(std::string_view key);

/// A ByteStore over a local directory: key "a/b" is the file <root>/a/b. Objects must resolve,
/// symbolic links followed, to files below `root`: a get of a key whose path leads out of the
/// store through a link throws Error(invalid_argument) naming `root` and the key. Throws
/// Error(io) naming `root` when it is not a readable directory.
std::shared_ptr<ByteStore> open_directory_store(std::string root);

}  // namespace resoct
