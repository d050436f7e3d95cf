#include "support/recording_backend.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "resoct/kernel/page_entry.glsl.h"
#include "resoct/kernel/request_key.glsl.h"

namespace resoct::test {

namespace {
RecordingBackend* g_last = nullptr;
}  // namespace

std::uint64_t RecordingBackend::slot_bytes() const noexcept {
  const glm::uvec3 p = config_.padded_brick;
  return std::uint64_t(p.x) * p.y * p.z * voxel_size(config_.voxel_type);
}

void RecordingBackend::configure(const BackendConfig& config) {
  config_ = config;
  ++configure_calls_;
  pages_.assign(std::size_t(config.page_pool_blocks) * kernel::RESOCT_PAGE_BLOCK_ENTRIES, 0u);
  directory_.assign(config.directory_entries, 0u);
  nodes_.assign(config.node_words, 0u);
  voxels_.assign(std::size_t(config.cache_slots * slot_bytes()), std::byte{0});
  updates_.clear();
}

void RecordingBackend::update(const FrameUpdate& u) {
  RecordedUpdate rec;
  for (const BrickUpload& b : u.bricks) {
    if (b.cache_slot >= config_.cache_slots) throw std::logic_error("upload to a bad cache slot");
    if (b.voxels.size() != slot_bytes()) throw std::logic_error("upload of the wrong size");
    std::memcpy(voxels_.data() + b.cache_slot * slot_bytes(), b.voxels.data(), b.voxels.size());
    rec.upload_slots.push_back(b.cache_slot);
    rec.upload_bytes += b.voxels.size();
  }
  if (u.pages_full) {
    if (u.all_pages.size() > pages_.size() || u.all_directory.size() != directory_.size() ||
        !u.page_deltas.empty() || !u.directory_deltas.empty()) {
      throw std::logic_error("full page update of the wrong size or with deltas");
    }
    if (u.directory_offsets.size() != config_.page_tables + 1u) {
      throw std::logic_error("directory offsets missing in a full update");
    }
    std::copy(u.all_pages.begin(), u.all_pages.end(), pages_.begin());
    std::fill(pages_.begin() + std::ptrdiff_t(u.all_pages.size()), pages_.end(), 0u);
    std::copy(u.all_directory.begin(), u.all_directory.end(), directory_.begin());
    rec.page_deltas = u.all_pages.size() + directory_.size();
  } else {
    for (const PageDelta& d : u.page_deltas) {
      if (d.index >= pages_.size()) throw std::logic_error("page delta out of range");
      pages_[d.index] = d.value;
    }
    for (const PageDelta& d : u.directory_deltas) {
      if (d.index >= directory_.size() || d.value >= config_.page_pool_blocks)
        throw std::logic_error("directory delta out of range");
      directory_[d.index] = d.value;
    }
    rec.page_deltas = u.page_deltas.size() + u.directory_deltas.size();
  }
  if (u.nodes_full) {
    if (u.all_nodes.size() != nodes_.size() || !u.node_deltas.empty()) {
      throw std::logic_error("full node update of the wrong size or with deltas");
    }
    std::copy(u.all_nodes.begin(), u.all_nodes.end(), nodes_.begin());
    rec.node_deltas = nodes_.size();
  } else {
    for (const OctreeWordDelta& d : u.node_deltas) {
      if (d.index >= nodes_.size()) throw std::logic_error("node delta out of range");
      nodes_[d.index] = d.value;
    }
    rec.node_deltas = u.node_deltas.size();
  }
  rec.pages_full = u.pages_full;
  rec.nodes_full = u.nodes_full;
  updates_.push_back(std::move(rec));
}

void RecordingBackend::render(const FrameTables& tables, FrameResult& result) {
  tables_.push_back(tables);
  result.image = Image(std::max(1u, tables.frame.width), std::max(1u, tables.frame.height));
  result.brick_requests.clear();
  result.node_requests.clear();
  result.used_cache_slots.clear();
  result.stats = {};
  if (script_) script_(tables, result, *this);
}

std::span<const std::byte> RecordingBackend::slot_voxels(std::uint32_t slot) const {
  if (slot >= config_.cache_slots) throw std::logic_error("slot out of range");
  return {voxels_.data() + slot * slot_bytes(), std::size_t(slot_bytes())};
}

void RecordingBackend::want(const PageTable& table, std::span<const PageAddress> bricks,
                            FrameResult& result) {
  for (const PageAddress& a : bricks) {
    const std::uint32_t d = table.directory_index(a);
    const std::uint32_t block = directory_.at(d);
    const std::uint32_t in = kernel::resoct_page_in_block_index(a.brick);
    const std::uint32_t entry =
        pages_.at(std::size_t(block) * kernel::RESOCT_PAGE_BLOCK_ENTRIES + in);
    if (kernel::resoct_page_is_mapped(entry)) {
      result.used_cache_slots.push_back(kernel::resoct_page_cache_slot(entry));
    } else if (kernel::resoct_page_state(entry) == kernel::RESOCT_PAGE_STATE_UNMAPPED) {
      const std::uint32_t key = block == 0u ? kernel::resoct_request_key_block_miss(d)
                                            : kernel::resoct_request_key_brick(block, in);
      result.brick_requests.push_back(Request{key, 1u, 0u});
    }
  }
}

void register_recording_backend() {
  register_backend("recording", [](const BackendOptions&) {
    auto b = std::make_unique<RecordingBackend>();
    g_last = b.get();
    return b;
  });
}

RecordingBackend* last_recording_backend() {
  return g_last;
}

}  // namespace resoct::test
