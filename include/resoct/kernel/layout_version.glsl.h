// resoct single-source kernel: the version of the records the host shares with the device.
//
// The records are the per-frame tables of frame.glsl.h (ResoctFrame, ResoctFxFrame,
// ResoctSlotInfo, ResoctLevelInfo, ResoctDepthInfo, ResoctRayStats), the page-table entry word
// (page_entry.glsl.h), the octree node record (octree_node.glsl.h), the request key
// (request_key.glsl.h), the transfer-function LUT size (tf.glsl.h) and the (index, value) delta
// pairs (PageDelta, OctreeWordDelta). A backend compiled against one layout misreads the tables of
// another, so whoever changes a record's size, field order or encoding increments this number;
// tests/core/kernel/test_kernel_layout_version.cpp pins what version N means and fails until both
// agree. Applications compare it with resoct::library_kernel_layout_version() (resoct/version.hpp).
#ifndef RESOCT_KERNEL_LAYOUT_VERSION_GLSL_H
#define RESOCT_KERNEL_LAYOUT_VERSION_GLSL_H

#include "resoct/kernel/common.glsl.h"

RESOCT_KERNEL_BEGIN

RESOCT_CONST(uint, RESOCT_KERNEL_LAYOUT_VERSION, 7u);

RESOCT_KERNEL_END

#endif  // RESOCT_KERNEL_LAYOUT_VERSION_GLSL_H
