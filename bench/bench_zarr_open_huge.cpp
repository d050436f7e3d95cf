// Opening an OME-Zarr that declares a huge array (2^40 u16 voxels, every chunk missing) from an
// in-memory store: with lazy region metadata this costs the metadata objects only, whatever
// the declared size. Counters: store gets per open, and the time of one region_meta query over
// a brick-sized region (computed from fill-value chunks) on a fresh source.
#include <benchmark/benchmark.h>

#include <atomic>
#include <map>
#include <string>
#include <vector>

#include "resoct/io/formats/ome_zarr.hpp"

namespace {

using namespace resoct;

class MemoryStore final : public ByteStore {
 public:
  explicit MemoryStore(std::map<std::string, std::string> objects) : objects_(std::move(objects)) {}
  std::optional<std::vector<std::byte>> get(std::string_view key, std::uint64_t) const override {
    ++gets;
    const auto it = objects_.find(std::string(key));
    if (it == objects_.end()) return std::nullopt;
    const auto* p = reinterpret_cast<const std::byte*>(it->second.data());
    return std::vector<std::byte>(p, p + it->second.size());
  }
  std::vector<std::byte> get_range(std::string_view key, std::uint64_t offset,
                                   std::uint64_t size) const override {
    ++gets;
    const std::string& s = objects_.at(std::string(key));
    const auto* p = reinterpret_cast<const std::byte*>(s.data()) + offset;
    return std::vector<std::byte>(p, p + size);
  }
  std::optional<std::vector<std::byte>> get_range_if_present(std::string_view key,
                                                             std::uint64_t offset,
                                                             std::uint64_t size) const override {
    if (!objects_.contains(std::string(key))) return std::nullopt;
    return get_range(key, offset, size);
  }
  std::optional<ObjectTail> get_suffix(std::string_view key, std::uint64_t size) const override {
    const auto it = objects_.find(std::string(key));
    if (it == objects_.end()) return std::nullopt;
    return ObjectTail{get_range(key, it->second.size() - size, size), it->second.size()};
  }
  std::string location(std::string_view key) const override {
    return "mem://bench/" + std::string(key);
  }
  mutable std::atomic<std::uint64_t> gets{0};

 private:
  std::map<std::string, std::string> objects_;
};

std::shared_ptr<MemoryStore> huge_store() {
  return std::make_shared<MemoryStore>(std::map<std::string, std::string>{
      {".zarray",
       R"({"zarr_format": 2, "shape": [8192, 8192, 16384], "chunks": [64, 64, 64],
           "dtype": "<u2", "compressor": null, "fill_value": 0, "order": "C",
           "filters": null})"}});
}

void BM_OpenHugeDeclaredZarr(benchmark::State& state) {
  auto store = huge_store();
  OmeZarrOptions o;
  o.pyramid.threads = 1;
  std::uint64_t opens = 0;
  for (auto _ : state) {
    auto src = open_ome_zarr(store, BrickLayout{glm::uvec3(32), 1}, o);
    benchmark::DoNotOptimize(src.get());
    ++opens;
  }
  state.counters["gets_per_open"] = double(store->gets.load()) / double(opens);
  state.counters["declared_voxels"] = double(std::uint64_t(1) << 40);
  state.SetItemsProcessed(std::int64_t(opens));
}
BENCHMARK(BM_OpenHugeDeclaredZarr)->Unit(benchmark::kMicrosecond);

void BM_LazyRegionMetaColdBrick(benchmark::State& state) {
  auto store = huge_store();
  OmeZarrOptions o;
  o.pyramid.threads = 1;
  const auto src = open_ome_zarr(store, BrickLayout{glm::uvec3(32), 1}, o);
  std::int64_t x = 0;
  for (auto _ : state) {
    // A fresh brick-sized region every time: 27 uncomputed blocks of 16^3 (fill chunks).
    const Box3 r{{x, 0, 0}, {x + 34, 34, 34}};
    x = (x + 48) % 16000;
    benchmark::DoNotOptimize(src->region_meta(0, r));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LazyRegionMetaColdBrick)->Unit(benchmark::kMicrosecond);

}  // namespace
BENCHMARK_MAIN();
