#pragma once
// Internal: JSON and validation of a Scene's "slices" and "lens" (docs/scene.md), kept apart from
// scene.cpp so that the rest of the scene format evolves independently.

#include <string>

#include <nlohmann/json_fwd.hpp>

#include "resoct/scene/scene.hpp"

namespace resoct::detail {

/// Reads doc["slices"] and doc["lens"] when present into `scene`. Throws
/// Error(invalid_argument) "<name>: <json path>: why" on malformed entries.
void read_slices_and_lens(const nlohmann::json& doc, const std::string& name, Scene& scene);
/// Range and consistency checks (also for scenes built in code); same error form with `what`.
void check_slices_and_lens(const Scene& scene, const std::string& what);
/// Writes "slices" and "lens" (only when the scene has them).
void slices_and_lens_to_json(const Scene& scene, nlohmann::json& doc);

}  // namespace resoct::detail
