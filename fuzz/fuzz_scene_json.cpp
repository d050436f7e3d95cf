// Fuzz target: the scene JSON parser. Any input either parses into a valid scene or throws
// resoct::Error; a parsed scene must survive scene_to_json -> parse_scene unchanged (the
// documented round trip), which catches fields that are accepted but written back differently.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.hpp"
#include "resoct/scene/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace resoct;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  fuzz::errors_only([&] {
    const Scene scene = parse_scene(text, "fuzz.json");
    const std::string json = scene_to_json(scene);
    Scene again;
    if (!fuzz::errors_only([&] { again = parse_scene(json, "round-trip.json"); })) {
      fuzz::fail("scene_to_json wrote JSON that parse_scene rejects:\n" + json);
    }
    if (!(again == scene)) fuzz::fail("scene changed in the JSON round trip:\n" + json);
  });
  return 0;
}
