#pragma once
/// \file
/// What to render: camera, viewport, visible channels with transfer functions and level
/// ranges, sampling and LOD parameters, background and requested effects. Loaded from and saved
/// to JSON (docs/scene.md).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec4.hpp>

#include "resoct/scene/camera.hpp"
#include "resoct/scene/scene_slices.hpp"
#include "resoct/scene/transfer_function.hpp"
#include "resoct/volume/volume_desc.hpp"

namespace resoct {

/// Optional rendering effects a scene may request (docs/architecture.md §4).
enum class Effect : std::uint8_t { shading, shadows };
/// "shading" / "shadows".
const char* to_string(Effect e) noexcept;

// --- Effects (docs/scene.md "Effects") ---------------------------------------------------------

/// How one channel is rendered.
enum class ChannelMode : std::uint8_t {
  dvr,  ///< emission-absorption volume rendering (default)
  iso,  ///< isosurfaces at `isovalues`, shaded
  mip,  ///< maximum intensity projection
  aip,  ///< average intensity projection
};
/// "dvr" / "iso" / "mip" / "aip".
const char* to_string(ChannelMode m) noexcept;

/// Most isovalues one iso channel may have.
inline constexpr std::size_t kMaxIsovalues = 4;

/// The light of "shading" and "shadows" and of isosurfaces (Blinn-Phong).
struct Light {
  enum class Kind : std::uint8_t { headlight, directional, point };
  Kind kind = Kind::headlight;  ///< headlight: shines along each view ray
  glm::dvec3 vector{0.0};       ///< directional: direction the light travels; point: position (box)
  double ambient = 0.25;        ///< each coefficient in [0, 10]
  double diffuse = 0.75;
  double specular = 0.25;
  double shininess = 32.0;  ///< Blinn-Phong exponent in [1, 1024]
  friend bool operator==(const Light&, const Light&) = default;
};

/// Finite differences of gradients (paper 004 §7.1).
enum class GradientStencil : std::uint8_t { central, forward };

// ------------------------------------------------------------------------------------------------

/// Highest level index a scene may name (the brick key holds 5 bits of level).
inline constexpr std::uint32_t kMaxSceneLevel = 31;

/// One visible channel.
struct ChannelSettings {
  std::uint32_t channel = 0;  ///< dataset channel, < kMaxChannels
  TransferFunction tf;
  std::uint32_t finest_level = 0;     ///< finest level this channel may render, <= coarsest
  std::uint32_t coarsest_level = 15;  ///< coarsest; clamped to the dataset's last level
  /// Request priority among channels; lower loads first. Ties keep the channel order.
  std::int32_t importance = 0;
  ChannelMode mode = ChannelMode::dvr;
  /// Iso mode only: 1..kMaxIsovalues values in the channel's normalized range [0, 1].
  std::vector<double> isovalues;
  friend bool operator==(const ChannelSettings&, const ChannelSettings&) = default;
};

/// A plain value type; copy freely. Not synchronised: do not modify while another thread reads.
struct Scene {
  Camera camera;
  Viewport viewport;
  std::vector<ChannelSettings> channels;
  double step_scale = 1.0;    ///< step as a multiple of Eq. 8.2-8.3's one-voxel step, > 0
  double lod_error_px = 1.0;  ///< allowed projected voxel size in pixels, > 0
  /// Error-bounded level of detail (docs/rendering.md "Error-bounded LOD"), in [0, 1]; 0 = off.
  /// Each channel samples the coarsest of its levels whose brick's measured down-sampling error,
  /// times the transfer function's steepest premultiplied-RGBA slope, is at most this (the
  /// colour error one sample may carry): coarser than lod_error_px would pick where the data is
  /// smooth, finer where it shows detail; lod_error_px then sets only the step. Needs a renderer
  /// with ViewerOptions::brick_errors.
  double lod_error_color = 0.0;
  double ert_opacity = 0.99;                  ///< early termination opacity, in (0, 1]
  glm::dvec4 background{0.0, 0.0, 0.0, 1.0};  ///< straight-alpha RGBA, each in [0, 1]
  std::vector<Effect> effects;
  /// Pre-integrated transfer functions for DVR channels (docs/rendering.md "Pre-integration").
  bool preintegration = false;
  // Slices and lens (docs/scene.md "Slices and lens").
  std::vector<SlicePlane> slices;  ///< at most kMaxSlices planes
  std::optional<Lens> lens;        ///< none: every channel everywhere
  // Effect parameters (docs/scene.md "Effects").
  Light light;
  GradientStencil gradient = GradientStencil::central;
  /// Shadow rays march a level whose voxels are this many times the view LOD's (power of two,
  /// 1..16; paper 004 §7.2 suggests 2).
  std::uint32_t shadow_lod_factor = 2;
  /// The timepoint of a time series to show (docs/scene.md "Time series"); must be below the
  /// source's BrickSource::timepoints(), so 0 for data without a time axis. Absent: the
  /// timepoint the source was opened at (BrickSource::timepoint(), e.g.
  /// OmeZarrOptions::timepoint), so scenes without the field show what they showed before.
  std::optional<std::uint32_t> timepoint;

  /// Whether the scene declares `e`.
  bool has_effect(Effect e) const noexcept;
  /// Whether any effect needs gradients: "shading" or an iso channel.
  bool needs_gradients() const noexcept;

  /// Throws Error(invalid_argument) "<what>: <field>: why" when a field is out of range (the
  /// same checks as loading), `what` e.g. a file name.
  void validate(const std::string& what = "scene") const;
  /// validate(), plus every channel must exist in `volume`.
  void validate(const VolumeDesc& volume, const std::string& what = "scene") const;
  /// The same, plus `timepoint` must be below `timepoints` (the source's count):
  /// "<what>: timepoint: 7 but the volume has 5 timepoints (0..4)".
  void validate(const VolumeDesc& volume, std::uint32_t timepoints,
                const std::string& what = "scene") const;

  friend bool operator==(const Scene&, const Scene&) = default;
};

/// Parses a scene from JSON text. `name` prefixes error messages. Malformed JSON throws
/// Error(corrupt) "<name>: offset <n>: ..."; a missing, mistyped, unknown or out-of-range field
/// throws Error(invalid_argument) "<name>: <json path>: why", e.g.
/// "scene.json: channels[2].tf[1]: value 1.3 outside [0,1]".
Scene parse_scene(std::string_view json_text, const std::string& name = "scene");
/// Reads and parses a file; Error(io) naming the path when it cannot be read.
Scene load_scene(const std::string& path);
/// The JSON text of a scene (every field written; parse_scene(scene_to_json(s)) == s).
std::string scene_to_json(const Scene& scene);
/// Writes scene_to_json atomically (temporary file in the same directory, then rename);
/// Error(io) naming the path on failure, leaving no file behind.
void save_scene(const Scene& scene, const std::string& path);

}  // namespace resoct
