#pragma once
// resoct-view's on-screen panel: a few lines of statistics drawn with a small built-in 5x7
// bitmap font into a float RGBA image, which the presenter copies over the top-left corner of
// the window (vk_window.hpp, set_panel). Debian's ImGui package ships its GLFW and Vulkan
// backends only as example sources, so the panel is drawn here rather than pulling them in.

#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

#include "resoct/backend/image.hpp"

namespace resoct::view {

/// Where the panel sits: pixels from the window's top-left corner.
inline constexpr std::uint32_t kPanelMargin = 8;

/// An opaque dark rectangle with `lines` in light grey, 2x-scaled 5x7 glyphs (letters are shown
/// upper-case; characters without a glyph as a box). Empty `lines` give an empty image.
Image draw_panel(const std::vector<std::string>& lines);

/// `panel` copied over `frame` at (kPanelMargin, kPanelMargin), clipped to the frame: what the
/// window shows, for screenshots of the window.
void composite_panel(Image& frame, const Image& panel);

}  // namespace resoct::view
