// Brute-force verification of a residency octree: everything recomputed from first principles.
#include <cstdio>
#include <string>
#include <vector>

#include "resoct/kernel/octree_node.glsl.h"
#include "resoct/engine/residency_octree.hpp"

namespace resoct {

namespace k = resoct::kernel;

namespace {
std::string hex(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

const char* word_name(std::uint32_t w) {
  switch (w) {
    case 0: return "residency";
    case 1: return "minmax";
    case 2: return "occupancy";
    default: return "flags";
  }
}
}  // namespace

std::optional<std::string> ResidencyOctree::check_invariants() const {
  const std::uint64_t nodes = layout_.node_count();
  auto describe = [&](std::uint64_t node, std::uint32_t slot, std::uint32_t w, std::uint32_t stored,
                      std::uint32_t expected, const std::string& what) {
    const glm::uvec3 c = layout_.node_coord(node);
    return what + ": node " + std::to_string(node) + " (depth " +
           std::to_string(layout_.depth_of(node)) + ", coord " + std::to_string(c.x) + "," +
           std::to_string(c.y) + "," + std::to_string(c.z) + ") slot " + std::to_string(slot) +
           " word " + word_name(w) + ": stored " + hex(stored) + ", expected " + hex(expected);
  };

  // (a) Residency: every resident brick marks every node it overlaps, at every depth.
  std::vector<std::uint32_t> residency(std::size_t(nodes) * slots_, 0u);
  for (std::uint32_t slot = 0; slot < slots_; ++slot) {
    for (std::uint32_t l = 0; l < hierarchy_.level_count(); ++l) {
      const glm::uvec3 n = hierarchy_.level(l).bricks;
      for (std::uint32_t z = 0; z < n.z; ++z) {
        for (std::uint32_t y = 0; y < n.y; ++y) {
          for (std::uint32_t x = 0; x < n.x; ++x) {
            if (!query_(slot, l, glm::uvec3(x, y, z))) continue;
            const Box3 box = hierarchy_.level0_box(l, glm::uvec3(x, y, z));
            for (std::uint32_t d = 0; d <= layout_.leaf_depth(); ++d) {
              layout_.for_each_node(d, layout_.node_range(d, box),
                                    [&](std::uint64_t node, glm::uvec3) {
                                      residency[std::size_t(node) * slots_ + slot] |= 1u << l;
                                    });
            }
          }
        }
      }
    }
  }
  for (std::uint64_t node = 0; node < nodes; ++node) {
    for (std::uint32_t slot = 0; slot < slots_; ++slot) {
      const std::uint32_t stored = words_[base(node, slot) + k::RESOCT_NODE_RESIDENCY];
      const std::uint32_t expected = residency[std::size_t(node) * slots_ + slot];
      if (stored != expected) {
        return describe(node, slot, k::RESOCT_NODE_RESIDENCY, stored, expected,
                        "residency differs from the brick query");
      }
    }
  }

  // (b) Metadata: the record rule applied bottom-up to everything supplied so far.
  std::vector<std::uint32_t> expect(words_.size(), 0u);
  for (std::uint32_t d = layout_.leaf_depth() + 1; d-- > 0;) {
    const NodeCoordRange all{glm::uvec3(0), layout_.depth(d).count};
    layout_.for_each_node(d, all, [&](std::uint64_t node, glm::uvec3 c) {
      for (std::uint32_t slot = 0; slot < slots_; ++slot) {
        const Record r = compute_record(d, node, c, slot, expect);
        const std::size_t b = base(node, slot);
        expect[b + k::RESOCT_NODE_MINMAX] = r.minmax;
        expect[b + k::RESOCT_NODE_OCCUPANCY] = r.occupancy;
        expect[b + k::RESOCT_NODE_FLAGS] = r.flags;
      }
    });
  }
  for (std::uint64_t node = 0; node < nodes; ++node) {
    for (std::uint32_t slot = 0; slot < slots_; ++slot) {
      for (std::uint32_t w = 1; w < k::RESOCT_NODE_WORDS; ++w) {
        const std::size_t i = base(node, slot) + w;
        if (words_[i] != expect[i]) {
          return describe(node, slot, w, words_[i], expect[i],
                          "metadata differs from the supplied data");
        }
      }
    }
  }

  // (c) A parent covers each child: culling a parent never hides a visible child.
  for (std::uint64_t node = 0; node < nodes; ++node) {
    const OctreeLayout::Children ch = layout_.children(node);
    for (std::uint32_t i = 0; i < ch.count; ++i) {
      for (std::uint32_t slot = 0; slot < slots_; ++slot) {
        const std::size_t p = base(node, slot);
        const std::size_t q = base(ch.first + i, slot);
        const std::uint32_t pm = words_[p + k::RESOCT_NODE_MINMAX];
        const std::uint32_t qm = words_[q + k::RESOCT_NODE_MINMAX];
        if (k::resoct_node_merge_minmax(pm, qm) != pm) {
          return describe(node, slot, k::RESOCT_NODE_MINMAX, pm,
                          k::resoct_node_merge_minmax(pm, qm),
                          "parent range narrower than child " + std::to_string(ch.first + i));
        }
        const std::uint32_t po = words_[p + k::RESOCT_NODE_OCCUPANCY];
        const std::uint32_t qo = words_[q + k::RESOCT_NODE_OCCUPANCY];
        if ((qo & ~po) != 0) {
          return describe(node, slot, k::RESOCT_NODE_OCCUPANCY, po, po | qo,
                          "parent occupancy misses bins of a child");
        }
      }
    }
  }
  return std::nullopt;
}

}  // namespace resoct
