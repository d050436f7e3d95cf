#pragma once
/// \file
/// 64-bit global brick identifier: (level, channel, brick x/y/z).

#include <cstdint>
#include <functional>

#include <glm/vec3.hpp>

namespace resoct {

/// Packs level, dataset channel and brick coordinates into 64 bits:
/// bits 0-16 x, 17-33 y, 34-50 z, 51-55 level, 56-63 channel. So a level may have up to 131072
/// bricks per axis (at 32³ bricks, 4 Mi voxels per axis), a dataset 32 levels and 256 channels.
/// Device structures use 32-bit local indices instead; this key lives on the host.
class BrickKey {
 public:
  static constexpr std::uint32_t kAxisBits = 17;
  static constexpr std::uint32_t kLevelBits = 5;
  static constexpr std::uint32_t kChannelBits = 8;
  static constexpr std::uint32_t kMaxAxis = (1u << kAxisBits) - 1u;
  static constexpr std::uint32_t kMaxLevel = (1u << kLevelBits) - 1u;
  static constexpr std::uint32_t kMaxChannel = (1u << kChannelBits) - 1u;

  constexpr BrickKey() = default;
  /// Coordinates beyond the field widths are a programming error; BrickHierarchy guarantees
  /// they fit for every hierarchy it accepts.
  constexpr BrickKey(std::uint32_t level, std::uint32_t channel, glm::uvec3 brick) noexcept
      : bits_((std::uint64_t(brick.x) & kMaxAxis) | ((std::uint64_t(brick.y) & kMaxAxis) << 17) |
              ((std::uint64_t(brick.z) & kMaxAxis) << 34) |
              ((std::uint64_t(level) & kMaxLevel) << 51) |
              ((std::uint64_t(channel) & kMaxChannel) << 56)) {}

  static constexpr BrickKey from_bits(std::uint64_t bits) noexcept {
    BrickKey k;
    k.bits_ = bits;
    return k;
  }

  constexpr std::uint64_t bits() const noexcept { return bits_; }
  constexpr std::uint32_t level() const noexcept { return std::uint32_t(bits_ >> 51) & kMaxLevel; }
  constexpr std::uint32_t channel() const noexcept {
    return std::uint32_t(bits_ >> 56) & kMaxChannel;
  }
  constexpr glm::uvec3 brick() const noexcept {
    return {std::uint32_t(bits_) & kMaxAxis, std::uint32_t(bits_ >> 17) & kMaxAxis,
            std::uint32_t(bits_ >> 34) & kMaxAxis};
  }

  friend constexpr bool operator==(BrickKey a, BrickKey b) noexcept { return a.bits_ == b.bits_; }
  friend constexpr bool operator<(BrickKey a, BrickKey b) noexcept { return a.bits_ < b.bits_; }

 private:
  std::uint64_t bits_ = 0;
};

}  // namespace resoct

template <>
struct std::hash<resoct::BrickKey> {
  std::size_t operator()(resoct::BrickKey k) const noexcept {
    // splitmix64 finaliser: keys differ mostly in low bits, and std::hash<uint64_t> is identity.
    std::uint64_t z = k.bits() + 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return std::size_t(z ^ (z >> 31));
  }
};
