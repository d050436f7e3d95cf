#pragma once
// What the loading benchmarks (bench_prefetch, bench_timeseries) share: their smoke switch and
// their scene. They time brick loading against paced frames, not the rig's resident rendering,
// so they do not use bench_rig.

#include <cstdlib>
#include <string_view>

namespace resoct::bench {

/// RESOCT_BENCH_SMOKE=1 (the ctest "bench-smoke" runs): tiny sizes, no pacing or latency.
inline bool loading_smoke() {
  const char* s = std::getenv("RESOCT_BENCH_SMOKE");
  return s != nullptr && std::string_view(s) == "1";
}

/// examples/scenes/turbulence.json (benchmarks do not know the source directory).
inline constexpr const char* kTurbulenceScene = R"({"camera": {"eye": [1.8, 1.1, 1.6],
  "target": [0.5, 0.5, 0.5], "up": [0, 1, 0], "fov_deg": 40, "projection": "perspective"},
  "viewport": {"width": 512, "height": 512}, "channels": [{"channel": 0, "tf": [[0.0, 0, 0, 0, 0],
  [0.35, 0.2, 0.2, 0.8, 0.0], [0.6, 0.9, 0.6, 0.2, 0.03], [1.0, 1.0, 0.2, 0.1, 0.2]],
  "levels": [0, 15], "importance": 0, "mode": "dvr"}], "step_scale": 1.0, "lod_error_px": 1.0,
  "ert_opacity": 0.99, "background": [0, 0, 0, 1], "effects": []})";

}  // namespace resoct::bench
