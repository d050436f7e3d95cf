#pragma once
// A frame's statistics as a Python dict (resoct.Frame.stats).

#include "bindings.hpp"
#include "resoct/render/frame_stats.hpp"

namespace resoct::python {

py::dict stats_dict(const FrameStats& stats);

}  // namespace resoct::python
