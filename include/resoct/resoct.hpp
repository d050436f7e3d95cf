#pragma once
/// \file
/// The viewer API in one include: open a source, set up a Renderer, describe a Scene, render
/// frames and write images (docs/api.md). A backend object comes from the backend's own header:
/// resoct/cpu/cpu_backend.hpp (resoct::cpu::make_backend) or resoct/vulkan/vulkan_backend.hpp
/// (resoct::vk::make_backend).

#include "resoct/scene/camera.hpp"
#include "resoct/base/error.hpp"
#include "resoct/backend/image.hpp"
#include "resoct/io/open_source.hpp"
#include "resoct/scene/overview_scene.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_options.hpp"
#include "resoct/scene/scene.hpp"
#include "resoct/version.hpp"
