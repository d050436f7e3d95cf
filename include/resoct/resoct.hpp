#pragma once
/// \file
/// The viewer API in one include: open a source, set up a Renderer, describe a Scene, render
/// frames and write images (docs/api.md). A backend object comes from the backend's own header:
/// resoct/cpu/cpu_backend.hpp (resoct::cpu::make_backend) or resoct/vulkan/vulkan_backend.hpp
/// (resoct::vk::make_backend).

#include "resoct/camera.hpp"
#include "resoct/error.hpp"
#include "resoct/image.hpp"
#include "resoct/open_source.hpp"
#include "resoct/overview_scene.hpp"
#include "resoct/renderer.hpp"
#include "resoct/renderer_options.hpp"
#include "resoct/scene.hpp"
#include "resoct/version.hpp"
