#pragma once
// Reads inner chunks of zarr v3 shards through a ByteStore by ranges (internal): the shard's
// index first (cached), then only the inner chunk's bytes, so a brick never costs a whole shard.

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "resoct/io/storage/byte_store.hpp"
#include "resoct/io/formats/zarr_v3.hpp"

namespace resoct::detail {

/// Thread-safety: every member may be called from any number of threads at once.
class ZarrShardReader {
 public:
  /// `index_cache_bytes` bounds the decoded shard indexes kept (LRU, 16 bytes per inner chunk).
  ZarrShardReader(std::shared_ptr<const ByteStore> store, std::uint64_t index_cache_bytes);

  /// The encoded bytes of inner chunk `inner` (C-order position in the shard) of the shard at
  /// `key`, or nullopt when the shard is missing or the inner chunk is empty (fill value).
  /// Throws what parse_zarr_shard_index and the store throw.
  std::optional<std::vector<std::byte>> inner_chunk(const std::string& key,
                                                    const ZarrShardingCodec& sharding,
                                                    std::uint64_t chunks_per_shard,
                                                    std::uint64_t inner,
                                                    std::uint64_t max_chunk_bytes) const;

 private:
  struct Index {
    bool present = false;  ///< false: the shard is missing
    std::vector<ZarrShardEntry> entries;
  };
  std::shared_ptr<const Index> index(const std::string& key, const ZarrShardingCodec& sharding,
                                     std::uint64_t chunks_per_shard,
                                     std::uint64_t max_chunk_bytes) const;

  std::shared_ptr<const ByteStore> store_;
  std::uint64_t budget_;
  mutable std::mutex mutex_;
  mutable std::list<std::pair<std::string, std::shared_ptr<const Index>>> lru_;  // newest first
  mutable std::unordered_map<std::string, decltype(lru_)::iterator> by_key_;
  mutable std::uint64_t bytes_ = 0;
};

}  // namespace resoct::detail
