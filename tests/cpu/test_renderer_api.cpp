// The viewer API of the Renderer: a backend object instead of a registered name, the small
// ViewerOptions, frame reports whose pixel buffers are reused, and the 8-bit output.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <limits>
#include <new>
#include <set>

#include "resoct/cpu/cpu_backend.hpp"
#include "resoct/scene/overview_scene.hpp"
#include "resoct/sources/procedural_source.hpp"
#include "resoct/render/renderer.hpp"
#include "resoct/render/renderer_inspection.hpp"
#include "support/expect_error.hpp"
#include "support/sanitized.hpp"

// Counts the allocations of the sizes of a frame's pixel buffers while `g_counting` is set: a
// frame that allocates image memory shows up here whatever container made the allocation.
namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::size_t> g_float_bytes{0};
std::atomic<std::size_t> g_rgba8_bytes{0};
std::atomic<std::uint64_t> g_image_allocations{0};
}  // namespace

// A sanitizer's runtime defines operator new itself (a second definition does not link): there
// nothing is counted, and the test that counts skips.
#if !RESOCT_TEST_SANITIZED
void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed) &&
      (n == g_float_bytes.load(std::memory_order_relaxed) ||
       n == g_rgba8_bytes.load(std::memory_order_relaxed))) {
    g_image_allocations.fetch_add(1, std::memory_order_relaxed);
  }
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
#endif

namespace resoct::test {
namespace {

constexpr std::uint32_t kSize = 96;

std::shared_ptr<const BrickSource> tubes() {
  return make_procedural_source("procedural:tubes:64x64x64", BrickLayout{glm::uvec3(16), 1});
}

Scene scene_of(const BrickSource& src) {
  return overview_scene(src.hierarchy().volume(), Viewport{kSize, kSize});
}

// Synchronous loads: every run renders the same frames.
ViewerOptions sync_viewer(FrameOutput output = FrameOutput::rgba32f) {
  ViewerOptions v;
  v.loader_threads = 0;
  v.output = output;
  return v;
}

TEST(RendererApi, BackendObjectRendersWhatTheRegisteredBackendRenders) {
  const auto src = tubes();
  const Scene scene = scene_of(*src);
  // The object needs no registration, and the options' backend name is ignored.
  RendererOptions named = sync_viewer();
  named.backend = "no-such-backend";
  Renderer by_object(src, cpu::make_backend(2), named);
  EXPECT_EQ(inspect::backend(by_object).name(), "cpu");
  const ConvergeReport a = by_object.render_until_converged(scene, 64);

  cpu::register_backend();
  named.backend = "cpu";
  Renderer by_name(src, named);
  const ConvergeReport b = by_name.render_until_converged(scene, 64);
  ASSERT_TRUE(a.converged);
  ASSERT_TRUE(b.converged);
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_GT(a.last.stats.backend.samples, 0u);
  EXPECT_EQ(a.last.image, b.last.image);
}

TEST(RendererApi, NullBackendIsRejectedNamingIt) {
  EXPECT_RESOCT_ERROR(Renderer(tubes(), std::unique_ptr<Backend>()), ErrorCode::invalid_argument,
                      "backend");
}

TEST(RendererApi, ASkipThresholdThatIsNoCountOfSamplesIsRejectedNamingIt) {
  for (float k :
       {-1.0f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    RendererOptions o = sync_viewer();
    o.skip_min_samples = k;
    EXPECT_RESOCT_ERROR(Renderer(tubes(), cpu::make_backend(1), o), ErrorCode::invalid_argument,
                        "skip_min_samples");
  }
}

TEST(RendererApi, ViewerOptionsKeepTheDefaultTuning) {
  ViewerOptions v = sync_viewer();
  v.device_cache_bytes = std::uint64_t(64) << 20;
  v.mode = RenderMode::pagetable;
  Renderer r(tubes(), cpu::make_backend(1), v);
  EXPECT_EQ(r.options().device_cache_bytes, std::uint64_t(64) << 20);
  EXPECT_EQ(r.options().mode, RenderMode::pagetable);
  EXPECT_EQ(r.options().ttl, TuningOptions{}.ttl);
  EXPECT_EQ(r.options().max_iterations, TuningOptions{}.max_iterations);
  v.device_cache_bytes = 0;
  EXPECT_RESOCT_ERROR(Renderer(tubes(), cpu::make_backend(1), v), ErrorCode::invalid_argument,
                      "device_cache_bytes");
}

// Steady frames (converged, nothing to load) through a reused report.
struct Steady {
  std::set<const void*> buffers;  // distinct pixel buffers the report held
  std::uint64_t allocations = 0;  // image-sized allocations while rendering
};

Steady steady_frames(FrameOutput output, bool reuse) {
  Renderer r(tubes(), cpu::make_backend(2), sync_viewer(output));
  const Scene scene = scene_of(r.source());
  EXPECT_TRUE(r.render_until_converged(scene, 64).converged);
  g_float_bytes = std::size_t(kSize) * kSize * sizeof(glm::vec4);
  g_rgba8_bytes = std::size_t(kSize) * kSize * 4u;
  Steady out;
  FrameReport report;
  for (int i = 0; i < 8; ++i) {
    g_counting = i >= 2;  // the first two frames fill the two alternating buffers
    const std::uint64_t before = g_image_allocations.load();
    if (reuse) {
      r.render_frame(scene, report);
    } else {
      report = r.render_frame(scene);
    }
    g_counting = false;
    if (i >= 2) {
      out.allocations += g_image_allocations.load() - before;
      out.buffers.insert(output == FrameOutput::rgba8
                             ? static_cast<const void*>(report.rgba8.data())
                             : static_cast<const void*>(report.image.pixels().data()));
    }
    EXPECT_TRUE(report.converged);
    EXPECT_EQ(report.width, kSize);
    EXPECT_EQ(report.height, kSize);
  }
  return out;
}

TEST(RendererApi, ReusedReportsAllocateNoImageMemory) {
  if (RESOCT_TEST_SANITIZED) {
    GTEST_SKIP() << "counts allocations by replacing operator new, which the sanitizer's runtime "
                    "defines";
  }
  for (const FrameOutput o :
       {FrameOutput::rgba32f, FrameOutput::rgba8, FrameOutput::both, FrameOutput::device}) {
    const Steady s = steady_frames(o, true);
    EXPECT_EQ(s.allocations, 0u) << to_string(o);
    EXPECT_LE(s.buffers.size(), 2u) << to_string(o);
  }
  // The value form hands each frame's image over and so allocates one per frame, which is what
  // the reused report avoids (and shows that the counting works).
  EXPECT_GE(steady_frames(FrameOutput::rgba32f, false).allocations, 6u);
}

TEST(RendererApi, Rgba8OutputIsTheFloatImageConverted) {
  const auto src = tubes();
  const Scene scene = scene_of(*src);
  Renderer both(src, cpu::make_backend(2), sync_viewer(FrameOutput::both));
  Renderer bytes(src, cpu::make_backend(2), sync_viewer(FrameOutput::rgba8));
  Renderer floats(src, cpu::make_backend(2), sync_viewer(FrameOutput::rgba32f));
  const ConvergeReport a = both.render_until_converged(scene, 64);
  const ConvergeReport b = bytes.render_until_converged(scene, 64);
  const ConvergeReport c = floats.render_until_converged(scene, 64);
  ASSERT_TRUE(a.converged && b.converged && c.converged);
  EXPECT_EQ(a.last.rgba8, a.last.image.to_rgba8());
  EXPECT_EQ(b.last.rgba8, a.last.rgba8);
  EXPECT_EQ(b.last.image.width(), 0u);  // rgba8 alone carries no float image
  EXPECT_EQ(b.last.rgba8.size(), std::size_t(kSize) * kSize * 4u);
  EXPECT_TRUE(c.last.rgba8.empty());
  EXPECT_EQ(c.last.image, a.last.image);
  // The CPU backend's device is the host: output device gives the float image there, as rgba32f.
  Renderer device(src, cpu::make_backend(2), sync_viewer(FrameOutput::device));
  const ConvergeReport d = device.render_until_converged(scene, 64);
  ASSERT_TRUE(d.converged);
  EXPECT_EQ(d.last.image, a.last.image);
  EXPECT_TRUE(d.last.rgba8.empty());
  EXPECT_EQ(d.last.device_image.handle, 0u);
  // Not a blank frame: the tubes cover a few percent of the overview (406 of 9216 pixels).
  std::size_t lit = 0;
  for (std::size_t i = 0; i < b.last.rgba8.size(); i += 4) lit += b.last.rgba8[i] > 20 ? 1u : 0u;
  EXPECT_GT(lit, std::size_t(kSize) * kSize / 50u);
}

}  // namespace
}  // namespace resoct::test
