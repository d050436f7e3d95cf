#include "io/formats/zarr_shard_reader.hpp"

#include "resoct/base/error.hpp"

namespace resoct::detail {

namespace {

std::uint64_t cost(const std::string& key, std::size_t entries) {
  return key.size() + 64 + 16 * std::uint64_t(entries);
}

}  // namespace

ZarrShardReader::ZarrShardReader(std::shared_ptr<const ByteStore> store,
                                 std::uint64_t index_cache_bytes)
    : store_(std::move(store)), budget_(index_cache_bytes) {}

std::shared_ptr<const ZarrShardReader::Index> ZarrShardReader::index(
    const std::string& key, const ZarrShardingCodec& sharding, std::uint64_t chunks_per_shard,
    std::uint64_t max_chunk_bytes) const {
  {
    std::lock_guard lock(mutex_);
    if (const auto it = by_key_.find(key); it != by_key_.end()) {
      lru_.splice(lru_.begin(), lru_, it->second);
      return it->second->second;
    }
  }
  // Read outside the lock: two threads missing the same index both read it, which costs less
  // than serializing every loader thread behind one network request.
  const std::string location = store_->location(key);
  const std::uint64_t index_bytes = zarr_shard_index_bytes(sharding, chunks_per_shard, location);
  auto idx = std::make_shared<Index>();
  if (sharding.index_at_end) {
    if (auto tail = store_->get_suffix(key, index_bytes)) {
      idx->present = true;
      idx->entries = parse_zarr_shard_index(tail->bytes, sharding, chunks_per_shard,
                                            tail->object_size - index_bytes, tail->object_size,
                                            max_chunk_bytes, location);
    }
  } else if (auto head = store_->get_range_if_present(key, 0, index_bytes)) {
    // The shard's size is not known here: an entry past its end fails when it is read.
    idx->present = true;
    idx->entries = parse_zarr_shard_index(*head, sharding, chunks_per_shard, 0, ~std::uint64_t(0),
                                          max_chunk_bytes, location);
  }
  std::lock_guard lock(mutex_);
  if (const auto it = by_key_.find(key); it != by_key_.end()) return it->second->second;
  const std::uint64_t c = cost(key, idx->entries.size());
  if (c <= budget_) {
    lru_.emplace_front(key, idx);
    by_key_[key] = lru_.begin();
    bytes_ += c;
    while (bytes_ > budget_) {
      const auto& [k, v] = lru_.back();
      bytes_ -= cost(k, v->entries.size());
      by_key_.erase(k);
      lru_.pop_back();
    }
  }
  return idx;
}

std::optional<std::vector<std::byte>> ZarrShardReader::inner_chunk(
    const std::string& key, const ZarrShardingCodec& sharding, std::uint64_t chunks_per_shard,
    std::uint64_t inner, std::uint64_t max_chunk_bytes) const {
  const auto idx = index(key, sharding, chunks_per_shard, max_chunk_bytes);
  if (!idx->present) return std::nullopt;
  if (inner >= idx->entries.size()) {
    throw invalid_parameter("inner", std::to_string(inner) + " >= " +
                                         std::to_string(idx->entries.size()) + " inner chunks");
  }
  const ZarrShardEntry& e = idx->entries[std::size_t(inner)];
  if (e.empty()) return std::nullopt;
  return store_->get_range(key, e.offset, e.nbytes);
}

}  // namespace resoct::detail
