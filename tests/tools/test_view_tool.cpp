// resoct-view as a process under Xvfb (xvfb-run) on lavapipe: a scripted session on a 2-channel
// procedural volume -- converge, orbit, toggle a channel, change a preset and a colour map, stand
// still until converged -- writes screenshots that differ where they should, and the converged
// screenshot equals resoct-render's image of the same view (the scene the viewer saved) within
// 2/255. The Vulkan session runs with the validation layers and must report no message. Bad input
// fails with one line naming the file, line or parameter, before a window opens.
//
// Without resoct-view (no GLFW at configure time) or without xvfb-run the window tests skip, or
// fail when RESOCT_REQUIRE_VULKAN=1 (CI).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/io/store/test_brick_store_util.hpp"
#include "resoct/backend/image.hpp"
#include "support/generated_data.hpp"
#include "support/tool_process.hpp"
#include "support/vulkan_required.hpp"

using resoct::test::shell_quote;
using resoct::test::TempDir;
using resoct::test::ToolRun;

namespace {

#ifdef RESOCT_VIEW
constexpr const char* kView = RESOCT_VIEW;
#else
constexpr const char* kView = "";
#endif

constexpr const char* kVolume = "procedural:tubes:64x64x64:2";

bool have_xvfb() {
  return std::system("command -v xvfb-run >/dev/null 2>&1") == 0;
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

// Runs the viewer under a fresh virtual X server.
ToolRun view(const TempDir& dir, const std::string& args) {
  return resoct::test::run_tool_process(
      dir.path().string(), "timeout",
      "120 xvfb-run -a -s '-screen 0 1024x768x24' " + shell_quote(kView) + " " + args);
}

// Pixels showing channel 2's magenta (red and blue well above green) and channel 1's green.
struct Colours {
  std::size_t magenta = 0;
  std::size_t green = 0;
  std::size_t white = 0;
};
Colours count_colours(const resoct::Image& img) {
  Colours c;
  for (const glm::vec4& p : img.pixels()) {
    if (p.r > p.g + 0.04f && p.b > p.g + 0.04f) ++c.magenta;
    if (p.g > p.r + 0.04f && p.g > p.b + 0.04f) ++c.green;
    if (p.r > 0.15f && std::abs(p.r - p.g) < 0.02f && std::abs(p.g - p.b) < 0.02f) ++c.white;
  }
  return c;
}

double max_abs_diff(const resoct::Image& a, const resoct::Image& b) {
  const resoct::ImageDiff d = resoct::compare_images(a, b);
  return std::max({d.max_abs.r, d.max_abs.g, d.max_abs.b, d.max_abs.a});
}

class ViewTool : public ::testing::Test {
 protected:
  void SetUp() override {
#ifdef RESOCT_VIEW_NOT_BUILT_BY_CHOICE
    GTEST_SKIP() << "this build leaves out the Vulkan backend, which resoct-view presents with";
#endif
    if (std::string(kView).empty()) {
      RESOCT_SKIP_WITHOUT_VULKAN("resoct-view is not built (GLFW 3 was not found)");
    }
  }
  void require_display() {
    if (!have_xvfb()) RESOCT_SKIP_WITHOUT_VULKAN("xvfb-run is not installed");
  }
};

// The session the issue describes, with the Vulkan backend under validation.
TEST_F(ViewTool, ScriptedSessionMatchesRenderUnderValidation) {
  require_display();
  if (IsSkipped() || HasFatalFailure()) return;
  TempDir dir;
  const auto f = [&](const char* name) { return dir.file(name); };
  write_file(f("session.txt"),
             "# converge, orbit, toggle channel 2, channel 1: preset and colour map\n"
             "wait-converged\n"
             "screenshot " +
                 f("start.png") +
                 "\n"
                 "orbit 50 20\n"
                 "wait 2\n"
                 "wait-converged\n"
                 "screenshot " +
                 f("orbited.png") +
                 "\n"
                 "key 2\n"
                 "wait-converged\n"
                 "screenshot " +
                 f("toggled.png") +
                 "\n"
                 "key 1\n"
                 "key 1\n"
                 "key c\n"
                 "key p\n"
                 "key p\n"
                 "zoom 1.2\n"
                 "wait-converged\n"
                 "screenshot " +
                 f("final.png") +
                 "\n"
                 "save-scene " +
                 f("final.json") +
                 "\n"
                 "# the still view averaged (16 jittered frames), a timepoint key on a volume\n"
                 "# without a t axis (nothing changes), the panel off and on again\n"
                 "wait-accumulated\n"
                 "screenshot " +
                 f("accumulated.png") +
                 "\n"
                 "key t\n"
                 "key T\n"
                 "key f1\n"
                 "key f1\n"
                 "wait 2\n"
                 "quit\n");
  const ToolRun r = view(dir, std::string("--volume ") + kVolume +
                                  " --size 160x120 --backend vulkan --validation --threads 2 "
                                  "--script " +
                                  shell_quote(f("session.txt")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("resoct-view: 0 validation messages"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("resoct-view: validation: "), std::string::npos) << r.err;

  const resoct::Image start = resoct::read_png(f("start.png"));
  const resoct::Image orbited = resoct::read_png(f("orbited.png"));
  const resoct::Image toggled = resoct::read_png(f("toggled.png"));
  const resoct::Image final_img = resoct::read_png(f("final.png"));
  ASSERT_EQ(start.width(), 160u);
  ASSERT_EQ(start.height(), 120u);
  // The orbit changes the picture; both channels show in it.
  EXPECT_GT(max_abs_diff(start, orbited), 0.2);
  const Colours before = count_colours(orbited);
  EXPECT_GT(before.magenta, 50u);
  EXPECT_GT(before.green, 50u);
  // Channel 2 toggled off: its magenta is gone, channel 1's green stays.
  const Colours after = count_colours(toggled);
  EXPECT_EQ(after.magenta, 0u);
  EXPECT_GT(after.green, 50u);
  // Channel 1 (selected by its key, pressed twice: off and on again) in the next colour map
  // (white) and preset (steep), zoomed: no green left, white shows.
  const Colours last = count_colours(final_img);
  EXPECT_EQ(last.green, 0u);
  EXPECT_EQ(last.magenta, 0u);
  EXPECT_GT(last.white, 20u);
  EXPECT_GT(max_abs_diff(toggled, final_img), 0.2);

  // resoct-render renders the saved view; the converged screenshot equals it within 2/255.
  const nlohmann::json scene = nlohmann::json::parse(resoct::test::slurp(f("final.json")));
  EXPECT_EQ(scene["channels"].size(), 1u);
  const ToolRun e = resoct::test::run_tool_process(
      dir.path().string(), RESOCT_RENDER,
      std::string("--volume ") + kVolume + " --scene " + shell_quote(f("final.json")) +
          " --backend vulkan --converge --threads 2 --out " + shell_quote(f("expected.png")));
  ASSERT_EQ(e.exit_code, 0) << e.err;
  const resoct::Image expected = resoct::read_png(f("expected.png"));
  EXPECT_LE(max_abs_diff(final_img, expected), 2.0 / 255.0 + 1e-6);

  // The accumulated still equals resoct-render --accumulate 16 of the same view, and differs
  // from the single frame (the jitter reached the device).
  const ToolRun acc = resoct::test::run_tool_process(
      dir.path().string(), RESOCT_RENDER,
      std::string("--volume ") + kVolume + " --scene " + shell_quote(f("final.json")) +
          " --backend vulkan --converge --accumulate 16 --threads 2 --out " +
          shell_quote(f("expected_acc.png")));
  ASSERT_EQ(acc.exit_code, 0) << acc.err;
  const resoct::Image accumulated = resoct::read_png(f("accumulated.png"));
  const double acc_vs_render = max_abs_diff(accumulated, resoct::read_png(f("expected_acc.png")));
  const double acc_vs_frame = max_abs_diff(accumulated, final_img);
  std::printf("[ view ] accumulated vs resoct-render --accumulate: %.4f, vs one frame: %.4f\n",
              acc_vs_render, acc_vs_frame);
  EXPECT_LE(acc_vs_render, 2.0 / 255.0 + 1e-6);
  EXPECT_GT(acc_vs_frame, 4.0 / 255.0);
}

// The statistics panel (F1) covers only its rectangle at the top-left corner: window
// screenshots with it on and off differ there and nowhere else. Also --half-res-moving.
TEST_F(ViewTool, PanelChangesOnlyItsRectangle) {
  require_display();
  if (IsSkipped() || HasFatalFailure()) return;
  TempDir dir;
  const auto f = [&](const char* name) { return dir.file(name); };
  write_file(f("p.txt"), "wait-converged\nwindow-screenshot " + f("on.png") +
                             "\nkey f1\nwindow-screenshot " + f("off.png") +
                             "\norbit 20 0\nwait 1\nwait-converged\nquit\n");
  const ToolRun r = view(dir, std::string("--volume ") + kVolume +
                                  " --size 480x200 --backend cpu --threads 2 --accumulate 0"
                                  " --half-res-moving --verbose --script " +
                                  shell_quote(f("p.txt")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The orbit's frame is rendered at half the size, the converged one at the full size.
  EXPECT_NE(r.err.find("240x100: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("half resolution"), std::string::npos) << r.err;
  const resoct::Image on = resoct::read_png(f("on.png"));
  const resoct::Image off = resoct::read_png(f("off.png"));
  ASSERT_EQ(on.width(), 480u);
  ASSERT_EQ(off.height(), 200u);
  // The panel: 4 lines of 2x-scaled 5x7 glyphs (18 px per line, 6 px padding) at (8, 8).
  const std::uint32_t x0 = 8, y0 = 8, y1 = 8 + 4 * 18 - 4 + 2 * 6;
  std::size_t inside = 0, outside = 0;
  std::uint32_t min_x = 480, min_y = 200;
  for (std::uint32_t y = 0; y < 200; ++y) {
    for (std::uint32_t x = 0; x < 480; ++x) {
      if (on.at(x, y) == off.at(x, y)) continue;
      min_x = std::min(min_x, x);
      min_y = std::min(min_y, y);
      (x >= x0 && y >= y0 && y < y1 ? inside : outside) += 1;
    }
  }
  EXPECT_EQ(outside, 0u);
  EXPECT_GT(inside, 2000u);
  EXPECT_EQ(min_x, x0);
  EXPECT_EQ(min_y, y0);
}

// Time series: 't' / 'T' step through the timepoints, wrapping.
TEST_F(ViewTool, TimepointKeysStepThroughASeries) {
  require_display();
  if (IsSkipped() || HasFatalFailure()) return;
  const std::string data = resoct::test::python_generated_dir(
      RESOCT_BINARY_DIR "/test-data", "ome-zarr", RESOCT_SOURCE_DIR "/tests/data/make_ome_zarr.py");
  ASSERT_FALSE(data.empty());
  // t = 3 timepoints of 6 x 7 x 8 u8 (tests/data/make_ome_zarr.py).
  const std::string volume = shell_quote(data + "/blosc-lz4-shuffle_leu1_small_tzyx.zarr");
  TempDir dir;
  const auto f = [&](const char* name) { return dir.file(name); };
  write_file(f("t.txt"),
             "wait-converged\nscreenshot " + f("t0.png") + "\nkey t\nwait-converged\nscreenshot " +
                 f("t1.png") + "\nsave-scene " + f("t1.json") +
                 "\nkey T\nkey pageup\nwait-converged\nsave-scene " + f("t2.json") + "\nquit\n");
  const ToolRun r =
      view(dir, "--volume " + volume + " --size 64x64 --backend cpu --threads 2 --script " +
                    shell_quote(f("t.txt")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(resoct::test::slurp(f("t1.json")))["timepoint"], 1);
  EXPECT_EQ(nlohmann::json::parse(resoct::test::slurp(f("t2.json")))["timepoint"], 2);
  EXPECT_GT(max_abs_diff(resoct::read_png(f("t0.png")), resoct::read_png(f("t1.png"))), 0.0);
}

// The CPU backend's frames reach the window through a staging buffer; the converged screenshot
// equals resoct-render's CPU image.
TEST_F(ViewTool, CpuBackendScreenshotMatchesRender) {
  require_display();
  if (IsSkipped() || HasFatalFailure()) return;
  TempDir dir;
  const auto f = [&](const char* name) { return dir.file(name); };
  // --exit-after-frames renders on after the accumulation (4 frames) is done.
  write_file(f("s.txt"),
             "orbit -30 -10\nwait-converged\nsave-scene " + f("s.json") + "\nwait-accumulated\n");
  const ToolRun r =
      view(dir, std::string("--volume ") + kVolume +
                    " --size 96x80 --backend cpu --threads 2 --accumulate 4 --script " +
                    shell_quote(f("s.txt")) + " --exit-after-frames 60" + " --screenshot " +
                    shell_quote(f("cpu.png")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find(", converged"), std::string::npos) << r.err;
  const ToolRun e = resoct::test::run_tool_process(
      dir.path().string(), RESOCT_RENDER,
      std::string("--volume ") + kVolume + " --scene " + shell_quote(f("s.json")) +
          " --converge --accumulate 4 --threads 2 --out " + shell_quote(f("expected.png")));
  ASSERT_EQ(e.exit_code, 0) << e.err;
  EXPECT_LE(max_abs_diff(resoct::read_png(f("cpu.png")), resoct::read_png(f("expected.png"))),
            2.0 / 255.0 + 1e-6);
}

// Bad input fails before any window opens (no display needed): one line, naming the culprit.
TEST_F(ViewTool, BadInputFailsWithOneLine) {
  if (IsSkipped() || HasFatalFailure()) return;
  TempDir dir;
  write_file(dir.file("bad_command.txt"), "wait 1\n\njump 3\n");
  write_file(dir.file("bad_number.txt"), "# comment\norbit 10 x\n");
  write_file(dir.file("bad_key.txt"), "key F13\n");
  write_file(dir.file("bad_wait.txt"), "wait 0\n");
  write_file(dir.file("bad_acc.txt"), "wait-accumulated 0\n");
  write_file(dir.file("bad_shot.txt"), "screenshot " + dir.file("no/such/dir/a.png") + "\n");
  const std::string vol = std::string("--volume ") + kVolume + " ";
  const struct {
    std::string args;
    std::string expect;
  } cases[] = {
      {"--volume " + dir.file("missing.rbs"), "missing.rbs"},
      {vol + "--size 0x100", "size"},
      {vol + "--size 100000x100", "size"},
      {vol + "--size big", "size"},
      {vol + "--backend opengl", "backend"},
      {vol + "--mode fast", "mode"},
      {vol + "--script " + dir.file("nope.txt"), "nope.txt"},
      {vol + "--script " + dir.file("bad_command.txt"),
       "bad_command.txt:3: unknown command 'jump'"},
      {vol + "--script " + dir.file("bad_number.txt"), "bad_number.txt:2: orbit"},
      {vol + "--script " + dir.file("bad_key.txt"), "bad_key.txt:1: key: unknown key 'F13'"},
      {vol + "--script " + dir.file("bad_wait.txt"), "bad_wait.txt:1: wait"},
      {vol + "--script " + dir.file("bad_acc.txt"), "bad_acc.txt:1: wait-accumulated"},
      {vol + "--accumulate 5000", "accumulate"},
      {vol + "--script " + dir.file("bad_shot.txt"), "bad_shot.txt:1"},
      {vol + "--scene " + dir.file("none.json"), "none.json"},
      {vol + "--screenshot " + dir.file("no/dir/x.png"), "no/dir"},
      {vol + "--frobnicate", "frobnicate"},
  };
  for (const auto& c : cases) {
    const ToolRun r = resoct::test::run_tool_process(dir.path().string(), kView, c.args);
    EXPECT_NE(r.exit_code, 0) << c.args;
    EXPECT_NE(r.exit_code, -1) << c.args << ": crashed";
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << ": " << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << c.args << ": not one line: " << r.err;
  }
}

}  // namespace
