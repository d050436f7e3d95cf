#pragma once
/// \file
/// A brick that could not be loaded, as the loader (brick_loader.hpp) reports it and a
/// FrameReport lists it.

#include <string>

#include "resoct/volume/brick_key.hpp"

namespace resoct {

/// A brick that could not be loaded; reported once.
struct LoadFailure {
  BrickKey key;
  std::string message;  ///< "<source name>: brick level L channel C (x, y, z): <reason>"
};

}  // namespace resoct
