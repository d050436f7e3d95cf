#pragma once
/// \file
/// A brick of one timepoint: the host-side key of decoded bricks when a source is a time series.

#include <cstdint>
#include <functional>

#include "resoct/volume/brick_key.hpp"

namespace resoct {

/// BrickKey packs all 64 bits (level, channel, x/y/z), so the timepoint travels next to it
/// rather than inside it. Only host structures that may hold bricks of several timepoints at
/// once use this key (the host brick cache and the loader's prefetch queue); the device side
/// (page table, device cache) only ever holds the current timepoint and keeps BrickKey.
struct TimedBrickKey {
  BrickKey key;
  std::uint32_t timepoint = 0;
  friend constexpr bool operator==(const TimedBrickKey&, const TimedBrickKey&) = default;
};

}  // namespace resoct

template <>
struct std::hash<resoct::TimedBrickKey> {
  std::size_t operator()(const resoct::TimedBrickKey& k) const noexcept {
    // Mixing the timepoint into the key's bits before BrickKey's splitmix64 finaliser spreads it
    // over every output bit.
    return std::hash<resoct::BrickKey>{}(resoct::BrickKey::from_bits(
        k.key.bits() ^ (std::uint64_t(k.timepoint) * 0x9e3779b97f4a7c15ull)));
  }
};
