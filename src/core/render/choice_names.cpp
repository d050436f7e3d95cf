// The names of the options' choices (RenderMode, RequestStrategy, Eviction, FrameOutput): one
// table per enum serves both to_string() and its parser, so that every parser names its parameter
// and lists the accepted names alike, and the tools and the Python module spell them the same.
#include <string>
#include <string_view>

#include "resoct/backend/backend.hpp"
#include "resoct/base/error.hpp"
#include "resoct/cache/eviction_policy.hpp"
#include "resoct/render/renderer_options.hpp"
#include "resoct/engine/request_set.hpp"

namespace resoct {

namespace {

template <typename E>
struct Choice {
  const char* name;
  E value;
};

constexpr Choice<RenderMode> kModes[] = {{"residency", RenderMode::residency},
                                         {"pagetable", RenderMode::pagetable},
                                         {"octree", RenderMode::octree}};
constexpr Choice<RequestStrategy> kStrategies[] = {{"greedy", RequestStrategy::greedy},
                                                   {"global", RequestStrategy::global}};
constexpr Choice<Eviction> kEvictions[] = {{"lru", Eviction::lru},
                                           {"octreemizer", Eviction::octreemizer},
                                           {"octreemizer-camera", Eviction::octreemizer_camera}};
constexpr Choice<FrameOutput> kOutputs[] = {{"rgba32f", FrameOutput::rgba32f},
                                            {"rgba8", FrameOutput::rgba8},
                                            {"both", FrameOutput::both},
                                            {"device", FrameOutput::device}};

// "unknown" for a value outside the table (an enum made by a cast from a bad integer), which
// ViewerOptions::validate() reports.
template <typename E, std::size_t N>
const char* name_in(const Choice<E> (&table)[N], E value) noexcept {
  for (const Choice<E>& c : table) {
    if (c.value == value) return c.name;
  }
  return "unknown";
}

template <typename E, std::size_t N>
E parse_in(const Choice<E> (&table)[N], std::string_view s, std::string_view parameter) {
  std::string names;
  for (const Choice<E>& c : table) {
    if (s == c.name) return c.value;
    names += (names.empty() ? "" : ", ") + std::string(c.name);
  }
  throw invalid_parameter(parameter, "'" + std::string(s) + "' is not one of " + names);
}

}  // namespace

const char* to_string(RenderMode m) noexcept {
  return name_in(kModes, m);
}
const char* to_string(RequestStrategy s) noexcept {
  return name_in(kStrategies, s);
}
const char* to_string(Eviction e) noexcept {
  return name_in(kEvictions, e);
}
const char* to_string(FrameOutput o) noexcept {
  return name_in(kOutputs, o);
}

RenderMode parse_render_mode(std::string_view s) {
  return parse_in(kModes, s, "mode");
}
RequestStrategy parse_request_strategy(std::string_view s, std::string_view parameter) {
  return parse_in(kStrategies, s, parameter);
}
Eviction parse_eviction(std::string_view s, std::string_view parameter) {
  return parse_in(kEvictions, s, parameter);
}
FrameOutput parse_frame_output(std::string_view s, std::string_view parameter) {
  return parse_in(kOutputs, s, parameter);
}

}  // namespace resoct
